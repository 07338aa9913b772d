"""A decorator's trait values, and that it decorates a class, are checked when the plug-in
is registered: a misspelt task or interface would otherwise list the plug-in in no tool,
without a word, and a function fail later with an AttributeError."""

import pytest

from ddwmmr.errors import ParameterError
from ddwmmr.registry import CONTROLLERS, register_arbiter, register_controller, register_plant


@pytest.mark.parametrize(
    ("decorator", "traits", "message"),
    [
        (
            register_controller,
            {"tasks": ("track",)},
            "register_controller('mine'): tasks must be a tuple of one or more of "
            "'tracking', 'waypoints' (got ('track',))",
        ),
        (
            register_controller,
            {"tasks": "tracking"},  # a str, not a tuple of words
            "register_controller('mine'): tasks must be a tuple of one or more of "
            "'tracking', 'waypoints' (got 'tracking')",
        ),
        (
            register_controller,
            {"tasks": ()},
            "register_controller('mine'): tasks must be a tuple of one or more of "
            "'tracking', 'waypoints' (got ())",
        ),
        (
            register_controller,
            {"interfaces": ("speed",)},
            "register_controller('mine'): interfaces must be a tuple of one or more of "
            "'velocity', 'force' (got ('speed',))",
        ),
        (
            register_controller,
            {"arbiter": "yes"},
            "register_controller('mine'): arbiter must be True or False (got 'yes')",
        ),
        (
            register_plant,
            {"interfaces": ["velocity", "torque"]},
            "register_plant('mine'): interfaces must be a tuple of one or more of "
            "'velocity', 'force' (got ('velocity', 'torque'))",
        ),
    ],
)
def test_a_trait_value_of_the_wrong_kind_is_refused_naming_it(decorator, traits, message):
    with pytest.raises(ParameterError) as error:
        decorator("mine", **traits)
    assert str(error.value) == message
    assert "mine" not in CONTROLLERS.names()


def test_valid_traits_are_taken_lists_as_tuples(registered):
    class Both:
        """Both tasks, both interfaces."""

    registered(CONTROLLERS, "mine", Both, tasks=["tracking", "waypoints"], interfaces=("force",))
    assert CONTROLLERS.traits("mine") == {
        "tasks": ("tracking", "waypoints"),
        "interfaces": ("force",),
        "arbiter": False,
    }
    assert Both.interfaces == ("force",)


@pytest.mark.parametrize("thing", [lambda robot: None, object()])
def test_only_a_class_is_registered(thing):
    with pytest.raises(ParameterError, match=r"^register_controller\('mine'\) registers a class "):
        register_controller("mine")(thing)
    assert "mine" not in CONTROLLERS.names()


@pytest.mark.parametrize(
    ("decorator", "args", "traits", "message"),
    [
        (
            register_controller,
            (),
            {"taks": ("tracking",)},
            "register_controller('mine'): unknown keyword 'taks' (did you mean tasks?) "
            "(keywords: tasks, interfaces, arbiter, description)",
        ),
        (
            register_plant,
            (),
            {"interface": ("velocity",)},
            "register_plant('mine'): unknown keyword 'interface' (did you mean interfaces?) "
            "(keywords: interfaces, description)",
        ),
        (
            register_arbiter,
            (),
            {"seed": 3},
            "register_arbiter('mine'): unknown keyword 'seed' (keywords: description)",
        ),
        (
            register_controller,
            (("tracking",),),
            {},
            "register_controller('mine'): takes the name alone by position, the traits as "
            "keywords (tasks, interfaces, arbiter, description; got 2 positional arguments)",
        ),
    ],
)
def test_a_keyword_the_decorator_does_not_take_is_one_line_naming_the_allowed(
    decorator, args, traits, message
):
    """Python's own TypeError before: no suggestion, and the plug-in module's import
    failed as a TypeError of the registry."""
    with pytest.raises(ParameterError) as error:
        decorator("mine", *args, **traits)
    assert str(error.value) == message
    assert "mine" not in CONTROLLERS.names()
