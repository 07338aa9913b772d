"""The figure scripts of docs/ make figures that show their data (tests/figure_checks.py):
every figure of docs/make_figures.py and docs/qp_figures.py (but its timed one), the
physics figures that take seconds, the frames of a physics run's animation, the
support-load figures (attribution from the committed numbers, validation on a short run)
and the benchmark figure."""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path

import numpy as np
import pytest

from figure_checks import SavedFigures, SaveGifCalls, blitted_and_full

DOCS = Path(__file__).resolve().parent.parent / "docs"


def docs_script(name: str, tmp_path: Path, monkeypatch):
    """Import ``docs/<name>.py`` as a module writing its figures to ``tmp_path`` (its
    ``FIGURES`` folder, or its one ``FIGURE`` under the same name)."""
    spec = importlib.util.spec_from_file_location(f"docs_{name}", DOCS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    monkeypatch.setitem(sys.modules, spec.name, module)  # dataclasses look their module up
    spec.loader.exec_module(module)
    if hasattr(module, "FIGURES"):
        monkeypatch.setattr(module, "FIGURES", tmp_path)
    else:
        monkeypatch.setattr(module, "FIGURE", tmp_path / module.FIGURE.name)
    return module


def test_theory_figures(tmp_path, monkeypatch):
    saved = SavedFigures(monkeypatch)
    script = docs_script("make_figures", tmp_path, monkeypatch)
    script.main()
    assert len(saved.problems) == 6
    assert saved.failing() == {}


@pytest.mark.parametrize(
    "function", ["sideways_reach", "ellipse_manipulability", "obstacle", "modes", "waypoints"]
)
def test_qp_figures(function, tmp_path, monkeypatch):
    saved = SavedFigures(monkeypatch)
    script = docs_script("qp_figures", tmp_path, monkeypatch)
    getattr(script, function)()
    assert len(saved.problems) == 1
    assert saved.failing() == {}


def test_physics_tipping_map(tmp_path, monkeypatch):
    """The tipping map's layout (its 400 MuJoCo holds take minutes): each hold is judged
    by the kinematic S instead, which MuJoCo matches on this grid (docs/physics.md)."""
    from ddwmmr import Robot

    script = docs_script("physics_figures", tmp_path, monkeypatch)

    def hold_pose(robot: Robot, th1: float, th2: float, **_) -> dict:
        return {"tipped": robot.stability([0.0, 0.0, 0.0, th1, th2])[2] <= 1.0}

    monkeypatch.setattr(script, "hold_pose", hold_pose)
    saved = SavedFigures(monkeypatch)
    assert script.tipping_map().endswith("0 where MuJoCo disagrees with S <= 1")
    assert list(saved.problems) == ["physics_tipping_map.png"]
    assert saved.failing() == {}


def test_physics_slow_reach_figure(tmp_path, monkeypatch):
    """physics_sideways_forces.png on a faster unfolding (0.4 rad/s: 250 steps instead of
    1650): the same figure, its layout checked."""
    script = docs_script("physics_figures", tmp_path, monkeypatch)
    saved = SavedFigures(monkeypatch)
    script.slow_sideways_reach(rate=0.4)
    assert list(saved.problems) == ["physics_sideways_forces.png"]
    assert saved.failing() == {}


@pytest.fixture(scope="module")
def tipping_runs():
    """ats and clrrmc-ts reaching sideways with 4 kg on the physics plant: both tip."""
    from ddwmmr import Robot, load_trajectory, simulate

    trajectory = load_trajectory("sideways_reach")
    robot = Robot().with_payload(4.0)
    q0 = robot.base_for_end_effector(trajectory.pose(0.0), 1.0, 1.6)
    return {
        (4.0, method): simulate(
            robot, trajectory, method, plant="mujoco", q0=q0, dt=0.02, duration=2.0
        )
        for method in ("ats", "clrrmc-ts")
    }


def test_physics_runs_figure_with_runs_that_tip(tipping_runs, tmp_path, monkeypatch):
    assert all(run.summary["tipped"] for run in tipping_runs.values())
    saved = SavedFigures(monkeypatch)
    script = docs_script("physics_figures", tmp_path, monkeypatch)
    script._plot_reach_runs(tipping_runs, (4.0,))
    assert list(saved.problems) == ["physics_sideways_runs.png"]
    assert saved.failing() == {}


def test_physics_animation_frames(tipping_runs, tmp_path, monkeypatch):
    """Every frame shows its data, and is a full render of the figure at its instant
    (the title with the time included; the moving artists are all redrawn)."""
    from ddwmmr.plants.mujoco import MujocoPlant
    from ddwmmr.reports import physics_plots

    result = tipping_runs[4.0, "clrrmc-ts"]
    plant = MujocoPlant(result.robot)
    saved = SavedFigures(monkeypatch)
    points = [s.point for s in plant.supports]
    calls = SaveGifCalls(monkeypatch, physics_plots)
    path = tmp_path / "tip.gif"
    physics_plots.save_physics_animation(result, points, plant.weight_n, path, frames=6)
    assert len(saved.problems) >= 6  # every frame is checked as it is drawn
    assert saved.failing() == {}
    ((fig, update, count),) = calls.calls
    top = fig.axes[0]
    for index, (blitted, full) in enumerate(blitted_and_full(fig, update, count)):
        above = slice(0, blitted.shape[0] - round(top.bbox.y1))  # the title's band
        assert np.array_equal(blitted[above], full[above]), index
        assert np.mean(np.abs(blitted - full)) < 0.5, index  # of 255


def test_benchmark_figure(tmp_path, monkeypatch):
    """docs/figures/bench.png from the committed benchmarks/bench.json."""
    spec = importlib.util.spec_from_file_location(
        "bench_docs", DOCS.parent / "benchmarks" / "bench_docs.py"
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    report = json.loads((DOCS.parent / "benchmarks" / "bench.json").read_text())
    saved = SavedFigures(monkeypatch)
    module.plot_report(report, tmp_path / "bench.png")
    assert len(saved.problems) == 1
    assert saved.failing() == {}


def test_support_load_figures(tmp_path, monkeypatch):
    """The attribution figures from the committed docs/support_loads.json; the validation
    figure on a 2 s fast turn (its full runs take minutes)."""
    script = docs_script("support_loads", tmp_path, monkeypatch)
    numbers = json.loads((DOCS / "support_loads.json").read_text())
    saved = SavedFigures(monkeypatch)
    script.draw_attribution(numbers["attribution"])
    script.validation_figure({"fast turn": script.fast_turn(duration=2.0)}, tmp_path / "v.png")
    assert list(saved.problems) == [
        "support_attribution_qp.png",
        "support_attribution_mpc.png",
        "v.png",
    ]
    assert saved.failing() == {}


def test_bounds_accounting_figure_and_table(tmp_path, monkeypatch):
    """docs/figures/bounds_accounting.png and docs/mpc.md's table from the committed
    accounting CSVs: every row's terms add up to its time (the lower bound plus the excess
    above it standing for the path and rotation at the bound's prices)."""
    script = docs_script("bounds_accounting", tmp_path, monkeypatch)
    saved = SavedFigures(monkeypatch)
    script.figure()
    assert list(saved.problems) == ["bounds_accounting.png"]
    assert saved.failing() == {}
    rows = script.table()[2:]
    assert len(rows) == len(script.SEEDS) * len(script.TRAJECTORIES)
    for row in rows:
        cells = [c.strip() for c in row.strip("|").split("|")]
        time, lower, *terms = (float(c) for c in cells[1:8])
        assert lower + sum(terms) == pytest.approx(time, abs=0.03)


def test_bounds_update_keeps_the_lower_replayed_time(tmp_path, monkeypatch):
    """docs/bounds_figures.py --update: a later bounds run's row replaces the committed
    one only where its replayed best-known time is lower (by more than the same optimum's
    rounding), and only those scenarios' plan-following runs are redone; a failed replay
    never wins."""
    script = docs_script("bounds_figures", tmp_path, monkeypatch)
    data, later = tmp_path / "data", tmp_path / "later"
    data.mkdir()
    later.mkdir()
    monkeypatch.setattr(script, "DATA", data)
    header = "scenario,lower_bound_s,best_known_s,starts,spread_s,replay_ok\n"
    committed = header + (
        "1,5.0,10.0,59,1.0,True\n2,5.0,9.0,59,1.0,True\n3,5.0,8.0,59,1.0,False\n"
        "5,5.0,10.0,59,1.0,True\n"
    )
    # as the bounds tool writes it: csv's CRLF line endings
    (data / "bounds_seed0.csv").write_bytes(committed.replace("\n", "\r\n").encode())
    (later / "bounds.csv").write_text(
        header + "1,5.0,9.5,60,2.0,True\n2,5.0,9.25,60,2.0,True\n3,5.0,7.5,60,2.0,True\n"
        "4,5.0,1.0,60,2.0,True\n5,5.0,9.9999999,60,2.0,True\n"
    )
    names = ",".join(script.CONTROLLERS)
    (data / "controllers_seed0.csv").write_text(
        f"scenario,{names}\n"
        + "".join(f"{s}," + ",".join(["20.0"] * 7) + "\n" for s in (1, 2, 3, 5))
    )
    calls = []

    def mpc_run(job):
        calls.append(job[1:3])
        return job[1], job[2], 11.0 + job[1]

    monkeypatch.setattr(script, "mpc_run", mpc_run)
    assert script.update(0, later, jobs=1) == [1, 3]
    assert sorted(calls) == [
        (1, "mpc-plan"),
        (1, "mpc-plan-cold"),
        (3, "mpc-plan"),
        (3, "mpc-plan-cold"),
    ]
    bounds = script.read_bounds(0)
    # 5: 1e-7 s lower is the same optimum, kept
    assert bounds == {1: (5.0, 9.5), 2: (5.0, 9.0), 3: (5.0, 7.5), 5: (5.0, 10.0)}
    written = (data / "bounds_seed0.csv").read_bytes()
    assert written.count(b"\r\n") == 5 and b"2,5.0,9.0,59,1.0,True\r\n" in written
    times = script.read_controllers(0)
    assert times["mpc-plan"] == {1: 12.0, 2: 20.0, 3: 14.0, 5: 20.0}
    assert times["mpc-plan-cold"] == {1: 12.0, 2: 20.0, 3: 14.0, 5: 20.0}
    assert times["mpc"] == {1: 20.0, 2: 20.0, 3: 20.0, 5: 20.0}
    assert script.update(0, later, jobs=1) == []  # the committed rows now win or tie


def test_bounds_ratios_figure_and_tables(tmp_path, monkeypatch):
    """docs/figures/bounds_ratios.png and docs/mpc.md's bracket tables from the committed
    CSVs: every controller's mean time over the best known is at least 1 and its time over
    the lower bound at least that (the bound is below the best known in every scenario)."""
    script = docs_script("bounds_figures", tmp_path, monkeypatch)
    saved = SavedFigures(monkeypatch)
    script.figure()
    assert list(saved.problems) == ["bounds_ratios.png"]
    assert saved.failing() == {}
    for seed in script.SEEDS:
        lines = script.table(seed)
        rows = [line for line in lines if line.startswith("| ") and "---" not in line][1:]
        assert len(rows) == len(script.CONTROLLERS)
        for row in rows:
            cells = [c.strip() for c in row.strip("|").split("|")]
            to_best, to_lower = (float(c.split()[0]) for c in cells[2:4])
            assert 1.0 <= to_best < to_lower


def test_bounds_rerun_redoes_the_named_mpc_columns_of_every_scenario(tmp_path, monkeypatch):
    """docs/bounds_figures.py --rerun: the named columns of every scenario are run again
    (the others kept), and one real run reproduces the committed seed-0 data."""
    script = docs_script("bounds_figures", tmp_path, monkeypatch)
    committed = script.read_controllers(0)
    # scenario 74: the shortest mpc run of seed 0 (11.7 s), its neighbours' times differ
    real = script.mpc_run((0, 74, "mpc", str(tmp_path)))
    assert real == (74, "mpc", committed["mpc"][74])
    data = tmp_path / "data"
    data.mkdir()
    monkeypatch.setattr(script, "DATA", data)
    names = ",".join(script.CONTROLLERS)
    (data / "controllers_seed0.csv").write_text(
        f"scenario,{names}\n" + "".join(f"{s}," + ",".join(["20.0"] * 7) + "\n" for s in (1, 2))
    )
    calls = []

    def mpc_run(job):
        calls.append(job[1:3])
        return job[1], job[2], 11.0 + job[1]

    monkeypatch.setattr(script, "mpc_run", mpc_run)
    script.rerun(0, tmp_path, ("mpc", "mpc-lookahead"), jobs=1)
    assert sorted(calls) == [(1, "mpc"), (1, "mpc-lookahead"), (2, "mpc"), (2, "mpc-lookahead")]
    times = script.read_controllers(0)
    assert times["mpc"] == times["mpc-lookahead"] == {1: 12.0, 2: 13.0}
    assert times["mpc-plan"] == times["thesis"] == {1: 20.0, 2: 20.0}


def test_bounds_rerun_command_line_checks_the_column_names(tmp_path, monkeypatch, capsys):
    """--rerun SEED DIR NAMES: the names (comma separated, spaces allowed) reach rerun();
    an unknown one is refused before any run, naming the columns."""
    script = docs_script("bounds_figures", tmp_path, monkeypatch)
    calls = []
    monkeypatch.setattr(script, "rerun", lambda *args: calls.append(args))
    for name in ("figure", "rewrite_page"):
        monkeypatch.setattr(script, name, lambda: None)
    monkeypatch.setattr(script, "table", lambda seed: [])
    monkeypatch.setattr(sys, "argv", ["bounds_figures.py", "--rerun", "1", "D", "mpc, mpc-plan"])
    script.main()
    assert calls == [(1, Path("D"), ("mpc", "mpc-plan"), 2)]
    monkeypatch.setattr(sys, "argv", ["bounds_figures.py", "--rerun", "1", "D", "mpc,nope"])
    with pytest.raises(SystemExit) as exit_:
        script.main()
    assert exit_.value.code == 2 and "unknown column 'nope' (of mpc, " in capsys.readouterr().err
    assert len(calls) == 1
