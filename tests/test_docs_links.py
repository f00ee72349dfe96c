"""Every relative link in README.md, CHANGELOG.md and docs/**/*.md points at a file or folder
that exists, and the docs carry no work diary (numbered rounds, issue numbers, paths outside the
repository)."""
from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

#: pages other branches add; a link to them is fine before they land
PENDING = {
    "docs/guide/installing.md",
    "docs/guide/exercises.md",
    "docs/reference/exercise-format.md",
    "docs/reference/files.md",
    "docs/science/gl-backend.md",
    "docs/science/cpu-backend.md",
}

#: [text](target) and ![alt](target); the target ends at whitespace or ')'
LINK = re.compile(r"!?\[[^\]]*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
CODE = re.compile(r"```.*?```|`[^`\n]*`", re.S)

DIARY = re.compile(
    r"(first|second|third|[a-z]+th|twenty-[a-z]+) session|sessions? [0-9]|session [0-9]+ ?[-–]"
    r"|\bround [0-9]|docs/bench/s[0-9]|\bissue #?[0-9]+|\.\./shared|/work/|shared/(seed|reference|notes)",
    re.I)


def pages() -> list[Path]:
    return [ROOT / "README.md", ROOT / "CHANGELOG.md", *sorted((ROOT / "docs").rglob("*.md"))]


def relative_links(text: str) -> list[str]:
    """The relative link targets of a Markdown text, without their #anchors; code is skipped."""
    out = []
    for target in LINK.findall(CODE.sub("", text)):
        if re.match(r"^[a-z][a-z0-9+.-]*:", target, re.I) or target.startswith("#"):
            continue  # http:, mailto:, ... or an anchor on the same page
        out.append(target.split("#", 1)[0])
    return out


def test_link_pattern_finds_links_and_skips_the_rest():
    text = ("See [a](docs/a.md#x), ![pic](img/p.png \"title\"), [web](https://x.org), [here](#top) "
            "and `[code](not/a/link.md)`.")
    assert relative_links(text) == ["docs/a.md", "img/p.png"]


@pytest.mark.parametrize("page", pages(), ids=lambda p: str(p.relative_to(ROOT)))
def test_relative_links_resolve(page):
    missing = []
    for target in relative_links(page.read_text(encoding="utf-8")):
        path = (page.parent / target).resolve()
        rel = path.relative_to(ROOT).as_posix() if path.is_relative_to(ROOT) else str(path)
        if not path.exists() and rel not in PENDING:
            missing.append(target)
    assert not missing, f"{page.relative_to(ROOT)}: links to missing files: {missing}"


@pytest.mark.parametrize("page", pages(), ids=lambda p: str(p.relative_to(ROOT)))
def test_no_work_diary(page):
    hits = [m.group(0) for m in DIARY.finditer(page.read_text(encoding="utf-8"))]
    assert not hits, f"{page.relative_to(ROOT)}: {hits}"
