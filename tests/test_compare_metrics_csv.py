"""compare's metrics.csv: a dict field (``mpc_options``) is a JSON cell a CSV reader can
parse; every other cell is written as before."""

from __future__ import annotations

import csv
import io
import json
import math

from ddwmmr import Ellipse, Robot, simulate
from ddwmmr.reports.compare.ranking import metrics_csv
from ddwmmr.sim.result import json_safe


def test_the_mpc_options_cell_reads_back_with_json_loads() -> None:
    """It held Python's repr (``{'model': 'kinematic', ..., 'huber': None}``), which
    json.loads refuses."""
    summary = simulate(Robot(), Ellipse(), "mpc", duration=0.1).summary
    options = summary["mpc_options"]
    assert options["model"] == "kinematic" and options["huber"] is None
    rows = [{"method": "mpc", "trajectory": "ellipse", **summary}]
    (row,) = csv.DictReader(io.StringIO(metrics_csv(rows)))
    cell = row["mpc_options"]
    assert json.loads(cell) == json_safe(options)
    # compact, keys sorted: the same options give the same text
    assert cell == json.dumps(json_safe(options), sort_keys=True, separators=(",", ":"))
    assert cell.startswith('{"arm_time_constant":') and " " not in cell


def test_a_non_finite_option_is_a_json_string_and_other_cells_keep_their_text() -> None:
    row = {
        "method": "mpc",
        "trajectory": "loop",
        "mpc_options": {"wheel_force_limit": math.inf, "route": [], "model": "kinematic"},
        "rms_position_error_m": 0.1 + 0.2,
        "max_position_error_m": math.nan,
        "tipped": False,
        "corner_position_error_m": None,
        "verdict_reasons": ["final_error_above_limit", "rms_error_above_limit"],
        "steps": 10,
    }
    text = metrics_csv([row])
    header, values = text.splitlines()
    assert header == ",".join(row)
    assert values == (
        'mpc,loop,"{""model"":""kinematic"",""route"":[],""wheel_force_limit"":""inf""}",'
        "0.30000000000000004,nan,False,,final_error_above_limit rms_error_above_limit,10"
    )
    (read,) = csv.DictReader(io.StringIO(text))
    assert json.loads(read["mpc_options"])["wheel_force_limit"] == "inf"
