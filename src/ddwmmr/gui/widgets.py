"""Small widget helpers of the control panel (matplotlib widgets, figure coordinates).

* :class:`Field` - a labelled text box that applies its text through a callback; when the
  callback raises :class:`ParameterError` the box returns to its previous text (the
  previous valid setting stays) and the error goes to the window's message line, until
  the box accepts a valid value (:class:`ErrorOwner`: every widget takes back its own
  error, and only its own).
* :class:`CycleButton` - a button showing ``name: value`` that steps through a list of
  values on every click (choices, on/off flags).
* :func:`radio` - radio buttons with small labels.
* :func:`wrap_to_width` - a text broken at its commas to fit a width on the canvas.
* :func:`fit_label` - a label made smaller, or broken in two lines, to fit its room.

Widgets are also driven programmatically (tests, ``--snapshot``): ``Field.submit(text)``
behaves like typing the text and pressing Enter.
"""

from __future__ import annotations

import functools
import warnings
from collections.abc import Callable, Sequence
from typing import Any

from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.font_manager import findfont, get_font
from matplotlib.text import Text
from matplotlib.widgets import Button, RadioButtons, TextBox

from ddwmmr.errors import ParameterError, escaped_controls
from ddwmmr.reports.canvas import renderer_of

#: Font size of panel labels and widget texts (points).
FONT = 8
#: Callback receiving an error message to show in the window (``report``), or one to
#: take back if the window still shows it (``withdraw``).
Reporter = Callable[[str], None]
#: A rectangle ``(left, bottom, width, height)`` in figure fractions.
Rect = tuple[float, float, float, float]
#: matplotlib's warning of a character its fonts have no glyph for (a regular expression).
MISSING_GLYPH = r"Glyph \d+ .* missing from font"


def panel_axes(figure: Figure, rect: Rect) -> Axes:
    """A bare axes at ``rect`` (left, bottom, width, height in figure fractions)."""
    ax = figure.add_axes(rect)
    ax.set_navigate(False)
    return ax


class QuietTextBox(TextBox):
    """A TextBox that does not redraw the whole figure when it need not.

    matplotlib's TextBox ends typing - and draws the full figure - on every click anywhere
    and every window resize, in each box, even when nobody types in it (with 15 boxes a
    click took seconds); and it draws the full figure on every key typed. Here ending
    typing does nothing unless this box is being typed in, and a key schedules an idle
    redraw instead of drawing at once.

    A character the font has no glyph for (a folder name in a script the font lacks) is
    drawn as matplotlib draws it, without its console warning, which matplotlib repeats
    whenever the text or the window's size changes: the window's message names such
    text once, its characters escaped (:func:`drawable`). The box keeps the text itself,
    the value it applies.
    """

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        for name in ("draw", "get_window_extent"):  # the two that lay the text out
            method = getattr(self.text_disp, name)
            setattr(self.text_disp, name, _without_glyph_warnings(self.text_disp, method))

    def stop_typing(self) -> None:
        if self.capturekeystrokes:
            super().stop_typing()

    def _rendercursor(self) -> None:  # overrides matplotlib's cursor redraw
        canvas = self.ax.figure.canvas
        # ignore: _get_renderer and _rendercursor are matplotlib's private methods (not
        # in its type hints)
        if self.ax.figure._get_renderer() is None:  # type: ignore[union-attr]
            super()._rendercursor()  # type: ignore[misc]
            return
        # ignore: an instance attribute hides the method until deleted below
        canvas.draw = canvas.draw_idle  # type: ignore[method-assign]
        try:
            super()._rendercursor()  # type: ignore[misc]
        finally:
            del canvas.draw


def _without_glyph_warnings(text: Text, method: Callable[..., Any]) -> Callable[..., Any]:
    """``method`` of ``text``, silent about the glyphs its font lacks (:data:`MISSING_GLYPH`)
    while ``text`` holds any non-ASCII character (every font has every ASCII glyph)."""

    @functools.wraps(method)
    def quietly(*args: Any, **kwargs: Any) -> Any:
        if text.get_text().isascii():
            return method(*args, **kwargs)
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", MISSING_GLYPH, UserWarning)
            return method(*args, **kwargs)

    return quietly


def message_line(text: str) -> str:
    """``text`` as one line of the message area: every character of
    :data:`~ddwmmr.errors.UNPRINTABLE_CATEGORIES` (a newline, a tab, a NUL, e.g. of a file
    name an error quotes) written as its Python escape (``\\n``), so nothing after it is
    lost and no font is asked for a glyph it has not; trailing whitespace dropped."""
    return escaped_controls(text.rstrip(), undecodable=False)


def drawable(text: str, artist: Text) -> str:
    """``text`` with each character the font of ``artist`` has no glyph for (a full-width
    digit a message quotes) written as its Python escape (``\\uff11``): matplotlib would
    draw an empty box and warn on the console at every draw."""
    if text.isascii():
        return text
    font = get_font(findfont(artist.get_fontproperties()))
    return "".join(
        c if c.isascii() or font.get_char_index(ord(c)) else ascii(c)[1:-1] for c in text
    )


def describe_error(exc: Exception) -> str:
    """One line for the message area (:func:`message_line`): a ParameterError's own text
    (whole: a line break in it is one of a value it quotes), else type and first line."""
    if isinstance(exc, ParameterError):
        return message_line(str(exc))
    text = str(exc).splitlines()[0] if str(exc) else ""
    return message_line(f"{type(exc).__name__}: {text}".rstrip(": "))


class ErrorOwner:
    """The error a widget put in the message line, taken back once the widget holds a
    valid value again: ``report(text)`` shows it, ``withdraw(text)`` clears it if the
    window still shows that text (a message said since, by anyone, stays)."""

    def __init__(self, report: Reporter, withdraw: Reporter) -> None:
        self.report = report
        self.withdraw = withdraw
        self._error: str | None = None

    def failed(self, exc: Exception) -> None:
        """Show why ``exc`` refused the widget's new value."""
        self._error = describe_error(exc)
        self.report(self._error)

    def accepted(self) -> None:
        """The widget holds a valid value: take back its error, if any."""
        if self._error is not None:
            self.withdraw(self._error)
            self._error = None


class Field(ErrorOwner):
    """A labelled text box whose submitted text is applied by ``apply(text)``.

    ``apply`` returns the text to show (e.g. normalised), or raises
    :class:`ParameterError`; then the box shows its previous text again and ``report``
    receives the message, which ``withdraw`` takes back when a valid text is submitted.
    """

    def __init__(
        self,
        figure: Figure,
        rect: Rect,
        label: str,
        text: str,
        apply: Callable[[str], str | None],
        report: Reporter,
        withdraw: Reporter,
        hint: str = "",
    ) -> None:
        super().__init__(report, withdraw)
        self.ax = panel_axes(figure, rect)
        self.box = QuietTextBox(self.ax, label, initial=text, label_pad=0.04)
        self.box.label.set_fontsize(FONT)
        self.box.text_disp.set_fontsize(FONT)
        self.box.text_disp.set_clip_on(True)  # long paths stay inside the box
        self.hint = None
        if hint:
            self.hint = self.ax.text(
                1.04,
                0.5,
                hint,
                transform=self.ax.transAxes,
                fontsize=FONT - 1,
                color="0.35",
                va="center",
                ha="left",
            )
        self.apply = apply
        self.valid_text = text
        self.box.on_submit(self._submitted)

    @property
    def text(self) -> str:
        """The text currently in the box."""
        return self.box.text

    def submit(self, text: str) -> None:
        """Type ``text`` into the box and press Enter."""
        self._set_silently(text)
        self._submitted(text)

    def show(self, text: str) -> None:
        """Display ``text`` as the valid content, without applying it."""
        self.valid_text = text
        self._set_silently(text)

    def set_visible(self, visible: bool) -> None:
        """Show or hide the box (a hidden box ignores clicks)."""
        self.ax.set_visible(visible)
        self.box.set_active(visible)

    def remove(self) -> None:
        """Take the box off the window: its axes and its canvas callbacks."""
        self.box.disconnect_events()
        self.ax.remove()

    def _submitted(self, text: str) -> None:
        if text == self.valid_text:  # the valid value already applied
            self.accepted()
            return
        try:
            shown = self.apply(text)
        except Exception as exc:  # the previous valid text stays; the window shows why
            self.failed(exc)
            self._set_silently(self.valid_text)
            return
        self.valid_text = text if shown is None else shown
        if shown is not None and shown != text:
            self._set_silently(shown)
        self.accepted()

    def _set_silently(self, text: str) -> None:
        # TextBox.set_val would show the typing cursor and redraw the whole figure.
        self.box.text_disp.set_text(text)
        self.box.cursor.set_visible(False)


class CycleButton(ErrorOwner):
    """A button labelled ``name: value`` that moves to the next of ``values`` when clicked.

    ``apply(value)`` may raise :class:`ParameterError`: the value then stays where it was
    and ``report`` shows why, until a click is accepted (``withdraw``).
    """

    def __init__(
        self,
        figure: Figure,
        rect: Rect,
        name: str,
        values: Sequence[Any],
        current: Any,
        apply: Callable[[Any], None],
        report: Reporter,
        withdraw: Reporter,
        format_value: Callable[[Any], str] = str,
    ) -> None:
        super().__init__(report, withdraw)
        self.ax = panel_axes(figure, rect)
        self.name = name
        self.values = list(values)
        self.format_value = format_value
        self.value = current
        self.button = Button(self.ax, self._caption(current), color="0.9", hovercolor="0.97")
        self.button.label.set_fontsize(FONT)
        self.apply = apply
        self.button.on_clicked(lambda _event: self.click())

    def click(self) -> None:
        """Move to the next value (what a mouse click does)."""
        position = self.values.index(self.value) if self.value in self.values else -1
        following = self.values[(position + 1) % len(self.values)]
        try:
            self.apply(following)
        except Exception as exc:  # the value stays; the window shows why
            self.failed(exc)
            return
        self.show(following)
        self.accepted()

    def show(self, value: Any) -> None:
        """Display ``value`` as the current one, without applying it."""
        self.value = value
        self.button.label.set_text(self._caption(value))

    def set_visible(self, visible: bool) -> None:
        """Show or hide the button (a hidden button ignores clicks)."""
        self.ax.set_visible(visible)
        self.button.set_active(visible)

    def remove(self) -> None:
        """Take the button off the window: its axes and its canvas callbacks."""
        self.button.disconnect_events()
        self.ax.remove()

    def _caption(self, value: Any) -> str:
        return f"{self.name}: {self.format_value(value)}"


def radio(figure: Figure, rect: Rect, labels: Sequence[str], active: int) -> RadioButtons:
    """Vertical radio buttons with panel-size labels and no frame."""
    ax = panel_axes(figure, rect)
    ax.set_frame_on(False)
    buttons = RadioButtons(ax, list(labels), active=active, label_props={"fontsize": [FONT]})
    return buttons


def set_radio_silently(buttons: RadioButtons, label: str) -> None:
    """Select ``label`` without calling the radio's callbacks."""
    labels = [text.get_text() for text in buttons.labels]
    events = buttons.eventson
    buttons.eventson = False
    try:
        buttons.set_active(labels.index(label))
    finally:
        buttons.eventson = events


def button(figure: Figure, rect: Rect, label: str, action: Callable[[], object]) -> Button:
    """A push button calling ``action()`` when clicked."""
    widget = Button(panel_axes(figure, rect), label, color="0.88", hovercolor="0.97")
    widget.label.set_fontsize(FONT + 1)
    widget.on_clicked(lambda _event: action())
    return widget


def wrap_to_width(text: str, artist: Text, right: float, indent: str = "    ") -> str:
    """``text`` broken after its commas into lines that, in the font of ``artist`` (a
    figure text), end left of the figure fraction ``right``; continuation lines are
    indented. Lines of ``text`` are wrapped one by one; a piece wider than the room on
    its own is broken at its spaces (a word wider than the room keeps a line of its own)."""
    # ignore: the artist is a figure text (of the window's Figure)
    figure: Figure = artist.get_figure()  # type: ignore[assignment]
    renderer = renderer_of(figure)
    font = artist.get_fontproperties()
    left = artist.get_transform().transform(artist.get_position())[0]
    room = right * figure.bbox.width - left

    def width(candidate: str) -> float:
        extent: float = renderer.get_text_width_height_descent(candidate, font, ismath=False)[0]
        return extent

    def at_spaces(line: str) -> list[str]:
        """``line`` itself if it fits, else broken at its spaces (a word wider than the
        room keeps a line of its own)."""
        if width(line) <= room:
            return [line]
        body = line.lstrip(" ")
        lines, current = [], line[: len(line) - len(body)]
        for word in body.split(" "):
            if not current.strip():
                current += word
            elif width(f"{current} {word}") <= room:
                current = f"{current} {word}"
            else:
                lines.append(current)
                current = indent + word
        return [*lines, current]

    wrapped: list[str] = []
    for line in text.split("\n"):
        pieces = line.split(", ")
        current = pieces[0]
        for piece in pieces[1:]:
            candidate = f"{current}, {piece}"
            if width(candidate + ",") <= room:
                current = candidate
            else:
                wrapped += at_spaces(current + ",")
                current = indent + piece
        wrapped += at_spaces(current)
    return "\n".join(wrapped)


def fit_label(label: Text, left: float, height: float, sizes: Sequence[float]) -> None:
    """Fit ``label`` (a text of the window) into its room: its extent starting at ``left``
    or right of it and at most ``height`` high (display px). Tried in turn: one line in
    each font size of ``sizes`` (points, largest first) but the last, two lines in each of
    those, then the last size on one line and on two. Two lines are broken before the
    unit (`` (``), else after an underscore (the longest first line first). The first
    that fits is kept, else the last tried; a label that fits in ``sizes[0]`` on one line
    stays as it is."""
    # ignore: the label is a text of the window's Figure
    figure: Figure = label.get_figure()  # type: ignore[assignment]
    renderer = renderer_of(figure)
    text = label.get_text()
    breaks = [text.index(" (")] if " (" in text else []
    breaks += [i + 1 for i in range(len(text) - 1, 0, -1) if text[i] == "_"]
    broken = [f"{text[:i].rstrip()}\n{text[i:].lstrip()}" for i in breaks]
    *larger, smallest = sizes
    tries = [(size, [text]) for size in larger] + [(size, broken) for size in larger]
    for size, shapes in [*tries, (smallest, [text, *broken])]:
        label.set_fontsize(size)
        for shape in shapes:
            label.set_text(shape)
            if "\n" in shape:
                label.set_linespacing(1.0)  # two lines kept close
            extent = label.get_window_extent(renderer)
            if extent.x0 >= left and extent.height <= height:
                return
