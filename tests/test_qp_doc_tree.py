"""docs/qp.md's "Architecture" tree is the package as it is: every module of
``src/ddwmmr/qp`` is listed, and every class and function the tree names beside a module
is defined there (a module added, moved or renamed fails here until the tree follows)."""

from __future__ import annotations

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "src" / "ddwmmr" / "qp"


def _tree() -> dict[str, list[str]]:
    """Module path (relative to the package) -> the names written on its lines."""
    text = (ROOT / "docs" / "qp.md").read_text(encoding="utf-8")
    block = text.split("```text\nsrc/ddwmmr/qp/\n", 1)[1].split("```", 1)[0]
    listed: dict[str, list[str]] = {}
    folder, module = "", None
    for line in block.splitlines():
        entry = re.match(r"( *)(\S+)(.*)", line)
        if entry is None:
            continue
        indent, name, rest = len(entry[1]), entry[2], entry[3]
        if name.endswith("/"):
            folder, module = name, None
            continue
        if name.endswith(".py"):
            module = (folder if indent > 2 else "") + name
            folder = folder if indent > 2 else ""
            listed[module] = []
        else:
            rest = line  # a continuation line of the module above
        if module is not None:
            # before its ':' or ';': CamelCase classes (not acronyms such as QP), snake_case
            # functions and any name called with parentheses; parenthesised notes left out
            head = re.split(r"[:;]", rest)[0]
            called = re.findall(r"\b([a-z_]+)\(", head)
            words = re.sub(r"\([^)]*\)?", "", head)
            found = re.findall(r"\b[A-Z][a-z]\w*\b|\b[a-z]+_[a-z_]+\b", words)
            listed[module] += called + found
    return listed


def _defined(module: Path) -> set[str]:
    tree = ast.parse(module.read_text(encoding="utf-8"))
    return {n.name for n in tree.body if isinstance(n, ast.ClassDef | ast.FunctionDef)}


def test_every_module_is_in_the_tree() -> None:
    modules = {
        p.relative_to(PACKAGE).as_posix() for p in PACKAGE.rglob("*.py") if p.name != "__init__.py"
    }
    assert set(_tree()) == modules


def test_the_names_beside_a_module_are_defined_in_it() -> None:
    listed = _tree()
    assert sum(len(names) for names in listed.values()) >= 20  # the parser found them
    missing = {
        module: sorted(set(names) - _defined(PACKAGE / module))
        for module, names in listed.items()
        if set(names) - _defined(PACKAGE / module)
    }
    assert missing == {}
