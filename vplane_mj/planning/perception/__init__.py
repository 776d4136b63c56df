"""Perception: what a planner makes of its scans, beyond the echoes themselves.

`tracker.Tracker` finds the small objects in each range scan and follows them from scan to
scan, so a planner can tell the obstacles that move, where they are heading and which of its
beams see them, from the fixed structure it maps. Numpy and numba only, like the rest of
`vplane_mj.planning`; importing this package loads neither.
"""
