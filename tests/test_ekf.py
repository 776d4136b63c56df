"""The pose a navigation stack sees (`sensors.pose = "ekf"`): the EKF over wheel odometry and a
gyro (sim.ekf, sim.odometry.FusedOdometry), the IMU in the model, and runs that use it."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from vplane_mj.scenario import parse_document
from vplane_mj.sim.ekf import GYRO_ROW, ODOMETRY_ROWS, PoseFilter
from vplane_mj.sim.loop import Run
from vplane_mj.sim.odometry import ODOMETRY_STDS
from vplane_mj.sim.world import IMU_ACCELEROMETER, IMU_GYRO, ROBOT_PREFIX, build_model
from vplane_mj.worlds.barn_protocol import generate_protocol

DT = 0.05


def drive_circle(skid: float, gyro_std: float, seconds: float = 30.0) -> tuple[PoseFilter, np.ndarray]:
    """The filter after a robot drove at 1 m/s turning at 0.5 rad/s from the origin, its odometry reading the
    turn `skid` times too fast (a skid-steer robot's encoders), its gyro the true rate with
    white noise `gyro_std`; and the true pose (x, y, yaw) then."""
    rng = np.random.default_rng(3)
    ekf = PoseFilter((0.0, 0.0, 0.0), accel_std=2.0, turn_accel_std=4.0)
    v, w = 1.0, 0.5
    ekf.state[3:] = v, w  # already under way
    for _ in range(round(seconds / DT)):
        ekf.correct(ODOMETRY_ROWS, np.array([v, skid * w]), ODOMETRY_STDS)
        ekf.correct(GYRO_ROW, np.array([w + gyro_std * rng.normal()]), np.array([max(gyro_std, 0.005)]))
        ekf.predict(DT)
    t = seconds
    truth = np.array(
        [v / w * math.sin(w * t), v / w * (1 - math.cos(w * t)), math.remainder(w * t, math.tau)]
    )
    return ekf, truth


def test_with_exact_rates_the_estimate_follows_the_arc():
    ekf, truth = drive_circle(skid=1.0, gyro_std=0.0, seconds=10.0)
    x, y, yaw = ekf.pose
    assert math.hypot(x - truth[0], y - truth[1]) < 0.01
    assert abs(math.remainder(yaw - truth[2], math.tau)) < 1e-3


def test_the_gyro_holds_the_heading_that_skidding_wheels_would_lose():
    ekf, truth = drive_circle(skid=1.27, gyro_std=0.005)
    heading_error = abs(math.remainder(ekf.pose[2] - truth[2], math.tau))
    assert math.degrees(heading_error) < 2.0  # wheels alone: 0.27 x 0.5 rad/s x 30 s = 4 rad off
    assert math.hypot(ekf.pose[0] - truth[0], ekf.pose[1] - truth[1]) < 0.2
    assert ekf.state[4] == pytest.approx(0.5, abs=0.02)  # the fused turn rate is the gyro's


def jackal_world(pose: str, index: int = 3) -> dict:
    case = generate_protocol(index + 1, 0)[index]
    document = dict(case.document)
    document["sensors"] = {**document.get("sensors", {}), "pose": pose, "noise_std": 0.01}
    document["planner"] = {"name": "vplane_plus"}
    return document


def test_only_an_ekf_world_carries_the_imu():
    ekf = build_model(parse_document(jackal_world("ekf"), "ekf.toml"), rangefinders=False)
    truth = build_model(parse_document(jackal_world("truth"), "truth.toml"), rangefinders=False)
    names = {ekf.sensor(i).name for i in range(ekf.nsensor)}
    assert {ROBOT_PREFIX + IMU_GYRO, ROBOT_PREFIX + IMU_ACCELEROMETER} <= names
    assert ekf.sensor(ROBOT_PREFIX + IMU_GYRO).type == mujoco.mjtSensor.mjSENS_GYRO
    assert not any("imu" in truth.sensor(i).name for i in range(truth.nsensor))


def run_summary(pose: str):
    run = Run(parse_document(jackal_world(pose), f"{pose}.toml"))
    return run.run().summary


def test_the_jackal_on_its_ekf_reaches_the_goal_believing_where_it_is():
    ekf, odometry = run_summary("ekf"), run_summary("odometry")
    assert ekf.success and ekf.collisions == 0
    assert 0.0 < ekf.odometry_error_m <= ekf.odometry_error_max_m < 0.3
    assert odometry.odometry_error_max_m > 2 * ekf.odometry_error_max_m  # its encoders see skids as turns


def test_the_true_pose_has_no_belief_to_err():
    summary = run_summary("truth")
    assert summary.odometry_error_m is None and summary.odometry_error_max_m is None


@pytest.mark.parametrize("pose", ["ekf", "odometry"])
def test_the_summary_measures_the_belief_of_the_final_instant(pose):
    """The run ends a tick after the pose was last sensed; the summary folds that tick's wheel
    travel in before it compares the belief with the true pose, so nothing is left to fold."""
    run = Run(parse_document(jackal_world(pose), f"{pose}.toml"))
    while run.step() is None:
        pass
    summary = run.summary()
    odometry = run.localiser.odometry
    measured = (odometry.x, odometry.y)
    run.localiser.pose(run.position, run.drive.yaw())
    assert (odometry.x, odometry.y) == measured
    assert summary.odometry_error_m == pytest.approx(math.dist(measured, run.position), abs=1e-12)
