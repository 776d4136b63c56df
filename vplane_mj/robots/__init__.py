"""The robots: each profile's published numbers and model (`profiles`), the facts read from its
MJCF (`facts`, via `mjcf_reader`), and the robot as a planner sees it (`facts.robot_body`). Below
the scenario format, which validates against them; no MuJoCo."""
