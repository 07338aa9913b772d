"""Every dotted name of the package that README.md and docs/*.md quote in backticks
(``ddwmmr.sim.verdict.verdict``, ``ddwmmr.errors.MAX_STEPS``...) exists: a module that
imports, then attributes of it. A user types these into Python; a rename or a move fails
here until the pages follow."""

from __future__ import annotations

import importlib
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
#: Quoted names that are no Python object: the entry-point group of plug-in packages.
NOT_OBJECTS = {"ddwmmr.plugins"}


def quoted_names() -> list[str]:
    found = set()
    for page in PAGES:
        found.update(re.findall(r"`(ddwmmr(?:\.\w+)+)", page.read_text(encoding="utf-8")))
    return sorted(found - NOT_OBJECTS)


def test_the_pages_quote_many_names() -> None:
    assert len(quoted_names()) >= 100


@pytest.mark.parametrize("name", quoted_names())
def test_the_name_exists(name: str) -> None:
    parts = name.split(".")
    for cut in range(len(parts), 0, -1):
        try:
            target = importlib.import_module(".".join(parts[:cut]))
        except ModuleNotFoundError:
            continue
        break
    for attribute in parts[cut:]:
        assert hasattr(target, attribute), f"{'.'.join(parts[:cut])} has no {attribute}"
        target = getattr(target, attribute)
