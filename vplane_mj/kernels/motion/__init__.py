"""Kernels of the motion: the potential fields (`fields`), the drive model (`drive_model`),
arcs ahead (`arcs`), the footprint's outline checks and clearance (`outline`,
`footprint_clearance`), the governor's memory of echoes (`memory`), following the way
(`way`) and the evasion of moving tracks (`evasion`)."""
