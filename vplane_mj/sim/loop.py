"""A run: physics at a fixed step, wheel PI at the motor rate, range sensor + planner at control_hz.

`Run` steps one control tick at a time (`step`) and decides in one place how the run ends
(`_ending`: the six ways, in the order they are checked), besides the planner's code raising,
which ends it as `error` with the exception kept (`_planner_raised`); `run_scenario` runs it
to the end.
A tick is two halves: `observe` (sense) and `apply` (a decision drives the wheels), so that
a decision can also come from outside (the reinforcement-learning environments, through
`vplane_mj.envs.task`). The robot is the scenario's profile; the planner sees only an
Observation (pose, goal, the ranges of its sonars or laser) and is built for the robot's body
(footprint, limits, sensor kind). The simulator's obstacle geometry is used only to score the
run (clearance of the footprint), to draw it, and to cast the laser's rays as a laser's
physics would, never to plan.
"""

from __future__ import annotations

import math
import re
import time
from dataclasses import dataclass, field
from typing import Protocol

import mujoco
import numpy as np

from vplane_mj.errors import VPlaneError
from vplane_mj.planning.perception.tracker import Track as TrackedObstacle
from vplane_mj.planning.perception.tracker import Tracker
from vplane_mj.planning.planners.run_governor import RunGovernor
from vplane_mj.planning.protocol.base import Planner
from vplane_mj.planning.protocol.events import Event, EventKind, point
from vplane_mj.planning.protocol.registry import make_planner
from vplane_mj.planning.protocol.types import Decision, Observation
from vplane_mj.robots.facts import robot_body
from vplane_mj.scenario import Scenario
from vplane_mj.sim.control import heading_command, within_limits
from vplane_mj.sim.drive import BELIEF_PATIENCE_S, CollisionCounter, Drive, Localiser
from vplane_mj.sim.failure import RunFailure, failure_of
from vplane_mj.sim.metrics import motion_quality, path_quality, robot_clearance, trajectory_digest
from vplane_mj.sim.moving import MovingObstacles
from vplane_mj.sim.sensors import range_sensor
from vplane_mj.sim.summary import Outcome, RunSummary
from vplane_mj.sim.world import build_model
from vplane_mj.terminal import Interrupted
from vplane_mj.version import __version__

EXTERNAL_PLANNER = "external"
"""The summary's planner name of a run whose decisions come from outside the package."""


@dataclass(frozen=True)
class Tick:
    """Everything known at one control tick, for observers (logs, renders). An observer may keep
    it: the run never changes its arrays afterwards (the `decision`'s are the planner's own)."""

    time_s: float
    position: np.ndarray
    yaw: float
    speed: float
    ranges: np.ndarray
    decision: Decision
    command: tuple[float, float]
    believed_pose: tuple[float, float, float] | None = None
    """The pose the planner used, when it comes from odometry rather than the simulator."""
    obstacles: np.ndarray | None = None
    """Where the moving obstacles stood (count, 2; m), in the order of the scenario's
    `world.moving`; None in a world without any."""
    tracks: tuple[TrackedObstacle, ...] = ()
    """The obstacles the planner's tracker follows from its scans (`planning.perception`),
    in the planner's frame."""


class Observer(Protocol):
    """Something that watches a run: every control tick and every event.

    After the last control tick it sees one more tick, the state the run ended in, with
    mode "finished" and no force (unless the run ended on a tick it already saw).
    """

    def on_tick(self, tick: Tick) -> None: ...

    def on_event(self, time_s: float, event: Event) -> None: ...


@dataclass(frozen=True)
class Track:
    """What a render shows of a run: the path at control ticks with the planner's modes,
    the final pose (x, y, yaw), collision points, virtual objectives and planes (e1, e2)."""

    positions: np.ndarray
    modes: list[str]
    final_pose: tuple[float, float, float]
    collision_points: list[tuple[float, float]] = field(default_factory=list)
    objectives: list[tuple[float, float]] = field(default_factory=list)
    planes: list[tuple[tuple[float, float], tuple[float, float]]] = field(default_factory=list)
    obstacle_places: np.ndarray | None = None
    """Where the moving obstacles stood at each of `positions` (ticks, count, 2; m), in the
    order of the scenario's `world.moving`; None in a world without any."""


@dataclass(frozen=True)
class Ending:
    """How a run ended: its outcome and the event that says so."""

    outcome: Outcome
    event: Event


@dataclass
class RunResult:
    """The summary of docs/interface.md section 3, the path at control ticks and the wheel torques."""

    summary: RunSummary
    times: np.ndarray
    positions: np.ndarray
    yaws: np.ndarray
    """base_link's yaw (rad) at each control tick, like `positions` (m) and `modes`."""
    modes: list[str]
    final_pose: tuple[float, float, float]
    """base_link's x, y (m) and yaw (rad) when the run ended."""
    torques: np.ndarray
    """(motor updates, 2) left and right wheel torques (N m), one row per motor period."""
    collision_points: list[tuple[float, float]] = field(default_factory=list)
    objectives: list[tuple[float, float]] = field(default_factory=list)
    """Every virtual new objective the planner placed, in order."""
    planes: list[tuple[tuple[float, float], tuple[float, float]]] = field(default_factory=list)
    """Every virtual plane the planner created, as (e1, e2)."""
    obstacle_places: np.ndarray | None = None
    """Where the moving obstacles stood at each control tick (ticks, count, 2; m), in the order
    of the scenario's `world.moving`; None in a world without any."""

    def track(self) -> Track:
        """What a render of this run shows."""
        return Track(
            self.positions,
            self.modes,
            self.final_pose,
            self.collision_points,
            self.objectives,
            self.planes,
            self.obstacle_places,
        )


class Run:
    """One run of a scenario, a control tick at a time (see the module docstring)."""

    def __init__(
        self,
        scenario: Scenario,
        observers: tuple[Observer, ...] = (),
        external: bool = False,
        physics: tuple[mujoco.MjModel, mujoco.MjData] | None = None,
    ):
        """`external`: the decisions come from outside through `observe` and `apply` (a learned
        policy, say), not from the scenario's planner, which is then not made; the summary
        names the planner EXTERNAL_PLANNER. `physics`: the model and data to step, when another
        owner holds them (dm_control's Physics, say); built from the scenario, without
        rangefinders (`world.build_model`), and fresh; by default the run builds its own."""
        self.scenario = scenario
        self.observers = observers
        if physics is None:
            physics = build_model(scenario, rangefinders=False), None
        self.model = physics[0]
        self.data = physics[1] if physics[1] is not None else mujoco.MjData(self.model)
        self.moving = (
            MovingObstacles(self.model, self.data, scenario.world) if scenario.world.moving else None
        )
        mujoco.mj_forward(self.model, self.data)
        profile = scenario.robot.profile
        self.drive = Drive(self.model, self.data, scenario.run.control_hz, profile, self.moving)
        self.sensor = range_sensor(scenario, self.data, self.moving)
        self.localiser = Localiser(self.drive, scenario)
        self.body = robot_body(profile, scenario.sensors.kind)
        self.radius = self.drive.geometry["radius_m"]
        self.planner_name = EXTERNAL_PLANNER if external else scenario.planner
        self.planner_failure: RunFailure | None = None  # what the planner's code raised, if it did
        self.planner, failed = (None, None) if external else self._make_planner()
        self.run_governor = (
            None if self.planner is None else RunGovernor.offered(self.planner, scenario.planner_governor)
        )
        self.clearance = robot_clearance(
            scenario, self.body, self.radius, None if self.moving is None else self.moving.pieces()
        )
        self.collisions = CollisionCounter(self.model, self.data)
        self.goal = np.asarray(scenario.robot.goal, float)
        self.tolerance = scenario.robot.goal_tolerance
        self.ranges = np.full(len(self.sensor.bearings), np.nan)
        self.scan_time_s = self.next_scan_s = 0.0  # when the sensor took `ranges`, takes the next (s)
        self.tracker = Tracker() if scenario.sensors.kind == "laser" else None
        self.tracks: tuple[TrackedObstacle, ...] = ()
        self.moving_echoes: np.ndarray | None = None
        self.position = self.drive.xpos[:2].copy()
        start = self.obstacles()
        self.clearance.add(
            np.array([[*self.position, self.drive.yaw()]]),
            None if start is None else self._places(start[None]),
        )
        self.times: list[float] = []
        self.positions: list[np.ndarray] = []
        self.modes: list[str] = []
        self.yaws: list[float] = []
        self.planner_cpu: list[float] = []
        self.objectives: list[tuple[float, float]] = []
        self.planes: list[tuple[tuple[float, float], tuple[float, float]]] = []
        self.places: list[np.ndarray] = []  # the moving obstacles' places at each recorded tick
        self.path_length = 0.0
        self.local_minima = self.escapes = 0
        self.time_to_goal: float | None = None
        self.ending: Ending | None = None
        self.wall_time_s = self.kernel_load_s = 0.0
        self._belief: tuple[np.ndarray, float] | None = None
        self._decision: Decision | None = None
        self._observation: Observation | None = None
        self._note(
            Event(
                EventKind.RUN_STARTED,
                f"run started: {scenario.name}, planner {self.planner_name}, seed {scenario.run.seed}",
            )
        )
        if failed is not None:
            self._planner_raised(failed)

    def _make_planner(self) -> tuple[Planner | None, Exception | None]:
        """The scenario's planner for the robot's body, or what its constructor raised (the run
        then ends at once as `error`); no planner by that name, or bad parameters, raise."""
        scenario = self.scenario
        try:
            return make_planner(scenario.planner, scenario.planner_params, self.body), None
        except (VPlaneError, Interrupted):
            raise
        except Exception as exc:  # the planner's own code
            return None, exc

    # -- the loop ---------------------------------------------------------------------------
    def step(self) -> Ending | None:
        """One control tick with the planner: `observe`, its decision, `apply`; the ending once
        the run is over (it stays over). The planner raising ends the run as `error`."""
        planner = self.planner
        if planner is None and self.ending is None:
            raise RuntimeError("step: this run's decisions come from outside: use observe and apply")
        observation = self.observe()
        if observation is None or planner is None:
            return self.ending
        started = time.perf_counter()
        try:
            decision = planner.step(observation)
        except Interrupted:
            raise
        except Exception as exc:  # the planner's own code: kept with its traceback
            self._observation = None
            return self._planner_raised(exc)
        if self.run_governor is not None:
            self.run_governor.drive(decision, observation)
        elapsed = time.perf_counter() - started
        self.planner_cpu.append(elapsed)
        self.wall_time_s += elapsed
        return self.apply(decision)

    def run(self) -> RunResult:
        """Load the compiled kernels that runs of this kind used (`kernels.preload`, timed apart
        from the loop as `kernel_load_s`), step to the end of the run; its result. The first run
        of a process adds the kernels it used to its kind's (`kernels.remember`): in a process
        that ran others before, which kernels this one used cannot be told apart."""
        from vplane_mj import kernels  # numba: the planners and sensors load it anyway

        kind = kernel_kind(self.planner_name, self.scenario.sensors.kind)
        first = kernels.loaded() == 0
        self.kernel_load_s = kernels.preload(kind)
        while self.step() is None:
            pass
        if first:
            kernels.remember(kind)
        return self.result()

    def observe(self) -> Observation | None:
        """Begin a control tick: check the physics state, read the sonar and the pose; what the
        planner sees on this tick, or None once the run is over.

        `step` passes it to the planner; a decision made elsewhere (a learned policy) is
        given back through `apply`, which ends the tick.
        """
        if self.ending is not None:
            return None
        if self._observation is not None:
            raise RuntimeError("observe: the decision of the current tick has not been applied")
        started = time.perf_counter()
        self._belief = self._decision = None
        belief = None
        if (ending := self._ending()) is None:
            belief = self._sense()
            ending = self._ending()
        self.wall_time_s += time.perf_counter() - started
        if ending is not None:
            self._finish(ending)
            return None
        assert belief is not None, "the run goes on: the pose was sensed"
        believed_xy, believed_yaw = belief
        self._observation = Observation(
            self.data.time,
            believed_xy,
            believed_yaw,
            self.goal,
            self.tolerance,
            self.sensor.bearings,
            self.ranges,
            self.sensor.beam_width,
            self.drive.wheel_velocity(),
            self.tracks,
            self.moving_echoes,
            self.scan_time_s,
        )
        return self._observation

    def apply(self, decision: Decision, command: tuple[float, float] | None = None) -> Ending | None:
        """End the tick begun by `observe` with a decision: record it, drive the wheels for one
        control period; the ending once the run is over.

        `command`, when given, is the body speed (m/s) and turn rate (rad/s) to drive instead
        of the heading controller's answer to the decision's force.
        """
        if self._observation is None:
            raise RuntimeError("apply: call observe first (and only while the run goes on)")
        self._observation = None
        started = time.perf_counter()
        self._take(decision)
        ending = self._ending()
        if ending is None or ending.outcome is Outcome.STUCK:
            self._report(command)  # observers see the tick the planner gave up on
        if ending is None:
            self._act()
        self.wall_time_s += time.perf_counter() - started
        if ending is not None:
            self._finish(ending)
        return ending

    def _ending(self) -> Ending | None:
        """The one place that decides whether the run is over, and how (dm_env's LAST step).

        Checked as the tick proceeds. On the physics state, before sensing: a fatal MuJoCo
        warning or a non-finite state (`error`), the goal within its tolerance (`reached`),
        the time limit (`timeout`). Once the pose is known: odometry holding the robot at a
        goal it has not reached for BELIEF_PATIENCE_S (`stuck`). On the planner's decision: a
        non-finite force (`error`), the planner giving up (`stuck`).
        """
        time_s = self.data.time
        if self._belief is None:
            if (message := self.drive.fatal_warning()) is not None:
                return Ending(Outcome.ERROR, Event(EventKind.ERROR, message))
            if math.hypot(self.goal[0] - self.position[0], self.goal[1] - self.position[1]) <= self.tolerance:
                self.time_to_goal = time_s
                return Ending(Outcome.REACHED, Event(EventKind.GOAL_REACHED, "goal reached"))
            if time_s >= self.scenario.run.time_limit_s - 1e-9:
                return Ending(Outcome.TIMEOUT, Event(EventKind.TIME_LIMIT, "time limit reached"))
            return None
        if self._decision is None:
            believed_xy, _ = self._belief
            if self.localiser.believes_arrived(time_s, believed_xy, self.goal, self.tolerance):
                away = math.dist(self.position, self.goal)
                believer = "the EKF" if self.scenario.sensors.pose == "ekf" else "odometry"
                message = (
                    f"{believer} has put the robot at the goal for {BELIEF_PATIENCE_S:g} s, but it is "
                    f"{away:.3f} m away: the planner has nowhere left to go"
                )
                return Ending(Outcome.STUCK, Event(EventKind.BELIEVED_ARRIVED, message))
            return None
        force = self._decision.force
        if not (math.isfinite(force[0]) and math.isfinite(force[1])):
            message = f"planner {self.planner_name!r} gave a non-finite force at t = {time_s:.3f} s"
            return Ending(Outcome.ERROR, Event(EventKind.ERROR, message))
        if self._decision.gave_up:
            gave_up = [e for e in self._decision.events if e.kind is EventKind.GAVE_UP]
            return Ending(Outcome.STUCK, gave_up[-1] if gave_up else Event(EventKind.GAVE_UP, "gave up"))
        return None

    # -- the stages of a tick ---------------------------------------------------------------
    def _sense(self) -> tuple[np.ndarray, float]:
        """Read the range sensor (when a reading is due at its rate), the pose the planner uses,
        and fold a new reading into the tracker at that pose (a laser's: a sonar ring's cones put
        too few echoes on an obstacle to cut a scan into clusters): the pose (position in m, yaw
        in rad), also kept for the rest of the tick."""
        time_s = self.data.time
        self.yaw = self.drive.yaw()
        scanned = time_s >= self.next_scan_s - 1e-9
        if scanned:
            self.ranges = self.sensor.read(float(self.position[0]), float(self.position[1]), self.yaw)
            self.scan_time_s = time_s
            while self.next_scan_s <= time_s + 1e-9:
                self.next_scan_s += 1.0 / self.sensor.rate_hz
        self.yaws.append(self.yaw)
        self._belief = self.localiser.pose(self.position, self.yaw)
        if scanned and self.tracker is not None:
            xy, yaw = self._belief
            self.tracks = self.tracker.update(time_s, xy, yaw, self.sensor.bearings, self.ranges)
            moving = self.tracker.moving_beams
            self.moving_echoes = moving if moving.any() else None
        return self._belief

    def _take(self, decision: Decision) -> None:
        """Keep the tick's decision: its events, its local minima and escapes, its virtual objects."""
        self._decision = decision
        force = decision.force
        if not (math.isfinite(force[0]) and math.isfinite(force[1])):
            return
        self.local_minima += decision.local_minimum
        self.escapes += decision.escape_completed
        for event in decision.events:
            if not (decision.gave_up and event.kind is EventKind.GAVE_UP):  # noted as the ending
                self._note(event)
        if decision.objective is not None or decision.planes:
            _collect_virtual(decision, self.objectives, self.planes)

    def _report(self, command: tuple[float, float] | None) -> None:
        """Record the tick (with its command: the given one, else the heading controller's) and
        show it to the observers."""
        decision = self._decision
        assert self._belief is not None and decision is not None, "reporting a tick not planned"
        believed_xy, believed_yaw = self._belief
        if command is None and decision.command is not None:
            command = within_limits(decision.command, self.drive.limits)
        if command is None:
            fx, fy = float(decision.force[0]), float(decision.force[1])
            command = heading_command(fx, fy, believed_yaw, self.drive.gains, self.drive.limits)
        self.command = command
        self.times.append(self.data.time)
        self.positions.append(self.position)
        self.modes.append(decision.mode)
        places = self.obstacles()
        if places is not None:
            self.places.append(places)
        if self.observers:
            belief = self.localiser.belief(believed_xy, believed_yaw)
            speed = self.drive.planar_speed()
            tick = Tick(
                self.data.time,
                self.position,
                self.yaw,
                speed,
                self.ranges,
                decision,
                self.command,
                belief,
                places,
                self.tracks,
            )
            for observer in self.observers:
                observer.on_tick(tick)

    def _act(self) -> None:
        """Drive the wheels for one control tick; measure the path, clearance and collisions."""
        trace, length, places = self.drive.run_tick(self.command, self._check_contacts)
        self.clearance.add(trace, None if places is None else self._places(places))
        self.path_length += length
        self.position = trace[-1, :2]

    def obstacles(self) -> np.ndarray | None:
        """Where the moving obstacles stand now (count, 2; m; a copy), in the order of the
        scenario's `world.moving`; None in a world without any."""
        return None if self.moving is None else self.moving.xy.copy()

    def _places(self, places: np.ndarray | None) -> np.ndarray | None:
        """Moving obstacles' places (..., count, 2) in the order the clearance packs them."""
        return None if places is None or self.moving is None else places[..., self.moving.packed_order, :]

    def _check_contacts(self) -> None:
        if self.collisions.touching or self.collisions.in_contact():
            contact = self.collisions.update(self.data)
            if contact is not None:
                text = f"collision at ({contact[0]:.2f}, {contact[1]:.2f})"
                self._note(Event(EventKind.COLLISION, text, {"point": point(contact)}))

    def _note(self, event: Event) -> None:
        for observer in self.observers:
            observer.on_event(self.data.time, event)

    def _planner_raised(self, exc: Exception) -> Ending:
        """End the run as `error` on an exception of the planner's code, kept in
        `planner_failure` with its traceback from the planner's call on."""
        trace = exc.__traceback__
        self.planner_failure = failure = failure_of(exc, trace.tb_next if trace else None)
        text = f"planner {self.planner_name!r} raised at t = {self.data.time:.3f} s: {failure.message}"
        ending = Ending(Outcome.ERROR, Event(EventKind.ERROR, text))
        self._finish(ending)
        return ending

    def _finish(self, ending: Ending) -> None:
        """Note how the run ended, bring the believed pose to the final instant (the summary's
        odometry errors compare it with the true pose there, not with the one a tick before)
        and show the observers the state it ended in."""
        self.ending = ending
        self.localiser.pose(self.position, self.drive.yaw())
        self._note(ending.event)
        self.clearance.flush()
        if self.observers and (not self.times or self.data.time > self.times[-1]):
            final = Decision(force=np.zeros(2), mode="finished")
            speed = self.drive.planar_speed()
            tick = Tick(
                self.data.time,
                self.position,
                self.drive.yaw(),
                speed,
                self.ranges,
                final,
                (0.0, 0.0),
                obstacles=self.obstacles(),
                tracks=self.tracks,
            )
            for observer in self.observers:
                observer.on_tick(tick)

    # -- the result -------------------------------------------------------------------------
    def governor_kind(self) -> str:
        """What drives the planner's forces on the robot's body: `own`, `run` or `none`
        (`RunSummary.governor`)."""
        if self.planner is not None and self.planner.governs_itself:
            return "own"
        return "none" if self.run_governor is None else "run"

    def result(self) -> RunResult:
        """The run's summary and path (call once it has ended)."""
        return RunResult(
            summary=self.summary(),
            times=np.array(self.times),
            positions=np.array(self.positions).reshape(-1, 2),
            yaws=np.array(self.yaws[: len(self.times)]),  # a last reading may end the run unrecorded
            modes=self.modes,
            final_pose=(float(self.position[0]), float(self.position[1]), self.drive.yaw()),
            torques=np.array(self.drive.torques).reshape(-1, 2),
            collision_points=self.collisions.points,
            objectives=self.objectives,
            planes=self.planes,
            obstacle_places=None
            if self.moving is None
            else np.array(self.places).reshape(-1, self.moving.count, 2),
        )

    def summary(self) -> RunSummary:
        """The run's summary (call once it has ended)."""
        scenario, ending, clearance = self.scenario, self.ending, self.clearance
        if ending is None:
            raise RuntimeError("the run has not ended")
        reached = ending.outcome is Outcome.REACHED
        success = reached and not self.collisions.points
        cpu = self.planner_cpu
        return RunSummary(
            scenario=scenario.name,
            planner=self.planner_name,
            seed=scenario.run.seed,
            outcome=ending.outcome,
            reached=reached,
            success=success,
            time_to_goal_s=None if self.time_to_goal is None else round(self.time_to_goal, 9),
            sim_time_s=round(self.data.time, 9),
            steps=self.drive.steps,
            physics_dt_s=self.model.opt.timestep,
            control_hz=scenario.run.control_hz,
            wall_time_s=self.wall_time_s,
            kernel_load_s=self.kernel_load_s,
            path_length_m=self.path_length,
            collisions=len(self.collisions.points),
            min_clearance_m=None if math.isinf(clearance.robot_minimum) else clearance.robot_minimum,
            mean_clearance_m=None if math.isinf(clearance.robot_mean) else clearance.robot_mean,
            moving_obstacles=len(scenario.world.moving),
            min_clearance_moving_m=None if self.moving is None else clearance.robot_moving_minimum,
            **motion_quality(np.array(self.yaws), self.path_length),
            planner_cpu_ms_mean=1e3 * float(np.mean(cpu)) if cpu else None,
            planner_cpu_ms_max=1e3 * float(np.max(cpu)) if cpu else None,
            local_minima=self.local_minima,
            escapes=self.escapes,
            robot_radius_m=self.radius,
            robot_profile=scenario.robot.profile,
            footprint_m=[[float(x), float(y)] for x, y in self.body.footprint],
            top_speed_mps=self.body.limits.max_speed_mps,
            sensor_kind=scenario.sensors.kind,
            **path_quality(
                scenario,
                self.radius if self.body.disc else self.body.half_width_m,
                success,
                self.path_length,
                self.time_to_goal,
                self.body.limits.max_speed_mps,
            ),
            final_distance_to_goal_m=math.hypot(
                self.goal[0] - self.position[0], self.goal[1] - self.position[1]
            ),
            odometry_error_m=self.localiser.error(self.position),
            odometry_error_max_m=self.localiser.largest(self.position),
            trajectory_sha256=trajectory_digest(self.positions, self.position, self.drive.yaw()),
            message="" if reached or ending.outcome is Outcome.TIMEOUT else ending.event.text,
            traceback=self.planner_failure.traceback if self.planner_failure else "",
            planner_params={} if self.planner is None else self.planner.params.as_dict(),
            governor=self.governor_kind(),
            version=__version__,
        )


def kernel_kind(planner: str, sensor_kind: str) -> str:
    """The kind of a run whose compiled kernels `Run.run` loads before its loop: its planner and
    sensor, as a file name."""
    return re.sub(r"[^A-Za-z0-9_]+", "_", f"{planner}-{sensor_kind}")


def run_scenario(scenario: Scenario, observers: tuple[Observer, ...] = ()) -> RunResult:
    """Simulate one scenario to the goal, the time limit, the planner giving up or an error."""
    return Run(scenario, observers).run()


def _collect_virtual(decision: Decision, objectives: list, planes: list) -> None:
    """Remember each new virtual objective and virtual plane of a decision (for renders)."""
    if decision.objective is not None:
        objective = (float(decision.objective[0]), float(decision.objective[1]))
        if not objectives or objectives[-1] != objective:
            objectives.append(objective)
    for e1, e2 in decision.planes:
        plane = ((float(e1[0]), float(e1[1])), (float(e2[0]), float(e2[1])))
        if plane not in planes:
            planes.append(plane)
