"""The scenario's moving obstacles in MuJoCo: kinematic mocap bodies placed before every physics step.

Each moving obstacle is the mocap body `moving<i>` (`vplane_mj.sim.world`); before each
`mj_step` at time t its position becomes its motion's at run time t (`geometry.motion`), so the
step's collision detection, and every sensor cast from the kinematics it leaves, see the
obstacles where they were at t. MuJoCo moves nothing else of them: they push the robot and are
not pushed. `pieces` gives their footprints where they stand now, for the laser's 2D cast.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from vplane_mj.geometry.motion import MotionTable
from vplane_mj.geometry.shapes import Disc, Rect
from vplane_mj.scenario import WorldSpec
from vplane_mj.sim.world import MOVING_PREFIX


class MovingObstacles:
    """The mocap bodies of a world's moving obstacles (in the order of `world.moving`)."""

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, world: WorldSpec):
        self.count = len(world.moving)
        self.table = MotionTable([moving.motion for moving in world.moving])
        ids = [int(model.body(f"{MOVING_PREFIX}{moving.index}").mocapid[0]) for moving in world.moving]
        if ids != list(range(self.count)):
            raise RuntimeError(f"the moving obstacles' mocap bodies are not the first, in order: {ids}")
        self.xy = data.mocap_pos[: self.count, :2]
        """Where each stands now (count, 2; m): a view into MuJoCo's mocap positions."""
        pieces = [moving.shape.footprint()[0] for moving in world.moving]
        discs = [i for i, piece in enumerate(pieces) if isinstance(piece, Disc)]
        rects = [i for i, piece in enumerate(pieces) if isinstance(piece, Rect)]
        self._disc_rows = np.array(discs, dtype=int)
        self._rect_rows = np.array(rects, dtype=int)
        self.packed_order = np.concatenate((self._disc_rows, self._rect_rows))
        """The obstacles' order in `pieces` (discs first): rows of `xy` by it line up with them."""
        self._discs = np.zeros((len(discs), 3))
        self._rects = np.zeros((len(rects), 6))
        for row, piece in enumerate(pieces[i] for i in discs):
            assert isinstance(piece, Disc)
            self._discs[row, 2] = piece.radius
        for row, piece in enumerate(pieces[i] for i in rects):
            assert isinstance(piece, Rect)
            self._rects[row, 2:] = (*piece.half, math.cos(piece.yaw), math.sin(piece.yaw))
        self.place(float(data.time))

    def place(self, time_s: float) -> None:
        """Set every mocap body where its motion is at run time `time_s` (s)."""
        self.table.positions(time_s, self.xy)

    def pieces(self) -> tuple[np.ndarray, np.ndarray]:
        """Their footprints where they stand now, packed as `sim.laser.RayCaster` packs pieces:
        discs (D, 3: x, y, radius) and rectangles (R, 6: x, y, half x, half y, cos and sin of yaw)."""
        self._discs[:, :2] = self.xy[self._disc_rows]
        self._rects[:, :2] = self.xy[self._rect_rows]
        return self._discs, self._rects
