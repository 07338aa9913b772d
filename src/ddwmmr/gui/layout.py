"""Where every control of the simulator window sits (figure fractions of a 16 x 10 in
window) and which handler it calls.

The window's size is decided here (:func:`window_size`): on a small screen it is laid out
on fewer inches at a higher resolution than the screen would give 16 x 10 in, so that its
text stays legible; the gaps that hold text then grow with :func:`text_scale`. A window the
user resizes takes the resolution the same rule gives its new size (:func:`canvas_size`,
:meth:`ddwmmr.gui.app.App.fit_canvas`); the placements that depend on the text scale are
recorded (:meth:`PanelLayout._place`) and set again (:meth:`PanelLayout._place_again`).

:class:`PanelLayout` builds the widgets into ``self.figure``; the handlers
(``self._on_*``, ``self._apply_*``, ``self.run``, ``self.export_*``...) belong to
:class:`ddwmmr.gui.app.App`, which inherits this class. Layout and behaviour are apart so
that each reads on its own.
"""

from __future__ import annotations

import functools
from typing import TYPE_CHECKING, Any

from matplotlib.patches import Rectangle
from matplotlib.widgets import Slider

from ddwmmr.controllers.base import available_methods
from ddwmmr.gui.options import OptionSpec, format_choice, plant_names
from ddwmmr.gui.settings import GEOMETRY, SLOTS
from ddwmmr.gui.view import RunView, add_view_axes, stacked_rects
from ddwmmr.gui.widgets import (
    FONT,
    CycleButton,
    Field,
    Rect,
    button,
    fit_label,
    panel_axes,
    radio,
)
from ddwmmr.plants.kinematic import INTEGRATORS
from ddwmmr.trajectories import available_trajectories

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

    from matplotlib.axes import Axes
    from matplotlib.figure import Figure
    from matplotlib.text import Text

    from ddwmmr.gui.settings import Settings

#: Window size (inches) and resolution of the window and its snapshot.
FIGSIZE = (16.0, 10.0)
DPI = 100
#: Lowest resolution (px per inch) of the desktop window, where the screen allows it
#: (:func:`window_size`): at 81 px per inch the panel font (8 pt) is 9 px high and the
#: smallest text (6 pt) 6.75 px.
MIN_DPI = 81.0
#: Largest :func:`text_scale` :func:`window_size` gives (a 1280 x 720 screen's is 1.34):
#: the layout keeps its text apart up to this one; a smaller screen gets smaller text.
MAX_TEXT_SCALE = 1.35
#: Entry of the trajectory list that stands for the path typed in the file field.
FILE_ENTRY = "file"
#: Entry of slot B's list that switches the side-by-side mode off.
OFF_ENTRY = "off"
#: Playback speeds (simulated seconds per wall-clock second).
SPEEDS = (0.25, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0)
DEFAULT_SPEED = 4.0
#: Right end (figure fraction) of the runs' summary lines under the view.
SUMMARY_RIGHT = 0.99
#: Method options shown per page (two columns).
OPTIONS_PER_PAGE = 12
PAYLOAD_RANGE = (0.0, 5.0)
#: Where a placed artist goes: a rectangle (left, bottom, width, height) for an axes, a
#: point (x, y) for a text, in figure fractions.
Place = Rect | tuple[float, float]


class PanelLayout:
    """Builds the window's widgets (mixed into :class:`ddwmmr.gui.app.App`)."""

    figure: Figure
    settings: Settings
    #: :func:`text_scale` of the figure when the window was last laid out (1 at 16 x 10 in).
    text_scale: float
    #: The axes and texts whose place depends on :attr:`text_scale`, each with the function
    #: that gives it (:meth:`_place`).
    _placed: list[tuple[Axes | Text, Callable[[], Place]]]

    if TYPE_CHECKING:  # the handlers, defined by App

        def _report(self, text: str) -> None: ...
        def _withdraw(self, text: str) -> None: ...
        def _on_trajectory(self, label: str) -> None: ...
        def _apply_file(self, text: str) -> str: ...
        def _apply_geometry(self, name: str, text: str) -> str: ...
        def _on_method(self, slot: int, label: str) -> None: ...
        def _on_plant(self, label: str) -> None: ...
        def _on_integrator(self, label: str) -> None: ...
        def _apply_options_slot(self, slot_name: str) -> None: ...
        def _apply_options_page(self, page: int) -> None: ...
        def _on_payload(self, value: float) -> None: ...
        def _apply_dt(self, text: str) -> str: ...
        def _apply_duration(self, text: str) -> str: ...
        def _apply_offset(self, text: str) -> str: ...
        def _apply_export_dir(self, text: str) -> str: ...
        def _apply_option(self, slot: int, spec: OptionSpec, value: Any) -> None: ...
        def _apply_option_text(self, slot: int, spec: OptionSpec, text: str) -> str: ...
        def export_data(self) -> list[Path]: ...
        def export_png(self) -> Path: ...
        def export_support_loads(self) -> list[Path]: ...
        def export_animation(self, fmt: str = "gif") -> Path: ...
        def run(self) -> None: ...
        def pause(self) -> None: ...
        def step(self) -> None: ...
        def reset(self) -> None: ...
        def _on_speed(self, position: float) -> None: ...
        def _on_time_slider(self, fraction: float) -> None: ...

    def _build(self) -> None:
        fig = self.figure
        self.text_scale = text_scale(fig)
        self._placed = []
        fig.text(0.012, 0.972, "ddwmmr simulator", fontsize=13, weight="bold")

        def command_at() -> tuple[float, float]:
            return (self._grown(0.15, 0.14), 0.974)

        x, y = command_at()
        command = fig.text(x, y, "python -m ddwmmr.gui", fontsize=FONT, color="0.4")
        self._place(command, command_at)
        self._build_trajectory()
        self._build_methods()
        self._build_options()
        self._build_simulation()
        self._build_export()
        self._build_messages()
        self._build_view()
        self._build_transport()

    def _place(self, artist: Axes | Text, where: Callable[[], Place]) -> None:
        """Record that ``artist`` (created at ``where()``) goes to ``where()`` again when the
        text scale changes (:meth:`_place_again`): ``where`` reads :attr:`text_scale`."""
        self._placed.append((artist, where))

    def _place_again(self) -> None:
        """Move every recorded artist (:meth:`_place`) to its place at :attr:`text_scale`."""
        for artist, where in self._placed:
            # ignore: an axes takes a rectangle and a text a point, as recorded
            artist.set_position(where())  # type: ignore[arg-type]

    def _grown(self, at: float, per_scale: float) -> float:
        """The figure fraction ``at`` of the 16 x 10 in window, moved by ``per_scale`` for
        each unit of :attr:`text_scale` beyond 1 (where a gap holding text grows with it)."""
        return at + per_scale * (self.text_scale - 1.0)

    def _drawing_widgets(self) -> list[Any]:
        """Widgets that redraw the canvas themselves when set (radios, sliders)."""
        return [
            self.traj_radio,
            *self.method_radios,
            self.plant_radio,
            self.integrator_radio,
            self.payload_slider,
            self.speed_slider,
            self.time_slider,
        ]

    def _heading(self, x: float, y: float, text: str) -> Text:
        return self.figure.text(x, y, text, fontsize=FONT + 1.5, weight="bold", color="0.15")

    def _build_trajectory(self) -> None:
        self._heading(0.012, 0.945, "Trajectory")
        names = [*available_trajectories(), FILE_ENTRY]
        height = min(0.026 * len(names), 0.16)
        self.traj_radio = radio(self.figure, (0.008, 0.935 - height, 0.12, height), names, 0)
        # ignore: a radio button hands its label (matplotlib hints None too, for none active)
        self.traj_radio.on_clicked(self._on_trajectory)  # type: ignore[arg-type]
        self.file_field = Field(
            self.figure,
            (0.032, 0.905 - height, 0.128, 0.024),
            "file",
            "",
            self._apply_file,
            self._report,
            self._withdraw,
        )
        self.figure.text(
            0.012,
            0.885 - height,
            ".toml (ellipse/rectangle) or .csv t,x,y[,phi]",
            fontsize=FONT - 1,
            color="0.4",
        )
        self._heading(0.19, 0.945, "Geometry")
        self.geometry_fields: dict[str, Field] = {}
        for row, (name, unit, allowed) in enumerate(GEOMETRY):
            label = name if unit == "-" else f"{name} ({unit})"
            self.geometry_fields[name] = Field(
                self.figure,
                (0.235, 0.912 - 0.027 * row, 0.06, 0.023),
                label,
                "",
                functools.partial(self._apply_geometry, name),
                self._report,
                self._withdraw,
                hint=allowed,
            )

    def _build_methods(self) -> None:
        methods = available_methods()
        top = 0.72
        self._heading(0.012, top + 0.008, "Method A")
        self._heading(0.122, top + 0.008, "Compare: B")
        height_a = min(0.026 * len(methods), 0.2)
        height_b = min(0.026 * (len(methods) + 1), 0.2)
        self.method_radios = [
            radio(self.figure, (0.008, top - height_a, 0.11, height_a), methods, 0),
            radio(self.figure, (0.118, top - height_b, 0.11, height_b), [OFF_ENTRY, *methods], 0),
        ]
        self.method_radios[0].on_clicked(functools.partial(self._on_method, 0))
        self.method_radios[1].on_clicked(functools.partial(self._on_method, 1))
        self._heading(0.235, top + 0.008, "Plant")
        plants = plant_names()
        height = 0.026 * len(plants)
        self.plant_radio = radio(self.figure, (0.232, top - height, 0.1, height), plants, 0)
        # ignore: a radio button hands its label (matplotlib hints None too, for none active)
        self.plant_radio.on_clicked(self._on_plant)  # type: ignore[arg-type]
        below = top - height - 0.02
        self._heading(0.235, below, "Integrator")
        height = 0.026 * len(INTEGRATORS)
        self.integrator_radio = radio(
            self.figure, (0.232, below - 0.008 - height, 0.1, height), list(INTEGRATORS), 0
        )
        # ignore: a radio button hands its label (matplotlib hints None too, for none active)
        self.integrator_radio.on_clicked(self._on_integrator)  # type: ignore[arg-type]
        self._methods_bottom = min(top - height_b, below - 0.008 - height)

    def _build_options(self) -> None:
        top = self._methods_bottom - 0.02
        self._options_top = top - 0.012
        self.options_title = self._heading(0.012, top, "Options")
        self.options_slot_button = CycleButton(
            self.figure,
            (0.19, top - 0.004, 0.07, 0.022),
            "edit",
            list(SLOTS),
            "A",
            self._apply_options_slot,
            self._report,
            self._withdraw,
        )
        self.options_page_button = CycleButton(
            self.figure,
            (0.265, top - 0.004, 0.065, 0.022),
            "page",
            [1],
            1,
            self._apply_options_page,
            self._report,
            self._withdraw,
        )
        self.options_note = self.figure.text(
            0.012, self._options_top - 0.03 * 6 - 0.018, "", fontsize=FONT - 1, color="0.4"
        )

    def _build_simulation(self) -> None:
        top = self._options_top - 0.03 * 6 - 0.048
        self._heading(0.012, top, "Simulation")
        self.payload_ax = panel_axes(self.figure, (0.09, top - 0.03, 0.17, 0.02))
        low, high = PAYLOAD_RANGE
        self.payload_slider = Slider(
            self.payload_ax,
            "payload (kg)",
            low,
            max(high, self.settings.payload),  # a heavier --payload widens the slider to it
            valinit=self.settings.payload,
            valstep=0.05,
            valfmt="%.2f kg",
        )
        self.payload_slider.label.set_fontsize(FONT)
        self.payload_slider.valtext.set_fontsize(FONT)
        self.payload_slider.on_changed(self._on_payload)
        row = top - 0.062

        def duration_rect() -> Rect:
            return (self._grown(0.255, 0.03), row, self._grown(0.05, -0.03), 0.023)

        self.dt_field = Field(
            self.figure,
            (0.09, row, 0.06, 0.023),
            "dt (s)",
            "",
            self._apply_dt,
            self._report,
            self._withdraw,
            hint="blank: T/N",
        )
        self.duration_field = Field(
            self.figure,
            duration_rect(),
            "duration (s)",
            "",
            self._apply_duration,
            self._report,
            self._withdraw,
            hint="blank: T",
        )
        self._place(self.duration_field.ax, duration_rect)
        self.offset_field = Field(
            self.figure,
            (0.09, row - 0.03, 0.09, 0.023),
            "offset dx dy (m)",
            "",
            self._apply_offset,
            self._report,
            self._withdraw,
            hint="start error of the end effector",
        )
        self._simulation_bottom = row - 0.03

    def _build_export(self) -> None:
        top = self._simulation_bottom - 0.035
        self._heading(0.012, top, "Export")
        self.export_field = Field(
            self.figure,
            (0.09, top - 0.032, 0.24, 0.023),
            "folder",
            "runs/gui",
            self._apply_export_dir,
            self._report,
            self._withdraw,
        )
        row = top - 0.07
        # (x, width) of each button on the row: the animation formats' short labels
        # leave room for the physics runs' support-load panel
        places = {"data": (0.012, 0.07), "png": (0.086, 0.07), "gif": (0.16, 0.045)}
        places.update(mp4=(0.209, 0.045), loads=(0.258, 0.07))
        actions: dict[str, tuple[str, Callable[[], object]]] = {
            "data": ("CSV + JSON", self.export_data),
            "png": ("PNG (window)", self.export_png),
            "gif": ("GIF", functools.partial(self.export_animation, "gif")),
            "mp4": ("MP4", functools.partial(self.export_animation, "mp4")),
            "loads": ("Support loads", self.export_support_loads),
        }
        self.export_buttons = {
            key: button(self.figure, (x, row, width, 0.028), *actions[key])
            for key, (x, width) in places.items()
        }
        for widget in self.export_buttons.values():
            widget.label.set_fontsize(FONT)
        self._export_bottom = row

    def _build_messages(self) -> None:
        def box_rect() -> Rect:
            # A larger text scale takes from the margins above and under the box, so that
            # it still holds three lines of the smallest font.
            bottom = self._grown(0.015, -0.03)
            top = self._export_bottom - self._grown(0.012, -0.01)
            return (0.008, bottom, 0.325, top - bottom)

        ax = panel_axes(self.figure, box_rect())
        self._place(ax, box_rect)
        ax.set_xticks([])
        ax.set_yticks([])
        ax.set_facecolor("0.97")
        # lines 1.1 apart: three lines of the smallest message font (parentheses and
        # descenders included) fit at every dpi (matplotlib's 1.2 ran a point over the
        # box at 40 and 90 dpi, and the message was cut to two)
        self.message_text = ax.text(
            0.02,
            0.94,
            "",
            transform=ax.transAxes,
            fontsize=FONT,
            va="top",
            ha="left",
            family="monospace",
            linespacing=1.1,
            parse_math=False,  # a message quotes what was typed: "$" is a dollar sign
        )

    def _build_view(self) -> None:
        # Larger text takes more room: under the top view (its axis labels, its legend),
        # between it and the plots (their y labels), under the plots (the summary lines).
        def path_rect() -> Rect:
            path_bottom = self._grown(0.33, 0.25)
            return (0.385, path_bottom, 0.31, 0.955 - path_bottom)

        def plots_rect() -> Rect:
            plots_left, plots_bottom = self._grown(0.745, 0.1), self._grown(0.27, 0.2)
            return (plots_left, plots_bottom, 0.99 - plots_left, 0.955 - plots_bottom)

        def plot_rect(number: int) -> Rect:
            return stacked_rects(plots_rect())[number]

        def summary_at() -> tuple[float, float]:
            return (0.385, self._grown(0.228, 0.14))

        path_ax, plot_axes = add_view_axes(self.figure, path_rect(), plots_rect())
        self._place(path_ax, path_rect)
        for number, ax in enumerate(plot_axes.values()):
            self._place(ax, functools.partial(plot_rect, number))
        self.view = RunView(path_ax, plot_axes)
        x, y = summary_at()
        self.summary_text = self.figure.text(
            x, y, "", fontsize=FONT, va="top", linespacing=1.3, parse_math=False
        )
        self._place(self.summary_text, summary_at)

    def _build_transport(self) -> None:
        row = 0.07
        self.transport = {
            "run": button(self.figure, (0.385, row, 0.055, 0.038), "Run", self.run),
            "pause": button(self.figure, (0.445, row, 0.055, 0.038), "Pause", self.pause),
            "step": button(self.figure, (0.505, row, 0.055, 0.038), "Step", self.step),
            "reset": button(self.figure, (0.565, row, 0.055, 0.038), "Reset", self.reset),
        }
        self.speed_ax = panel_axes(self.figure, (0.68, row + 0.01, 0.1, 0.02))
        self.speed_slider = Slider(
            self.speed_ax,
            "speed",
            0,
            len(SPEEDS) - 1,
            valinit=SPEEDS.index(DEFAULT_SPEED),
            valstep=1,
            initcolor="none",
        )
        self.speed_slider.label.set_fontsize(FONT)
        self.speed_slider.valtext.set_fontsize(FONT)
        self.speed_slider.on_changed(self._on_speed)
        self._on_speed(self.speed_slider.val)
        self.progress_ax = panel_axes(self.figure, (0.845, row + 0.004, 0.145, 0.03))
        self.progress_ax.set_xlim(0, 1)
        self.progress_ax.set_ylim(0, 1)
        self.progress_ax.set_xticks([])
        self.progress_ax.set_yticks([])
        self.progress_bar = Rectangle((0, 0), 0, 1, color="tab:green", alpha=0.5)
        self.progress_ax.add_patch(self.progress_bar)
        self.progress_text = self.progress_ax.text(
            0.5,
            0.5,
            "idle",
            ha="center",
            va="center",
            fontsize=FONT,
            transform=self.progress_ax.transAxes,
        )
        self.time_ax = panel_axes(self.figure, (0.42, 0.025, 0.52, 0.025))
        self.time_slider = Slider(
            self.time_ax, "time", 0.0, 1.0, valinit=0.0, valfmt="%.2f", initcolor="none"
        )
        self.time_slider.label.set_fontsize(FONT)
        self.time_slider.valtext.set_fontsize(FONT)
        self.time_slider.on_changed(self._on_time_slider)

    def _option_widget(self, slot: int, number: int, spec: OptionSpec) -> Field | CycleButton:
        row, column = divmod(number % OPTIONS_PER_PAGE, 2)
        left = 0.012 + 0.163 * column
        bottom = self._options_top - 0.03 * (row + 1)
        apply = functools.partial(self._apply_option, slot, spec)
        if spec.kind == "choice":
            return CycleButton(
                self.figure,
                (left, bottom, 0.155, 0.024),
                spec.label,
                spec.choices,
                spec.default,
                apply,
                self._report,
                self._withdraw,
                format_choice,
            )
        field = Field(
            self.figure,
            (left + self._grown(0.092, 0.02), bottom, self._grown(0.062, -0.02), 0.024),
            spec.label,
            spec.format(spec.default),
            lambda text: self._apply_option_text(slot, spec, text),
            self._report,
            self._withdraw,
        )
        # A long name (and a window of a large text scale) has its label smaller or on
        # two lines, inside its column and its row.
        width, height = self.figure.bbox.width, self.figure.bbox.height
        fit_label(field.box.label, left * width, 0.03 * height, (FONT, FONT - 1, FONT - 2))
        return field


def window_size(
    screen_width: float, screen_height: float, ratio: float = 1.0
) -> tuple[tuple[float, float], float]:
    """The desktop window's figure size (inches) and dpi on a ``screen_width`` x
    ``screen_height`` px screen whose Tk pixel ratio (``tk scaling`` against the usual 96
    px per inch) is ``ratio``.

    The window takes the pixels of the 16 x 10 in layout at the resolution that fits the
    screen (at most :data:`DPI`), leaving room for the toolbar, the title bar and a desktop
    panel. Where that resolution is below :data:`MIN_DPI`, the same pixels hold fewer
    inches at a higher resolution (by at most :data:`MAX_TEXT_SCALE`), so that the text,
    sized in points, stays legible: 16 x 10 in at 90.72 dpi (1451 x 907 px) on a 1920 x
    1080 screen, 12.74 x 7.96 in at 81 dpi (1032 x 645 px) on 1366 x 768. Tk multiplies
    the returned dpi by ``ratio``, which the fit includes.
    """
    fit = min(DPI, 0.96 * screen_width / FIGSIZE[0], 0.84 * screen_height / FIGSIZE[1])
    dpi = resolution(fit)
    inches = (FIGSIZE[0] * fit / dpi, FIGSIZE[1] * fit / dpi)
    return inches, dpi / max(ratio, 1e-3)


def resolution(fit: float) -> float:
    """The window's resolution (px per inch) where the 16 x 10 in layout fits its pixels
    at ``fit`` px per inch: ``fit`` itself, but at least :data:`MIN_DPI` (the layout then
    on fewer inches, its text larger against it), by a factor of at most
    :data:`MAX_TEXT_SCALE` (:func:`text_scale` is this over ``fit``)."""
    return min(max(fit, MIN_DPI), fit * MAX_TEXT_SCALE)


def canvas_size(width: float, height: float) -> tuple[tuple[float, float], float]:
    """The figure size (inches) and resolution (px per inch) of a window whose canvas the
    user resized to ``width`` x ``height`` px: the :func:`resolution` of the 16 x 10 in
    layout fitted into those pixels (no :data:`DPI` cap, so that the text grows with a
    window larger than 1600 x 1000 px), on the inches that fill them."""
    dpi = resolution(min(width / FIGSIZE[0], height / FIGSIZE[1]))
    return (width / dpi, height / dpi), dpi


def text_scale(figure: Figure) -> float:
    """How much larger text is against the layout than in the 16 x 10 in window (whose
    figure fractions and point sizes the layout is drawn for): ``16 in / width`` or
    ``10 in / height``, whichever is larger (a resized window need not be 16 x 10), at
    least 1 (a figure of :data:`FIGSIZE`, or larger, is 1) and at most
    :data:`MAX_TEXT_SCALE`, the largest the layout's grown gaps are made for (a narrower
    figure, such as a caller's own of 5 in, keeps that layout, its text crowded)."""
    width, height = (float(size) for size in figure.get_size_inches())
    return scale_of(width, height)


def scale_of(width: float, height: float) -> float:
    """:func:`text_scale` of a figure of ``width`` x ``height`` in."""
    return min(MAX_TEXT_SCALE, max(1.0, FIGSIZE[0] / width, FIGSIZE[1] / height))


def desktop_figure() -> Figure:
    """A Tk window's figure, sized by :func:`window_size` to fit the screen.

    The layout is in figure fractions and the fonts in points, so a lower dpi shrinks the
    whole window evenly, down to :data:`MIN_DPI`; on a smaller screen the window is laid
    out on fewer inches instead, its text larger against the layout.
    """
    import tkinter

    import matplotlib.pyplot as plt

    probe = tkinter.Tk()  # raises TclError without a display
    probe.withdraw()
    try:
        screen_width, screen_height = probe.winfo_screenwidth(), probe.winfo_screenheight()
        ratio = float(probe.tk.call("tk", "scaling")) * 72.0 / 96.0
    finally:
        probe.destroy()
    figsize, dpi = window_size(screen_width, screen_height, ratio)
    # The simulator is a Tk program (the probe above, the Tk event loop gui.check drives),
    # whatever backend matplotlib would pick by itself (Qt where it is installed).
    plt.switch_backend("TkAgg")
    figure = plt.figure(figsize=figsize, dpi=dpi)
    # ignore: a pyplot figure has a window manager
    figure.canvas.manager.set_window_title("ddwmmr simulator")  # type: ignore[union-attr]
    return figure
