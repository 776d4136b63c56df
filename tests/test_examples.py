"""The scripts of examples/ run as a user runs them (a subprocess each, short arguments) and do
what they say: exit 0, write the files they name, print numbers that parse and agree with them."""

from __future__ import annotations

import csv
import json
import re
import struct
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow  # a long suite: `python -m pytest -m slow` runs it

EXAMPLES = Path(__file__).parents[1] / "examples"
SUMMARY_LINE = re.compile(
    r"^(?P<scenario>\w+) \[(?P<planner>\w+), seed (?P<seed>\d+)\]: (?P<outcome>\w+) after "
    r"(?P<sim_time>[\d.]+) s simulated, path (?P<path>[\d.]+) m, collisions (?P<collisions>\d+), "
    r".*local minima (?P<minima>\d+), escapes (?P<escapes>\d+)",
    re.M,
)


def run_example(script: str, *args: str, expect: int = 0) -> str:
    """Run examples/<script> with `args`; its stdout, after checking the exit status."""
    done = subprocess.run(
        [sys.executable, str(EXAMPLES / script), *args], capture_output=True, text=True, timeout=600
    )
    assert done.returncode == expect, done.stdout + done.stderr
    assert "Traceback" not in done.stderr, done.stderr
    return done.stdout if expect == 0 else done.stderr


def written(stdout: str) -> list[Path]:
    """The files a script says it wrote ("wrote PATH" lines), each checked to exist and be non-empty."""
    paths = [Path(line.removeprefix("wrote ")) for line in stdout.splitlines() if line.startswith("wrote ")]
    for path in paths:
        assert path.is_file() and path.stat().st_size > 0, path
    return paths


def png_size(path: Path) -> tuple[int, int]:
    """Width and height (px) from a PNG's header, after checking its signature."""
    head = path.read_bytes()[:24]
    assert head[:8] == b"\x89PNG\r\n\x1a\n" and head[12:16] == b"IHDR", path
    return struct.unpack(">II", head[16:24])


def summaries(stdout: str) -> dict[tuple[str, str], dict[str, str]]:
    """The printed run summary lines by (scenario, planner)."""
    return {(m["scenario"], m["planner"]): m.groupdict() for m in SUMMARY_LINE.finditer(stdout)}


def test_paper_figures_runs_the_four_scenarios_and_draws_them(tmp_path):
    stdout = run_example("paper_figures.py", "--time-limit", "45", "--out", str(tmp_path))
    runs = summaries(stdout)
    scenarios = ("paper_c_avoid", "paper_c_escape", "paper_h_avoid", "paper_h_escape")
    assert set(runs) == {(s, p) for s in scenarios for p in ("vplane", "apf")}
    for scenario in scenarios:  # the paper's result: vplane reaches every goal, APF is trapped
        assert runs[scenario, "vplane"]["outcome"] == "reached"
        assert runs[scenario, "apf"]["outcome"] == "stuck" and int(runs[scenario, "apf"]["minima"]) >= 1
    assert int(runs["paper_c_escape", "vplane"]["escapes"]) == 1
    assert int(runs["paper_h_escape", "vplane"]["escapes"]) == 1
    paths = written(stdout)
    assert len(paths) == 9
    for path in paths[:-1]:  # each run's summary agrees with its printed line
        summary = json.loads(path.read_text())
        line = runs[summary["scenario"], summary["planner"]]
        assert summary["outcome"] == line["outcome"]
        assert f"{summary['path_length_m']:.2f}" == line["path"]
    figure = paths[-1]
    assert figure.name == "paper_figures.png" and figure.stat().st_size > 50_000
    width, height = png_size(figure)
    assert width >= 1000 and height >= 1200  # two columns, four rows


def test_sweep_influence_prints_and_plots_a_curve_per_planner(tmp_path):
    stdout = run_example(
        "sweep_influence.py",
        "--values", "0.6,1.0",
        "--planners", "vplane,apf",
        "--traps", "1",
        "--scenarios", "paper_c_escape",
        "--seeds", "0",
        "--time-limit", "60",
        "--jobs", "1",
        "--out", str(tmp_path),
    )  # fmt: skip
    assert "8 runs: 2 worlds x 2 planners x seeds 0 x 2 values" in stdout
    printed = re.findall(r"^(vplane|apf) +([\d.]+) +([\d.]+) +([\d.]+|-)$", stdout, re.M)
    expected = [("vplane", 0.6), ("vplane", 1.0), ("apf", 0.6), ("apf", 1.0)]
    assert [(planner, float(value)) for planner, value, _, _ in printed] == expected
    paths = written(stdout)
    table = next(p for p in paths if p.name == "influence.csv")
    with table.open() as file:
        rows = list(csv.DictReader(file))
    for row, (planner, value, rate, ratio) in zip(rows, printed, strict=True):
        assert (row["planner"], float(row["influence_m"])) == (planner, float(value))
        assert float(row["success_rate"]) == pytest.approx(float(rate), abs=5e-4)
        assert (row["median_path_ratio"] == "") == (ratio == "-")
    for planner, _, rate, ratio in printed:
        if planner == "vplane":  # it reaches both goals; a path is never shorter than the shortest
            assert float(rate) == 1.0 and float(ratio) >= 1.0
        else:  # APF cannot leave paper_c_escape's trap, whatever its influence
            assert float(rate) <= 0.5
    journals = [p for p in paths if p.name == "bench.jsonl"]
    assert [p.parent.name for p in journals] == ["influence-0.6", "influence-1"]
    for journal in journals:
        assert len(journal.read_text().splitlines()) == 4  # 2 worlds x 2 planners x 1 seed
    worlds = [p for p in paths if p.suffix == ".toml"]
    assert len(worlds) == 1 and tomllib.loads(worlds[0].read_text())["world"]["obstacles"]
    figure = next(p for p in paths if p.name == "influence.png")
    assert png_size(figure)[0] >= 1000


def test_sweep_influence_refuses_a_planner_without_the_parameter(tmp_path):
    stderr = run_example(
        "sweep_influence.py", "--planners", "vplane,bug2", "--traps", "0", "--scenarios", "paper_c_escape",
        "--seeds", "0", "--out", str(tmp_path), expect=2,
    )  # fmt: skip
    assert stderr.startswith("error: ") and "planner.influence" in stderr
    assert not (tmp_path / "influence.csv").exists()


@pytest.mark.parametrize(
    ("arguments", "named"),
    [(("--seeds", "x"), "--seeds"), (("--jobs", "0"), "--jobs"), (("--scenarios", "nope"), "nope")],
)
def test_sweep_influence_refuses_bad_input_before_it_writes_the_trap_worlds(tmp_path, arguments, named):
    out = tmp_path / "out"
    stderr = run_example("sweep_influence.py", "--traps", "1", *arguments, "--out", str(out), expect=2)
    assert named in stderr and "Traceback" not in stderr
    assert not out.exists()


def test_custom_world_is_validated_run_saved_and_runs_again_alike(tmp_path):
    stdout = run_example("custom_world.py", "--time-limit", "60", "--out", str(tmp_path))
    reason = "must be greater than 2*thickness (0.2), got 0.15"
    assert f"rejected as expected: <code>: world.obstacles[1].width: {reason}" in stdout
    runs = summaries(stdout)
    assert runs["corridor_trap", "vplane"]["outcome"] == "reached"
    assert runs["corridor_trap", "apf"]["outcome"] != "reached"
    paths = written(stdout)
    saved = next(p for p in paths if p.suffix == ".toml")
    document = tomllib.loads(saved.read_text())
    assert document["name"] == "corridor_trap"
    kinds = [obstacle["kind"] for obstacle in document["world"]["obstacles"]]
    assert kinds == ["wall", "wall", "u", "box", "box", "cylinder"]
    first, again = (p for p in paths if p.name == "corridor_trap-vplane-0.json")
    assert again.parent.name == "again"
    digest = json.loads(first.read_text())["trajectory_sha256"]
    assert len(digest) == 64 and json.loads(again.read_text())["trajectory_sha256"] == digest
    assert "round trip: the same trajectory" in stdout
    assert png_size(next(p for p in paths if p.suffix == ".png"))[0] >= 1000


def test_compare_planners_sweeps_the_custom_planner_with_built_in_ones(tmp_path):
    stdout = run_example(
        "compare_planners.py", "paper_c_escape", "--planners", "apf,vplane", "--seeds", "0",
        "--time-limit", "60", "--jobs", "1", "--out", str(tmp_path),
    )  # fmt: skip
    table = {
        fields[0]: fields
        for line in stdout.splitlines()
        if (fields := line.split()) and fields[0] in ("random_walk", "apf", "vplane")
    }
    assert set(table) == {"random_walk", "apf", "vplane"}
    assert table["random_walk"][1] == "run" and table["apf"][1] == table["vplane"][1] == "own"  # governor
    assert all(fields[2] == "1" for fields in table.values())  # runs
    assert float(table["vplane"][3]) == 1.0 and float(table["apf"][3]) == 0.0  # success_rate
    assert re.search(r"^paper_c_escape +[01]/1 +0/1 +1/1$", stdout, re.M)
    paths = written(stdout)
    report_files = {"bench.csv", "bench.json", "bench.png", "bench-scenarios.png", "bench.html"}
    assert {p.name for p in paths} == report_files
    report = json.loads((tmp_path / "bench.json").read_text())
    assert sorted(row["planner"] for row in report["rows"]) == ["apf", "random_walk", "vplane"]
    random_walk = next(row for row in report["table"] if row["planner"] == "random_walk")
    assert random_walk["success_rate"] == float(table["random_walk"][2])
    assert "random_walk" in (tmp_path / "bench.html").read_text()
    assert png_size(tmp_path / "bench.png")[0] > 500


def test_the_documented_drawing_example_runs(tmp_path, monkeypatch, doc_examples):
    monkeypatch.chdir(tmp_path)
    exec(compile(doc_examples("python-api.md", "Examples"), "docs/python-api.md", "exec"), {})
    assert png_size(tmp_path / "paper_c_escape.png")[0] >= 600


def test_pixel_strip_saves_both_cameras_views_of_one_episode(tmp_path):
    stdout = run_example(
        "pixel_strip.py", "open_field", "--frames", "3", "--size", "48", "--out", str(tmp_path)
    )
    line = re.search(
        r"^open_field \[vplane, seed 0\]: reached after ([\d.]+) s simulated, (\d+) observations; "
        r"the strip shows t = 0\.0, [\d.]+, ([\d.]+) s$",
        stdout,
        re.M,
    )
    assert line and abs(float(line[1]) - float(line[3])) <= 0.05 and int(line[2]) > 100  # the last one shown
    (path,) = written(stdout)
    assert png_size(path) == (3 * 64 + 2 * 4, 2 * 48 + 4)  # 3 pictures of 64 x 48 px a row, 2 rows
    assert run_example("pixel_strip.py", "--frames", "1", expect=2).startswith("error: --frames")
