"""The simulator window: control panel, view with live plots, run/playback, export.

One matplotlib figure holds everything (``App(figure)``); with the Tk backend it is a
desktop window, with Agg it is drawn off-screen (tests, ``--snapshot``). The app never
simulates by itself: Run builds the controllers with :func:`ddwmmr.make_controller` and
calls :func:`ddwmmr.simulate` (through :func:`ddwmmr.gui.settings.simulate_settings`) in a
background :class:`~ddwmmr.gui.worker.Worker`; the finished run is then played back (the
time slider scrubs it).

Every handler is guarded: a bad value shows a one-line message in the window and the
previous valid setting stays; an unexpected error is shown the same way, never as a
traceback that ends the app.
"""

from __future__ import annotations

import contextlib
import datetime
import functools
import os
import re
import textwrap
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib.figure import Figure

from ddwmmr.errors import ParameterError, plain_float, shown
from ddwmmr.gui import export
from ddwmmr.gui.layout import (
    FILE_ENTRY,
    OFF_ENTRY,
    OPTIONS_PER_PAGE,
    SPEEDS,
    SUMMARY_RIGHT,
    PanelLayout,
    canvas_size,
    scale_of,
    text_scale,
)
from ddwmmr.gui.options import NOTES, OptionSpec, method_options
from ddwmmr.gui.paths import check_export_root
from ddwmmr.gui.settings import (
    SLOTS,
    Settings,
    build_controller,
    build_trajectory,
    check_geometry,
    check_settings,
    geometry_of,
    simulate_settings,
)
from ddwmmr.gui.widgets import (
    FONT,
    CycleButton,
    Field,
    describe_error,
    drawable,
    set_radio_silently,
    wrap_to_width,
)
from ddwmmr.gui.worker import Worker
from ddwmmr.reports.canvas import renderer_of
from ddwmmr.reports.compare.document import fmt
from ddwmmr.reports.metrics import METRICS, Metric
from ddwmmr.sim.verdict import held_limits, lost_support, short_verdict
from ddwmmr.trajectories import load_trajectory

if TYPE_CHECKING:
    from matplotlib.widgets import RadioButtons

#: Playback frame and progress poll intervals (ms).
FRAME_MS = 40
POLL_MS = 100
#: After a resize of the desktop window, the layout follows once no further resize came
#: for this long (ms): dragging a window's edge sends a resize per pixel.
RESIZE_SETTLE_MS = 250
#: A resized window is laid out again where its text scale changes by more than this, or
#: its resolution by more than this fraction (a window whose canvas is a pixel off the size
#: it was opened at keeps its layout).
RESCALE_STEP = 0.01
#: The smallest canvas (px) the layout follows: one dragged smaller keeps its last layout,
#: cut (a few px per inch would make fonts too small for FreeType to draw).
SMALLEST_FOLLOWED = (320, 200)
#: Characters a line of the message box holds in the panel font (the box is 0.325 of the
#: 16 in window wide; 62 leaves room for the widest letters); a window laid out on fewer
#: inches holds fewer (divided by its text scale, :func:`ddwmmr.gui.layout.text_scale`).
MESSAGE_CHARS = 62
#: (font size in points, characters a line at 16 in) tried in turn until a message fits
#: its box (in the 16 x 10 in window two lines in the panel font, three in the smallest).
MESSAGE_FITS = ((FONT, MESSAGE_CHARS), (FONT - 1, 72), (FONT - 2, 86))


@contextlib.contextmanager
def _drawing_deferred(canvas: Any) -> Iterator[None]:
    """Hold back the redraws widgets request while they are built (a Slider draws itself
    when created; on Agg each request is a full render)."""
    own = canvas.__dict__.get("draw_idle")  # an instance-level override stays
    canvas.draw_idle = lambda *args, **kwargs: None
    try:
        yield
    finally:
        if own is None:
            del canvas.draw_idle
        else:
            canvas.draw_idle = own


def guarded(handler: Callable[..., Any]) -> Callable[..., Any]:
    """Show any error of a widget handler in the window instead of raising it."""

    @functools.wraps(handler)
    def wrapper(self: App, *args: Any, **kwargs: Any) -> Any:
        try:
            return handler(self, *args, **kwargs)
        except Exception as exc:  # the window must survive anything a handler meets
            self.say(describe_error(exc), error=True)
        return None

    return wrapper


#: The title of a support-load window, before the run's label.
SUPPORT_LOADS_WINDOW = "support loads: "


class _OptionGroup:
    """The option widgets of one method in one slot, a page of them created when first
    shown (``make(number, spec)`` builds the widget of option ``number``)."""

    def __init__(
        self,
        specs: tuple[OptionSpec, ...],
        make: Callable[[int, OptionSpec], Field | CycleButton],
    ) -> None:
        self.specs = specs
        self.make = make
        self.widgets: dict[int, Field | CycleButton] = {}

    @property
    def pages(self) -> int:
        return max(1, -(-len(self.specs) // OPTIONS_PER_PAGE))

    def page(self, page: int) -> list[tuple[OptionSpec, Field | CycleButton]]:
        """The (spec, widget) pairs of ``page``, creating the widgets if needed."""
        numbers = range(
            page * OPTIONS_PER_PAGE, min((page + 1) * OPTIONS_PER_PAGE, len(self.specs))
        )
        for number in numbers:
            if number not in self.widgets:
                self.widgets[number] = self.make(number, self.specs[number])
        return [(self.specs[n], self.widgets[n]) for n in numbers]

    def hide(self) -> None:
        for widget in self.widgets.values():
            widget.set_visible(False)

    def remove(self) -> None:
        """Take every widget made so far off the window (they are made again when shown)."""
        for widget in self.widgets.values():
            widget.remove()
        self.widgets.clear()


class App(PanelLayout):
    """The simulator window in ``figure`` (see the module docstring).

    Args:
        figure: an empty figure with a canvas (Tk for a desktop window, Agg off-screen).
        settings: initial settings (checked; bad ones raise :class:`ParameterError`).
        interactive: run timers for playback and progress (a desktop window); off-screen
            apps are advanced by :meth:`wait` and :meth:`advance`.
    """

    def __init__(
        self, figure: Figure, settings: Settings | None = None, interactive: bool = False
    ) -> None:
        self.figure = figure
        self.interactive = interactive
        self.settings = check_settings(settings or Settings())
        self.results: list[Any] | None = None
        self.run_settings: Settings | None = None
        self.worker: Worker | None = None
        self.playing = False
        self.message = ""
        self.message_is_error = False
        self.failure: tuple[str, bool] | None = None
        self.export_dir: Path | None = None
        self._run_stamp = ""
        self._options_slot = 0
        self._options_page = 0
        self._groups: dict[tuple[int, str], _OptionGroup] = {}
        self._last_tick = 0.0
        self._moving_slider = False
        self._summary = ""  # the runs' summary lines before wrapping (_show_summary)
        self._resizes = 0  # resize events of the desktop window so far
        self.closed = False  # the desktop window was closed
        self.frames_shown = 0  # instants drawn by show_index (playback frames)
        with _drawing_deferred(figure.canvas):
            self._build()
        # The layout the window opened with: the figure's own dpi (the canvas multiplies it
        # by its pixel ratio) and the text scale (fit_canvas).
        self._opened = (figure.dpi / figure.canvas.device_pixel_ratio, self.text_scale)
        for widget in self._drawing_widgets():
            widget.drawon = interactive
        self.time_slider.drawon = False  # drawn with the playback frames (see _refresh)
        self._canvas = figure.canvas
        self._blitting = interactive and figure.canvas.supports_blit
        self._background = None
        if self._blitting:
            figure.canvas.mpl_connect("draw_event", self._on_full_draw)
        self._sync_widgets()
        self._preview()
        self._play_timer = figure.canvas.new_timer(interval=FRAME_MS)
        self._play_timer.add_callback(self._on_frame)
        self._poll_timer = figure.canvas.new_timer(interval=POLL_MS)
        self._poll_timer.add_callback(self._poll)
        figure.canvas.mpl_connect("close_event", self._on_close)
        self._resize_timer = figure.canvas.new_timer(interval=RESIZE_SETTLE_MS)
        self._resize_timer.single_shot = True
        self._resize_timer.add_callback(self._on_resize_settled)
        if interactive:
            figure.canvas.mpl_connect("resize_event", self._on_resize)

    # ================================================================ window size
    def _on_resize(self, _event: Any) -> None:
        """The window was resized: lay it out again once the resizing pauses."""
        self._resizes += 1
        self._resize_timer.stop()
        self._resize_timer.start()

    @guarded
    def _on_resize_settled(self) -> None:
        """No resize for :data:`RESIZE_SETTLE_MS`: fit the layout to the canvas, unless a
        resize was still queued (a window being mapped takes its size in steps, a full
        draw between them): that one's own timer decides."""
        seen = self._resizes
        self.figure.canvas.flush_events()
        if self._resizes == seen and not self.closed and self.fit_canvas():
            self._redraw()

    def fit_canvas(self) -> bool:
        """Give the figure the resolution and the inches :func:`canvas_size` gives its
        canvas's current size in pixels, as the window's were chosen when it opened
        (:func:`ddwmmr.gui.layout.window_size`), and lay it out again for its new text
        scale (:meth:`relayout`). A canvas whose layout would be within
        :data:`RESCALE_STEP` of the window's opening one takes that one (a canvas a pixel
        off its opening size, or back from another, is drawn as the window opened).
        Returns False, changing nothing, where the layout is within that step of the
        current one, or where the canvas is smaller than :data:`SMALLEST_FOLLOWED`."""
        figure = self.figure
        ratio = figure.canvas.device_pixel_ratio  # a HiDPI screen's pixels per logical px
        width, height = figure.bbox.width, figure.bbox.height  # px of the canvas
        if width < SMALLEST_FOLLOWED[0] or height < SMALLEST_FOLLOWED[1]:
            return False
        inches, dpi = canvas_size(width, height)
        # (the figure's own dpi, which the canvas multiplies by the ratio; text scale)
        layout = (dpi / ratio, scale_of(*inches))
        if _near(layout, self._opened):
            layout = self._opened
        if _near(layout, (figure.dpi / ratio, self.text_scale)):
            return False
        own_dpi, scale = layout
        # ignore: Figure._set_dpi and _original_dpi are matplotlib's own (not in its hints):
        # the dpi without resizing the window (forward=False), and the dpi the canvas
        # multiplies by its ratio and saves the figure at
        figure._set_dpi(own_dpi * ratio, forward=False)  # type: ignore[attr-defined]
        figure._original_dpi = own_dpi  # type: ignore[attr-defined]
        figure.set_size_inches(width / figure.dpi, height / figure.dpi, forward=False)
        self.relayout(scale)
        return True

    def relayout(self, scale: float | None = None) -> None:
        """Lay the window out again for the text scale ``scale`` (default: its figure's
        :func:`text_scale`): the grown gaps, the option widgets (their labels fitted anew),
        the view and its legends, the summary lines and the message wrapped anew. The
        settings, the run and the instant shown stay."""
        self.text_scale = text_scale(self.figure) if scale is None else scale
        message, error = self.message, self.message_is_error
        with _drawing_deferred(self.figure.canvas):
            self._place_again()
            for group in self._groups.values():
                group.remove()
            self._show_options()
            if self.results is not None and self.run_settings is not None:
                index = self.view.index
                obstacles = self._obstacles(self.run_settings)
                self.view.set_runs(self.results, self.labels(), obstacles)
                self.view.show_index(index)
            else:
                self.view.preview(build_trajectory(self.settings), self._obstacles(self.settings))
            self._animate(self._blitting)
            self._background = None  # saved again by the next full draw
            if self._summary:
                self._show_summary(self._summary)
            self.say(message, error)

    # ================================================================ messages
    def say(self, text: str, error: bool = False) -> None:
        """Show ``text`` in the message area (red for errors) and redraw."""
        self.message, self.message_is_error = text, error
        self._fit_message("error: " if error else "", text)
        self.message_text.set_color("tab:red" if error else "0.1")
        self._redraw()

    def _fit_message(self, prefix: str, text: str) -> None:
        """Show ``prefix`` + ``text`` wrapped inside the message box: in the panel font at
        :data:`MESSAGE_CHARS` a line (fewer in a window of a larger :attr:`text_scale`)
        when it fits, else in the first smaller font of
        :data:`MESSAGE_FITS` that holds it; what still overflows the smallest is cut at a
        line end, marked ``...`` (a message names its parameter first)."""
        artist = self.message_text
        text = drawable(text, artist)
        # ignore: the message text sits in its axes
        box = artist.axes.bbox  # type: ignore[union-attr]
        renderer = renderer_of(self.figure)

        def show(lines: list[str]) -> bool:
            artist.set_text(prefix + "\n".join(lines))
            extent = artist.get_window_extent(renderer)
            fits: bool = extent.y0 >= box.y0 and extent.x1 <= box.x1
            return fits

        for size, chars in MESSAGE_FITS:
            width = int(chars / self.text_scale)
            lines = textwrap.wrap(text, width, break_on_hyphens=False) if text else []
            artist.set_fontsize(size)
            if show(lines) or not lines:
                return
        while len(lines) > 1 and artist.get_window_extent(renderer).y0 < box.y0:
            lines = [*lines[:-2], lines[-2] + " ..."]
            show(lines)

    def _report(self, text: str) -> None:
        self.say(text, error=True)

    def _withdraw(self, text: str) -> None:
        """Clear the error ``text`` if the message area still shows it (a widget that
        reported it holds a valid value again)."""
        if self.message_is_error and self.message == text:
            self.say("")

    def _redraw(self) -> None:
        """Redraw the whole window (soon). Off-screen (Agg) draw_idle would render at once:
        there the figure is drawn only when saved."""
        if self.interactive:
            self.figure.canvas.draw_idle()

    # ---------------------------------------------------------------- fast redraws
    # Playback and progress change only a few artists (robots, trails, plot lines,
    # cursors, time slider, progress bar). On a desktop canvas that can blit, those are
    # "animated": a full draw leaves them out and saves the background, and every frame
    # restores it and draws just them (matplotlib's blitting recipe).
    def _dynamic_artists(self) -> list[Any]:
        slider = self.time_slider
        handle = getattr(slider, "_handle", None)  # the knob; private in matplotlib
        extra = [slider.poly, slider.valtext, self.progress_bar, self.progress_text]
        return [*self.view.dynamic_artists(), *extra, *([handle] if handle else [])]

    def _animate(self, on: bool) -> None:
        """Mark the dynamic artists as animated (blitting) or normal (full draws)."""
        for artist in self._dynamic_artists():
            artist.set_animated(on)

    def _on_full_draw(self, event: Any) -> None:
        if event.canvas is not self._canvas:  # savefig draws on a temporary canvas
            return
        self._background = self._canvas.copy_from_bbox(self.figure.bbox)
        self._draw_dynamic()

    def _draw_dynamic(self) -> None:
        for artist in self._dynamic_artists():
            self.figure.draw_artist(artist)

    def _refresh(self) -> None:
        """Show changed dynamic artists: blit them when possible, else redraw."""
        if not self.interactive or self.closed:
            return
        if not self._blitting or self._background is None:
            self._redraw()
            return
        canvas = self._canvas
        self._animate(True)  # artists created since the last frame join the animation
        canvas.restore_region(self._background)
        self._draw_dynamic()
        canvas.blit(self.figure.bbox)

    # ================================================================ settings
    def apply(self, settings: Settings) -> None:
        """Replace the settings (checked first: bad ones raise ParameterError)."""
        check_settings(settings)
        self._set_settings(settings)
        self._sync_widgets()

    def _set_settings(self, settings: Settings) -> None:
        """Take checked settings; a run made with other settings is dropped, one being
        simulated is stopped (the message says so: "simulating ..." would stay)."""
        changed = settings != self.settings
        self.settings = settings
        if changed:
            simulating = self.worker is not None and not self.worker.finished
            self._cancel_worker()
            if simulating:
                self.say("settings changed: simulation stopped; press Run")
            elif self.results is not None:
                self.results = None
                self.run_settings = None
                self.say("settings changed: press Run")
            self._preview()

    def _try(self, settings: Settings) -> None:
        """Take ``settings`` if they check out (ParameterError propagates to the widget)."""
        self._set_settings(check_settings(settings))

    def _sync_widgets(self) -> None:
        """Show the current settings in every widget (without applying anything)."""
        s = self.settings
        names = [t.get_text() for t in self.traj_radio.labels]
        if s.trajectory in names and s.trajectory != FILE_ENTRY:
            set_radio_silently(self.traj_radio, s.trajectory)
        else:
            set_radio_silently(self.traj_radio, FILE_ENTRY)
            self.file_field.show(s.trajectory)
        self._show_geometry()
        set_radio_silently(self.method_radios[0], s.methods[0])
        set_radio_silently(self.method_radios[1], s.methods[1] or OFF_ENTRY)
        set_radio_silently(self.plant_radio, s.plant)
        set_radio_silently(self.integrator_radio, s.integrator)
        events = self.payload_slider.eventson
        self.payload_slider.eventson = False
        self.payload_slider.set_val(s.payload)
        self.payload_slider.eventson = events
        self.dt_field.show("" if s.dt is None else f"{s.dt:g}")
        self.duration_field.show("" if s.duration is None else f"{s.duration:g}")
        self.offset_field.show(f"{s.offset[0]:g} {s.offset[1]:g}")
        if s.methods[self._options_slot] is None:
            self._options_slot = 0
        self._show_options()

    def _show_geometry(self) -> None:
        own = {**geometry_of(load_trajectory(self.settings.trajectory)), **self.settings.geometry}
        for name, field in self.geometry_fields.items():
            value = own.get(name)
            field.show("" if value is None else f"{value:.6g}")
            field.set_visible(value is not None)

    # ---------------------------------------------------------------- trajectory
    @guarded
    def _on_trajectory(self, label: str) -> None:
        if label == FILE_ENTRY:
            path = self.file_field.text.strip()
            if not path:
                self._undo_radio(self.traj_radio, self.settings.trajectory)
                raise ParameterError("traj: type a .toml or .csv path into the file field")
            target = path
        else:
            target = label
        try:
            self._try(self.settings.replace(trajectory=target, geometry={}))
        except Exception:  # the list shows the setting that stays
            self._undo_radio(self.traj_radio, self.settings.trajectory)
            raise
        self._show_geometry()
        self.say(f"trajectory: {target}")

    def _undo_radio(self, buttons: RadioButtons, value: str) -> None:
        names = [t.get_text() for t in buttons.labels]
        set_radio_silently(buttons, value if value in names else FILE_ENTRY)

    def _apply_file(self, text: str) -> str:
        path = text.strip()
        if not path:
            return ""
        self._try(self.settings.replace(trajectory=path, geometry={}))
        set_radio_silently(self.traj_radio, FILE_ENTRY)
        self._show_geometry()
        self.say(f"trajectory file: {path}")
        return path

    def _apply_geometry(self, name: str, text: str) -> str:
        try:
            number: float | str = plain_float(text)
        except ValueError:
            number = text  # not a number: the check refuses it naming the allowed range
        value = check_geometry(name, number)
        self._try(self.settings.with_geometry(name, value))
        return f"{value:.6g}"

    # ---------------------------------------------------------------- methods
    @guarded
    def _on_method(self, slot: int, label: str) -> None:
        method = None if label == OFF_ENTRY else label
        try:
            self._try(self.settings.with_method(slot, method))
        except Exception:  # the list shows the setting that stays
            self._undo_radio(self.method_radios[slot], self.settings.methods[slot] or OFF_ENTRY)
            raise
        if method is not None:
            self._options_slot, self._options_page = slot, 0
        elif self._options_slot == slot:
            self._options_slot, self._options_page = 0, 0
        self._show_options()
        self._redraw()

    def _apply_options_slot(self, slot_name: str) -> None:
        slot = SLOTS.index(slot_name)
        if self.settings.methods[slot] is None:
            raise ParameterError("slot B is off: pick a method under Compare: B first")
        self._options_slot, self._options_page = slot, 0
        self._show_options()

    def _apply_options_page(self, page: int) -> None:
        self._options_page = page - 1
        self._show_options()

    def _show_options(self) -> None:
        """Show the option widgets of the edited slot's method (one page of them). An
        option of the page whose name misleads (``dt``, :data:`NOTES`, the command lines'
        ``--help`` note) gets that note in the message area, unless it shows an error."""
        slot = self._options_slot
        method = self.settings.methods[slot]
        for group in self._groups.values():
            group.hide()
        # ignore: the edited slot is an active one, which has a method
        group = self._option_group(slot, method)  # type: ignore[arg-type]
        pages = group.pages
        self._options_page = min(self._options_page, pages - 1)
        shown = group.page(self._options_page)
        for _, widget in shown:
            widget.set_visible(True)
        self.options_title.set_text(f"Options of {SLOTS[slot]}: {method}")
        self.options_slot_button.show(SLOTS[slot])
        self.options_page_button.values = list(range(1, pages + 1))
        self.options_page_button.format_value = lambda page: f"{page}/{pages}"
        self.options_page_button.show(self._options_page + 1)
        self.options_page_button.set_visible(pages > 1)
        changed = dict(self.settings.options[slot])
        for spec, widget in shown:
            value = changed.get(spec.name, spec.default)
            if isinstance(widget, CycleButton):
                widget.show(value)
            else:
                widget.show(spec.format(value))
        noted = [spec.name for spec, _ in shown if spec.name in NOTES]
        self.options_note.set_text(
            "none (this method has no options)"
            if not group.specs
            else "blank number field: automatic value (None); Enter applies a field"
            + (f"; {', '.join(noted)}: see the note below" if noted else "")
        )
        if noted and not self.message_is_error:
            self.say(" ".join(f"{name} ({method}): {NOTES[name]}" for name in noted))
        self._redraw()

    def _option_group(self, slot: int, method: str) -> _OptionGroup:
        key = (slot, method)
        if key not in self._groups:
            make = functools.partial(self._option_widget, slot)
            self._groups[key] = _OptionGroup(method_options(method), make)
        return self._groups[key]

    def _apply_option(self, slot: int, spec: OptionSpec, value: Any) -> None:
        self._try(self.settings.with_option(slot, spec.name, value))
        shown = spec.format(value) or "auto"
        self.say(f"{SLOTS[slot]} {self.settings.methods[slot]}: {spec.name} = {shown}")

    def _apply_option_text(self, slot: int, spec: OptionSpec, text: str) -> str:
        value = spec.parse(text)
        self._apply_option(slot, spec, value)
        return spec.format(value)

    # ---------------------------------------------------------------- simulation settings
    @guarded
    def _on_plant(self, label: str) -> None:
        try:
            self._try(self.settings.replace(plant=label))
        except Exception:  # the list shows the setting that stays
            self._undo_radio(self.plant_radio, self.settings.plant)
            raise

    @guarded
    def _on_integrator(self, label: str) -> None:
        self._try(self.settings.replace(integrator=label))

    @guarded
    def _on_payload(self, value: float) -> None:
        self._try(self.settings.replace(payload=round(float(value), 6)))

    def _apply_dt(self, text: str) -> str:
        value = _optional_positive("dt", text)
        self._try(self.settings.replace(dt=value))
        return "" if value is None else f"{value:g}"

    def _apply_duration(self, text: str) -> str:
        value = _optional_positive("duration", text)
        self._try(self.settings.replace(duration=value))
        return "" if value is None else f"{value:g}"

    def _apply_offset(self, text: str) -> str:
        """The offset field: two numbers dx dy in m, apart by spaces, a comma or both, a
        point the decimal mark; a comma between two digits ("0,3") is refused, being a
        decimal comma to many readers (0.3, not 0 and 3)."""
        if re.search(r"\d,\d", text):
            raise ParameterError(
                f"offset must be two numbers dx dy in m, a point the decimal mark (got "
                f"{shown(text)}: a comma between digits could be a decimal comma; write "
                "e.g. 0 0.3 or 0, 0.3)"
            )
        parts = text.replace(",", " ").split()
        try:
            values = tuple(plain_float(p) for p in parts)
        except ValueError:
            raise ParameterError(
                f"offset must be two numbers dx dy in m (got {shown(text)})"
            ) from None
        if len(values) != 2:
            raise ParameterError(f"offset must be two numbers dx dy in m (got {shown(text)})")
        self._try(self.settings.replace(offset=values))
        return f"{values[0]:g} {values[1]:g}"

    def _apply_export_dir(self, text: str) -> str:
        # no shell reads the field: ~ is the home folder here too (not a folder named ~)
        text = os.path.expanduser(text.strip())
        check_export_root(text)  # a folder, or where one can be made
        self.export_dir = None  # the next export makes a new run folder under the new root
        self.say(f"export folder: {text}")
        return text

    # ================================================================ preview and runs
    def _obstacles(self, settings: Settings) -> list[Any]:
        circles: list[Any] = []
        for slot in settings.active_slots:
            circles += list(getattr(build_controller(settings, slot), "obstacles", ()) or ())
        return circles

    def _preview(self) -> None:
        self.view.preview(build_trajectory(self.settings), self._obstacles(self.settings))
        self._animate(self._blitting)
        self._summary = ""
        self.summary_text.set_text("")
        self._set_slider_time(0.0)
        self._set_progress(0.0, "idle")
        self._redraw()

    def labels(self) -> list[str]:
        """Labels of the current runs: the method, or ``A-<method>``/``B-<method>`` side by side."""
        settings = self.run_settings or self.settings
        slots = settings.active_slots
        if len(slots) == 1:
            # ignore: an active slot has a method
            return [settings.methods[slots[0]]]  # type: ignore[list-item]
        return [f"{SLOTS[s]}-{settings.methods[s]}" for s in slots]

    @guarded
    def run(self) -> None:
        """Run button: simulate (if needed) and play the run from its start."""
        worker = self.worker
        if worker is not None and not worker.finished:
            if worker.state == "paused":
                worker.resume()
                self.say("simulation resumed")
            return
        if self.results is not None and self.run_settings == self.settings:
            if self.view.index >= self.view.last_index:
                self.show_index(0)
            self._play()
            return
        self._start_worker()

    def _start_worker(self) -> None:
        settings = check_settings(self.settings)
        self.run_settings = settings
        self.results = None
        self.failure = None
        self._stop()
        self.worker = Worker(
            lambda progress: simulate_settings(settings, progress), len(settings.active_slots)
        )
        self._started = time.perf_counter()
        self.worker.start()
        self._set_progress(0.0, "simulating 0 %")
        self.say("simulating " + " and ".join(self.labels()) + " ...")
        if self.interactive:
            self._poll_timer.start()

    def wait(self) -> None:
        """Block until the current simulation ends and take its result (off-screen use)."""
        if self.worker is not None:
            self.worker.join()
        self._poll()

    @guarded
    def _poll(self) -> None:
        worker = self.worker
        if worker is None or self.closed:
            return
        state, fraction = worker.state, worker.fraction
        if state in ("running", "paused"):
            word = "simulating" if state == "running" else "paused"
            self._set_progress(fraction, f"{word} {100 * fraction:.0f} %")
            self._refresh()
            return
        if self.interactive:
            self._poll_timer.stop()
        self.worker = None
        if state == "done":
            self._take_results(worker.result)
        elif state == "failed":
            self.run_settings = None
            self.failure = (worker.error, worker.bad_input)
            self._set_progress(0.0, "failed")
            self.say(worker.error, error=True)
        else:
            self.run_settings = None
            self._set_progress(0.0, "cancelled")

    def _take_results(self, results: list[Any]) -> None:
        elapsed = time.perf_counter() - self._started
        self.results = results
        self._run_stamp = datetime.datetime.now().strftime("%Y%m%d-%H%M%S")
        self.export_dir = None
        # ignore: run set run_settings before the worker it takes the results of
        self.view.set_runs(results, self.labels(), self._obstacles(self.run_settings))  # type: ignore[arg-type]
        self._animate(self._blitting)
        steps = results[0].summary["steps"]
        # The wall time only in a window: a snapshot is a document, the same on every run.
        took = f", {elapsed:.1f} s" if self.interactive else ""
        self._set_progress(1.0, f"done: {steps} steps{took}")
        self._show_summary(
            "\n".join(_summary_line(label, r) for label, r in zip(self.labels(), results))
        )
        self.say(f"run finished ({steps} steps per method): playing; drag time to scrub")
        self.show_index(0)
        self._play()

    def _show_summary(self, summary: str) -> None:
        """Show the runs' ``summary`` lines under the view, wrapped to the window (a physics
        run's line is longer than the view is wide): in the panel font, or in the first
        smaller one (down to ``FONT - 2``) whose lines end above the transport buttons
        (long lines in a window of a large :attr:`text_scale`), else in that smallest."""
        self._summary = summary
        artist = self.summary_text
        renderer = renderer_of(self.figure)
        buttons_top = self.transport["run"].ax.bbox.y1
        for size in (FONT, FONT - 1, FONT - 2):
            artist.set_fontsize(size)
            artist.set_text(wrap_to_width(summary, artist, SUMMARY_RIGHT))
            if artist.get_window_extent(renderer).y0 > buttons_top:
                return

    def _cancel_worker(self) -> None:
        if self.worker is not None and not self.worker.finished:
            self.worker.cancel()
            self.worker.join()
            self._poll()

    # ================================================================ playback
    def _play(self) -> None:
        self.playing = True
        self._last_tick = time.perf_counter()
        if self.interactive:
            self._play_timer.start()

    def _stop(self) -> None:
        self.playing = False
        if self.interactive:
            self._play_timer.stop()

    @guarded
    def pause(self) -> None:
        """Pause button: hold the simulation (while computing) or the playback."""
        if self.worker is not None and not self.worker.finished:
            self.worker.pause()
            self._poll()
            self.say("simulation paused: Run resumes it")
            return
        self._stop()
        self.say(f"paused at t = {self.view.time:.2f} s")

    def _no_run(self, what: str) -> ParameterError:
        """Why ``what`` (step, export) has no run to act on: none finished yet, or one is
        still being simulated (Run would not start another)."""
        if self.worker is not None and not self.worker.finished:
            return ParameterError(f"{what}: the run is still being simulated; wait for it")
        return ParameterError(f"{what}: no finished run yet (press Run)")

    @guarded
    def step(self) -> None:
        """Step button: pause and move the playback one recorded step (dt) forward; at
        the run's last instant it says so (a press there changes nothing)."""
        if self.results is None:
            raise self._no_run("step")
        self._stop()
        if self.view.index >= self.view.last_index:
            self.say(f"step: the run ends here (t = {self.view.time:.2f} s); Reset goes to 0")
            return
        self.show_index(self.view.index + 1)

    @guarded
    def reset(self) -> None:
        """Reset button: stop any simulation and playback, back to t = 0."""
        self._cancel_worker()
        self._stop()
        if self.results is not None:
            self.show_index(0)
        else:
            self._preview()
        self.say("reset to t = 0")

    @property
    def speed(self) -> float:
        """Playback speed (simulated s per wall-clock s)."""
        return SPEEDS[round(self.speed_slider.val)]

    def _on_speed(self, position: float) -> None:
        self.speed_slider.valtext.set_text(f"{SPEEDS[round(position)]:g} x real time")

    def advance(self, wall_seconds: float) -> None:
        """Move a playing run forward by ``speed * wall_seconds`` of simulated time."""
        if not self.playing or self.results is None:
            return
        target = self.view.time + self.speed * wall_seconds
        if target >= self.view.duration:
            self.show_index(self.view.last_index)
            self._stop()
            return
        self.show_time(target)

    def _on_close(self, _event: Any) -> None:
        """The window closes: stop the timers and any simulation, and close the support-load
        windows it opened (the program ends with its window)."""
        self.closed = True
        self._play_timer.stop()
        self._poll_timer.stop()
        if self.worker is not None:
            self.worker.cancel()
        if self.interactive:
            import matplotlib.pyplot as plt

            for label in plt.get_figlabels():
                if label.startswith(SUPPORT_LOADS_WINDOW):
                    plt.close(label)

    @guarded
    def _on_frame(self) -> None:
        now = time.perf_counter()
        elapsed, self._last_tick = now - self._last_tick, now
        self.advance(elapsed)

    def show_time(self, t: float) -> int:
        """Show the run at time ``t`` (s); returns the recorded index shown."""
        return self.show_index(self.view.index_at(t))

    def show_index(self, k: int) -> int:
        """Show the recorded instant ``k`` of the run; returns it (clipped)."""
        k = self.view.show_index(k)
        self.frames_shown += 1
        duration = self.view.duration
        self._set_slider_time(self.view.time / duration if duration > 0 else 0.0)
        self._refresh()
        return k

    def _set_slider_time(self, fraction: float) -> None:
        self._moving_slider = True
        try:
            self.time_slider.set_val(fraction)
        finally:
            self._moving_slider = False
        self.time_slider.valtext.set_text(f"{self.view.time:.2f} s")

    @guarded
    def _on_time_slider(self, fraction: float) -> None:
        if self._moving_slider or self.results is None:
            if self.results is None and not self._moving_slider:
                self.time_slider.valtext.set_text("no run")
            return
        self._stop()
        self.show_time(float(fraction) * self.view.duration)

    def _set_progress(self, fraction: float, text: str) -> None:
        self.progress_bar.set_width(fraction)
        self.progress_text.set_text(text)

    # ================================================================ export
    def _export_folder(self) -> Path:
        if self.results is None:
            raise self._no_run("export")
        if self.export_dir is None:
            # ignore: results come with the settings of their run; an active slot has a method
            settings: Settings = self.run_settings  # type: ignore[assignment]
            names = "-vs-".join(settings.methods[s] for s in settings.active_slots)  # type: ignore[misc]
            trajectory = Path(settings.trajectory).stem
            root = Path(self.export_field.text.strip() or "runs/gui")
            self.export_dir = export.run_folder(root, f"{names}-{trajectory}-{self._run_stamp}")
        return self.export_dir

    @contextlib.contextmanager
    def _exporting(self) -> Iterator[Path]:
        """The run's export folder (:meth:`_export_folder`) for one export; where the
        export fails and left nothing in a folder it made, the folder goes again (the
        next export makes it anew), so a refused export leaves no empty folder behind."""
        made = self.export_dir is None
        folder = self._export_folder()
        try:
            yield folder
        except BaseException:
            if made and folder.is_dir() and not any(folder.iterdir()):
                folder.rmdir()
                self.export_dir = None
            raise

    @guarded
    def export_data(self) -> list[Path]:
        """Export button: timeseries.csv and summary.json (the files `track` writes, with
        the record `python -m ddwmmr.track --rerun` repeats)."""
        with self._exporting() as folder:
            # ignore: _export_folder refused a missing run (results, run_settings are set)
            paths = export.write_run_data(folder, self.results, self.labels(), self.run_settings)  # type: ignore[arg-type]
        self.say(f"wrote {len(paths)} files to {folder}")
        return paths

    @guarded
    def export_png(self) -> Path:
        """Export button: a PNG of the whole window."""
        self._animate(False)  # a saved figure leaves animated artists out
        try:
            with self._exporting() as folder:
                path = export.write_window_png(self.figure, folder)
        finally:
            self._animate(self._blitting)
        self.say(f"wrote {path}")
        return path

    @guarded
    def export_support_loads(self) -> list[Path]:
        """Support loads button: each physics run's support-load panel (every edge's load
        with the optimisers' floor, the base's tilt; the figure a physics ``track`` run
        writes) as ``support_loads.png``, and on the desktop in a window of its own."""
        with self._exporting() as folder:
            # ignore: _export_folder refused a missing run (results, run_settings are set)
            written = export.write_support_loads(folder, self.results, self.labels())  # type: ignore[arg-type]
        if self.interactive:
            self._show_support_loads()
        self.say(f"wrote {', '.join(str(path) for path in written)}")
        return written

    def _show_support_loads(self) -> None:
        """The physics runs' support-load panels, each in a desktop window of its own."""
        import matplotlib.pyplot as plt

        from ddwmmr.reports import physics_plots as pp

        # pyplot's backend is still the desktop window's (layout.desktop_figure's TkAgg):
        # the reports modules leave it alone, so these figures are Tk windows too.
        # ignore: called after export_support_loads wrote the run's files
        for result, label in zip(self.results, self.labels()):  # type: ignore[arg-type]
            if pp.is_physics_run(result):
                window = plt.figure(
                    figsize=pp.SUPPORT_LOADS_FIGSIZE, num=f"{SUPPORT_LOADS_WINDOW}{label}"
                )
                window.clear()
                pp.draw_support_loads(window, result)
                window.show()

    @guarded
    def export_animation(self, fmt: str = "gif") -> Path:
        """Export button: the run's animation as GIF or MP4."""
        with self._exporting() as folder:
            self.say(f"writing {fmt} ...")
            if self.interactive:  # show the message before the export blocks the window
                self.figure.canvas.draw()
                self.figure.canvas.flush_events()
            # ignore: _export_folder refused a missing run (results, run_settings are set)
            obstacles = self._obstacles(self.run_settings)  # type: ignore[arg-type]
            path = export.write_animation(self.results, self.labels(), obstacles, folder, fmt)  # type: ignore[arg-type]
        self.say(f"wrote {path}")
        return path


def _near(layout: tuple[float, float], other: tuple[float, float]) -> bool:
    """Whether the (dpi, text scale) ``layout`` is within :data:`RESCALE_STEP` of ``other``
    (the dpi by that fraction, the scale by that much)."""
    return abs(layout[0] / other[0] - 1.0) <= RESCALE_STEP and (
        abs(layout[1] - other[1]) <= RESCALE_STEP
    )


def _optional_positive(name: str, text: str) -> float | None:
    text = text.strip()
    if not text:
        return None
    try:
        value = plain_float(text)
    except ValueError:
        raise ParameterError(
            f"{name} must be a number > 0 in s, or blank (got {shown(text)})"
        ) from None
    if not (value > 0 and np.isfinite(value)):
        raise ParameterError(f"{name} must be > 0 s, or blank (got {text})")
    return value


#: The metrics of a run's summary line, as summary keys: each is written with its short
#: label, unit and scale (:data:`ddwmmr.reports.metrics.METRICS`; errors in mm, as ``track``
#: and ``compare`` print them) and 3 significant digits, as in the comparison's metric table.
SUMMARY_METRICS = (
    "rms_position_error_m",
    "max_position_error_m",
    "rms_orientation_error_rad",
    "max_wheel_speed_rad_s",
    "min_stability",
    "min_manipulability",
    "saturated_steps",
)


def _summary_line(label: str, result: Any) -> str:
    """One method's line of the summary: its verdict first (docs/cli.md, "Verdict"), then
    the metrics (:data:`SUMMARY_METRICS`), the safe-fallback steps and the rate and
    actuator limits the run held (:func:`held_limits`), which ``saturated steps`` (the
    commands the plant clipped) does not count."""
    s = result.summary
    metrics = [_metric(METRICS[key], s.get(key)) for key in SUMMARY_METRICS]
    line = f"{label}: {short_verdict(s)}; {', '.join(metrics)}, fallbacks {s['fallback_steps']}"
    line += _physics_verdict(s)
    held = held_limits(s)
    return line + (f"; limits held: {', '.join(held)}" if held else "")


def _metric(metric: Metric, value: Any) -> str:
    """``value`` (summary units) after the metric's short label, in its display unit with 3
    significant digits, the unit after the number: ``RMS pos 6.83 mm``."""
    text = f"{metric.name} {fmt(metric.shown(value))}"
    return f"{text} {metric.unit}" if metric.unit else text


def _physics_verdict(summary: dict[str, Any]) -> str:
    """The physics plant's tip-over verdict for the summary line ('' on other plants):
    tipped, stood, or stood but lost support (an edge of the support polygon unloaded for
    ``unloaded_time_s`` of ``duration`` s: the verdict's warning, :func:`lost_support`)."""
    if "tipped" not in summary:
        return ""
    if summary["tipped"]:
        return f", TIPPED at {summary['tip_time_s']:.2f} s (physics)"
    margin = f"{METRICS['min_physics_stability'].label} {summary['min_physics_stability']:.3g}"
    if lost_support(summary):
        unloaded, duration = summary.get("unloaded_time_s") or 0.0, summary.get("duration") or 0.0
        return (
            f", stood but LOST SUPPORT: an edge unloaded for {unloaded:.3g} of {duration:.3g} s"
            f" (physics: {margin})"
        )
    return f", stood (physics: {margin})"
