"""What a planner is and what it exchanges with a run: the `Planner` base class, the robot it is
built for (`body`), its parameters (`params`), the `Observation` it receives and the `Decision`
it returns (`types`) with their events, angles and vectors, and how planners are found by name
(`registry`, `plugins`). A planner of one's own imports these, through `vplane_mj.planning`."""
