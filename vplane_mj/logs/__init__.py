"""The MCAP log of a run: the writer (`writer`, an observer of the run loop, drawing its scene
with `scene`), the reader (`reader`), and what is recomputed from a log alone (`replay`: the
summary and the path; `timeline`: the moving parts over time)."""
