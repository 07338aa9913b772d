"""Layering rules of the package: an explicit layer order that imports only ever go down
(or stay within a layer), and controllers never import plants, plants never import
controllers (the simulation loop connects them) -- directly or through other modules."""

import ast
import functools
import subprocess
import sys
from pathlib import Path

import ddwmmr

PACKAGE = Path(ddwmmr.__file__).parent
CONTROLLER_SIDE = (
    "controllers",
    "qp",
    "behaviours",
    "arbiters",
    "resolution",
    "mpc",
    "thesis_controller.py",
)

#: The layers, lowest first, each with the modules and packages it holds (a package holds
#: its modules). A module may import from its own layer and the layers below, never from
#: a layer above. The top holds the entry points: the package itself (the public API that
#: gathers every layer) and the ``python -m`` shims (any ``__main__`` module, ``track``,
#: ``compare``), which only hand over to the command lines.
LAYERS: tuple[tuple[str, tuple[str, ...]], ...] = (
    (
        "foundation",
        (
            "_version",
            "errors",
            "interrupts",
            "inheritance",
            "commands",
            "gains",
            "progress",
            "outputs",
            "workers",
            "user_warnings",
        ),
    ),
    ("registry", ("registry",)),
    ("model", ("model", "trajectories")),
    ("resolution", ("resolution",)),
    ("controllers", ("controllers", "behaviours")),
    ("qp", ("qp",)),
    ("mpc", ("mpc",)),
    ("arbiters", ("arbiters",)),
    ("thesis controller", ("thesis_controller",)),
    ("plants", ("plants",)),
    ("simulation", ("sim",)),
    ("records and reports", ("provenance", "reports")),
    ("scenarios", ("scenarios",)),
    ("benchmark", ("bench", "bounds")),
    ("gui", ("gui",)),
    ("command lines", ("cli",)),
    ("entry points", ("", "__main__", "track", "compare")),
)
PLANT_SIDE = ("plants",)


def imported_modules(path: Path) -> set[str]:
    """Every module named in an import statement of a source file (``from a import b``
    names ``a`` and, when it is a module of the package, ``a.b``)."""
    return set(_names_imported_by(path.read_text()))


@functools.cache
def _parsed(source: str) -> ast.Module:
    """The syntax tree of a file's text, cached on the text: every reachable() walk and
    the layer rule parse the same package modules again (the trees are only read)."""
    return ast.parse(source)


@functools.cache
def _names_imported_by(source: str) -> frozenset[str]:
    """imported_modules of a file's text (cached, as _parsed)."""
    names: set[str] = set()
    for node in ast.walk(_parsed(source)):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module:
            names.add(node.module)
            names.update(f"{node.module}.{alias.name}" for alias in node.names)
    return frozenset(names)


@functools.cache
def module_file(name: str, package: Path = PACKAGE) -> Path | None:
    """The source file of package module ``name`` (None outside the package). Cached: the
    package's files do not change while the tests run (each sample package of a test is a
    folder of its own)."""
    if name != "ddwmmr" and not name.startswith("ddwmmr."):
        return None
    parts = name.split(".")[1:]
    base = package.joinpath(*parts)
    for candidate in (base.with_suffix(".py"), base / "__init__.py"):
        if candidate.is_file():
            return candidate
    return None


def module_name(path: Path, package: Path = PACKAGE) -> str:
    relative = path.relative_to(package.parent).with_suffix("")
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
    """The source files of package folders (or single modules: ``name.py``)."""
    found = []
    for folder in folders:
        target = PACKAGE / folder
        found += [target] if target.suffix == ".py" else sorted(target.rglob("*.py"))
    return found


def layer_of(module: str, layers=LAYERS) -> int | None:
    """Index in ``layers`` of a package module (``ddwmmr.a.b``): every ``__main__`` module
    is an entry point, the package itself is where ``""`` is listed; otherwise the layer
    listing the longest prefix of its name (None: no layer lists it)."""
    parts = module.split(".")[1:]
    if parts and parts[-1] == "__main__":
        return len(layers) - 1
    best: tuple[int, int] | None = None
    for index, (_, members) in enumerate(layers):
        for member in members:
            if not member:  # the package itself
                if not parts:
                    return index
                continue
            prefix = member.split(".")
            if parts[: len(prefix)] == prefix and (best is None or len(prefix) > best[0]):
                best = (len(prefix), index)
    return None if best is None else best[1]


def import_targets(path: Path, package: Path = PACKAGE) -> set[str]:
    """The package modules a source file imports directly: ``from a import b`` imports the
    module ``a.b`` when there is one, else (a name defined in ``a``) the module ``a``; so
    ``from ddwmmr import sim`` imports ``ddwmmr.sim`` and ``from ddwmmr import
    __version__`` the package itself. Imports inside functions and under TYPE_CHECKING
    count: they are dependencies all the same."""
    targets: set[str] = set()
    for node in ast.walk(_parsed(path.read_text())):
        if isinstance(node, ast.Import):
            targets.update(a.name for a in node.names if module_file(a.name, package))
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            for alias in node.names:
                name = f"{node.module}.{alias.name}"
                if module_file(name, package):
                    targets.add(name)
                elif module_file(node.module, package):
                    targets.add(node.module)
    return targets


def upward_imports(package: Path = PACKAGE, layers=LAYERS) -> list[str]:
    """Every import of the package that goes to a higher layer, as ``a -> b``."""
    found = []
    for path in sorted(package.rglob("*.py")):
        source = module_name(path, package)
        for target in sorted(import_targets(path, package)):
            if layer_of(target, layers) > layer_of(source, layers):
                found.append(f"{source} -> {target}")
    return found


def test_every_module_has_a_layer():
    unplaced = [module_name(p) for p in PACKAGE.rglob("*.py") if layer_of(module_name(p)) is None]
    assert not unplaced, f"modules in no layer of LAYERS: {sorted(unplaced)}"


def test_imports_never_go_to_a_higher_layer():
    upward = upward_imports()
    assert not upward, "imports up the layers of LAYERS:\n" + "\n".join(upward)


def test_the_layer_rule_sees_an_upward_import(tmp_path):
    """A low module that imports a command line, or the package for its version, is caught;
    a module imported by name through the package (``from ddwmmr import sim``) is not the
    package."""
    package = tmp_path / "ddwmmr"
    (package / "cli").mkdir(parents=True)
    for name in ("__init__.py", "sim.py", "cli/__init__.py", "cli/common.py", "cli/__main__.py"):
        (package / name).write_text("")
    (package / "outputs.py").write_text(
        "from ddwmmr.cli.common import ArgumentParser\nfrom ddwmmr import __version__\n"
    )
    (package / "sim.py").write_text("from ddwmmr import outputs\n")
    (package / "cli" / "__main__.py").write_text("from ddwmmr.cli import common\n")
    layers = (("low", ("outputs",)), ("sim", ("sim",)), ("cli", ("cli",)), ("top", ("",)))
    found = upward_imports(package, layers)
    assert found == ["ddwmmr.outputs -> ddwmmr", "ddwmmr.outputs -> ddwmmr.cli.common"]


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
