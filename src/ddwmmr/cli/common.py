"""Helpers shared by the command-line tools: error reporting, signals, robots, outputs.

Every tool's ``main(argv)`` runs through :func:`run_main`, which gives the tools one
behaviour for everything that is not a result:

* bad input (:class:`ParameterError`): one line ``error: ...`` on stderr, status 2;
* Ctrl-C (SIGINT): one line, status 130; SIGTERM, SIGHUP (terminal closed) and SIGQUIT
  (Ctrl-\\): one line, status 143, 129 and 131 (128 + the signal number, the shell
  convention). Each first stops the tool's worker processes and unwinds the stack, so the
  output folder's staging copy is removed (:mod:`ddwmmr.outputs`). Before ``main`` runs
  (the tool's imports) and after, the start guard of :mod:`ddwmmr.cli.signals` gives the
  same line and status;
* an operating-system error while writing (disk full...): one line, status 1.
"""

from __future__ import annotations

import argparse
import ast
import codecs
import contextlib
import datetime as dt
import logging
import math
import multiprocessing
import os
import re
import signal
import sys
import threading
import warnings
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, NoReturn, overload

from ddwmmr import interrupts
from ddwmmr.cli import signals
from ddwmmr.cli.signals import EXIT_INTERRUPTED, EXIT_TERMINATED, STOP_SIGNALS, say, stop_line
from ddwmmr.errors import (
    MASS_RANGE_KG,
    ParameterError,
    PluginError,
    did_you_mean,
    message_line,
    plain_float,
    plain_number_text,
    shown,
    shown_number_text,
)
from ddwmmr.model import Robot
from ddwmmr.outputs import (
    check_output_folder,
    committed_output,
    first_free,
    output_folder,
    package_version,
    recording_commits,
)
from ddwmmr.user_warnings import library_warning
from ddwmmr.workers import IN_WORKERS, SHOWN

if TYPE_CHECKING:
    from typing import TextIO

    from ddwmmr.controllers.option_specs import OptionSpec

#: Exit status for bad input (argparse uses the same).
EXIT_USAGE = 2

__all__ = [
    "EXIT_USAGE",
    "ArgumentParser",
    "Terminated",
    "add_force_argument",
    "add_option_argument",
    "add_plant_option_argument",
    "add_robot_arguments",
    "add_traj_scale_argument",
    "built_plant",
    "check_output_folder",
    "check_plant_option_names",
    "console_text",
    "default_run_folder",
    "first_free",
    "given_text",
    "horizon_defaults",
    "horizon_range",
    "integer_type",
    "method_options_text",
    "number_type",
    "offset_type",
    "option_target",
    "output_folder",
    "output_target",
    "parse_plant_options",
    "payload_type",
    "plant_option_specs",
    "refuse_plant_option_argument",
    "robot_from_arguments",
    "run_main",
    "run_method_options",
    "scaled_trajectory",
    "seconds_type",
    "split_names",
]


#: Arguments that are negative numbers, not option names: argparse's own pattern misses
#: scientific notation and the IEEE words (``-3e-2``, ``-1E5``, ``-inf``), so
#: ``--offset -3e-2 -3e-2`` was refused as "expected 2 arguments".
NEGATIVE_NUMBER = re.compile(
    r"^-(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$|^-(inf|infinity|nan)$", re.IGNORECASE
)


#: argparse's message for options it does not know (``--methd x``).
UNRECOGNISED = "unrecognized arguments: "
#: argparse's message for a value not among an option's choices (the value as its repr).
INVALID_CHOICE = re.compile(
    r"argument (?:[^:]*/)?(?P<option>--[\w-]+): invalid choice: "
    r"(?P<value>'(?:[^'\\]|\\.)*'|\"(?:[^\"\\]|\\.)*\")"
)


def integer_type(
    low: int, high: int | None = None, *, checked_later: bool = False
) -> Callable[[str], int]:
    """An argparse ``type``: an integer >= ``low`` (and <= ``high``); anything else (a
    fraction, ``nan``, an empty text, an integer of more digits than Python reads) is
    refused as ``argument --n: must be an integer in [low, high] (got '1.5')`` (argparse
    names the option; status 2; the text as :func:`shown_number_text` quotes it).
    ``checked_later``: the option's own check refuses an integer out of the range (in its
    words); here only a text that is no integer is, stating the same range."""
    allowed = f">= {low}" if high is None else f"in [{low}, {high}]"

    def refused(text: str) -> argparse.ArgumentTypeError:
        got = shown_number_text(text, integer=True)
        return argparse.ArgumentTypeError(f"must be an integer {allowed} (got {got})")

    def parse(text: str) -> int:
        try:
            if not plain_number_text(text):
                raise ValueError(text)
            value = int(text)
        except ValueError:
            raise refused(text) from None
        if not checked_later and (value < low or (high is not None and value > high)):
            raise refused(text)
        return value

    return parse


def number_type(allowed: str, finite: bool = False) -> Callable[[str], float]:
    """An argparse ``type``: a float. A text that is none (``abc``, an empty text, a
    number a float cannot hold, ``1e999`` or ``1e-400``: :func:`plain_float`; with
    ``finite``, also ``nan`` and ``inf``) is refused as ``argument --dt: must be a number
    <allowed> (got '1e-400', too small for a float, which reads it as 0)`` (the text as
    :func:`shown_number_text` quotes it); ``allowed`` states the range (``"> 0 s"``,
    ``"in [0, 1] m"``), the one the option's own check enforces on the number, which
    states it alike."""

    def parse(text: str) -> float:
        try:
            value = plain_float(text)
        except ValueError:
            value = math.nan
            finite_only = True
        else:
            finite_only = finite
        if finite_only and not math.isfinite(value):
            raise argparse.ArgumentTypeError(
                f"must be a number {allowed} (got {shown_number_text(text)})"
            )
        return value

    return parse


#: ``--payload KG``: the range :meth:`Robot.with_payload` checks.
payload_type = number_type(f"in [{MASS_RANGE_KG[0]:g}, {MASS_RANGE_KG[1]:g}] kg")
#: ``--offset DX DY`` (m): each within the arm's reach, as the start's check has it.
offset_type = number_type(
    f"in [-reach, reach] m, the arm's reach L1 + L2 ({Robot().reach:g} m for Robot())"
)
#: ``--dt`` and ``--duration`` (s) of a run, before the step count is checked.
seconds_type = number_type("> 0 s")


def split_names(values: Sequence[str] | None, option: str) -> list[str]:
    """Items of repeated and/or comma-separated option values, in order, without repeats.
    A value with no name in it (``--methods ''``, ``--only ,``) or an empty item in a list
    (``pi,,ats``, ``pi,``) is refused naming ``option``: a name went missing there."""
    items = []
    for value in values or []:
        names = [item.strip() for item in value.split(",")]
        if not any(names):
            raise ParameterError(f"{option}: no name given (got {value!r})")
        if not all(names):
            raise ParameterError(f"{option}: an empty name in the list (got {value!r})")
        items.extend(names)
    return list(dict.fromkeys(items))


@overload
def given_text(option: str, value: str, what: str, empty: str = "path") -> str: ...
@overload
def given_text(option: str, value: None, what: str, empty: str = "path") -> None: ...
def given_text(option: str, value: str | None, what: str, empty: str = "path") -> str | None:
    """``value`` unless it is an empty (or blank) text, which is refused as ``option: give
    <what> (got an empty <empty>)``: ``--out "$DIR"`` with ``DIR`` unset must not mean the
    current folder, nor ``--robot ""`` the default robot. None (not given) passes."""
    if value is not None and not value.strip():
        raise ParameterError(f"{option}: give {what} (got an empty {empty})")
    return value


class _StoreOnce(argparse._StoreAction):
    """argparse's ``store``, refused when its option is given a second time in one command
    line (argparse would keep the last value without a word)."""

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: str | Sequence[Any] | None,
        option_string: str | None = None,
    ) -> None:
        given = getattr(parser, "_given", None)
        if given is not None:
            if self in given:
                name = "/".join(self.option_strings) or self.dest
                parser.error(
                    f"argument {name}: given more than once (first {given[self]}, then "
                    f"{_shown_values(values)}); give it once"
                )
            given[self] = _shown_values(values)
        super().__call__(parser, namespace, values, option_string)


def _shown_values(values: object) -> str:
    items = values if isinstance(values, list) else [values]
    return " ".join(shown(v if isinstance(v, str | int | float) else str(v)) for v in items)


class ArgumentParser(argparse.ArgumentParser):
    """argparse with one-line errors: ``prog: error: message`` and exit status 2, and
    negative numbers in any float notation taken as values (:data:`NEGATIVE_NUMBER`);
    ``--version``; a mistyped option gets the closest one (``--methd``: "did you mean
    --method?"); an option that takes one value (or one group of values) given twice is
    refused, naming it (repeatable ones, e.g. ``--option``, use ``append``/``extend``)."""

    #: What starts an error line (None: the parser's ``prog``).
    error_prefix: str | None = None

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = NEGATIVE_NUMBER
        self._given: dict[argparse.Action, str] | None = None
        self._words: list[str] = []  # the command line being parsed
        # argparse's own hook: the default action, and "store", are the refusing store
        for name in (None, "store"):
            self.register("action", name, _StoreOnce)
        if self.add_help:
            self.add_argument("--version", action="version", version=f"ddwmmr {package_version()}")

    # ignore: argparse's overloads type the namespace; this one override passes it through
    def parse_known_args(  # type: ignore[override]
        self, args: Sequence[str] | None = None, namespace: argparse.Namespace | None = None
    ) -> tuple[argparse.Namespace, list[str]]:
        outer, self._given = self._given, {}
        # kept after the parse: parse_args refuses the words left over once this returns
        self._words = list(sys.argv[1:] if args is None else args)
        try:
            return super().parse_known_args(args, namespace)
        finally:
            self._given = outer

    def error(self, message: str) -> None:  # type: ignore[override]
        prefix = self.prog if self.error_prefix is None else self.error_prefix
        line = message_line(self._with_suggestions(message))  # as a ParameterError's
        self.exit(EXIT_USAGE, f"{prefix}: error: {line}\n")

    def _with_suggestions(self, message: str) -> str:
        """``message``, with the closest known option after each unknown one, and after a
        value that follows another option's one value (``--method ats pi``) that option;
        an unknown name of a registry's choice (``--method``, ``--plant``...) gets what
        :func:`ddwmmr.registry.unknown_hint` adds."""
        if not message.startswith(UNRECOGNISED):
            return message + self._choice_hint(message)
        known = [o for o in self._option_string_actions if o.startswith("--")]
        strays = self._stray_values()
        words = []
        for word in message[len(UNRECOGNISED) :].split():
            if word.startswith("--") and not NEGATIVE_NUMBER.match(word):
                word += did_you_mean(word.split("=")[0], known)
            elif word in strays:
                action = self._option_string_actions[strays[word]]
                count = "one value" if action.nargs in (None, 1) else f"{action.nargs} values"
                # argparse names no public type for action="append"; its class is stable
                again = ", repeat it" if isinstance(action, argparse._AppendAction) else ""
                word += f" ({strays.pop(word)} takes {count}{again})"
            words.append(word)
        return UNRECOGNISED + " ".join(words)

    def _choice_hint(self, message: str) -> str:
        """For argparse's "argument --method: invalid choice: 'x' (choose from ...)" of an
        option whose choices are plug-in names, the closest choice or how plug-ins are
        loaded (:func:`~ddwmmr.registry.unknown_hint`); else nothing."""
        from ddwmmr.registry import ARBITERS, CONTROLLERS, PLANTS, unknown_hint

        found = INVALID_CHOICE.match(message)
        action = found and self._option_string_actions.get(found["option"])
        if not found or action is None or not action.choices:
            return ""
        choices = [str(choice) for choice in action.choices]
        value = ast.literal_eval(found["value"])
        for registry in (CONTROLLERS, PLANTS, ARBITERS):
            names = registry.names()
            if set(choices) <= set(names):  # a registered name not offered: no plug-in's
                return "" if value in names else unknown_hint(value, choices)
        return ""

    def _stray_values(self) -> dict[str, str]:
        """The words of the command line that follow the values of an option taking a
        fixed number of them (``--method ats pi``, ``--method=ats pi``: ``{"pi":
        "--method"}``; ``--offset 1 2 3``: ``{"3": "--offset"}``), the first such option
        of each word."""
        strays: dict[str, str] = {}
        words = self._words
        for at, word in enumerate(words):
            option, inline, _ = word.partition("=")
            action = self._option_string_actions.get(option)
            if not option.startswith("--") or action is None:
                continue
            count = 1 if action.nargs is None else action.nargs
            if not isinstance(count, int) or count < 1 or (inline and count != 1):
                continue
            after = at + 1 + (0 if inline else count)
            if after < len(words) and (
                not words[after].startswith("-") or NEGATIVE_NUMBER.match(words[after])
            ):
                strays.setdefault(words[after], option)
        return strays


class Terminated(BaseException):
    """SIGTERM (or another of :data:`STOP_SIGNALS`) arrived: raised in the main thread so
    that cleanup code runs."""

    def __init__(self, signum: int = signal.SIGTERM) -> None:
        super().__init__(signum)
        self.signum = int(signum)

    @property
    def status(self) -> int:
        """Exit status: 128 + the signal number."""
        return 128 + self.signum

    @property
    def name(self) -> str:
        """The signal's name, e.g. ``SIGHUP``."""
        return signal.Signals(self.signum).name


def stop_workers(timeout: float = 2.0) -> None:
    """Stop the worker processes this process started (process pools, Dask's nannies).

    Dask's scheduler, client and nannies in this process would log each lost worker and
    each lost result: the tool says one line for the stop, so every log in the process is
    silenced first. (Raising the level of the ``distributed`` logger alone is not enough:
    Dask's configuration gives ``distributed.client`` a level of its own.)"""
    logging.disable(logging.CRITICAL)
    children = multiprocessing.active_children()
    for child in children:
        child.terminate()
    for child in children:
        child.join(timeout)
        if child.is_alive():
            child.kill()


@contextlib.contextmanager
def interruptible() -> Iterator[None]:
    """Turn SIGINT and :data:`STOP_SIGNALS` into exceptions raised after the workers are
    stopped; a signal the process was started ignoring (under ``nohup``) stays ignored.

    Forked workers inherit the handler: there it ignores SIGINT, SIGHUP and SIGQUIT (a
    Ctrl-C, a Ctrl-\\ or a closed terminal reaches the whole process group, and the parent
    stops the workers itself, so they print no traceback) and exits at once on SIGTERM
    (the parent's :func:`stop_workers`).

    Python runs a handler wherever the main thread is, a weakref callback or a ``__del__``
    included, where what it raises is printed as "Exception ignored in ..." with a
    traceback and dropped; other C code drops it silently. Such a stop says nothing
    here (it is recorded, :mod:`ddwmmr.interrupts`) and is raised at the next check, at
    the latest when the block ends; an exception that ends the block after a stop (a
    process pool its handler broke) gives way to the stop: one signal, one ending.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    owner = os.getpid()
    # A signal the tool was started ignoring (``nohup`` ignores SIGHUP) stays ignored.
    handled = tuple(
        s for s in (signal.SIGINT, *STOP_SIGNALS) if signal.getsignal(s) is not signal.SIG_IGN
    )

    def handle(signum: int, frame: object) -> None:
        if os.getpid() != owner:
            if signum == signal.SIGTERM:
                os._exit(EXIT_TERMINATED)
            return
        for number in handled:  # one signal is enough
            signal.signal(number, signal.SIG_IGN)
        stop_workers()
        stop = KeyboardInterrupt() if signum == signal.SIGINT else Terminated(signum)
        interrupts.record(stop)  # a solver in C may swallow what is raised here
        raised.append(stop)
        raise stop

    raised: list[BaseException] = []
    shown = sys.unraisablehook

    def unraisable(report: sys.UnraisableHookArgs) -> None:
        if not any(report.exc_value is stop for stop in raised):
            shown(report)

    sys.unraisablehook = unraisable
    previous = {s: signal.signal(s, handle) for s in handled}
    try:
        yield
    except BaseException as error:
        if raised and error is not raised[0]:  # what the stop caused (a broken pool), or
            raise raised[0] from error  # what the code it left did: the stop ends the tool
        raise
    else:
        interrupts.raise_pending()  # a stop dropped after the run's last check
    finally:
        interrupts.clear()
        for number, handler in previous.items():
            signal.signal(number, handler)
        sys.unraisablehook = shown


def forget_unhandled_interrupt() -> None:
    """Let the status :func:`run_main` returns stand after a caught Ctrl-C.

    CPython marks a KeyboardInterrupt that leaves code run by ``exec`` of a string (the
    methods a dataclass or namedtuple generates while a module imports) as unhandled, even
    when it is caught further up, and ends such a process by SIGINT at exit (status -2
    for its parent) instead of with the status it returns. Each ``exec`` of a string
    clears the mark before it runs; this one runs nothing else."""
    exec("pass")


@contextlib.contextmanager
def one_line_warnings() -> Iterator[None]:
    """Show the library's own warnings (a :class:`UserWarning` the package issued,
    :func:`~ddwmmr.user_warnings.library_warning`, whichever line it names) as one line
    on stderr, ``warning: <message>`` (their messages name the parameter and what to
    change), instead of Python's default form (the source file, line number and
    line of code, which reads like a traceback); any other warning (another
    library's, or a NumPy ``RuntimeWarning`` whose location is the clue) is shown as
    Python would. Each line is shown once: a warning that every run repeats (a plant's
    about the robot) is said once per command. The worker processes of
    :func:`ddwmmr.workers.process_pool` started meanwhile show them the same way, whatever
    their start method, and not the lines shown before they started."""
    previous = warnings.showwarning
    warnings.showwarning = _one_line_display(previous)
    try:
        yield
    finally:
        warnings.showwarning = previous


def install_one_line_warnings() -> None:
    """From now on, show the library's warnings in this process (a pool worker) as
    :func:`one_line_warnings` does; nothing if they already are (a forked worker inherits
    its parent's display)."""
    if getattr(warnings.showwarning, IN_WORKERS, None) is not install_one_line_warnings:
        warnings.showwarning = _one_line_display(warnings.showwarning)


def _one_line_display(previous: Callable[..., None]) -> Callable[..., None]:
    """The display of :func:`one_line_warnings` (a ``warnings.showwarning``), handing
    every warning that is not the library's to ``previous``."""

    shown: set[str] = set()

    def show(
        message: Warning | str,
        category: type[Warning],
        filename: str,
        lineno: int,
        file: TextIO | None = None,
        line: str | None = None,
    ) -> None:
        if not (library_warning(message, filename) and issubclass(category, UserWarning)):
            previous(message, category, filename, lineno, file, line)
            return
        text = f"warning: {' '.join(str(message).split())}"
        if text not in shown:  # once per command, however many runs or workers repeat it
            shown.add(text)
            say(text)

    setattr(show, IN_WORKERS, install_one_line_warnings)  # how pool workers get it
    setattr(show, SHOWN, shown)  # and the lines already shown
    return show


#: Stand-ins for the non-ASCII marks the tools print, on a console that cannot show them.
_ASCII_MARKS = {"\u2020": "+"}


def console_text(text: str, stream: object = None) -> str:
    """``text`` as ``stream`` (default ``sys.stdout``) can print it: unchanged where its
    encoding holds every character, else with each mark of :data:`_ASCII_MARKS` replaced
    by its ASCII stand-in and any other character the encoding lacks by ``?`` (a latin-1
    or ASCII console would otherwise end the tool with a UnicodeEncodeError)."""
    encoding = getattr(stream if stream is not None else sys.stdout, "encoding", None)
    if not encoding:
        return text
    try:
        text.encode(encoding)
    except UnicodeEncodeError:
        for mark, stand_in in _ASCII_MARKS.items():
            text = text.replace(mark, stand_in)
        return text.encode(encoding, errors="replace").decode(encoding)
    except LookupError:  # an encoding Python does not know: leave the text to print's rules
        return text
    return text


def run_main(main: Callable[[Sequence[str] | None], int], argv: Sequence[str] | None) -> int:
    """Run ``main``: bad input, interrupts and write errors become one line on stderr, and
    the library's warnings one line each (:func:`one_line_warnings`).

    A stop (Ctrl-C, one of :data:`STOP_SIGNALS`) exits with 128 + the signal number even
    when it comes after ``main`` committed its output folder (while it prints its summary
    or stops its workers); its line then says that output is complete, not removed."""
    committed: list[Path] = []  # the output folders main completed (recording_commits)
    signals.report_outputs(committed)  # for a stop while the process exits (the guard's)
    try:
        with (
            interruptible(),
            one_line_warnings(),
            recording_commits(committed),
            printable_stdout(),
        ):
            return main(argv)
    except ParameterError as exc:
        say(f"error: {exc}")
        return EXIT_USAGE
    except PluginError as exc:  # a user's controller raised: its one line, not a traceback
        say(f"error: {exc}")
        return 1
    except KeyboardInterrupt as stop:
        forget_unhandled_interrupt()
        say(stop_line(signal.SIGINT, _complete_output(stop, committed)))
        return EXIT_INTERRUPTED
    except Terminated as stop:
        say(stop_line(stop.signum, _complete_output(stop, committed)))
        return stop.status
    except BrokenPipeError:  # e.g. output piped into head: nothing left to say
        return 1
    except OSError as exc:
        where = f"{exc.filename}: " if exc.filename else ""
        say(f"error: {where}{exc.strerror or exc}")
        return 1


#: The error handler :func:`printable_stdout` gives ``sys.stdout`` in place of each one
#: that raises on a character the encoding lacks.
_PRINTABLE_ERRORS = {"strict": "replace", "surrogateescape": "ddwmmr.surrogateescape_or_replace"}


def _surrogateescape_or_replace(error: UnicodeError) -> tuple[bytes, int]:
    """Encoding error handler: a lone surrogate U+DC80-U+DCFF (a file name's undecodable
    byte, as ``surrogateescape`` reads it) as that byte again, as ``surrogateescape``
    writes it; any other character the encoding lacks as ``?``, as ``replace`` does."""
    if not isinstance(error, UnicodeEncodeError):
        raise error
    lacking = error.object[error.start : error.end]
    replaced = bytes(ord(c) - 0xDC00 if 0xDC80 <= ord(c) <= 0xDCFF else ord("?") for c in lacking)
    return replaced, error.end


codecs.register_error(_PRINTABLE_ERRORS["surrogateescape"], _surrogateescape_or_replace)


@contextlib.contextmanager
def printable_stdout() -> Iterator[None]:
    """While the tool runs, ``sys.stdout`` writes a character its encoding lacks as ``?``
    (as :func:`console_text` does) instead of raising: a trajectory name or an output
    path outside an ASCII or latin-1 console's characters would otherwise end the tool
    with a UnicodeEncodeError traceback after its output was written. A stream whose
    handler is ``strict`` (``PYTHONIOENCODING=ascii``, a latin-1 locale) gets ``replace``;
    one whose handler is ``surrogateescape`` (an ASCII locale without UTF-8 mode:
    ``LC_ALL=POSIX PYTHONUTF8=0``) still writes a file name's undecodable byte as that
    byte (:func:`_surrogateescape_or_replace`). stderr needs nothing: Python opens it with
    ``errors="backslashreplace"``. The stream's own handler is restored afterwards."""
    stream = sys.stdout
    errors = getattr(stream, "errors", None)
    reconfigurable = isinstance(errors, str) and hasattr(stream, "reconfigure")
    # ignore: errors is a str and stream has reconfigure when reconfigurable (checked above)
    printable = _PRINTABLE_ERRORS.get(errors) if reconfigurable else None  # type: ignore[arg-type]
    if printable is not None:
        stream.reconfigure(errors=printable)  # type: ignore[union-attr]
    try:
        yield
    finally:
        if printable is not None:
            with contextlib.suppress(OSError, ValueError):  # closed or broken meanwhile
                stream.reconfigure(errors=errors)  # type: ignore[union-attr]


def _complete_output(stop: BaseException, committed: list[Path]) -> Path | None:
    """The output folder complete in place when ``stop`` came: the one a commit it
    interrupted had already filled (:func:`committed_output`), else the last one committed
    before it; None if it came before any."""
    return committed_output(stop) or (committed[-1] if committed else None)


def run_script(main: Callable[..., object], *arguments: str) -> NoReturn:
    """End a user's script the way the tools end: call ``main(*arguments)`` and exit with
    status 0 when it returns; a :class:`ParameterError` (a value the library refuses)
    gives one line ``error: ...`` on stderr and status 2, Ctrl-C status 130, a user's
    controller raising status 1, each without a traceback (:func:`run_main`). The
    examples end with it. What ``main`` returns is ignored."""

    def call(_argv: Sequence[str] | None) -> int:
        main(*arguments)
        return 0

    sys.exit(run_main(call, None))


class RefusedOption(argparse.Action):
    """An option a tool does not have though another tool does (``--robot``): refused
    with one line saying why (``reason``), exit status 2, instead of as a misspelling.
    Hidden from ``--help``; takes an optional value so that ``--robot FILE`` is one
    refusal."""

    def __init__(
        self, option_strings: Sequence[str], dest: str, reason: str, **kwargs: Any
    ) -> None:
        super().__init__(option_strings, dest, nargs="?", help=argparse.SUPPRESS, **kwargs)
        self.reason = reason

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: str | Sequence[Any] | None,
        option_string: str | None = None,
    ) -> None:
        """Refuse the option: ``parser.error`` exits with status 2."""
        parser.error(f"{option_string}: {self.reason}")


def add_robot_arguments(parser: argparse.ArgumentParser) -> None:
    """``--robot FILE`` and ``--payload KG``."""
    parser.add_argument(
        "--robot",
        metavar="FILE",
        help="robot description: a TOML file whose keys are Robot fields, in m, kg and rad "
        "(default: the thesis robot, Robot())",
    )
    parser.add_argument(
        "--payload",
        type=payload_type,
        metavar="KG",
        help="payload at the end effector in kg (default: the robot's, 1.25 for Robot())",
    )


def add_option_argument(
    parser: argparse.ArgumentParser | argparse._ArgumentGroup,
    what: str,
    examples: str = "horizon=2, aux=sum, tau=0.5,0.5,inf, obstacles=FILE",
) -> None:
    """``--option NAME=VALUE`` (repeatable): any option of the method(s), parsed and
    checked as the simulator's fields are (:func:`ddwmmr.controllers.option_specs.
    parse_option`); ``what`` says what it sets (the help's first sentence), ``examples`` a few."""
    parser.add_argument(
        "--option",
        action="append",
        metavar="NAME=VALUE",
        help=f"{what}; repeatable, e.g. {examples}. The options of each method are listed "
        "at the end; the common ones also have a flag of their own",
    )


def option_target(text: str) -> tuple[str | None, str]:
    """``--option METHOD:NAME=VALUE`` -> ``(METHOD, "NAME=VALUE")``; ``NAME=VALUE`` ->
    ``(None, text)``. A colon marks a method only before the first ``=``: a value may hold
    one (``plan=C:/runs``), a name never does (:data:`ddwmmr.registry.NAME_PATTERN`)."""
    target, colon, rest = text.partition(":")
    if colon and "=" not in target:
        return target, rest
    return None, text


def run_method_options(texts: Sequence[str] | None, method: str, flag: str) -> list[str]:
    """The ``--option`` texts of a tool that runs the one method ``method`` (chosen with
    ``flag``, e.g. ``--method``) as ``NAME=VALUE``: ``METHOD:NAME=VALUE`` is taken, as
    ``compare`` takes it, when METHOD is ``method``, and refused in one line when it
    names another."""
    options = []
    for text in texts or ():
        target, rest = option_target(text)
        if target is not None and target != method:
            raise ParameterError(
                f"option: {target!r} is not the method of this run ({flag} {method}); "
                f"METHOD:NAME=VALUE takes {method}:NAME=VALUE or NAME=VALUE (got {text!r})"
            )
        options.append(rest)
    return options


def method_options_text(methods: Sequence[str]) -> str:
    """``--help``'s list of each method's options (``--option NAME=VALUE``), one line per
    method: ``  qp: stability_min, manipulability_weight, ...``; then, for each option of
    :data:`~ddwmmr.controllers.option_specs.NOTES` a listed method takes, a line saying
    what it is: ``  dt (qp, mpc): the step the controller plans each command for, ...``."""
    from ddwmmr.controllers.option_specs import NOTES, option_names

    names = {m: option_names(m) for m in methods}
    lines = [f"  {m}: {', '.join(names[m]) or '(none)'}" for m in methods]
    for option, note in NOTES.items():
        takers = [m for m in methods if option in names[m]]
        if takers:
            lines.append(f"  {option} ({', '.join(takers)}): {note}")
    return "options of each method (--option NAME=VALUE; docs/api.md, Controllers):\n" + (
        "\n".join(lines)
    )


def horizon_defaults() -> tuple[float, float]:
    """``(tracking, waypoints)``: the mpc's horizon (s) when none is given, for the
    ``--horizon`` help of each tool (None in its signature: chosen per objective,
    :data:`ddwmmr.mpc.options.GRID_DEFAULTS`)."""
    from ddwmmr.mpc.options import GRID_DEFAULTS  # here: the MPC imports CasADi

    return GRID_DEFAULTS["tracking"][2], GRID_DEFAULTS["reach"][2]


def horizon_range() -> str:
    """``--horizon``'s range, as the mpc checks it: ``in [0.0001, 100] s``."""
    from ddwmmr.mpc.ocp import MAX_HORIZON, MIN_INTERVAL  # here: the MPC imports CasADi

    return f"in [{MIN_INTERVAL:g}, {MAX_HORIZON:g}] s"


def add_force_argument(parser: argparse.ArgumentParser | argparse._ArgumentGroup) -> None:
    """``--force``: write into an existing folder another tool or the user made."""
    parser.add_argument(
        "--force",
        action="store_true",
        help="also write into an --out that is not this tool's earlier output; deletes only "
        "files a ddwmmr manifest lists, every other file is kept",
    )


def default_run_folder(name: str) -> Path:
    """``runs/<name>-<YYYYmmdd-HHMMSS>`` (local time, relative to the working folder): the
    output folder of a tool run without ``--out``. The one place the tools make that name;
    :func:`output_target` takes :func:`first_free` of it for ``output_folder(...,
    fresh=True)``, so a default run never replaces an earlier one."""
    return Path("runs") / f"{name}-{dt.datetime.now().strftime('%Y%m%d-%H%M%S')}"


def output_target(given: str | None, default: Callable[[], Path]) -> tuple[Path, Path, bool]:
    """``(base, out, fresh)`` of a tool's ``--out`` (``given``, None when not given):
    ``fresh`` when it was not, ``base`` the folder to hand ``output_folder(base, tool,
    force, fresh)`` (``default()`` if fresh, else the given path, an empty one refused by
    :func:`given_text`) and ``out`` the folder to check before the run (the first free
    name from ``base`` if fresh, else ``base``). The folder written is ``out.with_name(
    writer.path.name)``: a fresh writer takes the next free name when it commits."""
    fresh = given is None
    base = default() if given is None else Path(given_text("out", given, "an output folder"))
    return base, (first_free(base, folder=True) if fresh else base), fresh


#: Constructor parameters of a plant that ``--plant-option`` does not set: the robot (the
#: tools' ``--robot``) and the kinematic plant's integrator (``--integrator``, which
#: ``simulate`` passes to the plant itself).
PLANT_ARGUMENTS = ("robot", "integrator")


def plant_option_specs(plant: str) -> dict[str, OptionSpec]:
    """The options ``--plant-option NAME=VALUE`` sets on the registered plant ``plant``
    (name -> :class:`~ddwmmr.controllers.option_specs.OptionSpec`): the keyword parameters
    of its constructor but :data:`PLANT_ARGUMENTS`, each read as ``--option`` reads a
    method's option of that type (:func:`~ddwmmr.controllers.option_specs.
    constructor_option_specs`). Imports the plant's module (MuJoCo's: about 0.4 s)."""
    from ddwmmr.controllers.option_specs import constructor_option_specs
    from ddwmmr.plants import plant_class

    return constructor_option_specs(plant_class(plant), PLANT_ARGUMENTS)


def check_plant_option_names(plant: str, names: Iterable[str]) -> dict[str, OptionSpec]:
    """:func:`plant_option_specs` of ``plant`` if it has every one of ``names``, else a
    one-line :class:`ParameterError`: the kinematic plant (or any plant without options)
    has none; another name than the plant's is named with the closest one and the list."""
    names = list(names)
    if not names:
        return {}
    specs = plant_option_specs(plant)
    if not specs:
        raise ParameterError(
            f"plant-option: the {plant} plant has no options (got {shown(names[0])}"
            + ("; --integrator sets its integrator)" if plant == "kinematic" else ")")
        )
    for name in names:
        if name not in specs:
            raise ParameterError(
                f"plant-option: the {plant} plant has no option {name!r}"
                f"{did_you_mean(name, specs)} (options: {', '.join(specs)})"
            )
    return specs


def parse_plant_options(plant: str, texts: Sequence[str] | None) -> dict[str, Any]:
    """``{name: value}`` of the ``--plant-option NAME=VALUE`` texts for the plant named
    ``plant``: a name as :func:`check_plant_option_names` allows, a value read as
    :func:`parse_named_options` reads one (a number option's text that is no number is
    passed on for the plant's own check, :func:`built_plant`)."""
    return parse_named_options(
        texts or (), "plant-option", lambda names: check_plant_option_names(plant, names)
    )


def parse_named_options(
    texts: Sequence[str],
    flag: str,
    specs_for: Callable[[list[str]], Mapping[str, OptionSpec]],
) -> dict[str, Any]:
    """``{name: value}`` of ``NAME=VALUE`` texts given to ``--flag`` (a plant's or an
    arbiter's constructor options): ``specs_for(names)`` refuses a name the object does
    not take and returns the specs of those it does; each value is read as ``--option``
    reads one (:meth:`~ddwmmr.controllers.option_specs.OptionSpec.parse`: a number
    option's text that is no number comes back as a
    :class:`~ddwmmr.controllers.base.NumberText` for the caller to refuse). A text
    without ``=`` or a name given twice is a one-line :class:`ParameterError`."""
    from ddwmmr.controllers.option_specs import parse_typed, split_option

    pairs = [(*split_option(text, flag), text) for text in texts]
    specs = specs_for([name for name, _, _ in pairs])
    options: dict[str, Any] = {}
    for name, value, text in pairs:
        if name in options:
            raise ParameterError(f"{flag}: {name} given twice (got {shown(text)})")
        options[name] = parse_typed(specs[name], value, flag)
    return options


def built_plant(plant: str, robot: Robot, options: dict[str, Any]) -> Any:
    """The plant named ``plant`` built for ``robot`` with ``options``: a value it refuses
    is its own one-line :class:`ParameterError` (``c2 must be in [1e-20, 1e+13] N m s/rad
    (got -1)``), raised before the run. Its warnings are left to the run's own plant,
    which says them once."""
    from ddwmmr.controllers.base import NumberText
    from ddwmmr.plants import make_plant

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        built = make_plant(plant, robot, **options)
    for name, value in options.items():
        if isinstance(value, NumberText):  # taken unchecked: refused as --option refuses it
            raise ParameterError(f"{name} must be {value.expected} (got {shown(value)})")
    return built


class _PlantOptionAction(argparse._AppendAction):
    """``append``, with a help text listing each plant's options, made only when the help
    is shown: listing the MuJoCo plant's imports the engine (about 0.4 s)."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        self._text = kwargs.pop("help")
        super().__init__(*args, **kwargs)

    @property
    def help(self) -> str:
        """The help: its text, then each plant's option names."""
        from ddwmmr.plants import available_plants

        lists = []
        for plant in available_plants():
            try:
                names = ", ".join(plant_option_specs(plant)) or "none"
            except (ImportError, ParameterError):
                names = "(cannot be imported)"
            lists.append(f"{plant}: {names}")
        return f"{self._text} (the options of each plant: {'; '.join(lists)})"

    @help.setter
    def help(self, value: str | None) -> None:  # argparse's Action sets it
        pass


def refuse_plant_option_argument(parser: argparse.ArgumentParser, tool: str) -> None:
    """``--plant-option``, refused with one line (exit status 2): ``tool`` (its name in
    the line) runs each plant on its defaults; ``track`` sets a plant's options."""
    parser.add_argument(
        "--plant-option",
        action=RefusedOption,
        reason=f"{tool} runs each plant with its default options; python -m ddwmmr.track "
        "--plant-option NAME=VALUE sets them",
    )


def add_plant_option_argument(parser: argparse.ArgumentParser | argparse._ArgumentGroup) -> None:
    """``--plant-option NAME=VALUE`` (repeatable): a constructor option of the ``--plant``
    (:func:`parse_plant_options`), as ``simulate(..., plant_options=...)`` sets it."""
    parser.add_argument(
        "--plant-option",
        action=_PlantOptionAction,
        metavar="NAME=VALUE",
        help="a constructor option of --plant (repeatable), read as --option reads a "
        "method's, e.g. c1=20, c2=2, force_limit=25 (thesis), timestep=0.001 (mujoco); a "
        "value the plant refuses is an error; for a robot other than the thesis robot the "
        "thesis plant's c1, c2 and force_limit default to values derived from its motors, "
        'mass and yaw inertia (docs/thesis.md, "What is simulated")',
    )


def robot_from_arguments(args: argparse.Namespace, plants: Sequence[str] = ()) -> Robot:
    """The robot selected by ``--robot`` / ``--payload``; with ``"mujoco"`` among
    ``plants``, a robot file MuJoCo cannot build is refused naming the file (the plant
    itself would refuse it only once the run starts, without the file's name)."""
    given_text("robot", args.robot, "the path of a robot TOML file")
    robot = Robot.from_toml(args.robot) if args.robot is not None else Robot()
    if args.payload is not None:
        robot = robot.with_payload(args.payload)
    if args.robot is not None and "mujoco" in plants:
        from ddwmmr.plants.mujoco.model import check_buildable  # imports the engine

        try:
            check_buildable(robot)
        except ParameterError as exc:
            # the message names the MuJoCo plant: prefixed with the file, not repeated
            raise ParameterError(f"robot: {args.robot}: {exc}") from None
    return robot


#: ``--traj-scale``'s word for the robot's length unit ``L1 / 0.35 m``.
ROBOT_SCALE = "robot"


def traj_scale_type(text: str) -> float | str:
    """An argparse ``type`` for ``--traj-scale``: :data:`ROBOT_SCALE` or a finite number
    (its range is checked with the robot, :func:`scaled_trajectory`)."""
    if text.strip() == ROBOT_SCALE:
        return ROBOT_SCALE
    from ddwmmr.trajectories.scaled import SCALE_RANGE

    low, high = SCALE_RANGE
    return number_type(f"in [{low:g}, {high:g}] or {ROBOT_SCALE}", finite=True)(text)


def add_traj_scale_argument(parser: argparse.ArgumentParser, which: str) -> None:
    """``--traj-scale S|robot``: scale ``which`` (the tool's trajectories, in words) in
    space (:func:`scaled_trajectory`)."""
    from ddwmmr.trajectories.scaled import SCALE_RANGE

    low, high = SCALE_RANGE
    parser.add_argument(
        "--traj-scale",
        type=traj_scale_type,
        metavar="S|robot",
        help=f"scale {which} in space by S about the world origin: positions and speeds "
        "times S, headings, durations and steps kept (ddwmmr.ScaledTrajectory), for a robot "
        f"of another size; {ROBOT_SCALE}: the robot's length unit L1/0.35 m (10 for a --robot "
        f"ten times the default); S in [{low:g}, {high:g}] (default 1: as given); obstacles stay "
        "in world metres; recorded with the trajectory (summary.json, run.json)",
    )


def scaled_trajectory(trajectory: Any, scale: float | str | None, robot: Robot) -> Any:
    """``trajectory`` scaled by ``--traj-scale`` (a number, :data:`ROBOT_SCALE` for the
    robot's length unit, None when not given): a
    :class:`~ddwmmr.trajectories.ScaledTrajectory`, or ``trajectory`` itself at a factor of
    exactly 1 (a default run stays bit for bit the same). A factor out of range is a
    one-line :class:`ParameterError` naming ``traj-scale``."""
    from ddwmmr.resolution.kernels import length_unit
    from ddwmmr.trajectories.scaled import ScaledTrajectory, check_scale

    if scale is None:
        return trajectory
    factor = length_unit(robot.L1) if scale == ROBOT_SCALE else scale
    factor = check_scale(factor, "traj-scale")
    return trajectory if factor == 1.0 else ScaledTrajectory(trajectory, factor)
