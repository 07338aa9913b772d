"""The verdict every tool gives on a run (ddwmmr.sim.verdict), and the API's warning on a
start in which the robot has tipped over."""

import json
import math
import warnings
from types import SimpleNamespace

import pytest

from ddwmmr import Robot, load_trajectory, simulate
from ddwmmr.errors import ParameterError
from ddwmmr.sim.verdict import ERROR_LIMIT_M, error_limit, short_verdict, verdict

#: A summary of a run that tracked: 2000 steps, 42.4 mm initial offset, converged.
CLEAN = {
    "steps": 2000,
    "singular_steps": 0,
    "saturated_steps": 0,
    "initial_offset_m": math.hypot(0.03, 0.03),
    "final_position_error_m": 0.0001,
    "rms_position_error_m": 0.004,
    "min_manipulability": 0.9,
}


def test_a_run_that_tracks_says_so_on_every_tool(tmp_path, capsys):
    from ddwmmr.cli.track import main as track

    result = simulate(Robot(), load_trajectory("ellipse"), "clrrmc-ts")
    assert result.summary["verdict"] == "tracked" and result.summary["verdict_reasons"] == []
    out = tmp_path / "run"
    argv = ["--method", "clrrmc-ts", "--traj", "ellipse", "--no-plots", "--no-progress"]
    assert track([*argv, "--out", str(out)]) == 0
    assert "\nverdict: tracked\n" in capsys.readouterr().out
    assert json.loads((out / "summary.json").read_text())["verdict"] == "tracked"


def test_the_slides_settings_on_the_rectangle_do_not_track(tmp_path, capsys):
    """The newcomer's first case: 2174 mm RMS, 1641 singular steps, printed as normal."""
    from ddwmmr.cli.track import main as track

    out = tmp_path / "run"
    argv = ["--method", "clrrmc-ts", "--traj", "rectangle", "--preset", "slides"]
    assert track([*argv, "--no-plots", "--no-progress", "--out", str(out)]) == 0
    printed = " ".join(capsys.readouterr().out.split())  # unwrapped
    assert "verdict: did not track: singular (damped) 1641 of 2000 steps" in printed
    assert "RMS error 2174 mm (limit 84.85 mm)" in printed
    assert "aux sum, the slides' setting" in printed and "docs/comparing.md" in printed
    summary = json.loads((out / "summary.json").read_text())
    assert summary["verdict_reasons"] == [
        "singular_most_of_run",
        "saturated_most_of_run",
        "rms_error_above_limit",
    ]
    assert summary["verdict"].startswith("did not track")


def test_a_run_that_ends_far_off_does_not_track():
    """The second case: Euler, dt 0.05 s, tau 0.3 s on the rectangle ends 361 mm off."""
    result = simulate(
        Robot(), load_trajectory("rectangle"), "clrrmc-cs", tau=0.3, integrator="euler", dt=0.05
    )
    summary = result.summary
    assert summary["final_position_error_m"] == pytest.approx(0.361, abs=0.001)
    assert summary["verdict_reasons"] == ["final_error_above_limit", "rms_error_above_limit"]
    assert "settled-end RMS position error 361 mm (limit 84.85 mm)" in summary["verdict"]
    assert "joint limit" in summary["verdict"]  # the elbow folded (min manipulability 0)


def test_the_error_limit_is_50_mm_or_twice_the_initial_offset():
    assert error_limit({"initial_offset_m": 0.0}) == ERROR_LIMIT_M == 0.05
    assert error_limit({"initial_offset_m": 0.01}) == 0.05
    assert error_limit(CLEAN) == pytest.approx(2 * 0.0424264, abs=1e-6)
    # an open-loop method keeps its 42.4 mm offset: tracked; 90 mm at the end is not
    assert verdict({**CLEAN, "final_position_error_m": 0.0424})["verdict"] == "tracked"
    far = verdict({**CLEAN, "final_position_error_m": 0.090})
    assert far["verdict_reasons"] == ["final_error_above_limit"]
    assert "settled-end RMS position error 90 mm (limit 84.85 mm)" in far["verdict"]
    assert verdict({**CLEAN, "rms_position_error_m": 0.0849})["verdict_reasons"] == [
        "rms_error_above_limit"
    ]


@pytest.mark.parametrize(
    ("changes", "reasons"),
    [
        ({"singular_steps": 1000}, []),  # half the run is not most of it
        ({"singular_steps": 1001}, ["singular_most_of_run"]),
        ({"saturated_steps": 1000}, []),
        ({"saturated_steps": 1001}, ["saturated_most_of_run"]),
        ({"diverged": "state not finite at step 7"}, ["diverged"]),
        ({"final_position_error_m": math.nan}, ["final_error_above_limit"]),
        ({"tipped": True}, ["tipped_over"]),
        ({"tipped": False}, []),
        ({"start_tipped": True, "start_stability": 0.9}, ["tipped_at_start"]),
    ],
)
def test_each_reason_at_its_threshold(changes, reasons):
    found = verdict({**CLEAN, **changes})
    assert found["verdict_reasons"] == reasons
    assert found["verdict"].startswith("did not track: ") == bool(reasons)
    assert short_verdict({**CLEAN, **changes}) == (
        "tracked" if not reasons else f"DID NOT TRACK ({', '.join(reasons)})"
    )


@pytest.mark.parametrize(
    ("key", "value", "shown"),
    [
        ("steps", "2000", "'2000'"),
        ("singular_steps", "5", "'5'"),
        ("saturated_steps", True, "True"),
        ("initial_offset_m", "x", "'x'"),
        ("final_position_error_m", "0.1", "'0.1'"),
        ("rms_position_error_m", [1.0], "[1.0]"),
        ("min_manipulability", "a", "'a'"),
        ("start_stability", {"S": 0.9}, "{'S': 0.9}"),
        ("final_position_error_m", 10**400, "an integer of about 1e400"),
    ],
)
def test_a_summary_value_that_is_not_a_number_is_one_line_naming_its_key(key, value, shown):
    summary = {**CLEAN, "start_tipped": True, "start_stability": 0.9, key: value}
    expected = f"summary: {key} must be a number, 'nan', 'inf', '-inf' or None (got {shown})"
    for function in (verdict, short_verdict):
        with pytest.raises(ParameterError) as info:
            function(summary)
        assert str(info.value) == expected


def test_short_verdict_refuses_reasons_that_are_not_a_list_of_codes():
    for reasons in (5, "diverged", [1]):
        with pytest.raises(ParameterError) as info:
            short_verdict({**CLEAN, "verdict_reasons": reasons})
        assert str(info.value).startswith(
            "summary: verdict_reasons must be a list of reason codes (strings such as "
        )
    assert short_verdict({"verdict_reasons": ("diverged",)}) == "DID NOT TRACK (diverged)"


def test_a_summary_read_back_from_json_keeps_its_non_finite_numbers():
    """summary.json writes nan and inf as strings: the verdict reads them as the numbers."""
    from ddwmmr.sim.result import json_safe

    blew_up = {**CLEAN, "final_position_error_m": math.nan, "rms_position_error_m": math.inf}
    read_back = json.loads(json.dumps(json_safe(blew_up)))
    assert read_back["final_position_error_m"] == "nan"
    assert verdict(read_back) == verdict(blew_up)
    assert verdict(read_back)["verdict_reasons"] == [
        "final_error_above_limit",
        "rms_error_above_limit",
    ]
    assert (
        verdict({**CLEAN, "min_manipulability": "-inf", "final_position_error_m": 1.0})["verdict"]
        == verdict({**CLEAN, "min_manipulability": -math.inf, "final_position_error_m": 1.0})[
            "verdict"
        ]
    )


def test_the_singular_cause_names_the_slides_row_only_with_it():
    singular = {**CLEAN, "singular_steps": 1500}
    assert "aux sum" in verdict({**singular, "aux": "sum"})["verdict"]
    assert "pi and ap" in verdict({**singular, "aux": "shoulder"})["verdict"]


def test_the_singularity_is_the_cause_from_a_quarter_of_the_run():
    """ap on the rectangle: 990 of 2000 steps singular (not most of the run), then 4.7 m
    off with the arm stretched: the singularity is named, not the folded arm."""
    far = {**CLEAN, "final_position_error_m": 4.7, "min_manipulability": 0.0}
    assert "cos th1 = 0" in verdict({**far, "singular_steps": 990})["verdict"]
    assert "cos th1 = 0" in verdict({**far, "singular_steps": 501})["verdict"]
    assert "joint limit" in verdict({**far, "singular_steps": 500})["verdict"]


def test_a_start_below_the_stability_floor_is_named_as_the_cause():
    """qp with --stability-min 9.9 from S = 2.18 ends 0.69 m off: the floor, not tau."""
    far = {**CLEAN, "final_position_error_m": 0.69, "start_stability": 2.18}
    below = verdict({**far, "stability_min": 9.9})["verdict"]
    assert "starts below its stability floor (start S = 2.18 < stability_min 9.9)" in below
    assert "check tau" in verdict({**far, "stability_min": 1.25})["verdict"]  # above it
    assert "check tau" in verdict(far)["verdict"]  # a method without a floor
    # a start that :g would spell as the floor itself is spelt in full
    close = verdict({**far, "start_stability": 1.2499999, "stability_min": 1.25})["verdict"]
    assert "(start S = 1.2499999 < stability_min 1.25)" in close
    # a run that tracked from below its floor: tracked, with a warning (not a reason)
    tracked = verdict({**CLEAN, "start_stability": 2.18, "stability_min": 9.9})
    assert tracked["verdict_reasons"] == []
    assert tracked["verdict"].startswith(
        "tracked; warning: the run started below its stability floor (start S = 2.18 < "
        "stability_min 9.9;"
    )


def test_qp_from_below_its_floor_names_the_floor(tmp_path):
    result = simulate(Robot(), load_trajectory("ellipse"), "qp", duration=1.0, stability_min=9.9)
    assert result.summary["start_stability"] < 9.9
    assert "starts below its stability floor" in result.summary["verdict"]


def test_compare_lists_the_runs_that_did_not_track():
    from ddwmmr.cli.compare import not_tracked

    specs = [SimpleNamespace(method=m, trajectory="rectangle") for m in ("qp", "pi", "ap")]
    summaries = [
        CLEAN,
        {**CLEAN, "singular_steps": 1272, "aux": None},
        {**CLEAN, "singular_steps": 990, "rms_position_error_m": 3.9},
    ]
    outputs = {id(s): SimpleNamespace(summary=v) for s, v in zip(specs, summaries)}
    plan = SimpleNamespace(main=specs)
    lines = not_tracked(plan, _ById(outputs))
    assert lines[0].startswith("Did not track (2 of 3 runs")
    assert lines[1] == "  pi on rectangle: singular (damped) 1272 of 2000 steps"
    assert lines[2] == "  ap on rectangle: RMS error 3900 mm (limit 84.85 mm)"
    assert len(lines) == 4 and lines[3].startswith("  likely cause (pi, ap): the resolution")
    assert not_tracked(SimpleNamespace(main=specs[:1]), _ById(outputs)) == [
        'Every run tracked (see docs/cli.md, "Verdict").'
    ]


class _ById(dict):
    def __getitem__(self, spec):
        return super().__getitem__(id(spec))


def test_the_simulator_summary_line_starts_with_the_verdict():
    from ddwmmr.gui.app import _summary_line

    summary = {
        **CLEAN,
        "max_position_error_m": 0.02,
        "rms_orientation_error_rad": 0.1,
        "max_wheel_speed_rad_s": 5.0,
        "min_stability": 1.3,
        "fallback_steps": 0,
    }
    assert _summary_line("A", SimpleNamespace(summary=summary)).startswith("A: tracked; RMS")
    bad = {**summary, "singular_steps": 1800}
    line = _summary_line("A", SimpleNamespace(summary=bad))
    assert line.startswith("A: DID NOT TRACK (singular_most_of_run); RMS")


# -- a start in which the robot has tipped over ----------------------------------------

#: examples/own_robot.py's longer arm with 6 kg, as the newcomer ran it.
LONG_ARM = Robot(L1=0.45, L2=0.35, base_length=0.55, base_width=0.40, payload=6.0)


def test_the_api_warns_on_a_start_that_tips_the_robot_and_the_summary_flags_it():
    with pytest.warns(UserWarning, match=r"a 6 kg payload tips the robot over .*S = 0\.943"):
        result = simulate(
            LONG_ARM,
            load_trajectory("ellipse"),
            "clrrmc-ts",
            duration=0.2,
            initial_offset=(-0.03, -0.03),  # as the newcomer ran it (not its own, 1.29 x)
        )
    summary = result.summary
    assert summary["start_tipped"] is True
    assert summary["start_stability"] == pytest.approx(0.943, abs=5e-4)
    assert LONG_ARM.stability(result.configurations()[0])[2] == summary["start_stability"]
    assert summary["verdict_reasons"] == ["tipped_at_start"]
    assert "S = 0.943" in summary["verdict"]


def test_the_api_refuses_or_allows_a_tipped_start_on_request():
    ellipse = load_trajectory("ellipse")
    with pytest.raises(ParameterError, match=r"^payload: a 6 kg payload tips the robot"):
        simulate(LONG_ARM, ellipse, "ats", duration=0.2, tipped_start="refuse")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        allowed = simulate(LONG_ARM, ellipse, "ats", duration=0.2, tipped_start="allow")
        upright = simulate(Robot(), ellipse, "ats", duration=0.2)  # no warning either
    assert allowed.summary["start_tipped"] and not upright.summary["start_tipped"]
    with pytest.raises(ParameterError, match=r"tipped_start must be one of warn, refuse, allow"):
        simulate(Robot(), ellipse, "ats", duration=0.2, tipped_start="maybe")


def test_the_warning_and_track_s_refusal_are_one_message(tmp_path, capsys):
    """One check: the API's warning starts with the line track refuses the run with."""
    from ddwmmr.cli.track import main as track

    robot_file = tmp_path / "long.toml"
    robot_file.write_text(
        "[robot]\nL1 = 0.45\nL2 = 0.35\nbase_length = 0.55\nbase_width = 0.40\npayload = 6.0\n"
    )
    argv = ["--method", "ats", "--traj", "ellipse", "--robot", str(robot_file), "--no-plots"]
    assert track([*argv, "--out", str(tmp_path / "out")]) == 2
    refusal = capsys.readouterr().err.strip().removeprefix("error: ")
    with pytest.warns(UserWarning) as caught:
        simulate(Robot.from_toml(robot_file), load_trajectory("ellipse"), "ats", duration=0.2)
    head = refusal.split(" or change ")[0]
    assert head.startswith("robot: a 6 kg payload") and str(caught[0].message).startswith(
        head.replace("robot:", "payload:", 1)
    )
