"""The planners' compiled kernels (numba, `@njit(cache=True)`, no fastmath): the loops a control
tick spends its time in, each written once, here.

Every module of this package imports numba, which takes about 0.3 s a process; the planning
modules import them only where a run needs them (a map's constructor, a planner's first
step), so `import vplane_mj`, `vplane-mj check` and `vplane-mj list` never load numba. The
kernels compile on their first call and are cached on disk beside their module, so later
processes load them. They use the C library's `atan2`, `sin`, `hypot` and the like, as numpy
does on a CPU without AVX-512 (numpy's own AVX-512 routines may differ in the last bit).
"""
