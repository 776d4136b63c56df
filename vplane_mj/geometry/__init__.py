"""Plane geometry without physics: the obstacle kinds as rectangles and discs (`shapes`), the
reference shortest path a run is scored against (`reference`, with its on-disk `cache`), path
simplification (`polyline`) and synthetic sonar scans for planner tests (`synthetic`). Pure numpy."""
