"""Inputs behind mypy's None and type findings that were real: each one crashed with a
raw traceback or gave a wrong result before its fix (the findings that were only wrong
hints changed no behaviour, which the golden runs hold)."""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np
import pytest

from ddwmmr import Ellipse, registry
from ddwmmr.errors import ParameterError
from ddwmmr.model import Robot, stability
from ddwmmr.mpc.min_time import MinimumTimeProblem, ShootingModel
from ddwmmr.outputs.commit import OutputFolder
from ddwmmr.plants.base import Observation
from ddwmmr.qp.limits.stability import stability_terms_from_trig
from ddwmmr.reports.compare import CompareConfig
from ddwmmr.reports.compare.plan import tau_methods


def test_edge_gradients_of_a_rectangle_are_its_closed_form():
    # the rectangle's coefficients have no edges (S in closed form): the edge functions
    # raised AttributeError on them
    k = stability.com_coefficients(0.6, 0.5, 4.0, 3.0, 1.0, 20.0, 0.6, 0.4)
    assert k.edges is None
    th1, th2 = 0.9, -0.4
    trig = (math.sin(th1), math.cos(th1), math.sin(th1 + th2), math.cos(th1 + th2))
    lon, lat = stability.polygon_terms_gradient(k, *trig)
    closed_lon, closed_lat = stability_terms_from_trig(k, *trig)
    assert lon == pytest.approx(closed_lon, rel=1e-12)
    assert lat == pytest.approx(closed_lat, rel=1e-12)
    assert lat[0] < stability.STABILITY_CAP and lon[0] < stability.STABILITY_CAP
    assert len(stability.edge_gradients(k, *trig)) == 4


@pytest.mark.parametrize("waypoint", [(1.0,), (1.0, 2.0, 3.0), (math.nan, 1.0)])
def test_minimum_time_problem_refuses_a_waypoint_that_is_not_two_finite_numbers(waypoint):
    # (1.0,) was read as (1.0, 1.0); three numbers failed inside CasADi
    with pytest.raises(ParameterError, match=r"^waypoints\[2\] must be \(x, y\)") as info:
        MinimumTimeProblem(Robot(), [(1.0, 0.5), waypoint], np.zeros(7))
    assert "\n" not in str(info.value)


def test_shooting_model_refuses_rows_without_their_bounds():
    # FreeTimeOCP indexed the missing bounds (TypeError: 'NoneType' is not subscriptable)
    bound = np.ones(2)
    with pytest.raises(ParameterError, match=r"^node_bounds: .* with node_rows$"):
        ShootingModel(3, 2, lambda x, u: x, -bound, bound, -bound, bound, node_rows=lambda x: x)


def test_a_builtin_decorator_with_double_star_traits_is_not_literal(tmp_path, monkeypatch):
    # its traits were read under the key None
    (tmp_path / "fake.py").write_text(
        '@register_controller("fake", **{"tasks": ("tracking",)})\nclass Fake:\n    pass\n'
    )
    monkeypatch.setattr(registry, "_PACKAGE", tmp_path)
    with pytest.raises(TypeError, match="takes literal arguments only"):
        registry._read_source("ddwmmr.fake")


def test_an_output_folder_not_entered_commits_nothing(tmp_path):
    folder = OutputFolder(tmp_path / "out", "track", force=False, fresh=False)
    with pytest.raises(RuntimeError, match="only the with-block it entered"):
        folder.__exit__(None, None, None)
    assert not (tmp_path / "out").exists()


def test_study_methods_set_back_to_none_resolve_to_the_default():
    config = CompareConfig(methods=("ats", "clrrmc-cs"), trajectories={"ellipse": Ellipse()})
    config.study_methods = None  # was iterated as None: TypeError
    assert tau_methods(config) == ["clrrmc-cs"]
    assert config.study_methods == ("ats", "clrrmc-cs")


def test_an_observation_from_a_named_tuple_has_an_array_q():
    Pose = namedtuple("Pose", "x y phi th1 th2")
    observation = Observation(Pose(1.0, 2.0, 0.5, 0.25, -0.5), 0.0, 0.0)
    assert isinstance(observation.q, np.ndarray)  # was the named tuple itself
    np.testing.assert_allclose(observation.q, [1.0, 2.0, 0.5, 0.25, -0.5], rtol=0, atol=0)
    assert observation.values == (1.0, 2.0, 0.5, 0.25, -0.5)
