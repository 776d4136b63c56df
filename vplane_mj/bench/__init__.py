"""Sweeps: scenarios x planners x seeds as jobs in a resumable journal (`sweep`), on a local pool
that outlives its workers (`pool`) or a Dask cluster, runs that failed as rows (`failures`), and
the report: table, figures and HTML (`report`); for the benchmark scripts, a result table with
the command and date it was measured (`tables`) and their options, checked before any work
(`options`)."""
