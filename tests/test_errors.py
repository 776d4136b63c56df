"""The one "did you mean" of every message about an unknown name, and how messages show what
came from outside."""

import os
import pickle

from vplane_mj.errors import ScenarioError, WorldFileError, closest, cut, did_you_mean, readable, shown
from vplane_mj.planning.protocol.params import ParamError

PLANNERS = ["apf", "bug2", "dwa", "vfh", "vobs", "vplane", "vplane_plus"]


def test_the_closest_known_name_is_suggested():
    assert closest("vplan", PLANNERS) == "vplane"
    assert closest("vplane_pls", PLANNERS) == "vplane_plus"
    assert closest("gaol", ["start", "goal", "goal_tolerance"]) == "goal"
    assert closest("VPlane", PLANNERS) == "vplane"  # case aside


def test_nothing_is_suggested_when_nothing_is_close_or_the_name_is_known():
    assert closest("os:system", PLANNERS) is None
    assert closest("vplane", PLANNERS) is None
    assert closest("anything", []) is None
    assert did_you_mean("zzzz", PLANNERS) == ""
    assert did_you_mean("dwaa", PLANNERS) == "; did you mean 'dwa'?"


def test_a_path_that_is_not_utf8_or_not_printable_is_shown_with_escapes():
    assert readable(os.fsdecode(b"worlds/w\xff.world")) == "worlds/w\\xff.world"
    assert readable("a\nb\x1b[31m") == "a\\nb\\x1b[31m"
    assert readable("\ud800 caf\u00e9") == "\\ud800 caf\u00e9"  # a surrogate of no byte; printable text kept


def test_a_long_name_is_cut_with_its_length():
    assert shown("crate") == "'crate'" and cut("crate") == "crate"
    assert shown("x" * 81) == "'" + "x" * 80 + "'... (81 characters)"
    assert cut("y" * 100) == "y" * 80 + "... (100 characters)"
    assert shown("a\x00") == "'a\\x00'"


def test_the_errors_with_arguments_cross_a_process_boundary():
    # A process pool's worker sends its exception back pickled: one that cannot be rebuilt
    # breaks the pool instead of reaching the user's message.
    for error in (
        ScenarioError("a.toml", "robot.goal", "inside an obstacle"),
        ScenarioError("a.toml", "planner.x", "unknown", origin="--set planner.x=1"),
        WorldFileError("w.world", "model[2]", "no geometry"),
        ParamError("gain", "must be positive"),
    ):
        copy = pickle.loads(pickle.dumps(error))
        assert type(copy) is type(error) and str(copy) == str(error) and vars(copy) == vars(error)
