"""Colours that mean the same thing in every figure the tools draw: the end effector and the
base in track's path figure, compare's panels and the scenario figures, the greys of the
robot drawn at chosen instants, and compare's colour per method. Plain matplotlib colour
strings; no matplotlib import, so a module that only names colours stays cheap to import."""

from __future__ import annotations

from collections.abc import Sequence

#: The end effector's path (and its start mark).
END_EFFECTOR = "tab:blue"
#: The base's path (the axle midpoint), a thin grey line.
BASE = "0.45"
#: Grey levels of the robot drawn at chosen instants, lightest (first instant) to darkest
#: (last): time reads as darkening, in no hue of a path or method line.
SNAPSHOT_GREYS = (0.80, 0.08)
#: The grey levels the snapshots skip: around :data:`BASE`'s 0.45, where a robot would read
#: as the base path in the plot and in the legend.
SNAPSHOT_SKIP = (0.37, 0.53)
#: The method colours, in the order methods are listed: matplotlib's default cycle (tab10),
#: reused from the start past ten methods.
METHOD_CYCLE = tuple(f"C{i}" for i in range(10))


def method_colors(labels: Sequence[str]) -> dict[str, str]:
    """A fixed colour per label, :data:`METHOD_CYCLE` in the order given, so a method looks
    the same in every figure of one report."""
    return {label: METHOD_CYCLE[i % len(METHOD_CYCLE)] for i, label in enumerate(labels)}
