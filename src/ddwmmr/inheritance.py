"""Whether an object's class is the library's own, and whether a subclass changed a
method that a fast path stands in for.

A plug-in's output (a controller's command, a plant's state, a QP piece's rows, an
arbiter's decision) is checked as it is produced; the library's own classes keep their
contracts by construction and run unchecked: :func:`from_library` tells them apart.

Fast paths (a QP piece's compiled writer, a controller's float-level ``law``, a
trajectory's vectorised ``sample``) describe the methods of the class that defines them.
A subclass that redefines one of those methods below that class has behaviour the fast
path does not know, so it must take the plain path: :func:`overrides` tells.
"""

from __future__ import annotations


def defining_class(cls: type, name: str) -> type | None:
    """The first class in ``cls``'s MRO whose own namespace defines ``name`` (None: none)."""
    return next((klass for klass in cls.__mro__ if name in klass.__dict__), None)


def overrides(obj: object, owner: type, name: str) -> bool:
    """True when ``obj``'s class redefines ``owner.<name>`` below ``owner``."""
    return getattr(type(obj), name) is not getattr(owner, name)


def from_library(obj: object) -> bool:
    """Whether ``obj``'s class is one of the library's (defined in a ``ddwmmr`` module)."""
    return class_from_library(type(obj))


def class_from_library(cls: type) -> bool:
    """Whether the class ``cls`` is one of the library's (defined in a ``ddwmmr`` module)."""
    return cls.__module__.split(".")[0] == "ddwmmr"
