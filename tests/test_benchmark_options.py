"""The benchmark scripts refuse bad input before any work: a bad option is argparse's error
naming it (exit 2), an output directory that cannot be written is one line "error: ..." (exit
2), and neither writes a file."""

from __future__ import annotations

import argparse
import importlib.util
import sys
from pathlib import Path
from types import ModuleType

import pytest

from vplane_mj.bench import options

BENCHMARKS = Path(__file__).parents[1] / "benchmarks"
SCRIPTS = sorted(path.stem for path in BENCHMARKS.glob("*.py"))


@pytest.fixture(autouse=True)
def _benchmarks_importable(monkeypatch):
    """The scripts import each other (sweep_rate.py the protocol worlds of barn_protocol.py)."""
    monkeypatch.syspath_prepend(str(BENCHMARKS))


def benchmark_module(name: str) -> ModuleType:
    """benchmarks/NAME.py as a module."""
    spec = importlib.util.spec_from_file_location(f"benchmark_{name}", BENCHMARKS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # for its dataclasses
    spec.loader.exec_module(module)
    return module


BAD_OPTIONS = [
    ("barn_protocol", ["--count", "0"], "--count: at least 1, not 0"),
    ("clutter", ["--dropout", "2"], "--dropout: a finite number at least 0 and at most 1, not '2'"),
    ("degradation", ["--reference", "0.1"], "--reference: NOISE,DROPOUT expected"),
    ("dm_control_env", ["--steps", "0"], "--steps: at least 1, not 0"),
    ("dynabarn_ceiling", ["--modes", "seen,oracle"], "--modes: unknown mode 'oracle'; available"),
    ("dynabarn", ["--noise", "nan"], "--noise: a finite number at least 0, not 'nan'"),
    ("dynabarn_collisions", ["--planners", "apf,nope"], "--planners: unknown planner 'nope'; available"),
    ("footprint_clearance", ["--repeat", "0"], "--repeat: at least 1, not 0"),
    ("laser_cast", ["--origins", "many"], "--origins: a whole number, not 'many'"),
    ("localisation", ["--poses", "gps"], "--poses: unknown pose 'gps'; available: ekf, odometry, truth"),
    ("log_growth", ["--minutes", "1,0"], "--minutes: a finite number greater than 0, not '0'"),
    ("map_update", ["--repeat", "-1"], "--repeat: at least 1, not -1"),
    ("motion_prediction", ["--span", "3"], "--span: longer than --window and the longest horizon"),
    ("overhead", ["--planners", "vplane,vplane"], "--planners: planner 'vplane' given twice"),
    ("peer_irsim", ["--blas-threads", "-1"], "--blas-threads: at least 0, not -1"),
    ("planner_cost", ["no_such_world"], "scenarios: no_such_world: no such file or built-in scenario"),
    ("pose_ceiling", ["--jobs", "0"], "--jobs: at least 1, not 0"),
    ("ros2_export", ["--seconds", "inf"], "--seconds: a finite number greater than 0, not 'inf'"),
    ("scaling", ["--seconds", "-1"], "--seconds: a finite number greater than 0, not '-1'"),
    ("soak", ["--poses", "truth,ekf"], "--poses: the first pose is the estimate the runs drive on"),
    ("startup", ["no_such_world"], "scenarios: no_such_world: no such file or built-in scenario"),
    ("sweep_rate", ["--seed", "-3"], "--seed: at least 0, not -3"),
    ("tracker_accuracy", ["--seeds", "5-2"], "--seeds: '5-2' is not a seed or a range like 0-19"),
    ("video", ["--planner", "vplane,apf"], "--planner: one planner, not 'vplane,apf'"),
]


def test_every_benchmark_script_has_a_bad_option_case():
    assert sorted(script for script, _, _ in BAD_OPTIONS) == SCRIPTS


@pytest.mark.parametrize(("script", "arguments", "message"), BAD_OPTIONS, ids=[c[0] for c in BAD_OPTIONS])
def test_a_bad_option_is_refused_naming_it_before_anything_is_written(
    script, arguments, message, tmp_path, monkeypatch, capsys
):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as refused:
        benchmark_module(script).main([*arguments, "--out", "out"])
    assert refused.value.code == 2
    assert f"error: argument {message}" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("script", SCRIPTS)
def test_an_output_path_that_is_a_file_is_refused_in_one_line(script, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "taken").write_text("kept", encoding="utf-8")
    assert benchmark_module(script).main(["--out", "taken"]) == 2
    error = capsys.readouterr().err
    assert len(error.strip().splitlines()) == 1 or script == "peer_irsim"  # without IR-SIM: what to install
    assert sorted(path.name for path in tmp_path.iterdir()) == ["taken"]
    assert (tmp_path / "taken").read_text(encoding="utf-8") == "kept"


def test_option_types_convert_what_they_accept():
    assert options.whole(1)("3") == 3
    assert options.number(0.0, most=1.0)("1") == 1.0
    assert options.positives("0.5, 2") == [0.5, 2.0]
    assert options.names(("ekf", "truth"), "pose")("truth, ekf") == ["truth", "ekf"]
    assert options.planner("apf") == "apf"
    assert options.seeds("0,2,5-7") == [0, 2, 5, 6, 7]
    assert options.scenario("paper_c_escape") == "paper_c_escape"


@pytest.mark.parametrize(
    ("kind", "text"),
    [
        (options.whole(1), "1.5"),
        (options.positive, "0"),
        (options.non_negative, "-inf"),
        (options.number(0.0, most=1.0), "1.01"),
        (options.positives, "1,,2"),
        (options.planners, "apf,"),
        (options.seeds, "-1"),
        (options.scenario, "."),
    ],
)
def test_option_types_refuse_what_they_do_not(kind, text):
    with pytest.raises(argparse.ArgumentTypeError):
        kind(text)
