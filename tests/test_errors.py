"""The one "did you mean" of every message about an unknown name."""

from vplane_mj.errors import closest, did_you_mean

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
