"""The local-minimum detector: both criteria, the start and goal exemptions, hysteresis."""

import numpy as np

from vplane_mj.planning.perception.minima import LocalMinimumDetector

DT = 0.05


def feed(detector, positions, start_time=0.0, near_goal=False):
    states = []
    for i, p in enumerate(positions):
        states.append(detector.update(start_time + i * DT, np.array(p, float), near_goal))
    return states


def make():
    return LocalMinimumDetector(window_s=2.0, displacement_m=0.2, speed_mps=0.02, startup_s=1.0)


def test_steady_driving_is_never_a_minimum():
    states = feed(make(), [(0.3 * i * DT, 0.0) for i in range(400)])
    assert not any(s.trapped for s in states)


def test_standing_still_is_detected_once_after_a_full_window():
    states = feed(make(), [(0.0, 0.0)] * 200)
    new = [i for i, s in enumerate(states) if s.new]
    assert new == [40]  # 2 s window at 20 Hz, past the 1 s start-up
    assert states[-1].trapped and states[-1].trapped_for_s > 7.0


def test_oscillating_in_place_is_detected_by_displacement():
    wobble = [(0.1 * np.sin(i * 0.7), 0.05 * np.cos(i * 0.3)) for i in range(200)]
    states = feed(make(), wobble)
    assert any(s.new for s in states)


def test_turning_in_place_for_less_than_a_window_is_not_a_minimum():
    path = [(0.0, 0.0)] * 20 + [(0.3 * i * DT, 0.0) for i in range(200)]
    assert not any(s.trapped for s in feed(make(), path))


def test_no_detection_inside_the_goal_tolerance():
    assert not any(s.trapped for s in feed(make(), [(0.0, 0.0)] * 200, near_goal=True))


def test_leaving_the_trap_ends_the_episode_and_a_second_trap_counts_again():
    detector = make()
    feed(detector, [(0.0, 0.0)] * 60)
    away = feed(detector, [(0.3 * i * DT, 0.0) for i in range(60)], start_time=3.0)
    assert not away[-1].trapped
    again = feed(detector, [(0.9, 0.0)] * 60, start_time=6.0)
    assert sum(s.new for s in again) == 1
