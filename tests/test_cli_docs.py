"""docs/cli.md's option table of ``track`` lists exactly the options its parser has.

The table is written by hand (its cells say more than ``--help`` does); this keeps it from
drifting: an option added to, renamed in or removed from :func:`ddwmmr.cli.track.build_parser`
fails here until the table follows.
"""

from __future__ import annotations

import re
from pathlib import Path

from ddwmmr.cli.track import build_parser

CLI_DOC = Path(__file__).resolve().parents[1] / "docs" / "cli.md"


def _section(text: str, heading: str) -> str:
    """The text of the section under ``heading`` up to the next heading of its level."""
    start = text.index(heading + "\n")
    level = heading.split(" ", 1)[0]
    rest = text[start + len(heading) + 1 :]
    end = re.search(rf"^{level} ", rest, flags=re.MULTILINE)
    return rest[: end.start()] if end else rest


def _table_options(section: str) -> set[str]:
    """The ``--option`` names in the first cell of each row of the section's tables."""
    names = set()
    for line in section.splitlines():
        if line.startswith("| `--"):
            first_cell = line.split(" | ", 1)[0]
            names.update(re.findall(r"`(--[a-z][a-z0-9-]*)", first_cell))
    return names


def test_track_option_table_matches_the_parser():
    parser_options = {
        option
        for action in build_parser()._actions
        for option in action.option_strings
        if option.startswith("--") and option != "--help"
    }
    section = _section(CLI_DOC.read_text(encoding="utf-8"), "## `python -m ddwmmr.track`")
    documented = _table_options(section)
    assert len(documented) >= 20
    assert documented - parser_options == set(), "documented but not in the parser"
    assert parser_options - documented == set(), "in the parser but not in docs/cli.md"
