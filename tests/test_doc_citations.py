"""Citations of the docs cannot rot: every section the code cites exists.

The code cites the project's own documentation as ``(docs/theory.md, "Tip-over stability")``
(a section's title, with or without its number, or a paragraph's bold run-in title) or as
``docs/theory.md#tip-over-stability`` (a heading's GitHub anchor). This test reads every
such citation in ``src/``, the trajectory files and the docs pages (there also as a link,
``[page.md](page.md), "Title"``), and every ``page.md#anchor`` link between the pages, and
checks it against the headings of ``docs/*.md``. It also checks that nothing cites the
original specification or the seed material, which are not part of the repository.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
CITING = (ROOT / "src", ROOT / "trajectories", DOCS)
SUFFIXES = {".py", ".toml", ".csv", ".md"}

#: ``docs/page.md`` (or a link to it, ``[...](page.md)``) then ``#anchor``, or ``, "Title"``
#: (more titles joined by ``and``).
CITATION = re.compile(
    r"(?:docs/|\]\()(?P<page>[\w-]+\.md)\)?"
    r'(?:#(?P<anchor>[\w-]+)|,?\s*(?P<titles>"[^"\n]+"(?:\s+and\s+"[^"\n]+")*))'
)
#: Markdown links between docs pages: ``(page.md#anchor)`` or ``(#anchor)``.
LINK = re.compile(r"\]\((?P<page>[\w-]+\.md)?#(?P<anchor>[\w-]+)\)")
#: Citations of material outside the repository (built so this file does not match itself).
EXTERNAL = re.compile(r"\b" + "SP" + r"EC\b|\bseeds?[ /]0\d\d")


def _headings(page: Path) -> tuple[list[str], list[str]]:
    """Heading titles of a markdown page, and its run-in titles (a paragraph opening with a
    bold label, as ``**Limits** (...)``: citable by name, but without an anchor). Fenced
    code blocks are skipped."""
    titles, run_in, fenced = [], [], False
    for line in page.read_text(encoding="utf-8").splitlines():
        if line.startswith("```"):
            fenced = not fenced
        elif not fenced and re.match(r"#{1,6} ", line):
            titles.append(line.lstrip("#").strip())
        elif not fenced and (label := re.match(r"\*\*([^*]+?)\.?\*\*", line)):
            run_in.append(label[1])
    return titles, run_in


def _plain(title: str) -> str:
    """A title without backticks and without a leading section number ("3. ")."""
    return re.sub(r"^\d+\.\s+", "", title.replace("`", "")).strip()


def _anchor(title: str) -> str:
    """GitHub's anchor of a heading: lower case, punctuation dropped, spaces to hyphens."""
    return re.sub(r"[^\w\- ]", "", title.lower()).replace(" ", "-")


def _sections() -> dict[str, tuple[set[str], set[str]]]:
    """Per page: the set of citable titles and the set of anchors."""
    sections = {}
    for page in sorted(DOCS.glob("*.md")):
        titles, run_in = _headings(page)
        names = {_plain(t) for t in titles + run_in} | {t.replace("`", "") for t in titles}
        sections[page.name] = (names, {_anchor(t) for t in titles})
    return sections


def _joined(text: str) -> str:
    """The text with line breaks (and the comment markers after them) turned into spaces, so
    that a title wrapped over two lines of a docstring or comment reads as one."""
    return re.sub(r"\s*\n\s*(?:#:?\s+)?", " ", text)


def _citing_files() -> list[Path]:
    return sorted(
        path
        for folder in CITING
        for path in folder.rglob("*")
        if path.suffix in SUFFIXES and path.is_file()
    )


def _citations() -> list[tuple[str, str, str, str]]:
    """(file, page, kind, name) for every citation in the citing files."""
    found = []
    for path in _citing_files():
        text = _joined(path.read_text(encoding="utf-8"))
        for match in CITATION.finditer(text):
            where = str(path.relative_to(ROOT))
            if match["anchor"]:
                found.append((where, match["page"], "anchor", match["anchor"]))
            elif match["titles"]:
                for title in re.findall(r'"([^"]+)"', match["titles"]):
                    found.append((where, match["page"], "title", title))
    return found


def test_the_code_cites_sections_of_the_docs():
    # Guards the parser: the code cites many sections, of several pages.
    citations = _citations()
    assert len(citations) >= 40
    assert {page for _, page, _, _ in citations} >= {"theory.md", "thesis.md", "qp.md", "mpc.md"}


def test_every_cited_section_exists():
    sections = _sections()
    missing = []
    for where, page, kind, name in _citations():
        if page not in sections:
            missing.append(f"{where}: docs/{page} does not exist")
            continue
        names, anchors = sections[page]
        if kind == "anchor" and name not in anchors:
            missing.append(f"{where}: docs/{page}#{name} is no heading's anchor")
        if kind == "title" and _plain(name) not in names and name not in names:
            missing.append(f'{where}: docs/{page} has no section "{name}"')
    assert not missing, "\n".join(missing)


def test_every_anchor_link_between_docs_pages_exists():
    sections = _sections()
    missing = []
    for page in sorted(DOCS.glob("*.md")):
        for match in LINK.finditer(page.read_text(encoding="utf-8")):
            target = match["page"] or page.name
            if target in sections and match["anchor"] not in sections[target][1]:
                missing.append(f"docs/{page.name}: {target}#{match['anchor']}")
    assert not missing, "\n".join(missing)


@pytest.mark.parametrize("folder", ["src", "tests", "docs", "trajectories", "examples"])
def test_nothing_cites_material_outside_the_repository(folder):
    this = Path(__file__).resolve()
    offenders = [
        f"{path.relative_to(ROOT)}:{number}: {line.strip()}"
        for path in sorted((ROOT / folder).rglob("*"))
        if path.suffix in SUFFIXES and path.is_file() and path.resolve() != this
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1)
        if EXTERNAL.search(line)
    ]
    assert not offenders, "\n".join(offenders)


@pytest.mark.parametrize(
    ("title", "anchor"),
    [
        ("1. Model", "1-model"),
        ("`pi`: pseudoinverse (RR-PI)", "pi-pseudoinverse-rr-pi"),
        ("Results: thesis Table 5.2", "results-thesis-table-52"),
        ("Threshold studies (thesis Tables 5.5–5.20)", "threshold-studies-thesis-tables-55520"),
    ],
)
def test_anchors_follow_github(title, anchor):
    # GitHub keeps letters, digits, hyphens and underscores, drops the rest, and turns each
    # space into a hyphen.
    assert _anchor(title) == anchor
