"""Layering rules of the package: controllers never import plants, plants never import
controllers (the simulation loops connect them)."""

import ast
from pathlib import Path

import ddwmmr

PACKAGE = Path(ddwmmr.__file__).parent
CONTROLLER_SIDE = ("controllers", "qp", "behaviours", "arbiters", "resolution")
PLANT_SIDE = ("plants",)


def imported_modules(path: Path) -> set[str]:
    """Every module named in an import statement of a source file."""
    names: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module:
            names.add(node.module)
    return names


def imports_of(folders: tuple[str, ...]) -> dict[str, set[str]]:
    return {
        str(path.relative_to(PACKAGE)): imported_modules(path)
        for folder in folders
        for path in (PACKAGE / folder).rglob("*.py")
    }


def test_controllers_never_import_plants():
    for source, modules in imports_of(CONTROLLER_SIDE).items():
        bad = {m for m in modules if m.startswith("ddwmmr.plants")}
        assert not bad, f"{source} imports {bad}"


def test_plants_never_import_controllers():
    forbidden = tuple(f"ddwmmr.{name}" for name in CONTROLLER_SIDE)
    for source, modules in imports_of(PLANT_SIDE).items():
        bad = {m for m in modules if m.startswith(forbidden)}
        assert not bad, f"{source} imports {bad}"


def test_the_rule_checker_sees_imports(tmp_path):
    sample = tmp_path / "sample.py"
    sample.write_text("import ddwmmr.plants.kinematic\nfrom ddwmmr.plants import thesis\n")
    assert imported_modules(sample) == {"ddwmmr.plants.kinematic", "ddwmmr.plants"}
