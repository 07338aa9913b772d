"""Layering rules of the package: controllers never import plants, plants never import
controllers (the simulation loop connects them) -- directly or through other modules."""

import ast
import subprocess
import sys
from pathlib import Path

import ddwmmr

PACKAGE = Path(ddwmmr.__file__).parent
CONTROLLER_SIDE = ("controllers", "qp", "behaviours", "arbiters", "resolution", "mpc")
PLANT_SIDE = ("plants",)


def imported_modules(path: Path) -> set[str]:
    """Every module named in an import statement of a source file (``from a import b``
    names ``a`` and, when it is a module of the package, ``a.b``)."""
    names: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module:
            names.add(node.module)
            names.update(f"{node.module}.{alias.name}" for alias in node.names)
    return names


def module_file(name: str) -> Path | None:
    """The source file of package module ``name`` (None outside the package)."""
    if not name.startswith("ddwmmr"):
        return None
    parts = name.split(".")[1:]
    base = PACKAGE.joinpath(*parts)
    for candidate in (base.with_suffix(".py"), base / "__init__.py"):
        if candidate.is_file():
            return candidate
    return None


def module_name(path: Path) -> str:
    relative = path.relative_to(PACKAGE.parent).with_suffix("")
    parts = relative.parts[:-1] if relative.name == "__init__" else relative.parts
    return ".".join(parts)


def reachable(path: Path) -> set[str]:
    """Package modules imported by ``path`` directly or through other package modules
    (parents of a module count: importing ``a.b`` runs ``a/__init__.py``; the top-level
    ``ddwmmr/__init__.py`` does not: it is the public API that gathers every layer)."""
    seen: set[str] = set()
    todo = [path]
    while todo:
        current = todo.pop()
        for name in imported_modules(current):
            pieces = name.split(".")
            for i in range(2, len(pieces) + 1):
                prefix = ".".join(pieces[:i])
                target = module_file(prefix)
                if target is not None and prefix not in seen:
                    seen.add(prefix)
                    todo.append(target)
    return seen


def sources(folders: tuple[str, ...]) -> list[Path]:
    return [path for folder in folders for path in sorted((PACKAGE / folder).rglob("*.py"))]


def test_controllers_never_import_plants():
    for source in sources(CONTROLLER_SIDE):
        bad = {m for m in reachable(source) if m.startswith("ddwmmr.plants")}
        assert not bad, f"{module_name(source)} reaches {sorted(bad)}"


def test_plants_never_import_controllers():
    forbidden = tuple(f"ddwmmr.{name}" for name in CONTROLLER_SIDE)
    for source in sources(PLANT_SIDE):
        bad = {m for m in reachable(source) if m.startswith(forbidden)}
        assert not bad, f"{module_name(source)} reaches {sorted(bad)}"


def test_the_rule_checker_sees_imports(tmp_path):
    sample = tmp_path / "sample.py"
    sample.write_text("import ddwmmr.plants.kinematic\nfrom ddwmmr.plants import thesis\n")
    assert imported_modules(sample) >= {"ddwmmr.plants.kinematic", "ddwmmr.plants.thesis"}


def test_the_rule_checker_follows_indirect_imports(tmp_path):
    """A module that imports the symbolic model reaches everything that model imports."""
    sample = tmp_path / "sample.py"
    sample.write_text("from ddwmmr.model.symbolic import ThesisDynamics\n")
    found = reachable(sample)
    assert "ddwmmr.model.symbolic" in found and "ddwmmr.model.thesis_base" in found
    assert not any(m.startswith("ddwmmr.plants") for m in found)


def test_the_method_registry_does_not_import_python_control():
    """python-control (with scipy.signal) takes most of a second to import; only designing
    an MPC terminal cost needs it, so listing or building another method must not pay it."""
    code = (
        "import sys; from ddwmmr import Robot, make_controller; "
        "from ddwmmr.controllers import available_methods; "
        "names = available_methods(); make_controller('ats', Robot()); "
        "print('mpc' in names, 'control' in sys.modules)"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=120
    )
    assert out.stdout.split() == ["True", "False"]
