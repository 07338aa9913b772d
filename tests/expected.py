"""Expectations the tests share, stated independently of the library."""

#: summary.json keys the core issue requires of every tracking run (stated here, not taken
#: from the library, so that dropping a key fails the tests).
REQUIRED_SUMMARY_KEYS = frozenset(
    {
        "method",
        "trajectory",
        "rms_position_error_m",
        "max_position_error_m",
        "final_position_error_m",
        "rms_orientation_error_rad",
        "max_nonholonomic_residual_m_s",
        "max_wheel_speed_rad_s",
        "min_manipulability",
        "min_stability",
        "singular_steps",
        "steps",
        "median_step_us",
    }
)
