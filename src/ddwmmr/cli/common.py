"""Helpers shared by the command-line tools: error reporting, robots, output folders."""

from __future__ import annotations

import argparse
import contextlib
import shutil
import sys
import tempfile
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path

from ddwmmr.errors import ParameterError
from ddwmmr.model import Robot

#: Exit status for bad input (argparse uses the same).
EXIT_USAGE = 2


class ArgumentParser(argparse.ArgumentParser):
    """argparse with one-line errors: ``prog: error: message`` and exit status 2."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message}\n")


def run_main(main: Callable[[Sequence[str] | None], int], argv: Sequence[str] | None) -> int:
    """Run ``main`` and turn a :class:`ParameterError` into one line on stderr and status 2."""
    try:
        return main(argv)
    except ParameterError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return EXIT_USAGE


def add_robot_arguments(parser: argparse.ArgumentParser) -> None:
    """``--robot FILE`` and ``--payload KG``."""
    parser.add_argument(
        "--robot", metavar="FILE", help="robot description (TOML, keys = Robot fields)"
    )
    parser.add_argument(
        "--payload",
        type=float,
        metavar="KG",
        help="payload at the end effector in kg (default: the robot's, 1.25 for Robot())",
    )


def robot_from_arguments(args: argparse.Namespace) -> Robot:
    """The robot selected by ``--robot`` / ``--payload``."""
    robot = Robot.from_toml(args.robot) if args.robot else Robot()
    if args.payload is not None:
        robot = robot.with_payload(args.payload)
    return robot


@contextlib.contextmanager
def atomic_output_dir(target: str | Path, marker: str) -> Iterator[Path]:
    """Yield a temporary folder that replaces ``target`` only if the block succeeds.

    An existing ``target`` is replaced only when it holds ``marker`` (a file a previous run
    of the same tool wrote), so a user's unrelated folder is never deleted. On any error
    the temporary folder is removed: nothing half-written is left behind.
    """
    target = Path(target)
    if target.exists() and (
        not target.is_dir() or (any(target.iterdir()) and not (target / marker).exists())
    ):
        raise ParameterError(
            f"out: {target} exists and is not an output folder of this tool (no {marker})"
        )
    target.parent.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=f".{target.name}.", dir=target.parent))
    try:
        yield staging
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
    if target.exists():
        shutil.rmtree(target)
    staging.rename(target)
