"""The planning base: one constructor for every planner, parameters as checked frozen dataclasses,
one angle wrap."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from vplane_mj.errors import ScenarioError
from vplane_mj.planning.protocol.base import Planner
from vplane_mj.planning.protocol.params import ParamError
from vplane_mj.planning.protocol.registry import PLANNERS, make_planner
from vplane_mj.planning.protocol.vectors import evenly_spaced, unit, wrap_angle
from vplane_mj.robots.facts import robot_radius_m
from vplane_mj.scenario import load_scenario


@pytest.mark.parametrize("name", sorted(PLANNERS))
def test_every_built_in_planner_is_a_planner_with_frozen_checked_parameters(name):
    cls = PLANNERS[name]
    assert issubclass(cls, Planner) and cls.name == name
    planner = make_planner(name, {}, robot_radius_m())
    assert isinstance(planner.params, cls.Params) and planner.radius == robot_radius_m()
    table = cls.Params.table()
    assert list(planner.params.as_dict()) == list(table)
    for key, spec in table.items():
        assert spec.check(getattr(planner.params, key)) is None
        assert isinstance(getattr(planner.params, key), int if spec.integer else float)
    with pytest.raises(dataclasses.FrozenInstanceError):
        planner.params.__setattr__(next(iter(table)), 1.0)


@pytest.mark.parametrize(
    ("overrides", "key", "reason"),
    [
        ({"influence": -1}, "influence", "must be greater than 0, got -1"),
        ({"influence": "far"}, "influence", "must be a number, got str"),
        ({"max_escapes": 2.5}, "max_escapes", "must be an integer, got 2.5"),
        ({"max_escapes": math.inf}, "max_escapes", "must be finite, got inf"),
        ({"influense": 0.5}, "influense", "not a parameter of planner 'vplane' (attract_gain, "),
    ],
)
def test_a_bad_parameter_is_refused_when_the_planner_is_built_as_the_scenario_refuses_it(
    overrides, key, reason
):
    with pytest.raises(ParamError) as built:
        make_planner("vplane", overrides, robot_radius_m())
    assert built.value.key == key and built.value.reason.startswith(reason)
    ((name, value),) = overrides.items()
    with pytest.raises(ScenarioError) as parsed:
        load_scenario("open_field", ["planner.name=vplane", f"planner.{name}={value!r}".replace("'", '"')])
    assert parsed.value.key == f"planner.{key}" and parsed.value.reason == built.value.reason


def test_integer_overrides_of_float_parameters_become_floats_and_counts_stay_integers():
    planner = make_planner("vplane", {"influence": 1, "max_escapes": 3}, robot_radius_m())
    assert planner.params.influence == 1.0 and isinstance(planner.params.influence, float)
    assert planner.params.max_escapes == 3 and isinstance(planner.params.max_escapes, int)


def test_a_planner_refuses_parameters_of_another_planner():
    with pytest.raises(TypeError, match="takes VPlaneParams"):
        PLANNERS["vplane"](PLANNERS["apf"].Params(), robot_radius_m())


def test_vplane_plus_shares_vplanes_map_parameters_with_its_own_defaults():
    plain, plus = PLANNERS["vplane"].Params.table(), PLANNERS["vplane_plus"].Params.table()
    assert (plain["map_cell_m"].default, plus["map_cell_m"].default) == (0.1, 0.05)
    assert dataclasses.replace(plus["map_cell_m"], default=0.1) == plain["map_cell_m"]
    assert list(plus)[: len(plain)] == list(plain)


def test_wrap_angle_keeps_floats_floats_and_wraps_arrays_element_by_element():
    angles = [-7.0, -math.pi, -1.0, 0.0, 3.0, math.pi, 10.0, 1e6]
    wrapped = wrap_angle(np.array(angles))
    for angle, value in zip(angles, wrapped, strict=True):
        single = wrap_angle(angle)
        assert isinstance(single, float) and single == value
        assert -math.pi <= single < math.pi and math.isclose(math.cos(single), math.cos(angle), abs_tol=1e-9)


def test_unit_has_length_one_or_is_zero():
    assert np.allclose(unit(np.array([3.0, 4.0])), [0.6, 0.8])
    assert np.all(unit(np.array([1e-15, 0.0])) == 0.0)


def test_evenly_spaced_is_numpys_linspace_bit_for_bit():
    rng = np.random.default_rng(0)
    for _ in range(20000):
        start = float(rng.uniform(-3.0, 3.0))
        stop = float(rng.choice([rng.uniform(-3.0, 3.0), start, start + 5e-324, 0.0]))
        count = int(rng.integers(0, 25))
        got, expected = evenly_spaced(start, stop, count), np.linspace(start, stop, count)
        np.testing.assert_array_equal(got, expected)
        assert got.dtype == expected.dtype
