"""A tool's ``main(argv)`` run in this process, as the command line would run it."""

from __future__ import annotations

from collections.abc import Callable, Sequence

import pytest


def call_main(
    main: Callable[[list[str]], int], args: Sequence[str], capsys: pytest.CaptureFixture[str]
) -> tuple[object, str, str]:
    """``(status, stdout, stderr)`` of ``main(list(args))``: argparse's refusals and
    ``--help`` leave through ``SystemExit``, whose code is taken as the status. The output
    is all that was captured since it was last read. An exception ``main`` lets out fails
    the test, as a traceback on a real stderr would."""
    try:
        status: object = main(list(args))
    except SystemExit as stop:
        status = stop.code
    captured = capsys.readouterr()
    return status, captured.out, captured.err
