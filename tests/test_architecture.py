"""House rules: the core never imports Qt (import-linter contract in pyproject.toml);
GLSL lives in shaders/*.glsl, never in Python strings; no pickle."""
import pathlib
import re
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[1]


def test_import_linter_contracts_hold():
    exe = pathlib.Path(sys.executable).with_name("lint-imports")
    result = subprocess.run([str(exe)], cwd=ROOT, capture_output=True, text=True)
    assert result.returncode == 0, result.stdout + result.stderr


def test_no_glsl_in_python_and_no_pickle():
    offenders = []
    for path in ROOT.glob("*/**/*.py"):
        if path.parts[len(ROOT.parts)] in {".venv", "tests", "build"}:
            continue
        text = path.read_text()
        if re.search(r"#version \d{3}", text) or "import pickle" in text or "allow_pickle=True" in text:
            offenders.append(str(path.relative_to(ROOT)))
    assert offenders == []


def test_installed_pyside6_does_not_drop_references_to_none():
    """The pinned PySide6 must not have the 6.12.0 defect (app/gui/qt_runtime.py): a void call
    leaves None's reference count where it was."""
    from feelflow.app.gui.qt_runtime import none_refcount_leak_per_call

    assert none_refcount_leak_per_call() == 0
