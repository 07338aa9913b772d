"""Text output: number formatting (:func:`fmt`, :func:`mm`), the :class:`Document`
model rendered as Markdown and as self-contained HTML, and the plain-text table of the
console summary (:func:`text_table`).
"""

from __future__ import annotations

import base64
import html
import math
import re
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

# -- number formatting --------------------------------------------------------------------


def fmt(value: Any, digits: int = 3) -> str:
    """``value`` with ``digits`` significant digits, plain notation for 1e-3 <= |v| < 1e5."""
    if value is None or value == "":
        return "n/a"
    if isinstance(value, bool | int | np.integer):
        return str(int(value))
    value = float(value)
    if math.isnan(value):
        return "n/a"
    if math.isinf(value) or value == 0.0:
        return str(value) if math.isinf(value) else "0"
    magnitude = abs(value)
    if 1e-3 <= magnitude < 1e5:
        decimals = max(0, digits - 1 - math.floor(math.log10(magnitude)))
        return f"{value:.{decimals}f}"
    return f"{value:.{digits - 1}e}"


def mm(value_m: float) -> str:
    """A length in m written in mm (3 significant digits)."""
    return fmt(1000.0 * float(value_m))


# -- the document model -------------------------------------------------------------------


class Document:
    """A small block document rendered both as Markdown and as self-contained HTML.

    Inline markup in text: ``**bold**`` and backquoted ``code`` only.
    """

    def __init__(self, title: str) -> None:
        self.title = title
        self.blocks: list[tuple[str, Any]] = []

    def heading(self, text: str, level: int = 2) -> None:
        """Section heading (level 2..4)."""
        self.blocks.append(("heading", (level, text)))

    def paragraph(self, text: str) -> None:
        """A paragraph."""
        self.blocks.append(("paragraph", text))

    def bullets(self, items: Sequence[str]) -> None:
        """A bullet list."""
        self.blocks.append(("bullets", list(items)))

    def table(
        self, headers: Sequence[str], rows: Sequence[Sequence[str]], left: Sequence[int] = (0,)
    ) -> None:
        """A table; the columns numbered in ``left`` (from 0; text) are left aligned, the
        others (numbers) right aligned."""
        self.blocks.append(("table", (list(headers), [list(r) for r in rows], tuple(left))))

    def figure(self, filename: str, caption: str) -> None:
        """A PNG figure (file in the report folder) with its caption."""
        self.blocks.append(("figure", (filename, caption)))

    def to_markdown(self) -> str:
        """Markdown text; figures are linked by relative file name."""
        parts = [f"# {_md_inline(self.title)}"]
        for kind, data in self.blocks:
            parts.append(_MARKDOWN[kind](data))
        return "\n\n".join(parts) + "\n"

    def to_html(self, folder: Path) -> str:
        """A self-contained HTML page: figures from ``folder`` embedded as data URIs."""
        body = [f"<h1>{_inline(self.title)}</h1>"]
        for kind, data in self.blocks:
            body.append(_html_figure(data, folder) if kind == "figure" else _HTML[kind](data))
        return _HTML_PAGE.format(title=html.escape(self.title), body="\n".join(body))


#: Where Markdown would start raw HTML: ``<`` before a tag name, ``/``, ``!`` or ``?``.
_MD_TAG = re.compile(r"<(?=[A-Za-z/!?])")
#: A backquoted code span of the inline markup (its text is shown as it is).
_MD_CODE = re.compile(r"(`[^`]*`)")
_LINE_BREAK = re.compile(r"\r\n|[\r\n\v\f\x85\u2028\u2029]")


def _md_inline(text: str) -> str:
    """Markdown for one block's text, as :func:`_inline` is its HTML: a name holding
    ``<img ...>`` shows as text (``&lt;img``, outside code spans, where Markdown would
    pass raw HTML through) and a line break becomes a space (it would end a table row or
    a heading, or start a block)."""
    text = _LINE_BREAK.sub(" ", text)
    parts = _MD_CODE.split(text)
    return "".join(p if i % 2 else _MD_TAG.sub("&lt;", p) for i, p in enumerate(parts))


def _md_table(data: tuple[list[str], list[list[str]], tuple[int, ...]]) -> str:
    headers, rows, left = data
    lines = [
        "| " + " | ".join(_md_cell(h) for h in headers) + " |",
        "|" + "|".join(":---" if i in left else "---:" for i in range(len(headers))) + "|",
    ]
    lines += ["| " + " | ".join(_md_cell(cell) for cell in row) + " |" for row in rows]
    return "\n".join(lines)


def _md_cell(text: str) -> str:
    """A table cell: :func:`_md_inline` with ``|`` escaped."""
    return _md_inline(text).replace("|", "\\|")


_MARKDOWN: dict[str, Callable[[Any], str]] = {
    "heading": lambda d: "#" * d[0] + " " + _md_inline(d[1]),
    "paragraph": _md_inline,
    "bullets": lambda d: "\n".join(f"- {_md_inline(item)}" for item in d),
    "table": _md_table,
    "figure": lambda d: f"![{_md_inline(d[1])}]({d[0]})\n\n*{_md_inline(d[1])}*",
}


def _inline(text: str) -> str:
    """HTML for the inline markup of :class:`Document` text."""
    text = html.escape(text, quote=False)
    text = re.sub(r"\*\*(.+?)\*\*", r"<strong>\1</strong>", text)
    return re.sub(r"`(.+?)`", r"<code>\1</code>", text)


def _html_table(data: tuple[list[str], list[list[str]], tuple[int, ...]]) -> str:
    headers, rows, left = data
    head = "".join(f"<th{_html_align(i, left)}>{_inline(h)}</th>" for i, h in enumerate(headers))
    body = "".join(
        "<tr>"
        + "".join(f"<td{_html_align(i, left)}>{_inline(c)}</td>" for i, c in enumerate(row))
        + "</tr>"
        for row in rows
    )
    return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def _html_align(column: int, left: tuple[int, ...]) -> str:
    """The cell attribute of a left-aligned text column; the page's style sheet already
    left-aligns the first column and right-aligns the others."""
    return ' style="text-align: left"' if column in left and column > 0 else ""


def _html_figure(data: tuple[str, str], folder: Path) -> str:
    filename, caption = data
    encoded = base64.b64encode((folder / filename).read_bytes()).decode("ascii")
    return (
        f'<figure><img alt="{html.escape(caption)}" src="data:image/png;base64,{encoded}">'
        f"<figcaption>{_inline(caption)}</figcaption></figure>"
    )


_HTML: dict[str, Callable[[Any], str]] = {
    "heading": lambda d: f"<h{d[0]}>{_inline(d[1])}</h{d[0]}>",
    "paragraph": lambda d: f"<p>{_inline(d)}</p>",
    "bullets": lambda d: "<ul>" + "".join(f"<li>{_inline(i)}</li>" for i in d) + "</ul>",
    "table": _html_table,
}

_HTML_PAGE = """<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>{title}</title>
<style>
body {{ font-family: sans-serif; max-width: 1100px; margin: 2em auto; padding: 0 1em;
       line-height: 1.45; color: #222; }}
table {{ border-collapse: collapse; margin: 1em 0; font-size: 0.9em; }}
th, td {{ border: 1px solid #ccc; padding: 0.25em 0.55em; text-align: right; }}
th:first-child, td:first-child {{ text-align: left; }}
thead {{ background: #f0f0f0; }}
figure {{ margin: 1.5em 0; }}
img {{ max-width: 100%; }}
figcaption {{ font-style: italic; color: #555; }}
code {{ background: #f4f4f4; padding: 0 0.2em; }}
</style>
</head>
<body>
{body}
</body>
</html>
"""


# -- console summary ----------------------------------------------------------------------


def text_table(headers: Sequence[str], rows: Sequence[Sequence[str]], left: int = 2) -> str:
    """An aligned plain-text table: the first ``left`` columns left aligned, others right."""
    widths = [max(len(str(x)) for x in column) for column in zip(headers, *rows)]

    def line(cells: Sequence[str]) -> str:
        parts = [str(x).ljust(w) for x, w in zip(cells[:left], widths[:left])]
        parts += [str(x).rjust(w) for x, w in zip(cells[left:], widths[left:])]
        return "  ".join(parts).rstrip()

    return "\n".join([line(headers), *(line(r) for r in rows)])
