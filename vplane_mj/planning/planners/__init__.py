"""The built-in planners, one module each (`apf`, `vplane`, `vplane_plus`, `vobs`, `vfh`,
`bug2`, `dwa`), the parameter groups they share (`groups`) and the virtual plane's geometry
(`vplane_geometry`). The registry imports a planner's module when it is first named."""
