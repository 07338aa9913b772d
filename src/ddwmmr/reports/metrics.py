"""The summary metrics as the outputs show them: each ``summary.json`` key's label, display
unit and scale, the one home of how ``track``'s printed table, ``compare``'s metric table
and the simulator's summary line name a metric, so that a metric reads the same in all
three.

A metric has a short label (``compare``'s column header, the simulator's summary line) and
a long one (``track``'s table), which spells out the short label's words in the same order
(an abbreviation is the start of its word: ``pos`` of ``position``) and may add words:
``RMS pos (mm)`` and ``RMS position error (mm)``. The outputs keep their own digits
(``track``: 6 significant digits, ``compare`` and the simulator: 3).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

#: Display units per summary unit of a length stored in m and shown in mm.
MM_PER_M = 1000.0


@dataclass(frozen=True)
class Metric:
    """How the outputs show one summary key.

    ``key``: the ``summary.json`` key (SI units: m, rad, s). ``name``: the short label
    without its unit (``"RMS pos"``). ``unit``: the display unit, ``""`` for a count, a flag
    or a unitless number. ``long``: ``track``'s label without its unit, ``""`` for
    ``name``. ``scale``: display units per summary unit (:data:`MM_PER_M` for a length shown
    in mm, 1 otherwise).
    """

    key: str
    name: str
    unit: str = ""
    long: str = ""
    scale: float = 1.0

    @property
    def label(self) -> str:
        """The short label with its unit: ``"RMS pos (mm)"``."""
        return _with_unit(self.name, self.unit)

    @property
    def long_label(self) -> str:
        """``track``'s label with its unit: ``"RMS position error (mm)"``."""
        return _with_unit(self.long or self.name, self.unit)

    def shown(self, value: Any) -> Any:
        """``value`` (summary units) in the display unit; unchanged when the scale is 1, so
        a count stays an int."""
        return value if self.scale == 1.0 else self.scale * float(value)


def _with_unit(name: str, unit: str) -> str:
    return f"{name} ({unit})" if unit else name


def _mm(key: str, name: str, long: str = "") -> Metric:
    """A length stored in m and shown in mm."""
    return Metric(key, name, "mm", long, MM_PER_M)


#: Every metric an output shows, in ``track``'s table order. ``final_position_error_m`` is
#: the RMS over the run's settled end, not the last sample's error
#: (``end_position_error_m``); ``saturated_steps`` counts the commands the plant clipped,
#: while a limit ``qp`` or ``mpc`` holds inside its own bounds shows only in
#: ``wheel_limit_steps`` / ``joint_rate_limit_steps`` (docs/cli.md, the summary table).
METRICS: dict[str, Metric] = {
    m.key: m
    for m in (
        _mm("rms_position_error_m", "RMS pos", "RMS position error"),
        _mm("max_position_error_m", "max pos", "max position error"),
        _mm("final_position_error_m", "settled-end RMS pos", "settled-end RMS position error"),
        _mm("end_position_error_m", "position error at the end"),
        _mm("corner_position_error_m", "corner position error"),
        Metric("rms_orientation_error_rad", "RMS orient", "rad", "RMS orientation error"),
        Metric(
            "max_nonholonomic_residual_m_s",
            "max nonhol. residual",
            "m/s",
            "max nonholonomic residual",
        ),
        Metric("max_wheel_speed_rad_s", "max wheel speed", "rad/s"),
        Metric("min_manipulability", "min manip.", long="min manipulability"),
        Metric("mean_manipulability", "mean manip.", long="mean manipulability"),
        Metric("min_stability", "min stability S"),
        Metric("singular_steps", "singular steps", long="singular (damped) steps"),
        Metric("saturated_steps", "saturated steps", long="saturated steps (plant clipped)"),
        Metric("wheel_limit_steps", "wheel-limit steps", long="wheel at speed limit (steps)"),
        Metric(
            "joint_rate_limit_steps", "joint-rate-limit steps", long="joint at rate limit (steps)"
        ),
        Metric("joint_limit_steps", "joint at position limit (steps)"),
        Metric("joint_limit_held", "position limit held (most steps)"),
        Metric("stability_violations", "steps with S < S_min"),
        Metric("qp_fallbacks", "QP fallbacks"),
        Metric("mpc_fallbacks", "MPC fallbacks (its qp commanded)"),
        _mm("min_obstacle_clearance_m", "min obstacle clearance"),
        Metric("max_wheel_force_n", "max wheel force", "N"),
        Metric("actuator_saturated_time_s", "time with an actuator at limit", "s"),
        Metric("tipped", "tipped over (physics)"),
        Metric("support_lost", "support lost (an edge unloaded)"),
        Metric("unloaded_time_s", "time with an edge unloaded", "s"),
        Metric("min_edge_load_n", "min support-edge load", "N"),
        Metric("min_predicted_edge_load_n", "min predicted edge load", "N"),
        Metric("min_edge_load_floor_n", "edge-load floor held", "N"),
        Metric("min_physics_stability", "min physics stability"),
        Metric("max_base_tilt_rad", "max base tilt", "rad"),
        Metric("max_wheel_slip_m_s", "max wheel slip", "m/s"),
        Metric("diverged", "plant diverged"),
        Metric("steps", "steps"),
        Metric("median_step_us", "median step", "us", "median controller step"),
    )
}
