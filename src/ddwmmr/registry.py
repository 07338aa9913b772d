"""Plug-in registries: the controllers, plants and arbiters every tool finds by name.

A plug-in is one class in one file, registered by its kind's decorator right above it::

    from ddwmmr.registry import register_controller

    @register_controller("p-only")
    class ProportionalOnly:
        \"\"\"Task-space P control without feed-forward.\"\"\"  # the description
        ...

The name, the first line of the class docstring (its description) and the traits given to
the decorator are what the tools list: ``track``, ``compare``, ``scenarios`` and ``bench``
take their choices and their ``--help`` from here, and so does the GUI.
:func:`ddwmmr.make_controller`, :func:`ddwmmr.plants.make_plant` and
:func:`ddwmmr.arbiters.make_arbiter` build a plug-in by name. The decorators and their
traits:

* :func:`register_controller` (``tasks``: ``"tracking"``, following a trajectory, and/or
  ``"waypoints"``, the scenario protocol's waypoint task, for which the class provides
  ``waypoint_options(run)``, see :class:`ddwmmr.controllers.base.WaypointRun`;
  ``interfaces``: the command interfaces it can send, ``"velocity"`` and/or ``"force"``
  (the decorator sets the class attribute of that name, which the simulation loop reads:
  :func:`ddwmmr.sim.loop.check_interface`); ``arbiter``: True when it takes an
  ``arbiter`` option and reports the arbiter's state);
* :func:`register_plant` (``interfaces``: the command interfaces it accepts; the decorator
  sets the class attribute of that name);
* :func:`register_arbiter` (no traits; built as ``cls(stability=..., manipulability=...)``,
  plus ``seed=`` when its constructor takes one).

A trait's value is checked when the class is registered (a tuple trait: a non-empty tuple,
or list, of the words above; ``arbiter``: a bool); anything else is a one-line
:class:`~ddwmmr.errors.ParameterError` naming the trait, and so is a keyword the decorator
does not take (:meth:`Registry.keywords`: its traits and ``description``), naming it.

Every decorator sets the class attribute ``name``. A name is what the command line types
(``--method NAME``, ``--option NAME:KEY=VALUE``, comma-separated lists, the run folder
``runs/NAME-...``), so it must match :data:`NAME_PATTERN`: 1 to :data:`MAX_NAME_LENGTH`
ASCII letters, digits, ``_``, ``-`` and ``.``, not starting with ``-`` or ``.`` (no space,
comma, colon or ``=``); any other name is refused when it is registered. Where plug-ins
come from:

* built in: the modules of :data:`BUILTIN_MODULES`, in that order (the order of every
  listing). Their decorators and docstrings are read from the source, without importing
  the module: a module is imported when one of its plug-ins is built or its class is asked
  for (importing the MuJoCo plant takes about 0.4 s, which listing the plants must not
  cost). Their decorators therefore take literal arguments only;
* other installed packages: the modules their ``ddwmmr.plugins`` entry points name;
* one-file plug-ins: the modules named in the environment variable ``DDWMMR_PLUGINS``
  (comma separated, importable from ``sys.path``);
* any module imported before a registry is asked (registration happens on import).

Entry points and ``DDWMMR_PLUGINS`` are imported the first time a registry is asked. A
run's record names the modules of the plug-ins it used (:func:`used_plugins`; a plug-in a
script registered in its own ``__main__`` by the script's path, which ``DDWMMR_PLUGINS``
cannot load: :func:`plugin_source`), and an unknown name's error says how plug-ins are
loaded (:func:`unknown_hint`).
"""

from __future__ import annotations

import ast
import importlib
import inspect
import os
import re
import sys
import threading
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from itertools import count
from pathlib import Path
from typing import Any, TypeVar, cast

from ddwmmr.errors import ParameterError, did_you_mean, one_line, raise_plugin_error, shown
from ddwmmr.inheritance import class_from_library

#: The built-in plug-in modules, in listing order.
BUILTIN_MODULES = (
    "ddwmmr.thesis_controller",
    "ddwmmr.controllers.resolved_rate",
    "ddwmmr.controllers.clrrmc",
    "ddwmmr.qp.controller",
    "ddwmmr.mpc.controller",
    "ddwmmr.plants.kinematic",
    "ddwmmr.plants.thesis",
    "ddwmmr.plants.mujoco.plant",
    "ddwmmr.arbiters.state_machine",
    "ddwmmr.arbiters.competitive",
)
#: Environment variable naming plug-in modules to import (comma separated).
PLUGINS_VARIABLE = "DDWMMR_PLUGINS"
#: How an error for an unknown name says plug-ins are loaded (:func:`unknown_hint`).
PLUGINS_HINT = (
    f"a plug-in's name is known once its module is imported: {PLUGINS_VARIABLE}=MODULE "
    '(docs/api.md, "Extending")'
)
#: What a run's record names as the source of a plug-in registered in a ``__main__``
#: without a file (``python -c``, an interactive session, a notebook): :func:`plugin_source`.
INTERACTIVE = "<interactive>"
#: A module name ``DDWMMR_PLUGINS`` can import: dotted identifiers (:func:`loadable`).
MODULE_PATTERN = re.compile(r"[^\W\d]\w*(?:\.[^\W\d]\w*)*")
#: How to run again a plug-in a script registered in its own ``__main__``.
SCRIPT_ADVICE = (
    "repeat the run in a process that registers it first (the script, then the tool's "
    f"main() with the recorded argv), or move the class into a module named in {PLUGINS_VARIABLE} "
    '(docs/api.md, "Extending")'
)
#: Entry-point group of plug-in modules of other packages.
ENTRY_POINT_GROUP = "ddwmmr.plugins"
#: Longest plug-in name (characters): it becomes part of a run folder's name.
MAX_NAME_LENGTH = 64
#: The plug-in names the command line can address (see the module docstring): the shell
#: splits words at whitespace, argparse reads a value starting with ``-`` as an option,
#: the option parsers split at ``,`` (lists), ``:`` (``METHOD:KEY=VALUE``) and ``=``, and
#: a leading ``.`` would hide the run folder.
NAME_PATTERN = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.-]*")
#: The allowed form of a name, as the messages word it.
NAME_FORM = (
    f"1 to {MAX_NAME_LENGTH} ASCII letters, digits, '_', '-' or '.', not starting with '-' or '.'"
)
_PACKAGE = Path(__file__).parent
#: A plug-in class: a decorator returns the class it was given, so type checkers keep the
#: class's own type (its constructor and members) instead of a bare ``type``.
PluginClass = TypeVar("PluginClass", bound=type)


@dataclass
class Entry:
    """One registered plug-in.

    Attributes:
        name: what the tools and the factories call it.
        description: first line of its class docstring ("(no description)" without one).
        traits: the decorator's keyword arguments over the kind's defaults.
        module, qualname: where its class is defined.
        cls: the class, None until its module is imported.
    """

    name: str
    description: str
    traits: dict[str, Any]
    module: str
    qualname: str
    cls: type | None = None
    order: tuple[int, int, int] = field(default=(1, 0, 0), repr=False)


class Registry:
    """The plug-ins of one kind, by name, in listing order.

    Args:
        kind: ``"controller"``, ``"plant"`` or ``"arbiter"`` (the decorator is
            ``register_<kind>``).
        label: the parameter named in errors (``"method"``, ``"plant"``, ``"arbiter"``).
        defaults: the traits a decorator may give, with their defaults.
        unknown: the one-line error for an unknown name, formatted with ``name`` (as
            :func:`~ddwmmr.errors.shown` echoes it) and
            ``known`` (the registered names, comma separated).
        sets: traits the decorator also sets as class attributes.
        allowed: the words each tuple trait may hold.
    """

    def __init__(
        self,
        kind: str,
        label: str,
        defaults: Mapping[str, Any],
        unknown: str,
        sets: tuple[str, ...] = (),
        allowed: Mapping[str, tuple[str, ...]] | None = None,
    ) -> None:
        self.kind = kind
        self.label = label
        self.decorator = f"register_{kind}"
        self.defaults = dict(defaults)
        self.unknown = unknown
        self.sets = sets
        self.allowed = dict(allowed or {})
        self._entries: dict[str, Entry] = {}

    # -- registration -----------------------------------------------------------------
    def register(
        self, name: str, *extra: Any, **traits: Any
    ) -> Callable[[PluginClass], PluginClass]:
        """Class decorator: register the class under ``name`` with ``traits`` (see the
        module docstring; ``description=`` overrides the docstring's first line). A name
        the command line cannot address (not :data:`NAME_FORM`), a trait given by position
        (``extra``) or a keyword the decorator does not take (``taks=``) is a one-line
        :class:`~ddwmmr.errors.ParameterError`, raised here."""
        self.check_name(name)
        if extra:
            raise ParameterError(
                f"{self.decorator}({name!r}): takes the name alone by position, the traits "
                f"as keywords ({', '.join(self.keywords())}; got {len(extra) + 1} positional "
                "arguments)"
            )
        description = traits.pop("description", None)
        resolved = self._traits(name, traits)

        def decorate(cls: PluginClass) -> PluginClass:
            if not isinstance(cls, type):  # a function or an instance has no class to build
                raise ParameterError(
                    f"{self.decorator}({name!r}) registers a class (got {shown(cls)})"
                )
            cls.name = name  # type: ignore[attr-defined]
            for trait in self.sets:
                setattr(cls, trait, resolved[trait])
            with _LOCK:
                if cls.__module__ not in BUILTIN_MODULES:
                    _know_builtins()  # a built-in's name is refused here, not at a query
                self._add(cls, name, resolved, description)
            return cls

        return decorate

    def check_name(self, name: Any) -> str:
        """``name`` if the command line can address it (:data:`NAME_PATTERN`, at most
        :data:`MAX_NAME_LENGTH` characters), else a one-line
        :class:`~ddwmmr.errors.ParameterError` naming ``name`` and the allowed form."""
        valid = (
            isinstance(name, str)
            and len(name) <= MAX_NAME_LENGTH
            and NAME_PATTERN.fullmatch(name) is not None
        )
        if not valid:
            raise ParameterError(
                f"{self.decorator}: name must be {NAME_FORM}, so that the command line can "
                f"address it (got {shown(name)})"
            )
        return cast(str, name)  # cast: valid holds only for a str

    def keywords(self) -> tuple[str, ...]:
        """The keywords the decorator takes: the kind's traits, then ``description``."""
        return (*self.defaults, "description")

    def _traits(self, name: str, given: Mapping[str, Any]) -> dict[str, Any]:
        unknown = sorted(set(given) - set(self.defaults))
        if unknown:
            raise ParameterError(
                f"{self.decorator}({name!r}): unknown keyword {unknown[0]!r}"
                f"{did_you_mean(unknown[0], self.keywords())} "
                f"(keywords: {', '.join(self.keywords())})"
            )
        resolved = {key: given.get(key, default) for key, default in self.defaults.items()}
        # Lists become tuples: traits are compared and filtered as tuples.
        resolved = {k: tuple(v) if isinstance(v, list) else v for k, v in resolved.items()}
        for key, value in resolved.items():
            self._check_trait(name, key, value)
        return resolved

    def _check_trait(self, name: str, key: str, value: Any) -> None:
        """Refuse (one-line :class:`ParameterError`) a trait value of the wrong kind: a
        tuple trait must be a non-empty tuple of its allowed words, a bool trait a bool
        (a misspelt ``tasks=("track",)`` would list the plug-in in no tool)."""
        default = self.defaults[key]
        where = f"{self.decorator}({name!r}): {key}"
        if isinstance(default, bool):
            if not isinstance(value, bool):
                raise ParameterError(f"{where} must be True or False (got {shown(value)})")
            return
        allowed = self.allowed[key]
        if not (
            isinstance(value, tuple)
            and value
            and all(isinstance(word, str) and word in allowed for word in value)
        ):
            raise ParameterError(
                f"{where} must be a tuple of one or more of {', '.join(map(repr, allowed))} "
                f"(got {shown(value)})"
            )

    def _add(self, cls: type, name: str, traits: dict[str, Any], description: str | None) -> None:
        entry = self._entries.get(name)
        if entry is not None and (entry.module, entry.qualname) == (
            cls.__module__,
            cls.__qualname__,
        ):
            # the same class again (a built-in read from source, now imported; a reload,
            # in a notebook): it replaces the entry's class, traits and description
            entry.cls, entry.traits = cls, traits
            entry.description = description if description is not None else _first_line(cls.__doc__)
            return
        if entry is not None:
            raise self.twice(name, entry, f"{cls.__module__}.{cls.__qualname__}")
        text = description if description is not None else _first_line(cls.__doc__)
        self._entries[name] = Entry(
            name, text, traits, cls.__module__, cls.__qualname__, cls, (1, next(_SEQUENCE), 0)
        )

    def twice(self, name: str, entry: Entry, other: str) -> ParameterError:
        """The one-line error for ``name``, registered by ``entry`` and again by the class
        ``other`` (its dotted path)."""
        return ParameterError(
            f"{self.label}: {name!r} is registered twice ({entry.module}.{entry.qualname} "
            f"and {other})"
        )

    def unregister(self, name: str) -> None:
        """Remove ``name`` (a plug-in registered for a while, e.g. by a test)."""
        with _LOCK:
            self._entries.pop(name, None)

    # -- queries ----------------------------------------------------------------------
    def names(self, **traits: Any) -> list[str]:
        """Registered names in listing order; ``traits`` filter them: a trait whose value
        is a tuple must contain the given value, any other must equal it."""
        discover()
        entries = sorted(self._entries.values(), key=lambda e: e.order)
        return [e.name for e in entries if all(_has(e.traits, k, v) for k, v in traits.items())]

    def entry(self, name: str) -> Entry:
        """The entry of ``name``; an unknown name is a one-line :class:`ParameterError`
        naming the registered ones (and how a plug-in's name is loaded:
        :func:`unknown_hint`)."""
        discover()
        entry = self._entries.get(name) if isinstance(name, str) else None
        if entry is None:
            names = self.names()
            text = self.unknown.format(name=shown(name), known=", ".join(names))
            raise ParameterError(text + unknown_hint(name, names))
        return entry

    def plugin_module(self, name: str) -> str | None:
        """The module that registered ``name`` when it is a plug-in from outside the
        built-in modules (None for a built-in or an unknown name)."""
        discover()
        entry = self._entries.get(name)
        if entry is None or entry.module in BUILTIN_MODULES:
            return None
        return entry.module

    def load(self, name: str) -> type:
        """The class registered as ``name`` (its module imported on first use)."""
        entry = self.entry(name)
        if entry.cls is None:
            importlib.import_module(entry.module)
            if entry.cls is None:  # the module did not register what its source says
                raise RuntimeError(f"{entry.module} did not register {self.kind} {name!r}")
        return entry.cls

    def describe(self, name: str) -> str:
        """The description of ``name`` (the first line of its class docstring)."""
        return self.entry(name).description

    def traits(self, name: str) -> dict[str, Any]:
        """The traits of ``name`` (a copy)."""
        return dict(self.entry(name).traits)


def unknown_hint(name: Any, known: Iterable[str]) -> str:
    """What follows the error for an unknown ``name`` among ``known``: the closest known
    name (:func:`~ddwmmr.errors.did_you_mean`), else, for a name a plug-in could have,
    how plug-ins are loaded (``"; a plug-in's name is known once its module is imported:
    DDWMMR_PLUGINS=MODULE ..."``), else nothing."""
    if not isinstance(name, str):
        return ""
    close = did_you_mean(name, known)
    if close or NAME_PATTERN.fullmatch(name) is None:
        return close
    return f"; {PLUGINS_HINT}"


def plugin_source(module: str) -> str:
    """Where a run's record says a plug-in registered by ``module`` comes from: the
    module's name, which ``DDWMMR_PLUGINS`` imports; for ``__main__``, a class the running
    script registered itself (``python study.py``, ``python -m pkg.study``), the script's
    absolute path, or :data:`INTERACTIVE` when ``__main__`` has no file (``python -c``, an
    interactive session, a notebook). A script is not recorded as a module: importing it
    by name would run whatever its top level runs, so no setting of ``DDWMMR_PLUGINS``
    is known to load it (:func:`loadable`)."""
    if module != "__main__":
        return module
    path = getattr(sys.modules.get("__main__"), "__file__", None)
    return os.path.abspath(path) if isinstance(path, str) and path else INTERACTIVE


def loadable(source: str) -> bool:
    """Whether a recorded :func:`plugin_source` is a module ``DDWMMR_PLUGINS`` can import
    (a dotted name), not a script's path or :data:`INTERACTIVE`."""
    return MODULE_PATTERN.fullmatch(source) is not None and source != "__main__"


def used_plugins(**names: Iterable[str]) -> dict[str, dict[str, str]]:
    """``{label: {name: source}}`` of the plug-ins among ``names``, given per registry
    label (``method``, ``plant``, ``arbiter``): for each name not built in, the module
    that registered it, which ``DDWMMR_PLUGINS`` must name to run it again, or the script
    that registered it in its own ``__main__`` (:func:`plugin_source`). A run's record
    holds it (:func:`ddwmmr.provenance.header`). Empty when every name is built in."""
    found: dict[str, dict[str, str]] = {}
    for label, given in names.items():
        registry = _LABELS[label]
        for name in given:
            module = registry.plugin_module(name)
            if module is not None:
                found.setdefault(label, {})[name] = plugin_source(module)
    return found


def check_recorded_plugins(plugins: Any) -> None:
    """Refuse (one-line :class:`~ddwmmr.errors.ParameterError`) to run a record's
    ``plugins`` (:func:`used_plugins`'s answer, as a run's record holds it) when one of
    its names is not registered: it names the plug-in, its module and the
    ``DDWMMR_PLUGINS`` setting that loads them all. Anything but a mapping of mappings of
    texts is left to the record's other checks."""
    if not isinstance(plugins, Mapping):
        return
    named = {
        label: {n: m for n, m in given.items() if isinstance(n, str) and isinstance(m, str)}
        for label, given in plugins.items()
        if label in _LABELS and isinstance(given, Mapping)
    }
    for label, given in named.items():
        for name, module in given.items():
            if name in _LABELS[label].names():
                continue
            if not loadable(module):
                raise ParameterError(
                    f"{label}: {name!r} is the plug-in of {_script(module)}, which "
                    f"{PLUGINS_VARIABLE} cannot load: {SCRIPT_ADVICE}"
                )
            raise ParameterError(
                f"{label}: {name!r} is the plug-in of module {module!r}, which is not "
                f"loaded: run with {PLUGINS_VARIABLE}={','.join(plugin_modules(named))} "
                '(importable from sys.path, e.g. with PYTHONPATH; docs/api.md, "Extending")'
            )


def plugin_modules(plugins: Mapping[str, Mapping[str, str]]) -> list[str]:
    """The modules of :func:`used_plugins`'s answer that ``DDWMMR_PLUGINS`` can import
    (:func:`loadable`), each once, in order: what it is set to to run them again."""
    sources = (m for named in plugins.values() for m in named.values())
    return [m for m in dict.fromkeys(sources) if loadable(m)]


def _script(source: str) -> str:
    """How a message names the script a recorded source that is not :func:`loadable`
    stands for."""
    if source == INTERACTIVE:
        return "a script without a file (python -c, an interactive session or a notebook)"
    return f"the script {source}"


def script_note(plugins: Mapping[str, Mapping[str, str]]) -> str:
    """For :func:`used_plugins`'s answer, what a run's repeat command needs besides
    ``DDWMMR_PLUGINS``: the plug-ins registered by a script (:func:`plugin_source`),
    which no setting loads (``"needs method 'mine' of the script /home/me/study.py,
    which DDWMMR_PLUGINS cannot load: ..."``); empty when there are none."""
    scripts = [
        f"{label} {name!r} of {_script(source)}"
        for label, named in plugins.items()
        for name, source in named.items()
        if not loadable(source)
    ]
    if not scripts:
        return ""
    return f"needs {', '.join(scripts)}, which {PLUGINS_VARIABLE} cannot load: {SCRIPT_ADVICE}"


def _has(traits: Mapping[str, Any], key: str, value: Any) -> bool:
    have = traits[key]
    return value in have if isinstance(have, tuple) else have == value


#: The description of a plug-in registered without a docstring (or a blank one).
NO_DESCRIPTION = "(no description)"


def _first_line(doc: str | None) -> str:
    """The first line of docstring ``doc``, else :data:`NO_DESCRIPTION`."""
    lines = inspect.cleandoc(doc or "").splitlines()
    return lines[0] if lines and lines[0] else NO_DESCRIPTION


#: The three registries (see the module docstring for their traits).
CONTROLLERS = Registry(
    "controller",
    "method",
    {"tasks": ("tracking",), "interfaces": ("velocity",), "arbiter": False},
    "method: unknown method {name} (known: {known})",
    sets=("interfaces",),
    allowed={"tasks": ("tracking", "waypoints"), "interfaces": ("velocity", "force")},
)
PLANTS = Registry(
    "plant",
    "plant",
    {"interfaces": ("velocity",)},
    "plant must be one of {known} (got {name})",
    sets=("interfaces",),
    allowed={"interfaces": ("velocity", "force")},
)
ARBITERS = Registry(
    "arbiter",
    "arbiter",
    {},
    "arbiter must be one of {known} (got {name})",
)
_REGISTRIES = {r.decorator: r for r in (CONTROLLERS, PLANTS, ARBITERS)}
_LABELS = {r.label: r for r in (CONTROLLERS, PLANTS, ARBITERS)}
register_controller = CONTROLLERS.register
register_plant = PLANTS.register
register_arbiter = ARBITERS.register

_LOCK = threading.RLock()
_SEQUENCE = count()
_discovered = False
_discovering = False
_builtins_known = False  # _know_builtins read them (a plug-in registered before a query)


def discover() -> None:
    """Find every plug-in once per process (see the module docstring): read the built-in
    modules' decorators from source, then import the modules of the ``ddwmmr.plugins``
    entry points and of ``DDWMMR_PLUGINS``. Other threads wait for it; within the thread
    that runs it (a plug-in module asking a registry on import) it returns at once."""
    global _discovered, _discovering
    if _discovered:
        return
    with _LOCK:
        if _discovered or _discovering:
            return
        _discovering = True
        try:
            if not _builtins_known:  # else read when a plug-in was registered
                _read_builtins()
            for module in _plugin_modules():
                _import_plugin(module)
            _discovered = True  # a failure leaves it False: the next query fails alike
        finally:
            _discovering = False


def _know_builtins() -> None:
    """The built-in plug-ins' entries (:func:`_read_builtins`) before a plug-in of another
    module is added: one registered before the first query under a built-in's name (a
    user's own ``pi``) is refused by its ``register``, where reading the built-ins at that
    query refused it (and every later query) instead."""
    global _builtins_known
    if not (_builtins_known or _discovered or _discovering):
        _read_builtins()
        _builtins_known = True


def _read_builtins() -> None:
    """Entries for the built-in plug-ins, read from source, in listing order."""
    for index, module in enumerate(BUILTIN_MODULES):
        for line, decorator, name, traits, qualname, doc in _read_source(module):
            registry = _REGISTRIES[decorator]
            registry.check_name(name)
            description = traits.pop("description", None)
            resolved = registry._traits(name, traits)
            entry = registry._entries.get(name)
            if entry is None:
                text = description if description is not None else _first_line(doc)
                entry = registry._entries[name] = Entry(name, text, resolved, module, qualname)
            elif (entry.module, entry.qualname) != (module, qualname):
                # a plug-in imported before the first query took a built-in's name: refused
                # as when it comes after (:meth:`Registry._add`), never a silent replacement
                raise registry.twice(name, entry, f"{module}.{qualname}")
            entry.order = (0, index, line)


def _read_source(module: str) -> list[tuple[int, str, str, dict[str, Any], str, str | None]]:
    """``(line, decorator, name, traits, class name, docstring)`` of every registered class
    of a built-in module, read from its file (the module is not imported)."""
    path = _PACKAGE.joinpath(*module.split(".")[1:]).with_suffix(".py")
    tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
    found = []
    for node in tree.body:
        if not isinstance(node, ast.ClassDef):
            continue
        for decorator in node.decorator_list:
            if not isinstance(decorator, ast.Call):
                continue
            function = decorator.func
            called = getattr(function, "id", None) or getattr(function, "attr", None)
            if called not in _REGISTRIES:
                continue
            try:
                (name,) = (ast.literal_eval(a) for a in decorator.args)
                named = [(k.arg, k.value) for k in decorator.keywords if k.arg is not None]
                if len(named) < len(decorator.keywords):  # a ``**traits``: not literal
                    raise ValueError
                traits = {key: ast.literal_eval(value) for key, value in named}
            except ValueError:
                raise TypeError(
                    f"{path}:{decorator.lineno}: @{called}(...) takes literal arguments only "
                    "(the registry reads built-in plug-ins from their source)"
                ) from None
            doc = ast.get_docstring(node)
            found.append((node.lineno, called, name, traits, node.name, doc))
    return found


def _plugin_modules() -> list[str]:
    """The modules named by the entry points and by ``DDWMMR_PLUGINS``."""
    from importlib.metadata import entry_points  # ~50 ms to import: only when asked

    modules = [point.value.partition(":")[0] for point in entry_points(group=ENTRY_POINT_GROUP)]
    text = os.environ.get(PLUGINS_VARIABLE, "")
    modules += [name.strip() for name in text.split(",") if name.strip()]
    return list(dict.fromkeys(modules))


def _import_plugin(module: str) -> None:
    """Import plug-in ``module``; any failure of its import (missing, a syntax error,
    whatever its code raises) is a one-line :class:`ParameterError` naming the module and
    the error (its ``__cause__``). Interrupts (not an :class:`Exception`) pass."""
    try:
        importlib.import_module(module)
    except Exception as exc:
        text = one_line(str(exc), 200)
        if not isinstance(exc, ImportError | ParameterError):
            text = f"{type(exc).__name__}: {text}" if text else type(exc).__name__
        raise ParameterError(
            f"{PLUGINS_VARIABLE}: cannot import plug-in module {module!r} ({text})"
        ) from exc


def build(
    cls: Any,
    call: str,
    args: tuple[Any, ...] = (),
    options: Mapping[str, Any] | None = None,
    quoted: bool = True,
) -> Any:
    """``cls(*args, **options)``, a registered class built for a run (the user's options
    in a mapping of their own: any name is theirs). What the constructor
    of a plug-in (a class from outside the library) raises, but a ParameterError, is a
    one-line :class:`~ddwmmr.errors.PluginError` "<call> raised <type>: <message>" (the
    ``__cause__`` what it raised; ``quoted``: the message as its repr); a library class's
    error keeps its traceback (a bug of ours)."""
    try:
        return cls(*args, **(options or {}))
    except Exception as error:
        if class_from_library(cls):
            raise
        raise_plugin_error(call, error, quoted=quoted)


__all__ = [
    "ARBITERS",
    "BUILTIN_MODULES",
    "CONTROLLERS",
    "ENTRY_POINT_GROUP",
    "INTERACTIVE",
    "MAX_NAME_LENGTH",
    "MODULE_PATTERN",
    "NAME_FORM",
    "NAME_PATTERN",
    "PLANTS",
    "PLUGINS_HINT",
    "PLUGINS_VARIABLE",
    "SCRIPT_ADVICE",
    "Entry",
    "PluginClass",
    "Registry",
    "check_recorded_plugins",
    "discover",
    "loadable",
    "plugin_modules",
    "plugin_source",
    "register_arbiter",
    "register_controller",
    "register_plant",
    "script_note",
    "unknown_hint",
    "used_plugins",
]
