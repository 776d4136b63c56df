"""The directions of a scan's beams, as the local map judges cells by them.

A scan's bearings come in any order, unevenly spaced, over any field of view, and several
beams may share a bearing (they then act as one, with the shortest of their echoes). A
point's beam is the one whose bearing is nearest to the point's; the map then asks whether
the point lies within half a beam width of it. For an evenly spaced ring the nearest beam
follows by arithmetic, for any directions by a search among the bounds half-way between
neighbouring directions (`kernels.map_update.nearest_in_ring` and `nearest_by_search`).
"""

from __future__ import annotations

import math

import numpy as np

SAME_DIRECTION_RAD = 1e-9
"""Bearings closer than this (rad) are one direction: their beams act as one."""
RING_TOLERANCE_RAD = 1e-12
"""Directions this close (rad) to an even ring's are that ring (the nearest beam by arithmetic)."""
QUICK_GAP_RAD = 0.1
COVER_SLACK_RAD = 1e-10
"""A direction is `quick` when the gaps to its neighbours are at most QUICK_GAP_RAD and its half
beam at least half the wider gap less COVER_SLACK_RAD (far below the map's SURE_RAD: a cell that
surely lies inside the bounds is surely within the beam)."""


class BeamFan:
    """The directions of a scan's beams: sorted, those that share a bearing merged, with what
    the rule that gives a cell its beam (the nearest direction) needs.

    Directions are angles in [0, 2 pi) (one slightly below 0 when a bearing lies within
    SAME_DIRECTION_RAD below a full turn); `relative` are them less the first. Each beam's
    cone is clipped to its share of the circle: `half_before` and `half_after` (rad) are the
    half beam or, if less, half the gap to the neighbouring direction.
    """

    def __init__(self, bearings: np.ndarray, beam: float):
        turn = 2 * math.pi
        self.source = bearings
        """The bearings as given (a sensor gives the same array at every scan)."""
        self.bearings = np.array(bearings, dtype=float)
        self.beam = beam
        wrapped = np.mod(self.bearings, turn)
        wrapped[wrapped > turn - SAME_DIRECTION_RAD] -= turn
        self._order = np.argsort(wrapped, kind="stable")
        ordered = wrapped[self._order]
        self._first = np.flatnonzero(np.diff(ordered, prepend=-math.inf) > SAME_DIRECTION_RAD)
        self._sorted = len(self._first) == len(ordered) and bool(np.all(np.diff(self._order) == 1))
        self.directions = ordered[self._first]
        self.count = len(self.directions)
        self.relative = self.directions - self.directions[0]
        gaps = np.diff(self.relative, append=turn)  # to the next direction, counter-clockwise
        self.bounds = self.relative + gaps / 2  # where the next direction becomes the nearest
        self.half_before = np.minimum(beam / 2, np.roll(gaps, 1) / 2)
        self.half_after = np.minimum(beam / 2, gaps / 2)
        self.bound_units = np.column_stack((np.cos(self.bounds), np.sin(self.bounds)))
        """The unit vectors (count, 2) of the bounds (relative to the first direction)."""
        widest = np.maximum(gaps, np.roll(gaps, 1))
        self.quick = (widest <= QUICK_GAP_RAD) & (beam / 2 >= widest / 2 - COVER_SLACK_RAD)
        """Directions whose beam covers their whole share, between bounds at most QUICK_GAP_RAD
        apart: a cell between those bounds is the direction's and within its beam, which the
        map's update decides by the side of the bounds the cell lies on."""
        ring = np.arange(self.count) * (turn / self.count)
        even = self.count == len(self.bearings) and np.max(np.abs(self.relative - ring)) <= RING_TOLERANCE_RAD
        self.spacing = turn / self.count if even else None
        """The ring's spacing (rad) when the directions are an evenly spaced ring, else None."""

    def readings(self, ranges: np.ndarray) -> np.ndarray:
        """One range per direction (m): the shortest echo of its beams, NaN when none echoed."""
        ranges = np.asarray(ranges, dtype=float)
        if self._sorted:
            return ranges
        ordered = ranges[self._order]
        return ordered if self.count == len(ordered) else np.fmin.reduceat(ordered, self._first)
