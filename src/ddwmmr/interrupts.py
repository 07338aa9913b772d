"""An interrupt that arrived while a solver ran in C, kept so the run stops after it.

CasADi lets Python's signal handlers run during a solve (IPOPT's iterations check for
Ctrl-C) and turns the exception a handler raises into a warning, then carries on: the
tools' SIGINT/SIGTERM would be lost, and the signal-handling code ignores a second one
(one is enough to stop). So the tools' handler (:func:`ddwmmr.cli.common.interruptible`)
also records the exception here with :func:`record`, and the code that calls such a
solver calls :func:`raise_pending` when it returns: the run then stops as it would have,
one solve later.
"""

from __future__ import annotations

_pending: BaseException | None = None


def record(exception: BaseException) -> None:
    """Keep ``exception`` (a KeyboardInterrupt or the tools' Terminated) until
    :func:`raise_pending` raises it, or :func:`clear` drops it."""
    global _pending
    _pending = exception


def clear() -> None:
    """Forget a recorded interrupt (the handler that recorded it is gone)."""
    global _pending
    _pending = None


def raise_pending() -> None:
    """Raise the interrupt recorded since the last call, if any (once)."""
    global _pending
    exception, _pending = _pending, None
    if exception is not None:
        raise exception
