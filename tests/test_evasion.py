"""Evasion of moving tracks: the time-indexed check of motions (kernels.evasion), the ranking that
picks a motion clear of a crossing obstacle, the governor that drives it, dwa's arcs against
tracks, and in physics a Jackal that lets a crossing cylinder pass."""

import math

import numpy as np
import pytest

from vplane_mj.kernels.motion import evasion as kernels
from vplane_mj.planning.motion import evasion as ranking_terms
from vplane_mj.planning.motion.evasion import Evasion
from vplane_mj.planning.perception.tracker import Track
from vplane_mj.planning.planners.groups import MotionParams
from vplane_mj.planning.protocol.types import Observation
from vplane_mj.robots.facts import robot_body
from vplane_mj.scenario import parse_scenario
from vplane_mj.sim.loop import Run

JACKAL = robot_body("jackal", "laser")
EVASION = Evasion(JACKAL, horizon_s=3.0, margin_m=0.15, growth_mps=0.15)


def track(x: float, y: float, vx: float, vy: float, moving: bool = True, radius: float = 0.5) -> Track:
    return Track(
        track_id=1,
        position=np.array([x, y]),
        velocity=np.array([vx, vy]),
        radius_m=radius,
        position_std_m=0.01,
        velocity_std_mps=0.02,
        first_seen_s=0.0,
        last_seen_s=0.0,
        moving=moving,
        stamp_s=0.0,
    )


def observation(tracks: tuple[Track, ...], speed: float = 1.5) -> Observation:
    """The Jackal at the origin heading +x at `speed`, its goal 10 m ahead, no echoes."""
    bearings = np.linspace(-2.3, 2.3, 720)
    return Observation(
        0.0, np.zeros(2), 0.0, np.array([10.0, 0.0]), 1.0, bearings, np.full(720, np.nan), 0.0064,
        (speed, 0.0), tracks,
    )  # fmt: skip


CROSSING = track(3.0, -3.0, 0.0, 1.5)
"""A cylinder 3 m ahead and 3 m to the right, crossing the robot's line at 1.5 m/s: where a
robot at 1.5 m/s straight ahead will be when it gets there."""


def test_a_straight_motion_meets_the_crossing_cylinder_and_a_slower_one_does_not():
    threat = EVASION.threat(np.zeros(2), (CROSSING,), 0.0)
    candidates = np.array([[1.5, 0.0, 3.0], [0.3, 0.0, 3.0]])  # held all the horizon
    risks = EVASION.risks(candidates, (0.0, 0.0, 0.0), (1.5, 0.0), threat, np.array([10.0, 0.0]))
    assert 1.0 < risks[0, 0] < 2.5  # meets it about when both reach the crossing
    assert math.isinf(risks[1, 0])  # lets it pass first
    assert tuple(risks[0, 3:5]) == (1.5, 0.0)  # the command


def test_a_dodge_resumes_toward_the_aim():
    # Held for half a second, then the heading controller makes for the aim: a turn away first
    # still ends up nearer the aim than where it started, unlike the same turn held throughout.
    candidates = np.array([[1.5, 1.5, 0.5], [1.5, 1.5, 3.0]])
    no_threat = EVASION.threat(np.zeros(2), (), 0.0)
    risks = EVASION.risks(candidates, (0.0, 0.0, 0.0), (1.5, 0.0), no_threat, np.array([10.0, 0.0]))
    assert risks[0, 2] > 2.5 > risks[1, 2]


def test_tracks_that_stand_still_or_cannot_reach_the_robot_are_no_threat():
    far = track(40.0, 0.0, -1.0, 0.0)
    assert not EVASION.threat(np.zeros(2), (track(2.0, 0.0, 0.0, 0.0, moving=False), far), 0.0)
    assert EVASION.threat(np.zeros(2), (CROSSING,), 0.0)


def test_the_ranking_picks_a_clear_motion_that_still_makes_progress():
    threat = EVASION.threat(np.zeros(2), (CROSSING,), 0.0)
    candidates = EVASION.candidates((1.5, 0.0))
    risks = EVASION.risks(candidates, (0.0, 0.0, 0.0), (1.5, 0.0), threat, np.array([10.0, 0.0]))
    assert not math.isinf(risks[0, 0])  # the command asked for meets it
    best = EVASION.ranking(candidates, risks)[0]
    assert math.isinf(risks[best, 0])
    assert risks[best, 2] > 1.0  # gets on toward the goal, not away from it


def random_tracks(seed: int, count: int, spread_m: float) -> np.ndarray:
    """`count` tracks as the check takes them (x, y within `spread_m` of the origin, up to 2
    m/s each way, radius 0.5 m, growth 0.15 m/s), drawn from `seed`."""
    rng = np.random.default_rng(seed)
    return np.column_stack(
        (
            rng.uniform(-spread_m, spread_m, (count, 2)),
            rng.uniform(-2, 2, (count, 2)),
            np.full(count, 0.5),
            np.full(count, 0.15),
        )
    )


def check_arguments(tracks: np.ndarray) -> tuple:
    """The compiled check's arguments after the candidates and before the room cap: the Jackal
    at the origin heading 0.3 rad at 1 m/s and 0.2 rad/s, its limits, a 3 s horizon in 0.1 s
    steps, `tracks`, a 0.15 m margin, the aim 10 m ahead and the first second."""
    limits = JACKAL.limits
    return (
        (0.0, 0.0, 0.3), (1.0, 0.2),
        (limits.max_speed_mps, limits.max_turn_rate_radps, limits.max_accel_mps2,
         limits.braking_in_turn_mps2, limits.max_turn_accel_radps2, JACKAL.gains.turn_gain),
        (3.0, 0.1), np.ascontiguousarray(JACKAL.footprint, float), float(JACKAL.radius_m), tracks,
        0.15, (10.0, 0.0), 1.0,
    )  # fmt: skip


def test_the_room_cap_skips_only_gaps_the_ranking_does_not_count():
    # Gaps beyond the cap are pruned in the kernel; every column the ranking reads must equal
    # what the uncapped check gives: the meeting, the progress, the command, the room up to the
    # cap and any overlap within the first second. Two draws of four crossing tracks give gaps
    # below and above the cap, and overlaps.
    least, near = [], []
    for seed in (1, 4):
        args = (EVASION.candidates((1.5, 0.3)), *check_arguments(random_tracks(seed, 4, 8.0)))
        capped, full = kernels.candidate_risks(*args, 1.0), kernels.candidate_risks(*args, math.inf)
        assert np.array_equal(capped[:, [0, 2, 3, 4]], full[:, [0, 2, 3, 4]])
        assert np.array_equal(np.minimum(capped[:, 1], 1.0), np.minimum(full[:, 1], 1.0))
        assert np.array_equal(np.minimum(capped[:, 5], 0.0), np.minimum(full[:, 5], 0.0))
        least += full[:, 1].tolist()
        near += full[:, 5].tolist()
    assert min(least) < 0.0 and any(0.3 < gap < 1.0 for gap in least) and max(least) > 1.0
    assert min(near) < 0.0


def test_a_candidate_that_follows_the_one_before_gets_what_it_gets_alone():
    # A candidate with the command of the one before, held as long or longer, starts from that
    # one's motion at the end of its hold (or where it stopped): every row must equal the row of
    # the candidate checked alone, bit for bit. The grid's pairs (held 0.5 and 1.5 s), and pairs
    # held 1.5 and 3 s, some of whose first meets a track within its hold and stops there.
    grid = EVASION.candidates((1.5, 0.3))
    assert (grid[1::2, :2] == grid[2::2, :2]).all()
    longer = np.repeat(grid[1::2], 2, axis=0)
    longer[:, 2] = np.tile([1.5, 3.0], len(longer) // 2)
    for seed, candidates in ((2, grid), (5, grid), (2, longer)):
        rest = (*check_arguments(random_tracks(seed, 6, 4.0)), 1.0)
        together = kernels.candidate_risks(candidates, *rest)
        alone = np.vstack(
            [kernels.candidate_risks(candidates[c : c + 1], *rest) for c in range(len(candidates))]
        )
        assert np.array_equal(together, alone)
        assert np.isinf(together[:, 0]).any() and (together[:, 0] < 1.5).any()


def test_the_ranking_orders_by_the_score_and_keeps_equal_scores_in_order():
    # The compiled ranking against the score its docstring states, in numpy: random risks, a
    # third of them meeting no track, three equal rows (equal scores keep their order) and the
    # last evasion's command kept.
    rng = np.random.default_rng(3)
    candidates = EVASION.candidates((1.0, 0.5))
    n = len(candidates)
    meet = np.where(rng.random(n) < 0.3, math.inf, rng.uniform(0.0, 3.0, n))
    risks = np.column_stack(
        (
            meet,
            rng.uniform(-0.5, 2.0, n),
            rng.uniform(-1.0, 6.0, n),
            candidates[:, :2],
            rng.uniform(-0.3, 1.0, n),
        )
    )
    risks[20] = risks[30] = risks[10]
    evasion = Evasion(JACKAL, horizon_s=3.0, margin_m=0.15, growth_mps=0.15)
    evasion.kept = (float(candidates[40, 0]), float(candidates[40, 1]))
    t = ranking_terms
    soon = 1.0 - np.minimum(risks[:, 0], 3.0) / 3.0
    score = (
        risks[:, 2] / (JACKAL.limits.max_speed_mps * 3.0)
        + t.ROOM_WEIGHT * np.clip(risks[:, 1], 0.0, t.ROOM_CAP_M) / t.ROOM_CAP_M
        - t.HIT_WEIGHT * soon**t.HIT_EXPONENT
        - t.DEPTH_WEIGHT * np.maximum(0.0, -risks[:, 5])
    )
    kept = score + t.KEEP_BONUS * np.all(candidates[:, :2] == evasion.kept, axis=1)
    order = list(evasion.ranking(candidates, risks))
    assert order == list(np.argsort(-kept, kind="stable"))
    assert order.index(10) < order.index(20) < order.index(30)
    evasion.kept = None
    assert list(evasion.ranking(candidates, risks)) == list(np.argsort(-score, kind="stable"))


def test_a_robot_already_in_the_way_gets_out_rather_than_on():
    # The cylinder is about to hit the robot's right side: every motion meets it at once; the
    # chosen one must take the robot away from it (left or back), not on across its path.
    beside = track(0.2, -1.05, 0.0, 1.0)
    threat = EVASION.threat(np.zeros(2), (beside,), 0.0)
    candidates = EVASION.candidates((1.5, 0.0))
    risks = EVASION.risks(candidates, (0.0, 0.0, 0.0), (0.5, 0.0), threat, np.array([10.0, 0.0]))
    best = EVASION.ranking(candidates, risks)[0]
    assert risks[best, 5] > np.median(risks[:, 5])  # more room in the first second than most


def test_the_compiled_arcs_meet_a_track_where_a_plain_simulation_does():
    commands = np.array([[1.5, 0.0], [1.0, 0.5], [0.0, 2.0], [0.5, -1.0]])
    tracks = np.array([[3.0, -3.0, 0.0, 1.5, 0.5, 0.0], [1.5, 1.5, 0.0, -0.2, 0.4, 0.1]])
    hits = kernels.arc_hits(
        commands, (0.0, 0.0, 0.0), (3.0, 0.1), JACKAL.footprint, JACKAL.radius_m, tracks, 0.1
    )
    for command, hit in zip(commands, hits, strict=True):
        expected = math.inf
        for step in range(1, 31):
            t = step * 0.1
            v, w = command
            yaw = w * t
            x, y = (v / w * math.sin(yaw), v / w * (1 - math.cos(yaw))) if w else (v * t, 0.0)
            for tx, ty, vx, vy, r, g in tracks:
                ox, oy = tx + vx * t - x, ty + vy * t - y
                local = (math.cos(yaw) * ox + math.sin(yaw) * oy, -math.sin(yaw) * ox + math.cos(yaw) * oy)
                dx = max(abs(local[0]) - 0.254, 0.0)
                dy = max(abs(local[1]) - 0.215, 0.0)
                inside = abs(local[0]) <= 0.254 and abs(local[1]) <= 0.215
                gap = (-1.0 if inside else math.hypot(dx, dy)) - r - g * t
                if gap < 0.1:
                    expected = min(expected, t)
            if math.isfinite(expected):
                break
        assert hit == pytest.approx(expected)


def test_the_governor_changes_a_command_that_runs_into_a_crossing_cylinder():
    governor = MotionParams().governor(JACKAL)
    force = np.array([1.0, 0.0])
    clear = governor.steer(force, observation(()), np.empty((0, 2)))
    governor = MotionParams().governor(JACKAL)
    evaded = governor.steer(force, observation((CROSSING,)), np.empty((0, 2)))
    assert clear.command is not None and evaded.command is not None
    assert evaded.command != clear.command


CROSSING_SCENARIO = """
format = 1
name = "crossing"
[world]
size = [12.0, 8.0]
[[world.obstacles]]
kind = "cylinder"
radius = 0.5
[world.obstacles.motion]
keyframes = [[0.0, 6.0, 7.5], [6.0, 6.0, 0.5]]
loop = false
interpolation = "linear"
phase_s = 0.3
[robot]
profile = "jackal"
start = [1.0, 4.0]
start_yaw_deg = 0
goal = [11.0, 4.0]
[planner]
name = "apf"
"""
"""A cylinder that crosses the Jackal's straight line to the goal at 1.17 m/s, timed to meet a
robot that drives straight on at its top speed (at x = 6 m after some 3 s)."""


@pytest.mark.slow
def test_a_jackal_lets_a_crossing_cylinder_pass_and_reaches_the_goal_without_a_collision():
    evading = Run(parse_scenario(CROSSING_SCENARIO, "crossing.toml")).run().summary
    assert evading.reached and evading.collisions == 0
    assert evading.min_clearance_moving_m > 0.05
    # The same run with a check too short to see it coming (0.1 s) runs into it.
    blind = parse_scenario(CROSSING_SCENARIO, "crossing.toml", ["planner.evade_horizon_s=0.1"])
    assert Run(blind).run().summary.collisions > 0
