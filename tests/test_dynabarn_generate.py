"""`generate_dynabarn`: worlds drawn by DynaBARN's recipe in the layout of `dynabarn_layout`, in
the ranges measured over the real 60 worlds (docs/dynabarn.md), and every
one clear of the start and the goal at every time of every loop."""

import numpy as np
import pytest

from vplane_mj.geometry.motion import Motion
from vplane_mj.scenario import parse_document
from vplane_mj.worlds.dynabarn_generate import generate_dynabarn
from vplane_mj.worlds.dynabarn_layout import DIFFICULTIES, GOAL_M, SQUARE_M, START_M

MEASURED = {
    "easy": {"obstacles": (5, 14), "mean": (0.66, 0.84), "std": (0.06, 0.17)},
    "medium": {"obstacles": (15, 19), "mean": (1.20, 1.26), "std": (0.12, 0.14)},
    "hard": {"obstacles": (20, 24), "mean": (1.69, 1.77), "std": (0.12, 0.14)},
}
"""The README's table per third: obstacles per world, mean and std of a world's keyframe-to-keyframe
speeds (m/s)."""
SLACK_M_S = 0.03
"""A measured range is itself the spread of 20 draws; 20 others may pass it by this much (m/s)."""
JACKAL_HALF_M = (0.254, 0.215)
"""Half the Jackal's footprint, 0.508 x 0.43 m, facing -x (m)."""
CLEARANCE_M = 0.55
"""Obstacle radius 0.5 m plus the 0.05 m the generator keeps (m)."""


@pytest.fixture(scope="module")
def worlds():
    """60 worlds of seed 7: 20 of each third, in DynaBARN's order."""
    return generate_dynabarn(60, 7)


def _frames(case):
    """Each obstacle's keyframes (K, 3) [t_s, x_m, y_m], arena frame."""
    return [np.array(ob["motion"]["keyframes"]) for ob in case.document["world"]["obstacles"]]


def _speeds(frames):
    """Speeds (m/s) between consecutive keyframes: distance / time."""
    steps = np.diff(frames, axis=0)
    return np.hypot(steps[:, 1], steps[:, 2]) / steps[:, 0]


def _third(worlds, difficulty):
    return [case for case in worlds if f"_{difficulty}_" in case.name]


def test_the_same_arguments_give_the_same_documents():
    first, again = generate_dynabarn(3, 11, "hard"), generate_dynabarn(3, 11, "hard")
    assert [case.document for case in first] == [case.document for case in again]
    other = generate_dynabarn(3, 12, "hard")
    assert [case.document["world"] for case in other] != [case.document["world"] for case in first]


def test_six_worlds_are_named_and_split_as_dynabarn_numbers_them():
    mixed = generate_dynabarn(6, 5)
    assert [case.name for case in mixed] == [
        "dynabarn_5_easy_000",
        "dynabarn_5_easy_001",
        "dynabarn_5_medium_002",
        "dynabarn_5_medium_003",
        "dynabarn_5_hard_004",
        "dynabarn_5_hard_005",
    ]
    easy = generate_dynabarn(6, 5, "easy")
    assert [case.name for case in easy] == [f"dynabarn_5_easy_{k:03d}" for k in range(6)]
    assert [case.document for case in easy[:2]] == [case.document for case in mixed[:2]]
    for case in mixed + easy:
        assert case.document["name"] == case.name


def test_sixty_worlds_are_dynabarns_thirds(worlds):
    assert [case.name for case in worlds] == [
        f"dynabarn_7_{DIFFICULTIES[k // 20]}_{k:03d}" for k in range(60)
    ]


def test_unknown_difficulty_is_refused():
    with pytest.raises(ValueError, match="difficulty"):
        generate_dynabarn(1, 0, "extreme")


@pytest.mark.parametrize("difficulty", DIFFICULTIES)
def test_counts_and_speeds_lie_in_the_measured_ranges(worlds, difficulty):
    measured = MEASURED[difficulty]
    means, stds = [], []
    for case in _third(worlds, difficulty):
        frames = _frames(case)
        low, high = measured["obstacles"]
        assert low <= len(frames) <= high
        speeds = np.concatenate([_speeds(f) for f in frames])
        assert ((speeds >= 0.49) & (speeds <= 1.95)).all()
        means.append(speeds.mean())
        stds.append(speeds.std())
        description = case.document["description"]
        assert difficulty in description and f"{len(frames)} moving cylinders" in description
        assert f"{speeds.mean():.2f} m/s" in description
    (low, high), (std_low, std_high) = measured["mean"], measured["std"]
    assert low <= np.mean(means) <= high
    assert low - SLACK_M_S <= min(means) and max(means) <= high + SLACK_M_S
    assert std_low - SLACK_M_S <= min(stds) and max(stds) <= std_high + SLACK_M_S


def test_keyframes_are_two_decimal_in_the_square_their_times_increasing(worlds):
    for case in worlds:
        for ob in case.document["world"]["obstacles"]:
            assert ob["kind"] == "cylinder" and ob["radius"] == 0.5
            motion = ob["motion"]
            assert motion["loop"] is True and motion["interpolation"] == "spline"
            assert motion["phase_s"] == "random"
            frames = np.array(motion["keyframes"])
            assert len(frames) >= 2
            assert np.array_equal(frames, np.round(frames, 2))
            assert ((frames[:, 1:] >= SQUARE_M[0]) & (frames[:, 1:] <= SQUARE_M[1])).all()
            assert frames[0, 0] == 0.0 and (np.diff(frames[:, 0]) > 0).all()


def _gap_to_footprint(centres, place):
    """Distance (m) from each centre to the Jackal's footprint at `place`, facing -x."""
    outside = np.maximum(np.abs(centres - np.asarray(place)) - np.asarray(JACKAL_HALF_M), 0.0)
    return np.hypot(outside[:, 0], outside[:, 1])


def test_no_obstacle_comes_near_the_start_or_the_goal_at_any_time(worlds):
    fractions = np.linspace(0.0, 1.0, 400)
    for case in worlds:
        for frames in _frames(case):
            times = (frames[:-1, :1] + fractions * np.diff(frames[:, 0])[:, None]).ravel()
            centres = Motion(tuple(map(tuple, frames)), interpolation="spline").position(times)
            for place in (START_M, GOAL_M):
                assert _gap_to_footprint(centres, place).min() >= CLEARANCE_M, case.name


def test_every_document_passes_the_scenario_parser(worlds):
    for case in worlds:
        scenario = parse_document(case.document, case.name + ".toml")
        assert len(scenario.world.moving) == len(case.document["world"]["obstacles"])
