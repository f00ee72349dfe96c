"""The documentation says what the code does: every lesson of the Presets menu has its row in
docs/guide/lessons.md, and every controller the window builds is listed in
docs/developer/window.md."""
from __future__ import annotations

import ast
import pathlib
import re

from feelflow.app.model.presets import PRESETS

ROOT = pathlib.Path(__file__).resolve().parents[1]


def test_every_lesson_is_in_the_lessons_guide():
    text = (ROOT / "docs" / "guide" / "lessons.md").read_text()
    missing = [lesson.title for lesson in PRESETS.values() if f"*{lesson.title}*" not in text]
    assert missing == []


def test_every_controller_the_window_builds_is_documented():
    tree = ast.parse((ROOT / "app" / "gui" / "main_window.py").read_text())
    built = {t.attr for node in ast.walk(tree) if isinstance(node, ast.Assign)
             for t in node.targets if isinstance(t, ast.Attribute) and isinstance(node.value, ast.Call)
             and isinstance(node.value.func, ast.Name) and node.value.func.id.endswith("Controller")}
    documented = set(re.findall(r"\| `window\.(\w+)` \|", (ROOT / "docs" / "developer" / "window.md").read_text()))
    assert built and built <= documented, built - documented
