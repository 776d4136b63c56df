"""A benchmark's result table: its Markdown, CSV and the sidecar saying how and when it was measured."""

import csv
import importlib.util
import json
import sys
from datetime import datetime
from pathlib import Path

from vplane_mj.bench import report
from vplane_mj.bench.tables import (
    Measurement,
    benchmark_command,
    formatted,
    markdown_table,
    measured_now,
    write_table,
)

TABLE = [{"planner": "vplane", "success_rate": 0.5, "runs": 2}, {"planner": "apf", "runs": 2}]
COLUMNS = ("planner", "runs", "success_rate")


def cell(key: str, value) -> str:
    return "-" if value is None else f"{value:.0%}" if key.endswith("_rate") else str(value)


def test_the_command_is_the_one_typed_at_the_repository_s_root():
    argv = ["/somewhere/benchmarks/clutter.py", "--barn", "4", "--planners", "apf, vplane"]
    assert benchmark_command(argv) == "python benchmarks/clutter.py --barn 4 --planners 'apf, vplane'"


def test_a_measurement_now_has_this_process_s_command_the_utc_time_and_the_cpus():
    measurement = measured_now(["benchmarks/video.py", "--repeat", "1"])
    assert measurement.command == "python benchmarks/video.py --repeat 1"
    assert datetime.fromisoformat(measurement.date).utcoffset().total_seconds() == 0
    assert measurement.machine is not None and "CPUs" in measurement.machine


def test_write_table_writes_the_markdown_with_its_measurement_the_csv_and_the_sidecar(tmp_path):
    measurement = Measurement("python benchmarks/x.py --count 2", "2026-11-25T10:00:00+00:00", "2 CPUs")
    text = markdown_table(TABLE, COLUMNS, cell)
    written = write_table(tmp_path, "x", TABLE, COLUMNS, text, measurement)
    assert [path.name for path in written] == ["x.csv", "x.md", "x.json"]
    page = (tmp_path / "x.md").read_text(encoding="utf-8")
    assert page == text + "\n\nMeasured 2026-11-25 with `python benchmarks/x.py --count 2` on 2 CPUs.\n"
    assert "| apf | 2 | - |" in page
    rows = list(csv.DictReader((tmp_path / "x.csv").open(encoding="utf-8")))
    assert rows[0] == {"planner": "vplane", "runs": "2", "success_rate": "0.5"}
    sidecar = json.loads((tmp_path / "x.json").read_text(encoding="utf-8"))
    assert sidecar["command"] == measurement.command and sidecar["date"] == measurement.date
    assert sidecar["columns"] == list(COLUMNS)
    assert sidecar["table"][1] == {"planner": "apf", "runs": 2, "success_rate": None}


def test_write_table_is_called_as_before_and_measures_now(tmp_path, monkeypatch):
    monkeypatch.setattr("sys.argv", ["benchmarks/log_growth.py", "--minutes", "1"])
    report.write_table(tmp_path, "log_growth", TABLE, COLUMNS, "| a |\n|---|")
    sidecar = json.loads((tmp_path / "log_growth.json").read_text(encoding="utf-8"))
    assert sidecar["command"] == "python benchmarks/log_growth.py --minutes 1"
    line = f"Measured {sidecar['date'][:10]} with `{sidecar['command']}` on {sidecar['machine']}.\n"
    assert (tmp_path / "log_growth.md").read_text(encoding="utf-8").endswith(line)


def test_formatted_cells_take_their_column_s_format():
    cell = formatted({"wall s": ".3f", "ratio": ".2f"})
    assert [cell("wall s", 0.12345), cell("ratio", 2.0), cell("name", "a"), cell("ratio", None)] == [
        "0.123",
        "2.00",
        "a",
        "-",
    ]


def benchmark_script(name: str):
    """A benchmark script of `benchmarks/`, imported as a module (its `main` not run)."""
    path = Path(__file__).parents[1] / "benchmarks" / f"{name}.py"
    spec = importlib.util.spec_from_file_location(f"benchmark_{name}", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # where its dataclasses look their annotations up
    spec.loader.exec_module(module)
    return module


def test_peer_irsim_sets_each_world_s_rates_side_by_side_with_their_ratio_to_irsim_s():
    peer = benchmark_script("peer_irsim")
    timings = {
        (peer.IRSIM, 16): peer.Timing(20.0, 4.0, 4.0, "collided, stopped"),
        (peer.IRSIM, 720): peer.Timing(20.0, 40.0, 40.0, "collided, stopped"),
        ("dwa", 16): peer.Timing(20.0, 2.0, 2.0, "timeout"),
        ("dwa", 720): peer.Timing(10.0, 2.5, 2.5, "reached"),
    }
    table, columns = peer.rates_table({"w": timings}, {"w": 150})
    assert table == [
        {
            "world": "w",
            "cylinders": 150,
            "IR-SIM 16": 5.0,
            "IR-SIM 720": 0.5,
            "`dwa` 16": 10.0,
            "`dwa` 16 over IR-SIM": 2.0,
            "`dwa` 720": 4.0,
            "`dwa` 720 over IR-SIM": 8.0,
        }
    ]
    assert columns == list(table[0])
    assert peer.rates_markdown(table, columns).splitlines() == [
        "| world | cylinders | IR-SIM 16 | IR-SIM 720 | `dwa` 16 | `dwa` 720 |",
        "|---|---|---|---|---|---|",
        "| w | 150 | 5.00 | 0.50 | 10.00 (2.00x) | 4.00 (8.00x) |",
    ]
