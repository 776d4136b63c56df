"""A benchmark's result table: its Markdown, CSV and the sidecar saying how and when it was measured."""

import csv
import json
from datetime import datetime

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
