"""The robot profiles: their models compile in the arena, carry the published numbers, stay
inside their outlines, and drive to their top speed and turn rate in a bare MuJoCo loop."""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass

import mujoco
import numpy as np
import pytest

from vplane_mj.errors import VPlaneError
from vplane_mj.files import model_path
from vplane_mj.planning.protocol.body import RobotBody
from vplane_mj.robots.facts import (
    BASE_BODY,
    WHEEL_JOINTS,
    WHEEL_MOTORS,
    read_robot_facts,
    robot_body,
    robot_facts,
    robot_geometry,
    robot_radius_m,
)
from vplane_mj.robots.profiles import (
    DRIVES,
    PROFILES,
    ControllerGains,
    ProfileError,
    RobotProfile,
    robot_profile,
)
from vplane_mj.sim.control import WheelPI, wheel_targets

PREFIX = "robot/"
OUTLINE_TOLERANCE_M = 1e-6
"""Geoms may touch the outline; the models' numbers are written to 9 decimals."""
RIM_SAMPLES = 73
NAMES = list(PROFILES)
REAL = [name for name in NAMES if PROFILES[name].footprint_m is not None]


def attached_model(profile: RobotProfile) -> mujoco.MjModel:
    """The profile's model in the arena, attached by a free joint under "robot/" as the world
    builder attaches the default robot."""
    arena = mujoco.MjSpec.from_file(str(model_path("arena.xml")))
    robot = mujoco.MjSpec.from_file(str(model_path(profile.model_file)))
    mount = arena.worldbody.add_body(name=PREFIX, pos=[0.0, 0.0, 0.0])
    mount.add_freejoint(name=PREFIX)
    arena.attach(robot, prefix=PREFIX, frame=mount.add_frame())
    return arena.compile()


def projected_outline(model: mujoco.MjModel, data: mujoco.MjData, geom: int) -> np.ndarray:
    """Points (n, 2) of the geom's outline seen from above: box corners, rim circles of a
    cylinder, the equator of a sphere (its widest horizontal circle about its centre)."""
    pos, rot, size = data.geom_xpos[geom], data.geom_xmat[geom].reshape(3, 3), model.geom_size[geom]
    ring = np.linspace(0.0, 2 * math.pi, RIM_SAMPLES)
    kind = model.geom_type[geom]
    if kind == mujoco.mjtGeom.mjGEOM_SPHERE:
        return pos[:2] + size[0] * np.column_stack((np.cos(ring), np.sin(ring)))
    if kind == mujoco.mjtGeom.mjGEOM_CYLINDER:
        rim = np.column_stack((size[0] * np.cos(ring), size[0] * np.sin(ring)))
        local = np.vstack([np.column_stack((rim, np.full(len(rim), z))) for z in (-size[1], size[1])])
    else:
        assert kind == mujoco.mjtGeom.mjGEOM_BOX
        local = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * size
    return (pos + local @ rot.T)[:, :2]


def outside_distance(polygon: np.ndarray, points: np.ndarray) -> np.ndarray:
    """How far (m) each point lies outside a convex CCW polygon (<= 0 inside)."""
    starts, ends = polygon, np.roll(polygon, -1, axis=0)
    edges = ends - starts
    normals = np.column_stack((edges[:, 1], -edges[:, 0])) / np.linalg.norm(edges, axis=1)[:, None]
    offsets = (points[:, None, :] - starts[None, :, :]) @ np.eye(2)
    return np.max(np.einsum("pkd,kd->pk", offsets, normals), axis=1)


def turns(polygon: np.ndarray) -> np.ndarray:
    """The cross product at each vertex of a polygon: all > 0 for a convex CCW polygon."""
    before, after = polygon - np.roll(polygon, 1, axis=0), np.roll(polygon, -1, axis=0) - polygon
    return before[:, 0] * after[:, 1] - before[:, 1] * after[:, 0]


def test_profiles_are_named_by_their_keys_and_unknown_names_are_refused():
    assert NAMES == ["default", "jackal", "pioneer3dx", "turtlebot3_burger"]
    for name, profile in PROFILES.items():
        assert profile.name == name
        assert profile.drive in DRIVES
        assert profile.sources
        if profile.drive == "differential":
            assert profile.track_scale == 1.0
    assert robot_profile("jackal") is PROFILES["jackal"]
    known = "known: default, jackal, pioneer3dx, turtlebot3_burger"
    with pytest.raises(ProfileError, match=f"^unknown robot profile 'husky'; {known}$"):
        robot_profile("husky")
    suggestion = "did you mean 'jackal'\\?"
    with pytest.raises(ProfileError, match=f"^unknown robot profile 'jackl'; {known}; {suggestion}$"):
        robot_profile("jackl")


@pytest.mark.parametrize("lookup", [robot_facts, robot_geometry, robot_radius_m, robot_body])
def test_a_profile_named_from_outside_is_looked_up_with_a_suggestion(lookup):
    with pytest.raises(ProfileError, match="did you mean 'pioneer3dx'") as raised:
        lookup("pioneer3d")
    assert isinstance(raised.value, VPlaneError) and not isinstance(raised.value, KeyError)


def test_the_default_profile_is_todays_robot_exactly():
    default = PROFILES["default"]
    assert default.model_file == "robot.xml"
    assert default.footprint_m is None and default.sonar_mounts is None
    assert default.gains == ControllerGains()
    assert dict(default.sensors) == {
        "kind": "sonar",
        "count": 16,
        "rays_per_sonar": 3,
        "beam_deg": 20.0,
        "range_max": 3.0,
        "rate_hz": 20.0,
    }
    assert default.sensor_height_m == 0.07
    facts = robot_facts()
    assert (default.wheel_radius_m, default.track_m) == (facts.wheel_radius_m, facts.track_m)
    assert (default.limits.max_speed_mps, default.limits.max_turn_rate_radps) == (0.5, 2.5)
    assert (default.gains.speed_gain, default.gains.turn_gain) == (0.5, 3.0)
    # A planner built from the robot's radius alone plans for this robot's drive and controller.
    bare = RobotBody.round(robot_radius_m())
    assert (bare.limits, bare.gains) == (robot_body().limits, robot_body().gains)


@pytest.mark.parametrize("name", NAMES)
def test_every_model_compiles_in_the_arena_with_the_conventions_the_code_relies_on(name):
    profile = PROFILES[name]
    model = attached_model(profile)
    base = model.body(PREFIX + BASE_BODY).id
    assert model.body_subtreemass[base] == pytest.approx(profile.mass_kg, abs=1e-9)
    for joint, motor in zip(WHEEL_JOINTS, WHEEL_MOTORS, strict=True):
        assert model.geom(PREFIX + joint).bodyid == model.joint(PREFIX + joint).bodyid
        actuator = model.actuator(PREFIX + motor)
        assert actuator.trnid[0] == model.joint(PREFIX + joint).id
        assert actuator.forcelimited and actuator.forcerange[1] > 0
    tyres = [g for g in range(model.ngeom) if model.geom_priority[g] == 1 and model.geom_condim[g] != 1]
    assert {float(model.geom_friction[g][0]) for g in tyres} == {profile.wheel_friction}
    if profile.sensors["kind"] == "laser":
        site = model.site(PREFIX + "laser")
        assert site.bodyid == base
        assert site.pos == pytest.approx([0.0, 0.0, profile.sensor_height_m], abs=1e-12)


@pytest.mark.parametrize("name", NAMES)
def test_the_facts_read_from_each_model_are_the_published_numbers(name):
    profile = PROFILES[name]
    facts = read_robot_facts(model_path(profile.model_file))
    assert facts.wheel_radius_m == profile.wheel_radius_m
    assert facts.track_m == profile.track_m
    assert facts.torque_limit_nm > 0
    if profile.footprint_m is not None:
        assert facts.radius_m == pytest.approx(profile.footprint_radius_m(), abs=OUTLINE_TOLERANCE_M)


@pytest.mark.parametrize("name", REAL)
def test_every_geom_lies_inside_the_footprint_and_reaches_it(name):
    profile = PROFILES[name]
    polygon = np.array(profile.footprint_m)
    assert np.all(turns(polygon) > 0), "the footprint is convex and counter-clockwise"
    model = attached_model(profile)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    origin = data.xpos[model.body(PREFIX + BASE_BODY).id][:2]
    points = np.vstack(
        [projected_outline(model, data, g) - origin for g in range(model.ngeom) if model.geom_bodyid[g] != 0]
    )
    assert np.max(outside_distance(polygon, points)) <= OUTLINE_TOLERANCE_M
    # The geoms fill the outline out to its farthest vertex.
    reach = np.max(np.hypot(points[:, 0], points[:, 1]))
    assert reach == pytest.approx(profile.footprint_radius_m(), abs=OUTLINE_TOLERANCE_M)


def test_the_pioneer_outline_is_the_hull_of_its_top_plate_and_wheels_and_its_sonars_sit_on_it():
    profile = PROFILES["pioneer3dx"]
    polygon = np.array(profile.footprint_m)
    plate_left = [(0.174, 0), (0.166, 0.056), (0.145, 0.107), (0.112, 0.155), (0.064, 0.19), (-0.074, 0.19)]
    plate_left += [(-0.096, 0.16), (-0.151, 0.16), (-0.2, 0.155), (-0.236, 0.107), (-0.256, 0.056)]
    plate_left += [(-0.264, 0.0)]
    half_width = 0.165 + 0.024
    wheels = [(sx * profile.wheel_radius_m, sy * half_width) for sx in (-1, 1) for sy in (-1, 1)]
    sources = np.array(plate_left + [(x, -y) for x, y in plate_left] + wheels)
    assert np.max(outside_distance(polygon, sources)) <= 1e-12
    assert all(any(np.allclose(vertex, point) for point in sources) for vertex in polygon)
    mounts = np.array(profile.sonar_mounts)
    assert len(mounts) == profile.sensors["count"] == 16
    assert np.max(outside_distance(polygon, mounts[:, :2])) < 0
    front = mounts[:8, 2]
    assert list(front) == [90, 50, 30, 10, -10, -30, -50, -90]
    rear = mounts[8:, 2]  # numbered on around the back: the front array mirrored
    assert list(np.mod(rear, 360)) == list(np.mod(180 - front[::-1], 360))


@dataclass(frozen=True)
class Run:
    """A drive from standing: times (s), body speed (m/s), yaw rate (rad/s), left wheel rate
    (rad/s), position (x, y in m), and the physics time per step (s)."""

    time: np.ndarray
    speed: np.ndarray
    yaw_rate: np.ndarray
    wheel_rate: np.ndarray
    x: np.ndarray
    y: np.ndarray
    step_cost_s: float

    def rise(self, signal: np.ndarray, target: float) -> tuple[float, float]:
        """Mean acceleration between 10 % and 90 % of `target`, and the time to 95 % of it."""
        reached = [np.flatnonzero(signal >= f * target)[0] for f in (0.1, 0.9, 0.95)]
        low, high, top = reached
        return (signal[high] - signal[low]) / (self.time[high] - self.time[low]), float(self.time[top])

    def steady(self, signal: np.ndarray) -> float:
        """The signal's mean over the last half of the run."""
        return float(np.mean(signal[len(signal) // 2 :]))


def drive_from_standing(
    profile: RobotProfile,
    speed: float,
    turn: float,
    ramp: bool,
    seconds: float,
    stop_s: float = math.inf,
    then: tuple[float, float] = (0.0, 0.0),
) -> Run:
    """Command (speed m/s, turn rad/s) from standing, ramped at the profile's accelerations or
    stepped (as today's drive does), through a wheel-speed PI loop per side at the motor rate
    (as vplane_mj.sim.drive runs it), the wheel targets from the track times the track_scale;
    from `stop_s` (s) on, command `then` (a stop by default)."""
    model = attached_model(profile)
    data = mujoco.MjData(model)
    gains, limits = profile.gains, profile.limits
    facts = read_robot_facts(model_path(profile.model_file))
    steps = round(1.0 / (gains.motor_rate_hz * model.opt.timestep))
    dt = steps * model.opt.timestep
    dofs = [model.jnt_dofadr[model.joint(PREFIX + joint).id] for joint in WHEEL_JOINTS]
    motors = [model.actuator(PREFIX + motor).id for motor in WHEEL_MOTORS]
    loops = [WheelPI(gains.wheel_kp, gains.wheel_ki, facts.torque_limit_nm) for _ in motors]
    base = model.body(PREFIX + BASE_BODY).id
    commanded = (0.0, 0.0)
    trace = []
    started = time.perf_counter()
    for _ in range(round(seconds / dt)):
        wanted = (speed, turn) if data.time < stop_s else then
        if ramp:
            dv, dw = limits.max_accel_mps2 * dt, limits.max_turn_accel_radps2 * dt
            commanded = (
                commanded[0] + float(np.clip(wanted[0] - commanded[0], -dv, dv)),
                commanded[1] + float(np.clip(wanted[1] - commanded[1], -dw, dw)),
            )
        else:
            commanded = wanted
        targets = wheel_targets(
            *commanded, facts.track_m * profile.track_scale, facts.wheel_radius_m, gains.max_wheel_speed
        )
        for loop, motor, dof, target in zip(loops, motors, dofs, targets, strict=True):
            data.ctrl[motor] = loop.torque(target, float(data.qvel[dof]), dt)
        mujoco.mj_step(model, data, steps)
        yaw = math.atan2(data.xmat[base][3], data.xmat[base][0])
        forward = data.qvel[0] * math.cos(yaw) + data.qvel[1] * math.sin(yaw)
        trace.append((data.time, forward, data.qvel[5], data.qvel[dofs[0]], data.qpos[0], data.qpos[1]))
    cost = (time.perf_counter() - started) / (len(trace) * steps)
    columns = np.array(trace).T
    return Run(*columns, step_cost_s=cost)


@pytest.mark.parametrize("name", NAMES)
def test_each_robot_reaches_its_top_speed_at_its_acceleration_without_wheel_spin(name):
    profile = PROFILES[name]
    top = profile.limits.max_speed_mps
    run = drive_from_standing(profile, top, 0.0, ramp=profile.ramped, seconds=3.0)
    assert run.steady(run.speed) == pytest.approx(top, rel=0.01)
    accel, _ = run.rise(run.speed, top)
    assert accel == pytest.approx(profile.limits.max_accel_mps2, rel=0.15)
    # The motors deliver at least that with the commands stepped, on rolling tyres.
    stepped = drive_from_standing(profile, top, 0.0, ramp=False, seconds=3.0)
    assert stepped.rise(stepped.speed, top)[0] >= 0.9 * profile.limits.max_accel_mps2
    rim = stepped.wheel_rate * profile.wheel_radius_m
    assert np.max(np.abs(rim - stepped.speed)) <= 0.05 * top, "a tyre spun"


@pytest.mark.parametrize("name", NAMES)
def test_each_robot_turns_in_place_at_its_top_turn_rate(name):
    profile = PROFILES[name]
    top = profile.limits.max_turn_rate_radps
    run = drive_from_standing(profile, 0.0, top, ramp=profile.ramped, seconds=4.0)
    assert run.steady(run.yaw_rate) == pytest.approx(top, rel=0.10)
    assert abs(run.steady(run.speed)) < 0.1 * profile.limits.max_speed_mps
    accel, _ = run.rise(run.yaw_rate, top)
    if profile.ramped:
        assert accel == pytest.approx(profile.limits.max_turn_accel_radps2, rel=0.15)
    else:  # stepped commands: the limit lies between the mean rise and the start's peak
        peak = float(np.max(np.diff(run.yaw_rate) / np.diff(run.time)))
        assert accel <= profile.limits.max_turn_accel_radps2 <= peak


@pytest.mark.parametrize("share", [0.5, 1.0])
def test_the_default_robots_odometry_is_calibrated_to_the_track_it_turns_on(share):
    # Turning in place, the wheels' rims travel (track / 2) x the yaw rate each way: the track
    # the model turns on, which the wheel odometry's separation must be for its heading to hold.
    profile = PROFILES["default"]
    run = drive_from_standing(profile, 0.0, share * profile.limits.max_turn_rate_radps, False, 4.0)
    rim = run.steady(run.wheel_rate) * profile.wheel_radius_m
    turned_on = 2 * (run.steady(run.speed) - rim) / run.steady(run.yaw_rate)
    assert turned_on / profile.track_m == pytest.approx(profile.odometry_track_scale, abs=0.01)


@pytest.mark.parametrize("name", [name for name in NAMES if PROFILES[name].ramped])
def test_each_robot_stops_turning_its_turn_lag_after_its_ramp(name):
    # Turning in place, then stopped: the drive ramps the turn rate down at the top turn
    # acceleration (omega^2 / 2 alpha of turn); the robot turns its turn lag x omega beyond.
    profile = PROFILES[name]
    for share in (0.5, 1.0):
        beyond = _turn_beyond_ramp(profile, share * profile.limits.max_turn_rate_radps)
        assert beyond == pytest.approx(profile.limits.turn_lag_s, abs=0.03)


def _turn_beyond_ramp(profile: RobotProfile, turn: float) -> float:
    """Turning in place at `turn` (rad/s), then stopped: how much farther (rad) the robot
    turns than the ramp's omega^2 / 2 alpha, per rad/s of turn (s)."""
    run = drive_from_standing(profile, 0.0, turn, ramp=True, seconds=5.0, stop_s=3.0)
    after = run.time > 3.0
    coast = float(np.sum(run.yaw_rate[after] * np.diff(run.time, prepend=0.0)[after]))
    return (coast - turn * turn / (2 * profile.limits.max_turn_accel_radps2)) / turn


@pytest.mark.parametrize("name", [name for name in NAMES if PROFILES[name].limits.turning_brake_mps2])
def test_a_robot_told_to_stop_and_turn_hard_slides_within_its_turning_brake(name):
    # At 1 m/s, then a stop with a turn in place: the body slides on, farther than a straight
    # stop (v^2 / 2a) on the Jackal, whose tyres drag sideways, but within v^2 / 2 b, b its
    # turning brake (the governor's prediction).
    profile = PROFILES[name]
    limits = profile.limits
    speed = min(1.0, limits.max_speed_mps)
    straight = _slide(profile, speed, (0.0, 0.0))
    assert straight == pytest.approx(speed**2 / (2 * limits.max_accel_mps2), rel=0.1)
    for share in (0.5, 0.75, 1.0):
        slid = _slide(profile, speed, (0.0, share * limits.max_turn_rate_radps))
        assert straight < slid <= speed**2 / (2 * limits.turning_brake_mps2)
    if name == "jackal":
        assert slid > 2 * straight


def _slide(profile: RobotProfile, speed: float, then: tuple[float, float]) -> float:
    """How far (m) the robot goes, driven straight at `speed` (m/s) and then commanded `then`
    (speed m/s, turn rad/s) from 2.5 s on, from where it was at 2.5 s to where it is at 5 s."""
    run = drive_from_standing(profile, speed, 0.0, ramp=True, seconds=5.0, stop_s=2.5, then=then)
    at = int(np.searchsorted(run.time, 2.5))
    return float(np.hypot(run.x[-1] - run.x[at], run.y[-1] - run.y[at]))


def test_a_profile_is_frozen_data():
    profile = PROFILES["jackal"]
    with pytest.raises(dataclasses.FrozenInstanceError):
        profile.track_scale = 1.0  # type: ignore[misc]
    with pytest.raises(TypeError):
        profile.sensors["beams"] = 10  # type: ignore[index]


def measured_table() -> str:
    """The docs' "Measured in MuJoCo" table (docs/robots.md), as Markdown, for every profile."""
    rows: dict[str, list[str]] = {key: [] for key in MEASURED_ROWS}
    for name in NAMES:
        profile = PROFILES[name]
        limits = profile.limits
        top, rate = limits.max_speed_mps, limits.max_turn_rate_radps
        run = drive_from_standing(profile, top, 0.0, ramp=profile.ramped, seconds=3.0)
        accel, rise_s = run.rise(run.speed, top)
        stepped = drive_from_standing(profile, top, 0.0, ramp=False, seconds=3.0)
        turning = drive_from_standing(profile, 0.0, rate, ramp=profile.ramped, seconds=4.0)
        rows["reached"].append(f"{run.steady(run.speed) / top:.3f}")
        rows["accel"].append(f"{accel:.2f}")
        rows["rise"].append(f"{rise_s:.2f}")
        rows["stepped"].append(f"{stepped.rise(stepped.speed, top)[0]:.2f}")
        rows["turn"].append(f"{turning.steady(turning.yaw_rate) / rate:.2f}")
        lags, slides = [], []
        for share in (0.5, 1.0) if profile.ramped else ():
            lags.append(f"{_turn_beyond_ramp(profile, share * rate):.3f}")
        speed = min(1.0, top)
        for then in (
            [(0.0, 0.0)] + [(0.0, share * rate) for share in (0.5, 0.75, 1.0)] if profile.ramped else []
        ):
            slides.append(_slide(profile, speed, then))
        rows["lag"].append(", ".join(lags) or "-")
        rows["slide"].append(
            f"{slides[0]:.3f}; " + ", ".join(f"{s:.3f}" for s in slides[1:]) if slides else "-"
        )
        braking = [speed * speed / (2 * s) for s in slides]
        rows["braking"].append(
            f"{braking[0]:.2f}; " + ", ".join(f"{b:.2f}" for b in braking[1:]) if slides else "-"
        )
        rows["step"].append(f"{run.step_cost_s * 1e6:.1f}")
    lines = ["| | " + " | ".join(f"`{name}`" for name in NAMES) + " |", "|---|" + "---|" * len(NAMES)]
    lines += [f"| {title} | " + " | ".join(rows[key]) + " |" for key, title in MEASURED_ROWS.items()]
    return "\n".join(lines)


MEASURED_ROWS = {
    "reached": "Top speed reached (of the profile's)",
    "accel": "Acceleration, 10-90 % (m/s^2)",
    "rise": "Time to 95 % of top speed (s)",
    "stepped": "Acceleration with the commands stepped (m/s^2)",
    "turn": "Turning in place: yaw rate / commanded",
    "lag": "Turn after a stop beyond omega^2 / 2 alpha, per rad/s of turn (s), at half and full turn rate",
    "slide": "Slide (m) from 1 m/s (the Burger: its top speed) told to stop straight, or to stop and turn "
    "at half, three quarters and all of the top turn rate",
    "braking": "Braking those slides show (m/s^2)",
    "step": "Physics step (microseconds, the robot alone)",
}


if __name__ == "__main__":  # python -m tests.test_profiles: the table of docs/robots.md
    print(measured_table())


def test_a_ros_robots_dwa_follows_the_maps_way_unless_the_scenario_says_otherwise():
    from vplane_mj.scenario import parse_document

    def dwa_params(profile: str, planner: dict) -> dict:
        doc = {
            "format": 1,
            "name": "open",
            "world": {"size": [10.0, 10.0]},
            "robot": {"profile": profile, "start": [2.0, 5.0], "goal": [8.0, 5.0]},
            "planner": {"name": "dwa", **planner},
        }
        return dict(parse_document(doc, "open.toml").planner_params)

    assert dwa_params("jackal", {}) == {"follow_way": 1, "clearance_weight": 0.05}
    assert dwa_params("turtlebot3_burger", {})["follow_way"] == 1
    assert dwa_params("jackal", {"follow_way": 0}) == {"follow_way": 0, "clearance_weight": 0.05}
    assert dwa_params("default", {}) == {} and dwa_params("pioneer3dx", {}) == {}  # the planner's own
