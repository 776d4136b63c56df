"""Kernels of the local map: the grid and its marks (`grid`), folding a scan in
(`map_update`), the distance transform (`edt`), the way search's step costs and Dijkstra
(`step_costs`, `grid_dijkstra`), the polar histogram (`histogram`) and the echo points
(`points`)."""
