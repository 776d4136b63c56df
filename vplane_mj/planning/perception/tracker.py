"""A multi-object tracker of moving obstacles, from range scans and the robot's pose alone.

Each scan is handled in five steps (the loops are numba kernels, `kernels.tracking`):

1. **Segmentation.** The echoes, by bearing, are cut into clusters where the gap between
   neighbours exceeds Borges and Aldon's adaptive breakpoint, max(min_gap, r sin(dphi) /
   sin(lambda - dphi) + 3 sigma_r) (G. A. Borges and M.-J. Aldon, "Line extraction in 2D range
   images for mobile robotics", J. Intelligent and Robotic Systems 40, 2004), or where more
   than `max_missing_beams` beams between them have no echo. Round objects that touch or
   overlap in the scan (two or three cylinders side by side, one against a wall) come as one
   cluster, too large for one object or whose circle fit fails: such a cluster is cut where
   its outline turns away from the sensor, an echo more than `split_depth_m` behind the line
   through its neighbours `split_reach_m` either way (a round object's echoes are convex
   toward the sensor, a wall's flat), where a part beside the cut is a round object of its
   own (a sane circle fit of at least `split_min_radius_m`): the other parts stay together,
   and a wall, bent or not, stays whole. Clusters larger than `max_object_size_m` (walls,
   blobs of clutter) are fixed structure and never tracked; so are those of fewer than
   `min_points` echoes. Each end of a cluster is a silhouette (clear), meets a nearer or about
   as near echo or the part it was cut from (blocked: the object may go on unseen) or is the
   edge of the field of view.
2. **Measurement.** A small cluster's centre is a circle fit when it has `fit_min_points`
   echoes and the fit is sane (a plausible radius, a small RMS, an arc of `fit_min_arc_deg`,
   a centre within `fit_max_std_m`, the centre behind the echoes): Kasa's algebraic fit (I.
   Kasa, IEEE Trans. Instrum. Meas. 25, 1976), refined by `fit_iterations` Gauss-Newton steps
   toward the geometric fit when its echoes are noisy (Kasa's circle of a short noisy arc is
   too small: N. Chernov, "Circular and Linear Regression", CRC Press 2010), its 1-sigma that
   of a parabola's radius over the arc, sqrt(45 / n) sigma / (arc / 2)^2; else the chord's
   midpoint pushed away from the sensor by half the chord (the centre of a disc whose near
   side the chord spans), its noise anisotropic about the line of sight, from the chord,
   larger when an end is not a silhouette.
3. **Association.** Predicted tracks and measured centres are paired within a gate on the
   squared Mahalanobis distance of the innovation (`gate_chi2`, and at most `max_gate_m`) by
   an optimal assignment, a global nearest neighbour (S. S. Blackman and R. Popoli, "Design
   and Analysis of Modern Tracking Systems", Artech House 1999, ch. 6): Kuhn's Hungarian
   method, compiled (it gives scipy's `linear_sum_assignment`'s pairs without its call and
   import), per connected component of the gated pairs (a pair alone is taken as it is).
4. **Filtering.** Each track is a constant-velocity Kalman filter on (x, y, vx, vy) with
   white-noise acceleration (Y. Bar-Shalom, X. R. Li and T. Kirubarajan, "Estimation with
   Applications to Tracking and Navigation", Wiley 2001, section 6.2.2). A new track starts
   at its first centre at rest with a velocity 1-sigma of `initial_speed_std_mps`, so its
   second measurement sets its velocity; it is confirmed after `confirm_hits` measurements,
   or when it is found moving. Only a cluster that places its object updates or starts a
   track: silhouettes at both ends, or an arc that fits a circle (cut by the edge of the view,
   by another object or by a cut). A track leaving the view (its part at the edge of the view
   shows fewer echoes than the last it took) coasts on the velocity of its whole views, as
   does one that takes a part that does not place its object (it labels its beams) or nothing.
   It is dropped when unseen for `coast_s`, when the beams toward its predicted centre pass
   through it `max_misses_in_view` scans in a row, or when it lies on a track that was seen
   and goes its way (a duplicate).
5. **Moving or not.** A fixed blob whose visible part changes as the robot drives past, or
   whose track hops between its fragments, seems to move. So a track is moving only when an
   earlier scan says so (C.-C. Wang, C. Thorpe and S. Thrun, "Online simultaneous localization
   and mapping with detection and tracking of moving objects", ICRA 2003: moving objects
   violate the free space of earlier scans): its echoes of now stand where that scan saw free
   space (at least `min_free_points` and `free_fraction` of them, every beam of that scan
   within `held_tolerance_m` sideways having passed more than `free_margin_m` beyond), or, for
   an object that recedes along the beams and so stands where it hid before, the echoes that
   scan had where the track stood then (its position less its velocity times the age) stand in
   the free space of now. A fixed surface does neither: a part newly seen was hidden before,
   which is no evidence. The earlier scans are the newest `slow_reference_age_s` old, in whose
   time a slow object has moved enough, and the newest `reference_age_s` old, twice that, ...
   below it: an object the old one cannot tell about (new in view, hidden then, or no scan that
   old yet) is told moving as soon as it has moved `free_margin_m` since one of them. Its speed
   must also exceed `moving_floor_mps` and `moving_sigmas` times its 1-sigma, measured
   `moving_min_hits` times and seen for `moving_min_age_s`; before it is confirmed, its
   velocity from fewer measurements, `young_moving_sigmas` times (a fast track is then
   confirmed at once); it stays moving while faster than `moving_hold_mps` and not judged
   fixed. A track whose echoes stand where the `slow_reference_age_s` old scan's
   did (half of them, and fewer than `min_free_points` free) is judged fixed; one not moving
   and judged fixed for `static_drop_s` is dropped, and a cluster judged fixed starts no track:
   fixed structure is the planner's map's. When the fixed structure itself (the clusters too
   large to track) seems to move against the oldest of those scans, more than
   `pose_check_share` of a sample of its echoes standing in the other scan's free space either
   way, the pose is off (odometry that drifts, wheels that slip): nothing is judged and no
   track is moving until it holds again. Without fixed structure in view a wrong pose cannot be
   told from motion.

Deterministic: no randomness, tracks in the order of their ids, which count up from 1.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from vplane_mj.planning.protocol.params import PlannerParams, param


@dataclass(frozen=True)
class Track:
    """A confirmed track: an obstacle's estimated disc and motion, in the planner's world frame.

    Attributes:
        track_id: The track's number, counting up from 1 in the order tracks start.
        position: The estimated centre [x, y] at `stamp_s` (m), read-only.
        velocity: The estimated velocity [vx, vy] at `stamp_s` (m/s), read-only.
        radius_m: Radius of a disc about `position` that holds what was seen of it (m).
        position_std_m: 1-sigma of `position` along its least certain direction (m).
        velocity_std_mps: 1-sigma of `velocity` along its least certain direction (m/s).
        first_seen_s: Time of its first measurement (s).
        last_seen_s: Time of its last measurement (s; earlier than `stamp_s` while it coasts
            unseen).
        moving: Whether it is confidently moving (see `TrackerParams`).
        stamp_s: Time of the tracker's last scan, when the estimates hold (s).
    """

    track_id: int
    position: np.ndarray
    velocity: np.ndarray
    radius_m: float
    position_std_m: float
    velocity_std_mps: float
    first_seen_s: float
    last_seen_s: float
    moving: bool
    stamp_s: float

    def predicted(self, time_s: float) -> np.ndarray:
        """The centre (2,; m) at `time_s` (s) at constant velocity."""
        return self.position + self.velocity * (time_s - self.stamp_s)


def tracks_of(states: np.ndarray, values: np.ndarray, stamp_s: float) -> tuple[Track, ...]:
    """`Track`s of the rows of `states` (K, 4: position and velocity, read-only) and `values`
    (K, 7: id, radius, position and velocity 1-sigma, first and last sight, moving), as
    `Track(...)` makes them but twice as fast: a frozen dataclass's __init__ sets each field
    through object.__setattr__, 2 us a track, and dozens are published at every scan."""
    tracks = []
    for position, velocity, v in zip(states[:, :2], states[:, 2:], values.tolist(), strict=True):
        track = object.__new__(Track)
        track.__dict__.update(
            track_id=int(v[0]),
            position=position,
            velocity=velocity,
            radius_m=v[1],
            position_std_m=v[2],
            velocity_std_mps=v[3],
            first_seen_s=v[4],
            last_seen_s=v[5],
            moving=v[6] > 0.0,
            stamp_s=stamp_s,
        )
        tracks.append(track)
    return tuple(tracks)


def moving_tracks(tracks: tuple[Track, ...], time_s: float) -> np.ndarray:
    """The moving ones of `tracks`, packed (M, 7): x, y (m) predicted at `time_s` (s), vx, vy
    (m/s), radius (m), position 1-sigma (m), velocity 1-sigma (m/s)."""
    rows = [  # tolist: unpacking an array makes a numpy scalar of each number, twice as slow
        (*t.position.tolist(), *t.velocity.tolist(), t.radius_m, t.position_std_m, t.velocity_std_mps,
         t.stamp_s)
        for t in tracks
        if t.moving
    ]  # fmt: skip
    if not rows:
        return np.empty((0, 7))
    packed = np.array(rows, dtype=float)
    packed[:, :2] += packed[:, 2:4] * (time_s - packed[:, 7:8])
    return packed[:, :7]


@dataclass(frozen=True)
class TrackerParams(PlannerParams):
    """The tracker's thresholds (defaults for a laser of about 0.4 degrees a beam and 0.01 m of
    noise at 10-20 Hz, and DynaBARN's obstacles: discs of 0.5 m radius at 0.5-1.95 m/s)."""

    breakpoint_lambda_deg: float = param(
        10.0,
        "deg",
        "lambda of Borges and Aldon: the shallowest incidence on a surface kept whole",
        gt=0,
        le=60,
    )
    range_sigma_m: float = param(0.01, "m", "sigma_r of the breakpoint: the ranges' noise", ge=0)
    min_gap_m: float = param(0.1, "m", "echoes nearer each other than this are never cut apart", ge=0)
    max_missing_beams: int = param(1, "", "beams without echo a cluster may bridge", ge=0, integer=True)
    clear_depth_m: float = param(
        0.2, "m", "a cluster's end is a silhouette when the next echo lies this much farther", ge=0
    )
    max_object_size_m: float = param(1.6, "m", "clusters larger than this are fixed structure", gt=0)
    min_points: int = param(3, "", "clusters of fewer echoes are not tracked", ge=1, integer=True)
    split_reach_m: float = param(
        0.15, "m", "how far along a cluster, each way, its outline's bend at an echo is measured", gt=0
    )
    split_depth_m: float = param(
        0.05,
        "m",
        "a cluster that is not one round object is cut where an echo lies this far behind its neighbours",
        gt=0,
    )
    split_min_radius_m: float = param(
        0.15,
        "m",
        "a cut is kept only beside a part that fits a circle at least this large (thin posts in a clump "
        "stay fixed structure)",
        ge=0,
    )
    fit_min_points: int = param(6, "", "echoes a cluster needs for a circle fit", ge=3, integer=True)
    fit_max_rms_m: float = param(0.03, "m", "largest RMS distance of the echoes from a sane fit", gt=0)
    fit_min_radius_m: float = param(0.05, "m", "smallest radius of a sane fit", ge=0)
    fit_min_arc_deg: float = param(
        45.0, "deg", "smallest arc of a sane fit, from the first echo to the last about its centre", ge=0
    )
    fit_max_std_m: float = param(
        0.05,
        "m",
        "largest 1-sigma of a sane fit's centre (a short arc of noisy echoes places it poorly)",
        gt=0,
    )
    fit_iterations: int = param(
        2, "", "Gauss-Newton steps that refine Kasa's circle into the geometric fit", ge=0, integer=True
    )
    measurement_floor_m: float = param(0.02, "m", "least 1-sigma of a measured centre", gt=0)
    accel_psd: float = param(
        0.5, "m^2/s^3", "q: spectral density of the white-noise acceleration of the motion model", gt=0
    )
    initial_speed_std_mps: float = param(2.0, "m/s", "1-sigma of a new track's velocity (set at 0)", gt=0)
    gate_chi2: float = param(
        13.8, "", "gate on the squared Mahalanobis distance (13.8: chi-square, 2 dof, 0.999)", gt=0
    )
    max_gate_m: float = param(2.0, "m", "no track takes a centre farther than this from its prediction", gt=0)
    confirm_hits: int = param(3, "", "measurements that confirm a track", ge=1, integer=True)
    tentative_coast_s: float = param(0.15, "s", "an unconfirmed track unseen this long is dropped", ge=0)
    coast_s: float = param(2.0, "s", "a confirmed track unseen this long is dropped", ge=0)
    max_misses_in_view: int = param(
        3, "", "scans in a row whose beams pass through a track's predicted disc drop it", ge=1, integer=True
    )
    hidden_margin_m: float = param(
        0.05, "m", "a beam ending this much before a predicted disc hides it (no miss)", ge=0
    )
    duplicate_speed_mps: float = param(
        0.5, "m/s", "an unseen track within a seen one's disc and this near its velocity is dropped", ge=0
    )
    radius_smoothing: float = param(
        0.2, "", "weight of a new measurement in a track's radius (a larger one is taken at once)", gt=0, le=1
    )
    reference_age_s: float = param(
        0.1,
        "s",
        "age of the youngest earlier scan whose free space a moving track's echoes may stand in "
        "(then twice that, ... below slow_reference_age_s)",
        gt=0,
    )
    slow_reference_age_s: float = param(
        0.5,
        "s",
        "age of the oldest earlier scan: slow objects show they moved against it, and it alone "
        "judges a track fixed",
        gt=0,
    )
    free_margin_m: float = param(
        0.1, "m", "an echo stands in free space when the earlier beams passed this much beyond it", ge=0
    )
    held_tolerance_m: float = param(
        0.05,
        "m",
        "an echo stands where the earlier scan echoed when a beam this near it sideways ended this near",
        ge=0,
    )
    free_fraction: float = param(
        0.2, "", "share of a track's echoes in free space that tells it moved", gt=0, le=1
    )
    min_free_points: int = param(2, "", "echoes in free space that tell a track moved", ge=1, integer=True)
    evidence_points: int = param(
        8, "", "echoes of a cluster, evenly spread, looked up in the earlier scan", ge=1, integer=True
    )
    pose_check_share: float = param(
        0.05,
        "",
        "share of fixed structure's echoes in free space above which the pose is off: no cluster judged",
        ge=0,
        le=1,
    )
    structure_points: int = param(
        32, "", "echoes of the fixed structure, evenly spread, that check the pose", ge=0, integer=True
    )
    static_drop_s: float = param(
        1.0, "s", "a track that is not moving, judged fixed this long, is dropped (left to the map)", ge=0
    )
    moving_floor_mps: float = param(0.15, "m/s", "a track slower than this is not moving", ge=0)
    moving_sigmas: float = param(1.0, "", "a moving track's speed exceeds its 1-sigma this many times", ge=0)
    moving_min_hits: int = param(
        2,
        "",
        "measurements a track needs to be moving (it is confirmed then, before confirm_hits)",
        ge=1,
        integer=True,
    )
    young_moving_sigmas: float = param(
        3.0, "", "moving_sigmas of a track not yet confirmed (its velocity from fewer measurements)", ge=0
    )
    moving_min_age_s: float = param(0.05, "s", "a track is moving only once seen this long", ge=0)
    moving_hold_mps: float = param(0.15, "m/s", "a moving track stays moving while faster than this", ge=0)


_Scan = tuple[np.ndarray, np.ndarray, float, np.ndarray]
"""An earlier scan as the free-space test takes it: its pose (x, y in m, yaw in rad), ranges (m)
by bearing, time (s) and its fixed structure's sample (K, 2; m)."""
_NO_SCAN: _Scan = (np.zeros(3), np.zeros(0), 0.0, np.zeros((0, 2)))
"""No earlier scan (no ranges)."""


class _Fan(NamedTuple):
    """A sensor's bearings (rad, robot frame) as given, and sorted for the kernels."""

    given: np.ndarray
    by_bearing: np.ndarray
    """The beams by bearing; none when they come sorted."""
    bearings: np.ndarray
    cos: np.ndarray
    sin: np.ndarray
    cyclic: bool
    """Whether the beams go all round: the first follows the last within 1.5 steps."""

    @classmethod
    def of(cls, bearings: np.ndarray) -> _Fan:
        """The fan of `bearings` (N,; any order, stably sorted)."""
        by_bearing = np.zeros(0, dtype=np.int64)
        if not np.all(np.diff(bearings) >= 0):
            by_bearing = np.argsort(bearings, kind="stable")
        ordered = bearings if by_bearing.size == 0 else bearings[by_bearing]
        gaps = np.diff(ordered)
        gaps = gaps[gaps > 0]
        cyclic = bool(gaps.size >= 2 and ordered[-1] - ordered[0] + 1.5 * gaps.min() >= 2 * math.pi)
        return cls(bearings.copy(), by_bearing, ordered, np.cos(ordered), np.sin(ordered), cyclic)

    @property
    def packed(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, bool]:
        """The sorted bearings, their cosines and sines, the beams by bearing, and `cyclic`."""
        return self.bearings, self.cos, self.sin, self.by_bearing, self.cyclic

    def sort(self, values: np.ndarray) -> np.ndarray:
        """`values` (N,) by bearing, a copy."""
        return values.copy() if self.by_bearing.size == 0 else values[self.by_bearing]


class _Table:
    """The tracks as arrays, one row each, the first `count` alive, in the order of their ids:
    `state` (x, y in m, vx, vy in m/s), its covariance `cov`, and `info`, whose columns
    `kernels.tracking` names (ID, RADIUS, ...)."""

    def __init__(self, columns: int, capacity: int = 64):
        self.count = 0
        self.state = np.zeros((capacity, 4))
        self.cov = np.zeros((capacity, 4, 4))
        self.info = np.zeros((capacity, columns))

    def room(self, extra: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The arrays, grown (to twice what is needed) when they hold fewer than `extra` rows
        beyond the live ones."""
        needed = self.count + extra
        if needed > self.state.shape[0]:
            grown = [np.zeros((2 * needed, *a.shape[1:])) for a in (self.state, self.cov, self.info)]
            for new, old in zip(grown, (self.state, self.cov, self.info), strict=True):
                new[: self.count] = old[: self.count]
            self.state, self.cov, self.info = grown
        return self.state, self.cov, self.info


class Tracker:
    """Tracks the small objects of a robot's range scans (see the module's docstring).

    `update` folds one scan at a time, in time order; after it, `tracks` holds the confirmed
    tracks, `moving_beams` which of that scan's beams echo from a moving one, and
    `beam_track_ids` the id of the confirmed track each beam echoes from (-1: none). A beam
    of an object no track took (a fragment of under `min_points` echoes, or one merged with
    fixed structure into a large cluster) is not marked.
    """

    def __init__(self, params: TrackerParams | None = None):
        from vplane_mj.kernels import tracking  # numba: loaded by the first tracker made

        self._k = tracking
        self.params = p = params if params is not None else TrackerParams()
        self._settings = tuple(
            np.array(values, dtype=float)
            for values in (
                (p.accel_psd, p.gate_chi2, p.max_gate_m),
                (
                    math.radians(p.breakpoint_lambda_deg),
                    p.range_sigma_m,
                    p.min_gap_m,
                    p.max_missing_beams,
                    p.clear_depth_m,
                ),
                (
                    p.min_points,
                    p.max_object_size_m,
                    p.fit_min_points,
                    p.fit_max_rms_m,
                    p.fit_min_radius_m,
                    math.radians(p.fit_min_arc_deg),
                    p.measurement_floor_m,
                    p.split_reach_m,
                    p.split_depth_m,
                    p.fit_iterations,
                    p.split_min_radius_m,
                    p.fit_max_std_m,
                ),
                (
                    p.confirm_hits,
                    p.radius_smoothing,
                    p.moving_floor_mps,
                    p.moving_sigmas,
                    p.moving_min_age_s,
                    p.moving_hold_mps,
                    p.moving_min_hits,
                    p.young_moving_sigmas,
                ),
                (
                    p.free_margin_m,
                    p.held_tolerance_m,
                    p.free_fraction,
                    p.min_free_points,
                    p.evidence_points,
                    p.min_points,
                    p.pose_check_share,
                    p.structure_points,
                ),
                (
                    p.coast_s,
                    p.tentative_coast_s,
                    p.max_misses_in_view,
                    p.hidden_margin_m,
                    p.duplicate_speed_mps,
                    p.static_drop_s,
                ),
                (p.initial_speed_std_mps, p.confirm_hits),
            )
        )
        ages = [p.reference_age_s]
        while 2.0 * ages[-1] < p.slow_reference_age_s:
            ages.append(2.0 * ages[-1])
        self._ages = (max(p.slow_reference_age_s, p.reference_age_s), *reversed(ages))
        """The ages (s) of the earlier scans the free-space test looks at, oldest first: the slow
        reference's, then `reference_age_s` doubled while below it, ..., `reference_age_s`."""
        self._table = _Table(tracking.INFO_COLUMNS)
        self._time: float | None = None
        self._next_id = 1
        self._fan: _Fan | None = None
        self._history: deque[_Scan] = deque()
        """Earlier scans (pose, ranges by bearing, time s, structure's sample), by time, the oldest
        the slow reference."""
        self._tracks: tuple[Track, ...] = ()
        self._moving_beams = np.zeros(0, dtype=bool)
        self._beam_ids = np.zeros(0, dtype=np.int64)

    @property
    def tracks(self) -> tuple[Track, ...]:
        """The confirmed tracks after the last scan, by id."""
        return self._tracks

    @property
    def moving_beams(self) -> np.ndarray:
        """Per beam of the last scan (its order), whether its echo belongs to a moving track: what a
        planner keeps out of its map of fixed obstacles. Read-only."""
        return self._moving_beams

    @property
    def beam_track_ids(self) -> np.ndarray:
        """Per beam of the last scan (its order), the id of the confirmed track its echo belongs
        to, -1 for none. Read-only."""
        return self._beam_ids

    def update(
        self, time_s: float, position: np.ndarray, yaw: float, bearings: np.ndarray, ranges: np.ndarray
    ) -> tuple[Track, ...]:
        """Fold one scan (ranges in m from the robot's centre along bearings in rad, robot frame,
        NaN = no return; any order) taken at pose (position m, yaw rad) at time_s; return the
        confirmed tracks."""
        bearings = np.asarray(bearings, dtype=float)
        ranges = np.asarray(ranges, dtype=float)
        if bearings.ndim != 1 or bearings.shape != ranges.shape:
            raise ValueError(
                f"bearings and ranges must be 1-D, of one length: {bearings.shape}, {ranges.shape}"
            )
        if self._time is not None and not time_s >= self._time:
            raise ValueError(f"scans must come in time order: {time_s} s after {self._time} s")
        fan = self._fan_of(bearings)
        table = self._table
        pose = np.array((position[0], position[1], yaw), dtype=float)
        ordered = fan.sort(ranges)
        arrays = table.room(ranges.shape[0] // self.params.min_points + 1)
        table.count, self._next_id, beam_ids, moving_beams, structure = self._k.track_scan(
            arrays,
            table.count,
            self._next_id,
            fan.packed,
            ordered,
            pose,
            time_s,
            0.0 if self._time is None else time_s - self._time,
            self._references(time_s),
            self._settings,
        )
        self._time = time_s
        beam_ids.flags.writeable = moving_beams.flags.writeable = False
        self._beam_ids, self._moving_beams = beam_ids, moving_beams
        self._remember(time_s, (pose, ordered, time_s, structure))
        self._tracks = self._publish(time_s)
        return self._tracks

    def _fan_of(self, bearings: np.ndarray) -> _Fan:
        """The fan of these bearings: the last one's when they are the same (the earlier scans,
        kept for the free-space test, are forgotten when they are not)."""
        fan = self._fan
        if fan is None or not self._k.same(fan.given, bearings):
            fan = self._fan = _Fan.of(bearings)
            self._history.clear()
        return fan

    def _references(self, time_s: float) -> tuple[_Scan, ...]:
        """The earlier scans for the free-space test, oldest first: for each of `_ages`, the
        newest scan at least that old (each: its pose, ranges by bearing, time and fixed
        structure's sample; no ranges when there is none)."""
        history, found = self._history, []
        k = len(history) - 1
        for age in reversed(self._ages):  # youngest first, walking back through the history
            while k >= 0 and time_s - history[k][2] < age - 1e-9:
                k -= 1
            found.append(history[k] if k >= 0 else _NO_SCAN)
        return tuple(reversed(found))

    def _remember(self, time_s: float, scan: _Scan) -> None:
        """Keep this scan (pose, ranges by bearing, time, structure's sample) for the free-space
        test; forget those older than the newest that is as old as the slow reference's age."""
        history = self._history
        history.append(scan)
        while len(history) > 1 and time_s - history[1][2] >= self._ages[0] - 1e-9:
            history.popleft()

    def _publish(self, time_s: float) -> tuple[Track, ...]:
        """The confirmed tracks as `Track`s, by id."""
        table = self._table
        states, values = self._k.confirmed(table.state, table.cov, table.info, table.count)
        states.flags.writeable = False
        return tracks_of(states, values, time_s)
