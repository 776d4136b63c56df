"""Runs and sweeps that share an output folder: one writer at a time, every kept file whole."""

import json
import os
import subprocess
import sys

import pytest

from vplane_mj.cli import main
from vplane_mj.files import exclusive
from vplane_mj.logs.reader import read_log

RUN = ["run", "paper_c_escape", "--planner", "apf", "--set", "planner.patience_s=1000", "--no-render"]
"""A run of apf trapped in the C: it lasts until its time limit."""


def cli_process(*argv):
    return subprocess.Popen(
        [sys.executable, "-m", "vplane_mj", *argv], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )


def test_a_run_whose_files_another_process_writes_is_refused_naming_it(tmp_path, capsys):
    with exclusive(tmp_path / ".paper_c_escape-apf-0.lock", "the test's files", "none"):
        assert main([*RUN, "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert f"paper_c_escape-apf-0.*: this run's files: in use by pid {os.getpid()}" in err
    assert "choose another --out" in err
    assert list(tmp_path.iterdir()) == []


def test_two_runs_of_one_name_into_one_folder_keep_a_whole_log_that_agrees_with_its_summary(tmp_path):
    argv = [*RUN, "--set", "run.time_limit_s=120", "--out", str(tmp_path)]
    runs = [cli_process(*argv), cli_process(*argv)]
    ended = [run.communicate(timeout=600) for run in runs]
    assert {run.returncode for run in runs} <= {0, 1, 2}
    assert 1 in {run.returncode for run in runs}  # one run ended (timeout); the other too, or refused
    for run, (_, err) in zip(runs, ended, strict=True):
        assert "Traceback" not in err
        assert run.returncode != 2 or "in use by pid" in err
    assert sorted(path.name for path in tmp_path.iterdir()) == [
        "paper_c_escape-apf-0.json",
        "paper_c_escape-apf-0.mcap",
    ]
    log = read_log(tmp_path / "paper_c_escape-apf-0.mcap")
    assert log.complete
    assert log.summary == json.loads((tmp_path / "paper_c_escape-apf-0.json").read_text())
    assert log.summary["outcome"] == "timeout" and log.summary["sim_time_s"] == pytest.approx(120, abs=0.1)


def test_a_killed_run_leaves_a_stale_lock_that_the_next_run_takes_over(tmp_path, capsys):
    stale = tmp_path / ".paper_c_escape-apf-0.lock"
    stale.write_text(json.dumps({"pid": 999999, "host": "gone", "since": "then", "command": "killed"}))
    leftover = tmp_path / ".paper_c_escape-apf-0.mcap.999999-0badf00d.partial"
    leftover.write_bytes(b"a killed run's log")
    assert main([*RUN, "--set", "run.time_limit_s=5", "--out", str(tmp_path)]) == 1
    assert not stale.exists() and leftover.read_bytes() == b"a killed run's log"
    assert read_log(tmp_path / "paper_c_escape-apf-0.mcap").summary["outcome"] == "timeout"


BENCH = ["bench", "single_box", "--planners", "apf,vplane", "--seeds", "0-1", "--jobs", "1"]


def test_a_sweep_into_a_folder_another_sweep_holds_is_refused(tmp_path, capsys):
    with exclusive(tmp_path / ".bench.lock", "the test's sweep", "none"):
        assert main([*BENCH, "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert f"the folder of a sweep: in use by pid {os.getpid()}" in err and "--wait" in err
    assert list(tmp_path.iterdir()) == []


def test_sweeps_that_wait_for_each_other_run_every_job_once(tmp_path):
    with exclusive(tmp_path / ".bench.lock", "the test's sweep", "none"):
        sweeps = [cli_process(*BENCH, "--out", str(tmp_path), "--wait") for _ in range(2)]
        for waiting in sweeps:
            assert "the folder of a sweep: waiting for pid" in waiting.stderr.readline()
    errs = [waiting.communicate(timeout=600)[1] for waiting in sweeps]
    assert [waiting.returncode for waiting in sweeps] == [0, 0]
    assert sorted("4 to run" in err for err in errs) == [False, True]
    assert any("4 already done, 0 to run" in err for err in errs)
    journal = [json.loads(line) for line in (tmp_path / "bench.jsonl").read_text().splitlines()]
    assert len(journal) == 4 and len({row["key"] for row in journal}) == 4
