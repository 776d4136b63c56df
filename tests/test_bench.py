"""`vplane-mj bench`: the sweep, its outputs, resuming, and invalid input."""

import json

import pytest

from vplane_mj.bench import family_of, parse_seeds
from vplane_mj.cli import main
from vplane_mj.sim import TIMING_KEYS

ARGS = ["bench", "open_field", "paper_c_escape", "--planners", "apf,vplane", "--seeds", "0-1", "--jobs", "2"]


def test_a_sweep_writes_rows_table_and_plot_and_resumes(tmp_path, capsys):
    assert main([*ARGS, "--out", str(tmp_path)]) == 0
    captured = capsys.readouterr()
    assert "8 runs: 0 already done, 8 to run" in captured.err
    document = json.loads((tmp_path / "bench.json").read_text())
    rows, table = document["rows"], document["table"]
    assert len(rows) == 8 and {(r["scenario"], r["planner"], r["seed"]) for r in rows} == {
        (s, p, seed) for s in ("open_field", "paper_c_escape") for p in ("apf", "vplane") for seed in (0, 1)
    }
    by_planner = {row["planner"]: row for row in table}
    assert by_planner["vplane"]["success_rate"] == 1.0
    assert by_planner["apf"]["success_rate"] == 0.5  # trapped in the C obstacle
    assert by_planner["apf"]["stuck"] == 2
    assert 1.0 <= by_planner["vplane"]["median_path_ratio"] < 1.6
    assert "success_rate" in captured.out and "vplane" in captured.out
    assert len((tmp_path / "bench.csv").read_text().splitlines()) == 9
    assert (tmp_path / "bench.png").stat().st_size > 10_000

    # Rerunning the same command runs nothing again and gives the same rows.
    assert main([*ARGS, "--out", str(tmp_path)]) == 0
    assert "8 already done, 0 to run" in capsys.readouterr().err
    again = json.loads((tmp_path / "bench.json").read_text())["rows"]
    assert [r["key"] for r in again] == [r["key"] for r in rows]

    # An interrupted sweep (journal with 5 rows, the last one torn) completes the rest.
    lines = (tmp_path / "bench.jsonl").read_text().splitlines()
    (tmp_path / "bench.jsonl").write_text("\n".join(lines[:5]) + "\n" + lines[5][:40])
    assert main([*ARGS, "--out", str(tmp_path)]) == 0
    assert "5 already done, 3 to run" in capsys.readouterr().err
    resumed = json.loads((tmp_path / "bench.json").read_text())["rows"]

    def strip(table):
        return [{k: v for k, v in r.items() if k not in TIMING_KEYS} for r in table]

    assert strip(resumed) == strip(rows)


@pytest.mark.parametrize(
    "extra, fragment",
    [
        (["--seeds", "5-2"], "--seeds"),
        (["--seeds", "x"], "--seeds"),
        (["--planners", "apf,nope"], "planner.name"),
        (["--jobs", "0"], "--jobs"),
        (["--scheduler", "tcp://127.0.0.1:8786"], "--scheduler"),
        (["--set", "sensors.dropout=2"], "sensors.dropout"),
    ],
)
def test_invalid_input_exits_2_and_writes_nothing(tmp_path, capsys, extra, fragment):
    assert main(["bench", "open_field", *extra, "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and fragment in err
    assert list(tmp_path.iterdir()) == []


def test_parse_seeds():
    assert parse_seeds("0-3") == [0, 1, 2, 3]
    assert parse_seeds("7") == [7]
    assert parse_seeds("5,0-1,5") == [0, 1, 5]


def test_a_dask_cluster_gives_the_same_rows_as_the_local_pool(tmp_path, capsys):
    distributed = pytest.importorskip("distributed")
    local, remote = tmp_path / "local", tmp_path / "dask"
    local.mkdir()
    remote.mkdir()
    args = ["bench", "open_field", "paper_c_escape", "--planners", "apf,vplane", "--seeds", "0"]
    assert main([*args, "--jobs", "2", "--out", str(local)]) == 0
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True) as cluster:
        assert main([*args, "--scheduler", cluster.scheduler_address, "--out", str(remote)]) == 0
    assert "on the Dask cluster at" in capsys.readouterr().err

    def rows(directory):
        document = json.loads((directory / "bench.json").read_text())
        return [{k: v for k, v in r.items() if k not in TIMING_KEYS} for r in document["rows"]]

    assert rows(remote) == rows(local)


def test_family_of_a_generated_scenario():
    assert family_of("traps_1_003") == "traps"
    assert family_of("clutter_12_000") == "clutter"
    assert family_of("paper_c_avoid") == "paper_c_avoid"
