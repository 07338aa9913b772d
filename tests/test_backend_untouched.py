"""Importing ddwmmr and writing its figures leaves the user's matplotlib backend alone.

A user who chose a backend (``matplotlib.use``, Jupyter, a Qt or Tk program) and then
imports ddwmmr or writes a report keeps that backend: their ``plt.show()`` still shows.
The figure writers draw on figures of their own (:mod:`ddwmmr.reports.canvas`), never on
pyplot's. Runs in a fresh interpreter, where the backend is still the user's choice
(``svg`` here: not the Agg the PNGs are rendered with, and needing no display)."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

SCRIPT = textwrap.dedent(
    """
    import importlib
    import pkgutil
    import sys
    from pathlib import Path

    import matplotlib

    matplotlib.use("svg")
    import matplotlib.pyplot as plt

    out = Path(sys.argv[1])
    changed = []

    def check(step):
        if matplotlib.get_backend() != "svg" and not changed:
            changed.append(f"{step} -> {matplotlib.get_backend()}")  # the first to switch

    import ddwmmr
    import ddwmmr.reports
    import ddwmmr.scenarios

    check("import ddwmmr")
    names = []
    for package in (ddwmmr.reports, ddwmmr.scenarios):
        for info in pkgutil.walk_packages(package.__path__, package.__name__ + "."):
            if info.name.endswith("__main__"):
                continue  # runs the command line
            importlib.import_module(info.name)
            names.append(info.name)
            check(f"import {info.name}")

    from ddwmmr import Robot, load_trajectory, simulate
    from ddwmmr.reports import compare_plots, physics_plots, plots
    from ddwmmr.scenarios import arbiter_study, generate, report, run_scenario
    from ddwmmr.scenarios.protocol import RunConfig

    run = simulate(Robot(), load_trajectory("ellipse"), "ats", duration=1.0)
    written = plots.save_run_figures(run, out)
    check("plots.save_run_figures")
    written.append(plots.save_animation(run, out / "run.gif", frames=3))
    check("plots.save_animation")
    series, colours = {"ats": run.timeseries}, {"ats": "tab:blue"}
    fig = compare_plots.plot_errors(series, colours, "ats on ellipse")
    written.append(compare_plots.save(fig, out / "compare_errors.png"))
    check("compare_plots.plot_errors, save")
    physics = simulate(
        Robot().with_payload(3.0),
        load_trajectory("sideways_reach"),
        "qp",
        duration=0.2,
        plant="mujoco",
    )
    written.append(physics_plots.save_support_loads(physics, out / "support_loads.png"))
    check("physics_plots.save_support_loads")
    config = RunConfig(time_limit=0.5, record=True)
    scenario = generate(1, 0)[0]
    report.plot_state_times([run_scenario(scenario, config)], out / "times.png", "thesis")
    written.append(out / "times.png")
    check("scenarios.report.plot_state_times")
    weights = out / "weights.png"
    arbiter_study.plot_weights(scenario, config, weights, "thesis", compare_state_machine=False)
    written.append(weights)
    check("scenarios.arbiter_study.plot_weights")

    print("modules:", len(names))
    print("written:", sorted(p.name for p in written if p.stat().st_size > 0))
    print("pyplot figure canvas:", type(plt.figure().canvas).__name__)
    print("backend:", matplotlib.get_backend())
    print("changed:", changed)
    """
)


def test_a_chosen_backend_survives_importing_and_writing_figures(tmp_path: Path) -> None:
    script = tmp_path / "user.py"
    script.write_text(SCRIPT)
    out = tmp_path / "figures"
    out.mkdir()
    # No MPLBACKEND (conftest sets one) and no display: the script's matplotlib.use is
    # the user's only choice.
    env = {k: v for k, v in os.environ.items() if k not in ("MPLBACKEND", "DISPLAY")}
    env["PYTHONPATH"] = str(Path(__file__).parents[1] / "src")
    done = subprocess.run(
        [sys.executable, str(script), str(out)], capture_output=True, text=True, env=env
    )
    assert done.returncode == 0, done.stderr
    lines = dict(line.split(": ", 1) for line in done.stdout.splitlines() if ": " in line)
    assert lines["changed"] == "[]", done.stdout
    assert lines["backend"] == "svg"
    assert lines["pyplot figure canvas"] == "FigureCanvasSVG"
    assert int(lines["modules"]) >= 10  # every reports and scenarios module was imported
    assert lines["written"] == str(
        sorted(
            [
                "compare_errors.png",
                "errors.png",
                "metrics.png",
                "path.png",
                "rates.png",
                "run.gif",
                "support_loads.png",
                "times.png",
                "weights.png",
            ]
        )
    )
