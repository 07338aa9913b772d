"""The API reference of the documentation site (docs/reference/, built by ``make
docs-site``) covers every public module of the package: a module added to src/ddwmmr
without a page would be missing from the site without the strict build noticing."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "src" / "ddwmmr"

#: ``python -m`` shims whose whole content is a call of the module they name.
SHIMS = {"ddwmmr.compare", "ddwmmr.track", "ddwmmr.__main__"}


def documented_targets() -> set[str]:
    """The ``::: module`` targets of the reference pages."""
    pages = (ROOT / "docs" / "reference").glob("*.md")
    return {m for page in pages for m in re.findall(r"^::: ([\w.]+)", page.read_text(), re.M)}


def public_modules() -> set[str]:
    modules = set()
    for path in PACKAGE.rglob("*.py"):
        parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        if any(part.startswith("_") and part != "__main__" for part in parts):
            continue
        modules.add(".".join(parts))
    return modules - SHIMS - {"ddwmmr"}


def test_every_public_module_is_in_the_api_reference():
    targets = documented_targets() - {"ddwmmr"}  # the package page lists no submodules
    missing = sorted(
        module
        for module in public_modules()
        if not any(module == t or module.startswith(t + ".") for t in targets)
    )
    assert missing == []


def test_the_reference_targets_exist():
    modules = public_modules() | {"ddwmmr"}
    assert documented_targets() <= modules
