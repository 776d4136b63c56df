"""The simulation: the MuJoCo world of a scenario (`world`), the robot's drive and controller
(`drive`, `control`, `odometry`), its range sensor (`sensors`: `sonar` or `laser`), the run loop
(`loop`: physics, sensing, the planner, the ending) and what a run is judged by (`metrics`,
`summary`, `failure`). Writes no files: logs and renders observe it from above."""
