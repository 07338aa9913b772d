"""The pages agree with the code and with each other: command lines, in-page references,
the tool table, the figure-eight's size, the kernels' cost, the mpc's tracking table and the
compare report's singularity advice."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from ddwmmr.__main__ import TOOLS
from ddwmmr.cli.track import build_parser
from ddwmmr.reports.compare.advice import Profile, _singularity_line

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
PAGES = [DOCS / n for n in ("mpc.md", "theory.md", "api.md", "comparing.md")] + [ROOT / "README.md"]


def _joined(path: Path) -> str:
    return re.sub(r"\s*\n\s*", " ", path.read_text(encoding="utf-8"))


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_track_command_lines_use_options_the_parser_has(page: Path) -> None:
    options = {o for a in build_parser()._actions for o in a.option_strings}
    spans = re.findall(r"`(?:python -m ddwmmr\.)?track (--[^`]*)`", _joined(page))
    used = {flag for span in spans for flag in re.findall(r"(?<![\w-])--[a-z][a-z0-9-]*", span)}
    assert used - options == set()


def _labels(text: str) -> set[str]:
    """Headings, bold run-in titles and bullet labels (``* *Label.*``, ``- **Label.**``)."""
    labels = set()
    for line in text.splitlines():
        if heading := re.match(r"#{1,6} (.+)", line):
            labels.add(heading[1].strip())
        if label := re.match(r"\s*(?:[*-] )?(\*\*?)([^*]+?)\.?\1", line):
            labels.add(label[2].strip())
    return {label.replace("`", "") for label in labels}


@pytest.mark.parametrize("page", PAGES[:2], ids=lambda p: p.name)
def test_quoted_references_above_and_below_exist_on_the_page(page: Path) -> None:
    labels = {label.lower() for label in _labels(page.read_text(encoding="utf-8"))}
    quoted = re.findall(r'"([^"]{4,80})"\s+(?:under "[^"]+" )?(?:above|below)', _joined(page))
    assert quoted
    missing = {q for q in quoted if not any(x.startswith(_plain(q)) for x in labels)}
    assert missing == set()


def _plain(quote: str) -> str:
    return quote.replace("`", "").lower()


def test_readme_tool_table_lists_every_tool() -> None:
    listed = {module for module, _, _ in TOOLS}
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    rows = set(re.findall(r"^\| `python -m (ddwmmr\.\w+)`", readme, flags=re.MULTILINE))
    assert len(listed) == 6
    assert rows == listed


def test_figure8_size_in_the_readme_matches_its_samples() -> None:
    path = ROOT / "trajectories" / "figure8.csv"
    points = np.loadtxt(path, delimiter=",", comments="#", skiprows=3)
    half = (np.ptp(points[:, 1]) / 2, np.ptp(points[:, 2]) / 2)
    assert half == pytest.approx((3.0, 1.5), abs=1e-3)
    pattern = r"half-widths ([\d.]+) m x ([\d.]+) m \(([\d.]+) m x ([\d.]+) m"
    # the file's own header keeps "3 m x 1.5 m" (half-widths): changing it would change the
    # file's hash, and --rerun refuses a run whose trajectory file changed
    row = next(line for line in (ROOT / "README.md").open() if line.startswith("| `figure8`"))
    numbers = [float(v) for v in re.search(pattern, row).groups()]
    assert numbers == pytest.approx([*half, 2 * half[0], 2 * half[1]], abs=1e-3)


def _api_ratios() -> dict[str, float]:
    block = (DOCS / "api.md").read_text(encoding="utf-8").split("<!-- bench:api-table begin")[1]
    rows = re.findall(r"^(pi|ats|ap|clrrmc-ts|clrrmc-cs) +(?:[\d.]+ +){3}([\d.]+)", block, re.M)
    return {name: float(ratio) for name, ratio in rows}


def test_theory_cites_the_kernel_cost_of_the_api_table() -> None:
    ratios = _api_ratios()
    four = [ratios[m] for m in ("pi", "ats", "ap", "clrrmc-ts")]
    theory = _joined(DOCS / "theory.md")
    cited = re.search(
        r"\(`python -m ddwmmr.bench`, the table in \[api.md\].*?\): ([\d.]+)-([\d.]+)"
        r" for `pi`, `ats`, `ap` and `clrrmc-ts`.*?`clrrmc-cs` ([\d.]+)",
        theory,
    )
    assert [float(v) for v in cited.groups()] == [min(four), max(four), ratios["clrrmc-cs"]]


def test_readme_and_comparing_give_the_same_cpu_time_for_make_demo() -> None:
    readme = _joined(ROOT / "README.md")
    comparing = _joined(DOCS / "comparing.md")
    demo = {float(v) for v in re.findall(r"`make demo`[^|]*?: ([\d.]+) s of CPU", readme)}
    assert len(demo) == 1
    cited = re.search(r"The first command costs about ([\d.]+) CPU-seconds", comparing)
    assert demo == {float(cited[1])}


def _mpc_tracking_row() -> list[float]:
    text = (DOCS / "mpc.md").read_text(encoding="utf-8")
    row = next(line for line in text.splitlines() if line.startswith("| **mpc** (horizon 1 s"))
    return [float(v) for v in re.findall(r"([\d.]+) (?:mm|rad)", row)]


def test_mpc_tracking_table_matches_a_run_and_its_prose() -> None:
    from ddwmmr import Robot, simulate
    from ddwmmr.trajectories import Ellipse, Rectangle

    ellipse_rms, rms, peak, orientation = _mpc_tracking_row()
    rectangle = simulate(Robot(), Rectangle(), "mpc").summary
    assert 1e3 * rectangle["rms_position_error_m"] == pytest.approx(rms, abs=0.005)
    assert 1e3 * rectangle["max_position_error_m"] == pytest.approx(peak, abs=0.05)
    assert rectangle["rms_orientation_error_rad"] == pytest.approx(orientation, abs=5e-4)
    ellipse = simulate(Robot(), Ellipse(), "mpc").summary
    assert 1e3 * ellipse["rms_position_error_m"] == pytest.approx(ellipse_rms, abs=0.005)
    page = _joined(DOCS / "mpc.md")
    assert f"{rms:.2f} mm on the rectangle and {ellipse_rms:.2f} mm on the ellipse" in page
    horizon = re.search(r"\(RK4, as `track` runs it: [\d./ ]*\*\*([\d.]+)\*\*", page)
    assert float(horizon[1]) == pytest.approx(rms, abs=0.005)
    ts_row = re.search(r"\| clrrmc-ts \| [\d.]+ mm \| ([\d.]+) mm \| ([\d.]+) mm", page)
    ratios = re.search(r"([\d.]+)x smaller RMS error than `clrrmc-ts`.*?([\d.]+)x smaller", page)
    assert float(ratios[1]) == pytest.approx(float(ts_row[1]) / rms, abs=0.05)
    assert float(ratios[2]) == pytest.approx(float(ts_row[2]) / peak, abs=0.05)


def _profile(method: str, outcome: str) -> Profile:
    return Profile(
        method=method,
        scores={"ellipse": 0.001},
        step_us=1.0,
        settle_trajectory="ellipse",
        settle_s=1.0,
        open_loop=False,
        stability_floor=None,
        stability_violations=0,
        min_stability=2.0,
        singularity={"ellipse": (outcome, 1.0)},
        min_cos_th1=0.5,
    )


def test_singularity_advice_agrees_with_one_method_or_several() -> None:
    one = _singularity_line([_profile("mpc", "passes"), _profile("qp", "away")])
    assert "`mpc` passes it and keeps the path; `qp` stays away from it" in one
    several = _singularity_line(
        [_profile(m, "passes") for m in ("mpc", "qp")] + [_profile(m, "lost") for m in ("pi", "ap")]
    )
    assert "`mpc`, `qp` pass it and keep the path" in several
    assert "avoid `pi`, `ap`: they are driven into it and lose the path" in several
    lost = _singularity_line([_profile("pi", "lost")])
    assert "avoid `pi`: it is driven into it and loses the path" in lost


def test_mpc_force_model_row_on_mujoco_matches_a_run() -> None:
    pytest.importorskip("mujoco")
    from ddwmmr import Robot, simulate
    from ddwmmr.trajectories import Ellipse

    text = (DOCS / "mpc.md").read_text(encoding="utf-8")
    row = next(line for line in text.splitlines() if line.startswith("| ellipse, 3 kg"))
    cells = [c.strip() for c in row.split("|")[2:5]]
    rms, peak = (float(v) for v in re.findall(r"[\d.]+", cells[0]))
    run = simulate(Robot().with_payload(3.0), Ellipse(), "mpc", plant="mujoco").summary
    assert 1e3 * run["rms_position_error_m"] == pytest.approx(rms, abs=0.005)
    assert 1e3 * run["max_position_error_m"] == pytest.approx(peak, abs=0.05)
    assert run["min_physics_stability"] == pytest.approx(float(cells[1]), abs=0.005)
    assert run["max_wheel_slip_m_s"] == pytest.approx(float(cells[2].split()[0]), abs=5e-4)


def test_both_euler_drifts_of_ats_name_their_measure_and_match_a_run() -> None:
    from ddwmmr import Robot, simulate
    from ddwmmr.trajectories import Ellipse

    offset = simulate(Robot(), Ellipse(), "ats", integrator="euler").timeseries
    error = np.asarray(offset["position_error_m"])
    change = 1e3 * np.abs(error - error[0]).max()
    none = simulate(Robot(), Ellipse(), "ats", integrator="euler", initial_offset=(0.0, 0.0))
    largest = 1e3 * max(none.timeseries["position_error_m"])
    theory, comparing = _joined(DOCS / "theory.md"), _joined(DOCS / "comparing.md")
    drift = re.search(
        r"initial offset by ([\d.]+) mm \(dt = 0.02 s\).*?\(the largest change", theory
    )
    assert float(drift[1]) == pytest.approx(change, abs=0.05)
    assert f"without an offset, {largest:.2f} mm at 0.02 s" in theory
    assert f"drift {largest:.2f} mm off (the largest position error of the run" in comparing
    assert f"the {float(drift[1]):g} mm of" in comparing
