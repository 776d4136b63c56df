"""Sensor and actuation faults: each one acts in the physics, and vplane degrades gracefully."""

import math

import mujoco
import numpy as np
import pytest

from vplane_mj.errors import ScenarioError
from vplane_mj.sim import loop as sim
from vplane_mj.sim.odometry import WheelOdometry
from vplane_mj.sim.world import ROBOT_PREFIX, build_model, standalone_xml

WHEEL_RADIUS, TRACK = 0.04, 0.15
SENSOR_FAULTS = (
    "sensors.noise_std=0.02",
    "sensors.dropout=0.1",
    "sensors.crosstalk=0.03",
    "sensors.dead=[3, 11]",
)
SENSOR_AND_ACTUATION_FAULTS = (
    *SENSOR_FAULTS,
    "robot.wheel_friction=0.7",
    "robot.motor_gain=[1.0, 0.8]",
    "robot.motor_bias_nm=[0.01, 0.0]",
)
ODOMETRY = ('sensors.pose="odometry"', "sensors.odometry_noise=0.005")


def test_odometry_integrates_straight_lines_and_turns_exactly():
    rng = np.random.default_rng(0)
    odometry = WheelOdometry((1.0, 2.0, 0.0), (0.0, 0.0), WHEEL_RADIUS, TRACK, 0.0, rng)
    assert odometry.update((10.0, 10.0)) == pytest.approx((1.4, 2.0, 0.0))
    # Wheels turning opposite ways: a turn on the spot of (right - left) / track.
    x, y, yaw = odometry.update((10.0 - 1.0, 10.0 + 1.0))
    assert (x, y) == pytest.approx((1.4, 2.0)) and yaw == pytest.approx(2 * WHEEL_RADIUS / TRACK)
    # A quarter circle of radius TRACK around the left wheel's contact point, in ten updates.
    odometry = WheelOdometry((0.0, 0.0, 0.0), (0.0, 0.0), WHEEL_RADIUS, TRACK, 0.0, rng)
    quarter = (math.pi / 2) * (1.5 * TRACK) / WHEEL_RADIUS, (math.pi / 2) * (0.5 * TRACK) / WHEEL_RADIUS
    for step in range(1, 11):
        x, y, yaw = odometry.update((quarter[1] * step / 10, quarter[0] * step / 10))
    assert (x, y, yaw) == pytest.approx((TRACK, TRACK, math.pi / 2))


def test_odometry_noise_makes_the_belief_drift_by_the_seed():
    def drift(seed):
        odometry = WheelOdometry((0, 0, 0), (0, 0), WHEEL_RADIUS, TRACK, 0.02, np.random.default_rng(seed))
        for step in range(1, 201):
            x, y, _ = odometry.update((step * 0.5, step * 0.5))
        return x, y

    assert drift(1) == drift(1) != drift(2)
    x, y = drift(1)
    assert abs(x - 200 * 0.5 * WHEEL_RADIUS) < 0.2 and 0.0 < abs(y) < 1.0


def test_faults_are_validated_with_key_and_reason(shipped):
    cases = {
        "sensors.dead=[16]": ("sensors.dead", "no sonar 16"),
        "sensors.dead=[2, 2]": ("sensors.dead", "listed twice"),
        "sensors.dead=[-1]": ("sensors.dead", "at least 0"),
        'sensors.pose="gps"': ("sensors.pose", "must be one of"),
        "sensors.crosstalk=1.0": ("sensors.crosstalk", "less than 1"),
        "robot.wheel_friction=0": ("robot.wheel_friction", "at least 0.01"),
        "robot.motor_gain=[1.0, 0.0]": ("robot.motor_gain", "greater than 0"),
        "robot.motor_gain=0.5": ("robot.motor_gain", "[left, right]"),
        "robot.motor_bias_nm=[0.0, 0.5]": ("robot.motor_bias_nm", "torque limit"),
    }
    for override, (key, fragment) in cases.items():
        with pytest.raises(ScenarioError) as error:
            shipped("open_field", override)
        assert error.value.key == key and fragment in error.value.reason, override


def _spin_wheels(model, torque, seconds=0.5):
    """Hold the robot in the air, apply the same torque command to both wheels; their speeds."""
    data = mujoco.MjData(model)
    data.qpos[2] = 1.0  # lift the robot off the floor: the wheels spin freely
    model.opt.gravity[:] = 0.0
    left, right = (model.actuator(ROBOT_PREFIX + name).id for name in ("wheel_left", "wheel_right"))
    dofs = [model.jnt_dofadr[model.joint(ROBOT_PREFIX + name).id] for name in ("wheel_left", "wheel_right")]
    data.ctrl[left] = data.ctrl[right] = torque
    mujoco.mj_step(model, data, nstep=round(seconds / model.opt.timestep))
    return data.qvel[dofs[0]], data.qvel[dofs[1]]


def test_a_weak_and_a_biased_motor_deliver_less_and_more_torque(shipped):
    healthy = _spin_wheels(build_model(shipped("open_field")), 0.01)
    assert healthy[0] == pytest.approx(healthy[1])
    weak = _spin_wheels(build_model(shipped("open_field", "robot.motor_gain=[1.0, 0.5]")), 0.01)
    assert weak[0] == pytest.approx(healthy[0], rel=0.01)
    assert weak[1] == pytest.approx(healthy[1] / 2, rel=0.05)
    biased = _spin_wheels(build_model(shipped("open_field", "robot.motor_bias_nm=[0.01, 0.0]")), 0.01)
    assert biased[0] == pytest.approx(2 * healthy[0], rel=0.05)
    assert biased[1] == pytest.approx(healthy[1], rel=0.01)


def test_the_exported_world_keeps_the_actuation_faults(shipped):
    faulty = shipped("open_field", "robot.motor_gain=[0.6, 1.0]", "robot.wheel_friction=0.3")
    model = mujoco.MjModel.from_xml_string(standalone_xml(faulty))
    assert model.actuator_gear[model.actuator(ROBOT_PREFIX + "wheel_left").id, 0] == pytest.approx(0.6)
    assert model.geom_friction[model.geom(ROBOT_PREFIX + "wheel_left").id, 0] == pytest.approx(0.3)


def test_slipping_wheels_fool_the_odometry(shipped):
    def odometry_error(friction):
        scenario = shipped(
            "single_box", 'sensors.pose="odometry"', f"robot.wheel_friction={friction}", "run.time_limit_s=8"
        )
        return sim.run_scenario(scenario).summary.odometry_error_m

    grippy, slippery = odometry_error(1.0), odometry_error(0.05)
    assert grippy < 0.05
    assert slippery > 3 * grippy


@pytest.mark.parametrize("name", ["paper_c_escape", "paper_h_escape"])
def test_vplane_escapes_the_paper_traps_with_every_sensor_and_actuation_fault(shipped, name):
    summary = sim.run_scenario(shipped(name, *SENSOR_AND_ACTUATION_FAULTS)).summary
    assert summary.outcome == "reached" and summary.success, summary
    assert summary.escapes >= 1 and summary.path_ratio < 2.5


def test_vplane_escapes_on_odometry_alone_with_every_sensor_fault_on(shipped):
    summary = sim.run_scenario(shipped("paper_h_escape", *SENSOR_FAULTS, *ODOMETRY)).summary
    assert summary.outcome == "reached" and summary.success, summary
    assert 0.0 < summary.odometry_error_m < 0.15


def test_with_every_fault_on_the_ekf_holds_the_pose_that_odometry_alone_loses(shipped):
    # Slipping wheels and a weak, biased motor turn the robot in ways its encoders do not see.
    def run(pose):
        faults = (*SENSOR_AND_ACTUATION_FAULTS, f'sensors.pose="{pose}"', "sensors.odometry_noise=0.005")
        return sim.run_scenario(shipped("paper_h_escape", *faults)).summary

    fused, dead_reckoned = run("ekf"), run("odometry")
    assert fused.outcome == "reached" and fused.success, fused
    assert fused.odometry_error_m < 0.15 < dead_reckoned.odometry_error_m


def test_a_robot_lost_by_its_odometry_stops_as_stuck_with_the_reason(shipped):
    scenario = shipped("open_field", 'sensors.pose="odometry"', "sensors.odometry_noise=0.3")
    summary = sim.run_scenario(scenario).summary
    assert summary.outcome == "stuck"
    assert "odometry has put the robot at the goal" in summary.message
    assert summary.final_distance_to_goal_m > 0.15 and summary.sim_time_s < 60
