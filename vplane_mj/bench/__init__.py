"""Sweeps: scenarios x planners x seeds as jobs in a resumable journal (`sweep`), on a local pool
that outlives its workers (`pool`) or a Dask cluster, runs that failed as rows (`failures`), and
the report: table, figures and HTML (`report`), and a benchmark's result table with the command
and date it was measured (`tables`)."""
