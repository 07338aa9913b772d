"""Support polygons whose centre lies on an edge, the diamond's S_lon, the --scenarios
parser's digit cap and the support-lost warning's floors."""

import math

import numpy as np
import pytest

import ddwmmr.model.robot as robot_module
from ddwmmr import ParameterError, Robot
from ddwmmr.cli import bounds as bounds_tool
from ddwmmr.errors import MAX_SCENARIOS
from ddwmmr.model.stability import STABILITY_CAP
from ddwmmr.sim.verdict import support_warning

#: Casters at (+-0.225, 0): with the wheels at (0, +-0.175) a diamond.
DIAMOND = ((0.225, 0.0), (-0.225, 0.0))


@pytest.mark.parametrize(
    "casters",
    [
        [(0.2, 0.0)],  # one caster ahead of the axle: a triangle on the axle
        [(0.2, 0.175), (0.2, -0.175)],  # casters only in front: the axle is the back edge
    ],
)
def test_a_base_centre_on_an_edge_is_refused_saying_so(casters):
    with pytest.raises(ParameterError) as error:
        Robot(caster_positions=casters)
    message = str(error.value)
    assert message.startswith(
        "caster_positions: the base centre must lie strictly inside the support polygon of "
        "the wheels and casters, not on an edge ("
    )
    assert "\n" not in message


def test_the_polygons_edges_have_one_home_name_per_function():
    """The module function and the method of the same name are two things."""
    assert not hasattr(robot_module, "_support_edges")
    edges = robot_module._edges_of_points(((0.0, 0.175), (0.0, -0.175), *DIAMOND))
    assert edges is not None and len(edges.lat) == 4
    assert robot_module._edges_of_points(((0.0, 0.175), (0.0, -0.175), (0.2, 0.0))) is None


def test_the_diamonds_edges_all_face_sideways_so_its_s_lon_is_the_cap():
    """docs/theory.md, "Tip-over stability": normals (+-0.614, +-0.789), no front or back
    edge; S_lon reads 10 in every pose and S_lat is S, the forward reach's included."""
    robot = Robot(caster_positions=DIAMOND).with_payload(3.0)
    edges = robot.com_coefficients.edges
    assert edges.lon == ()
    for n_x, n_y, _ in edges.lat:
        assert (abs(n_x), abs(n_y)) == pytest.approx((0.614, 0.789), abs=5e-4)
    generator = np.random.default_rng(7)
    for th1, th2 in generator.uniform(-math.pi, math.pi, (200, 2)):
        s_lon, s_lat, s = robot.stability(np.array([0.0, 0.0, 0.0, th1, th2]))
        assert s_lon == STABILITY_CAP and s_lat == s
    s_lon, s_lat, s = robot.stability(np.zeros(5))  # arm stretched forward
    # the centre of mass at A + B = 0.175 m ahead reaches the front vertex (0.225, 0)
    assert s_lon == STABILITY_CAP and s == s_lat == pytest.approx(0.225 / 0.175, rel=1e-12)


@pytest.mark.parametrize("text", ["9" * 5000, "1-" + "9" * 5000, "9" * 8, "0" * 4 + "9" * 7])
def test_scenarios_with_too_many_digits_are_refused_in_one_line(text):
    """int() refuses numbers of more than 4300 digits: a raw ValueError traceback."""
    with pytest.raises(ParameterError) as error:
        bounds_tool.parse_scenarios(text)
    message = str(error.value)
    assert message.startswith(f"scenarios must lie in 1-{MAX_SCENARIOS} with first <= last")
    assert len(message) < 120


def test_scenarios_keep_leading_zeros_and_the_largest_number():
    assert bounds_tool.parse_scenarios("0007") == [7]
    assert bounds_tool.parse_scenarios(f"{MAX_SCENARIOS}") == [MAX_SCENARIOS]
    assert bounds_tool.parse_scenarios(f"0{MAX_SCENARIOS - 1}-{MAX_SCENARIOS}") == [
        MAX_SCENARIOS - 1,
        MAX_SCENARIOS,
    ]


def test_the_bounds_tool_exits_2_on_5000_digits(capsys):
    assert bounds_tool.main(["--scenarios", "9" * 5000]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("error: scenarios must lie in 1-100000") and "\n" not in err


def test_the_support_lost_warning_names_both_controllers_floors():
    """qp and mpc both take stability_min and min_edge_load."""
    text = support_warning(
        {"support_lost": True, "tipped": False, "unloaded_time_s": 0.08, "duration": 2.0}
    )
    assert text.startswith("warning: an edge of the support polygon was unloaded for 0.08 of 2 s")
    assert "a higher floor (qp's and mpc's stability_min and min_edge_load) or a slower" in text
    assert "qp's min_edge_load" not in text


def test_tipping_causes_name_the_support_polygon_and_a_refusal_says_what_to_change():
    """On a caster layout the tipping edges run through the casters: the causes say
    'support polygon', not 'the wheels'; a refused layout says where casters must go."""
    from ddwmmr.sim import verdict as v

    for cause in (v.TIPPED, v.WOULD_TIP):
        assert "outside the support polygon (the wheels and casters" in cause
        assert "outside the wheels" not in cause
    with pytest.raises(ParameterError) as info:
        Robot(caster_positions=((0.2, 0.1), (0.2, -0.1)))
    assert str(info.value).endswith("put casters on both sides of the wheel axle (x > 0 and x < 0)")


def test_the_compare_reports_robot_line_names_a_caster_layout():
    """A report of a diamond layout must not read like the default robot's."""
    from ddwmmr.reports.compare.report import _other_fields

    assert _other_fields(Robot().with_payload(3.0)) == ""
    diamond = Robot(caster_positions=((0.225, 0.0), (-0.225, 0.0)))
    assert _other_fields(diamond) == (
        "; other fields than Robot()'s: caster_positions = ((0.225, 0.0), (-0.225, 0.0))"
    )
