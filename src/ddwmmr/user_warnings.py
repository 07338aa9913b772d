"""The library's warnings about the user's input, issued at the user's line.

A warning names a file and line; Python's ``stacklevel`` counts frames up from the
``warnings.warn`` call, which is right for one call path only (a check reached from
``simulate``, from a controller's ``reset`` and from the scenarios runner sits at
different depths). :func:`warn_user` names instead the first frame outside this package:
the line of the user's code that called the library, or of a plug-in's code (a user's
controller, plant or trajectory that the library runs) when that code called the library
function that warned. It is what Python 3.12's ``warnings.warn(...,
skip_file_prefixes=(<package folder>,))`` does, written as a frame walk because the
package supports Python 3.11; this walk is the only implementation, on every version.

The walk runs only when a warning is issued (the checks decide first), never per step.
"""

from __future__ import annotations

import os
import sys
import warnings
from types import FrameType
from typing import Any

#: The package's folder with a trailing separator (normalised as :func:`os.path.normcase`
#: does): a frame whose file lies below it is the library's own.
PACKAGE_PREFIX = os.path.normcase(os.path.dirname(os.path.abspath(__file__))) + os.sep

#: Attribute :func:`warn_user` sets (True) on the warning it issues: the tools' one-line
#: display (:func:`ddwmmr.cli.common.one_line_warnings`) knows it for the library's own by
#: that, wherever the warning points.
LIBRARY_MARK = "ddwmmr_library"


def warn_user(message: str, category: type[Warning] = UserWarning) -> None:
    """Issue ``message`` (one line) as a ``category`` warning attributed to the first
    stack frame, from the caller of this function up, whose file is outside this package
    (:func:`user_frame`), with the filters, the once-per-line registry and the display
    ``warnings.warn`` would use for that frame: ``-W error`` raises it, a
    ``DeprecationWarning`` is shown by default only when that frame is ``__main__``'s.
    When no frame is outside the package, it names ``sys:1``
    as ``warnings.warn`` does for a ``stacklevel`` beyond the stack.

    The warning carries :data:`LIBRARY_MARK`; its category is ``category`` itself."""
    warning = category(message)
    setattr(warning, LIBRARY_MARK, True)
    frame = user_frame(sys._getframe(1))
    if frame is None:
        where: dict[str, Any] = sys.__dict__
        filename, lineno = "sys", 1
    else:
        where = frame.f_globals
        filename, lineno = frame.f_code.co_filename, frame.f_lineno
    registry = where.setdefault("__warningregistry__", {})
    module = where.get("__name__", "<string>")
    # no module_globals: warnings.warn passes none either (the display reads the line)
    warnings.warn_explicit(warning, category, filename, lineno, module, registry)


def user_frame(frame: FrameType | None) -> FrameType | None:
    """``frame`` or the first frame it was called from whose file is outside this package
    and not the import machinery's (``importlib._bootstrap``, which ``warnings.warn``
    skips too); None if there is none."""
    while frame is not None and (
        in_package(frame.f_code.co_filename) or _import_machinery(frame.f_code.co_filename)
    ):
        frame = frame.f_back
    return frame


def in_package(filename: str) -> bool:
    """Whether ``filename`` (a code object's or a warning's) lies below this package's
    folder (:data:`PACKAGE_PREFIX`); never a pseudo-file such as ``<stdin>``."""
    if filename.startswith("<"):
        return False
    return os.path.normcase(os.path.abspath(filename)).startswith(PACKAGE_PREFIX)


def library_warning(message: Warning | str, filename: str) -> bool:
    """Whether a shown warning (``message`` and the ``filename`` it names, as
    ``warnings.showwarning`` receives them) is the library's own: issued by
    :func:`warn_user` (:data:`LIBRARY_MARK`), or naming a file of this package."""
    return getattr(message, LIBRARY_MARK, False) is True or in_package(filename)


def _import_machinery(filename: str) -> bool:
    """Whether ``filename`` is the import system's own (frozen ``importlib._bootstrap``
    and ``_bootstrap_external``), as ``warnings`` tells it."""
    return "importlib" in filename and "_bootstrap" in filename
