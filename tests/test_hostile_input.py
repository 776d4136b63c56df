"""Hostile input at the command line (fuzzed scenario files and --set overrides), extreme but
valid worlds, and output directories that cannot be used.

The fuzzed key paths come from the scenario format's own key tables (`vplane_mj.scenario.keys`)
and the planners' parameter tables, so keys added there are fuzzed without changing this file.
"""

from __future__ import annotations

import copy
import datetime
import json
import math
import os
import re
import resource
import subprocess
import sys
import tempfile
import time
import tracemalloc
from collections import Counter
from pathlib import Path

import pytest
import tomli_w
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from vplane_mj import run
from vplane_mj.cli import main
from vplane_mj.geometry.reference import shortest_path
from vplane_mj.logs.reader import read_log
from vplane_mj.logs.writer import METADATA_NAME
from vplane_mj.planning import register_planner
from vplane_mj.planning.protocol import registry
from vplane_mj.planning.protocol.params import Param
from vplane_mj.robots.facts import robot_radius_m
from vplane_mj.scenario import Field, keys, load_scenario, parse_scenario
from vplane_mj.sim.loop import run_scenario
from vplane_mj.sim.summary import RunSummary

FUZZ = settings(
    deadline=None,
    database=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)
RUN_TIME_LIMIT = "run.time_limit_s=0.3"
"""Appended last to every fuzzed run, so no override can make a run long."""
MEMORY_CAP = 8 * 2**30
"""Address-space cap (bytes) while these tests run: a blow-up fails here instead of swapping."""
OUTCOMES = {"reached", "timeout", "stuck"}

# --------------------------------------------------------------------------- the base scenario

START, GOAL = [0.6, 0.6], [3.4, 3.4]
BOX = {"kind": "box", "center": [2.0, 2.0], "size": [0.4, 0.4], "yaw_deg": 10.0}
SECOND_OBSTACLE = {
    "center": [3.0, 1.0],
    "size": [0.4, 0.3],
    "radius": 0.2,
    "width": 0.6,
    "depth": 0.5,
    "length": 0.5,
    "thickness": 0.05,
    "yaw_deg": 30.0,
    "from": [2.7, 1.0],
    "to": [3.3, 1.2],
}
"""Values for an obstacle of any kind near (3, 1), clear of the start, the goal and the box."""
GENERIC_VALUES = {"point": [3.0, 1.0], "pair": [1.0, 1.0], "number": 0.3, "int": 1, "bool": True, "ints": []}


def base_doc(kind: str | None = None, planner: str = registry.DEFAULT_PLANNER) -> dict:
    """A valid 4 x 4 m scenario with one box (and a second obstacle of `kind`); runs 0.3 s."""
    obstacles = [copy.deepcopy(BOX)]
    if kind is not None:
        second = {"kind": kind}
        for key, field in keys.OBSTACLE_KINDS[kind].fields.items():
            if key in SECOND_OBSTACLE:
                second[key] = copy.deepcopy(SECOND_OBSTACLE[key])
            elif field.required:
                second[key] = copy.deepcopy(GENERIC_VALUES.get(field.kind, 0.3))
        obstacles.append(second)
    return {
        "format": 1,
        "name": "fuzz",
        "description": "a small arena for fuzzing",
        "world": {"size": [4.0, 4.0], "border": True, "obstacles": obstacles},
        "robot": {"start": list(START), "goal": list(GOAL)},
        "planner": {"name": planner},
        "sensors": {"noise_std": 0.0},
        "run": {"seed": 0, "time_limit_s": 0.3},
    }


# --------------------------------------------------------------------------- key paths

_BARE = re.compile(r"[A-Za-z0-9_-]+")


def key_path(path: tuple) -> str:
    """("world", "obstacles", 2, "width") -> "world.obstacles[2].width" (odd keys quoted)."""
    text = ""
    for part in path:
        if isinstance(part, int):
            text += f"[{part}]"
        else:
            shown = part if _BARE.fullmatch(part) else json.dumps(part)
            text = f"{text}.{shown}" if text else shown
    return text


KIND_FIELD = Field("str", required=True)
TABLE = "table"


def section_fields(section: str) -> dict:
    """The key table of a section (`WORLD_FIELDS`, `SENSOR_FIELDS`, ...); {} for `planner`."""
    for name in (f"{section.upper()}_FIELDS", f"{section.upper().removesuffix('S')}_FIELDS"):
        if hasattr(keys, name):
            return getattr(keys, name)
    return {}


def slots(doc: dict) -> list[tuple[tuple, object]]:
    """Every key path of the scenario format that applies to `doc`, with its Field or Param."""
    found: list[tuple[tuple, object]] = [((key,), field) for key, field in keys.TOP_FIELDS.items()]
    found += [((section,), TABLE) for section in keys.SECTIONS]
    for section in keys.SECTIONS:
        found += [((section, key), field) for key, field in section_fields(section).items()]
    planner = doc.get("planner", {}).get("name", registry.DEFAULT_PLANNER)
    found.append((("planner", "name"), Field("str")))
    if planner in registry.PLANNERS:
        found += [(("planner", key), p) for key, p in registry.planner_info(planner).params.items()]
    found.append((("world", "obstacles"), TABLE))
    for index, item in enumerate(doc["world"]["obstacles"]):
        found.append((("world", "obstacles", index), TABLE))
        found.append((("world", "obstacles", index, "kind"), KIND_FIELD))
        kind = keys.OBSTACLE_KINDS[item["kind"]]
        found += [(("world", "obstacles", index, key), field) for key, field in kind.fields.items()]
    return found


def get_parent(doc: dict, path: tuple):
    """The table (or array) that holds path[-1], or None when a mutation has removed it."""
    node = doc
    for part in path[:-1]:
        in_table = isinstance(node, dict) and isinstance(part, str) and part in node
        in_array = isinstance(node, list) and isinstance(part, int) and part < len(node)
        if not (in_table or in_array):
            return None
        node = node[part]
    if isinstance(path[-1], int):
        return node if isinstance(node, list) and path[-1] < len(node) else None
    return node if isinstance(node, dict) else None


# --------------------------------------------------------------------------- values

HOSTILE_CONSTANTS = [
    True,
    False,
    0,
    -1,
    1,
    2**63 - 1,
    -(2**63),
    2**53 + 1,
    10**400,
    0.0,
    -0.0,
    5e-324,
    1e-300,
    -1e-9,
    1e308,
    -1e308,
    math.inf,
    -math.inf,
    math.nan,
    "",
    " ",
    "nan",
    "1.0",
    "box",
    "ü🚀\u202e",
    "x" * 10_000,
    [],
    [1.0],
    [1.0, 2.0, 3.0],
    [math.nan, 1.0],
    [math.inf, 2.0],
    [1e308, 1e308],
    [-1.0, -1.0],
    ["a", "b"],
    [[1.0, 2.0], [3.0, 4.0]],
    [True, False],
    [1, "x"],
    {},
    {"x": 1.0},
    {"size": [1.0, 1.0]},
    [{"kind": "box"}],
    datetime.date(2020, 1, 1),
    datetime.time(12, 30),
    datetime.datetime(2020, 1, 1, 12, 0, tzinfo=datetime.UTC),
]

hostile_values = st.one_of(
    st.sampled_from(HOSTILE_CONSTANTS),
    st.integers(),
    st.floats(),
    st.text(max_size=12),
    st.lists(st.one_of(st.floats(), st.integers()), max_size=4),
    st.dictionaries(st.text(max_size=5), st.integers(), max_size=2),
)


def _number_range(lower: float | None, upper: float | None, default: float | None) -> tuple[float, float]:
    """A modest range within the bounds (the whole domain of a parameter can be huge)."""
    centre = abs(default) if default else 1.0
    lo = centre / 10 if lower is None or lower < centre / 10 else lower
    hi = centre * 10 if upper is None or upper > centre * 10 else upper
    if lower is None and default is not None and default <= 0:
        lo = -10.0
    return lo, max(lo, hi)


def _bounded_floats(lo: float, hi: float, exclude_lo: bool, exclude_hi: bool):
    return st.floats(lo, hi, exclude_min=exclude_lo and lo < hi, exclude_max=exclude_hi and lo < hi)


def valid_values(spec, path: tuple) -> st.SearchStrategy:
    """Values the key accepts (for point-like keys: inside the arena); modest in size."""
    if isinstance(spec, Param):
        lower = spec.gt if spec.gt is not None else spec.ge
        lo, hi = _number_range(lower, spec.le, spec.default)
        if spec.integer:
            return st.integers(math.ceil(lo + (spec.gt is not None)), max(math.ceil(lo), math.floor(hi)))
        return _bounded_floats(lo, hi, spec.gt is not None, False)
    if not isinstance(spec, Field):
        return st.nothing()
    lower = spec.gt if spec.gt is not None else spec.ge
    upper = spec.lt if spec.lt is not None else spec.le
    if spec.kind in ("point", "pair"):
        lo, hi = (0.0, 4.0) if lower is None and upper is None else _number_range(lower, upper, None)
        item = _bounded_floats(lo, hi, spec.gt is not None, spec.lt is not None)
        return st.lists(item, min_size=2, max_size=2)
    if spec.kind == "number":
        if path[-1] == "time_limit_s":
            return st.floats(0.05, 0.3)
        lo, hi = _number_range(lower, upper, 0.0 if lower is None else None)
        return _bounded_floats(lo, hi, spec.gt is not None, spec.lt is not None)
    if spec.kind == "int":
        lo = 0 if lower is None else math.ceil(lower + (spec.gt is not None))
        hi = lo + 20 if upper is None else math.floor(upper - (spec.lt is not None))
        return st.integers(lo, max(lo, min(hi, lo + 1000)))
    if spec.kind == "ints":
        return st.lists(st.integers(0, 3), max_size=3, unique=True)
    if spec.kind == "bool":
        return st.booleans()
    if spec.kind == "str":
        choices = getattr(spec, "choices", ())
        if choices:
            return st.sampled_from(choices)
        if path == ("name",):
            return st.from_regex(r"[a-z0-9_]{1,20}", fullmatch=True)
        if path[-1] == "kind":
            return st.sampled_from(sorted(keys.OBSTACLE_KINDS))
        if path == ("planner", "name"):
            return st.sampled_from(sorted(registry.PLANNERS))
        return st.text(max_size=30)
    return st.nothing()


def _edges(gt, ge, lt, le) -> list[float]:
    """The extreme numbers a key bounded like this accepts, and some it may not."""
    lower = ge if ge is not None else (math.nextafter(gt, math.inf) if gt is not None else -1e308)
    upper = le if le is not None else (math.nextafter(lt, -math.inf) if lt is not None else 1e308)
    return [lower, upper, 0.0, 5e-324, 1e-300, 1e-9, 1e6, 1e12, 1e308, -1e308]


EXTREME_STRINGS = ["a" * 101, "z" * 5000, "ü" * 1000, "\x00", "a-b", "A", "_", "0"]


def extreme_values(spec, path: tuple) -> st.SearchStrategy:
    """Values at the very edges of what the key accepts, or far past any sensible size."""
    if isinstance(spec, Param):
        edges = _edges(spec.gt, spec.ge, None, spec.le)
        if spec.integer:
            edges = [int(e) for e in edges if float(e).is_integer()] + [2**62, -(2**62), 2**1000]
        return st.sampled_from(edges)
    if not isinstance(spec, Field):
        return st.nothing()
    edges = _edges(spec.gt, spec.ge, spec.lt, spec.le)
    if spec.kind == "number":
        return st.sampled_from(edges)
    if spec.kind == "int":
        ints = [int(e) for e in edges if float(e).is_integer() and abs(e) < 2**70]
        return st.sampled_from([*ints, 2**62, -(2**62), 2**1000])
    if spec.kind in ("point", "pair"):
        return st.lists(st.sampled_from([*edges, 4.0, 3.9]), min_size=2, max_size=2)
    if spec.kind == "ints":
        return st.sampled_from([[0, 2**62], list(range(200)), [-1], [2**1000]])
    if spec.kind == "str":
        return st.sampled_from(EXTREME_STRINGS)
    return st.nothing()


def draw_value(draw, how: str, spec, path: tuple):
    """A hostile, valid or extreme value for the key (None when the key has no such value)."""
    if how == "hostile" or spec is TABLE:
        return draw(hostile_values)
    strategy = (valid_values if how == "valid" else extreme_values)(spec, path)
    return None if strategy.is_empty else draw(strategy)


unknown_keys = st.one_of(
    st.from_regex(r"[a-z_][a-z0-9_]{0,12}", fullmatch=True),
    st.sampled_from(["", " ", "a b", "a.b", "ü", "kind2", "Size", "NAME", "x" * 200]),
)

# --------------------------------------------------------------------------- mutations

EXPENSIVE = {("run",), ("run", "time_limit_s"), ("run", "physics_dt_s"), ("run", "control_hz")}
"""Keys left alone in files that are run: changing them could make a run long."""


@st.composite
def mutated_docs(draw, for_run: bool) -> tuple[dict, list[str]]:
    """A base scenario after 1-3 mutations, and the key paths the mutations touched."""
    kinds = [None, *sorted(keys.OBSTACLE_KINDS)]
    doc = base_doc(draw(st.sampled_from(kinds)), draw(st.sampled_from(sorted(registry.PLANNERS))))
    touched: list[str] = []
    candidates = [s for s in slots(doc) if not (for_run and s[0][:2] in EXPENSIVE)]
    for _ in range(draw(st.integers(1, 3))):
        path, spec = draw(st.sampled_from(candidates))
        parent = get_parent(doc, path)
        if parent is None:
            continue
        op = draw(st.sampled_from(["delete", "hostile", "valid", "valid", "extreme", "extreme", "unknown"]))
        if op == "unknown":
            table = parent if isinstance(parent, dict) else doc
            table_path = path[:-1] if isinstance(parent, dict) else ()
            name = draw(unknown_keys)
            if name in table:
                continue
            table[name] = draw(hostile_values)
            touched.append(key_path((*table_path, name)))
            continue
        if op == "delete":
            if isinstance(parent, list):
                continue  # deleting an obstacle renumbers the others: not a mutation of one key
            if path[-1] not in parent:
                continue
            del parent[path[-1]]
        else:
            value = draw_value(draw, op, spec, path)
            if value is None:
                continue
            parent[path[-1]] = value
        touched.append(key_path(path))
    return doc, touched


def related(reported: str, touched: list[str]) -> bool:
    """Whether an error at `reported` can be caused by mutating the keys in `touched`.

    The same key, a key inside it or around it, a key of the same table (bounds that
    depend on each other, e.g. width and thickness), or the start and goal placement.
    """
    if reported in ("robot.start", "robot.goal"):
        return True
    for path in touched:
        if reported == path or _inside(reported, path) or _inside(path, reported):
            return True
        if _parent(reported) == _parent(path) != "":
            return True
    return False


def _inside(path: str, table: str) -> bool:
    """Whether the key path `path` lies inside the table or array at `table`."""
    return path.startswith((f"{table}.", f"{table}["))


def _parent(path: str) -> str:
    """The key path of the table that holds `path` ("" for the top level)."""
    match = re.fullmatch(r"(.*?)(?:\.(?:[A-Za-z0-9_-]+|\"(?:[^\"\\]|\\.)*\")|\[\d+\])", path)
    return match[1] if match else ""


def reported_key(err: str, source: str) -> str | None:
    """The key path in `error: SOURCE: KEY: reason`, or in `error: --set KEY: reason (applied
    to SOURCE)` (a key an override set); None when the message has none."""
    prefix = f"error: {source}: "
    if err.startswith("error: --set"):
        assert err.rstrip().endswith(f" (applied to {source})"), err[:500]
        if err.startswith("error: --set: "):  # an override without a key
            return None
        prefix = "error: --set "
    assert err.startswith(prefix), err[:500]
    rest = err[len(prefix) :]
    match = re.match(r"((?:[A-Za-z0-9_-]+|\"(?:[^\"\\]|\\.)*\"|\[\d+\]|\.)+): ", rest)
    return match[1] if match else None


# --------------------------------------------------------------------------- helpers


def run_cli(capsys, *argv: str) -> tuple[int, str, str]:
    """`vplane-mj ARGV` in-process: exit status, stdout, stderr (never a traceback)."""
    code = main(list(argv))
    out = capsys.readouterr()
    assert "Traceback" not in out.err, out.err[-2000:]
    assert "internal error" not in out.err, out.err[-2000:]
    return code, out.out, out.err


def write_doc(directory: Path, doc: dict) -> Path:
    """The scenario document as `scenario.toml` in `directory`."""
    path = directory / "scenario.toml"
    path.write_text(tomli_w.dumps(doc), encoding="utf-8")
    return path


def assert_run_outputs(out_dir: Path, code: int) -> None:
    """A finished run wrote exactly its .json summary, with an outcome that matches the exit code."""
    files = sorted(out_dir.iterdir())
    assert len(files) == 1 and files[0].suffix == ".json", files
    summary = json.loads(files[0].read_text())
    assert summary["outcome"] in OUTCOMES, summary.get("message")
    assert code == (0 if summary["reached"] else 1)
    event(f"run outcome: {summary['outcome']}")


@pytest.fixture(autouse=True, scope="module")
def memory_cap():
    """Cap the address space, so that an input that blows up memory fails instead of swapping."""
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    cap = min(limit for limit in (MEMORY_CAP, soft, hard) if limit != resource.RLIM_INFINITY)
    resource.setrlimit(resource.RLIMIT_AS, (cap, hard))
    yield
    resource.setrlimit(resource.RLIMIT_AS, (soft, hard))


def report(capsys, test: str, tally: Counter) -> None:
    """Print how many examples a property test ran, by result (shown even when output is captured)."""
    with capsys.disabled():
        print(f"\n{test}: {sum(tally.values())} examples, {dict(sorted(tally.items()))}")


# --------------------------------------------------------------------------- 1. fuzzing


def count_rejection(code: int, err: str, source: str, touched: list[str], tally: Counter) -> None:
    """A rejection: exit 2 and a message naming a key path the mutations explain; counted."""
    assert code == 2, (code, err)
    key = reported_key(err, source)
    assert key is not None and related(key, touched), (err, touched)
    tally["rejected"] += 1
    event("rejected")


@pytest.mark.slow
def test_check_accepts_or_rejects_fuzzed_scenarios_cleanly(capsys):
    """`check` on mutated scenario files: ok (exit 0), or exit 2 naming a key path the mutation explains."""
    tally: Counter = Counter()

    @settings(FUZZ, max_examples=300)
    @given(mutated_docs(for_run=False))
    def check_one(case):
        doc, touched = case
        with tempfile.TemporaryDirectory() as tmp:
            path = write_doc(Path(tmp), doc)
            code, out, err = run_cli(capsys, "check", str(path))
        if code == 0:
            assert out.startswith(f"ok: {path}") and not err
            tally["accepted"] += 1
            event("accepted")
            return
        count_rejection(code, err, str(path), touched, tally)

    check_one()
    report(capsys, "check fuzz", tally)
    assert tally["accepted"] > 0 and tally["rejected"] > 0


@pytest.mark.slow
def test_run_accepts_or_rejects_fuzzed_scenarios_cleanly(capsys):
    """`run` on mutated files: a finished run (exit 0/1, its summary) or exit 2 with nothing written."""
    tally: Counter = Counter()

    @settings(FUZZ, max_examples=80)
    @given(mutated_docs(for_run=True))
    def run_one(case):
        doc, touched = case
        with tempfile.TemporaryDirectory() as tmp:
            out_dir = Path(tmp) / "out"
            out_dir.mkdir()
            path = write_doc(Path(tmp), doc)
            argv = ["run", str(path), "--out", str(out_dir), "--no-log", "--no-render"]
            code, _, err = run_cli(capsys, *argv)
            if code in (0, 1):
                assert_run_outputs(out_dir, code)
                tally["ran"] += 1
                return
            assert list(out_dir.iterdir()) == []
            count_rejection(code, err, str(path), touched, tally)

    run_one()
    report(capsys, "run fuzz", tally)
    assert tally["ran"] > 0 and tally["rejected"] > 0


@st.composite
def damaged_texts(draw) -> bytes:
    """The base file's bytes, truncated, spliced with junk, or re-encoded."""
    data = tomli_w.dumps(base_doc("u")).encode()
    how = draw(st.sampled_from(["truncate", "insert", "delete", "bytes", "bom", "duplicate"]))
    cut = draw(st.integers(0, len(data)))
    if how == "truncate":
        return data[:cut]
    if how == "insert":
        junk = draw(st.sampled_from(['"', "[", "]]", "=", "\n[world]\n", "\x00", "\\u", "ü", "#", "{", ","]))
        return data[:cut] + junk.encode() + data[cut:]
    if how == "delete":
        return data[:cut] + data[cut + draw(st.integers(1, 20)) :]
    if how == "bytes":
        return data[:cut] + draw(st.binary(min_size=1, max_size=8)) + data[cut:]
    if how == "bom":
        return b"\xef\xbb\xbf" + data
    return data + b'\nname = "again"\n'


def test_check_rejects_damaged_files_naming_the_file(capsys):
    """Broken TOML, bad UTF-8 or duplicate keys: exit 0 or 2 with the file named, never a traceback."""
    tally: Counter = Counter()

    @settings(FUZZ, max_examples=150)
    @given(damaged_texts())
    def check_one(data):
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "damaged.toml"
            path.write_bytes(data)
            code, out, err = run_cli(capsys, "check", str(path))
        assert code in (0, 2), (code, err)
        if code == 2:
            assert err.startswith(f"error: {path}: ") and err.count("\n") == 1, err[:500]
        else:
            assert out.startswith(f"ok: {path}")
        tally["accepted" if code == 0 else "rejected"] += 1
        event("accepted" if code == 0 else "rejected")

    check_one()
    report(capsys, "damaged-file fuzz", tally)
    assert tally["rejected"] > 0


def _canonical(path: tuple, dotted_indices: bool) -> str:
    """The --set spelling of a key path: world.obstacles[1].width or world.obstacles.1.width."""
    if not dotted_indices:
        return key_path(path)
    return ".".join(str(part) for part in path)


MALFORMED_SETS = [
    "a..b=1",
    "=",
    "=1",
    "x[99]=1",
    "world.obstacles[99].width=1",
    "world.obstacles[0][0]=1",
    "world.size[0]=1",
    "world.size.x=1",
    ".robot.goal=[1, 1]",
    "robot.goal.=1",
    "robot..goal=[1, 1]",
    "run.seed",
    "novalue",
    "ü=1",
    "planner.näme=vplane",
    "world.obstacles[-1].width=1",
    "world.obstacles[1e3].width=1",
    "name[0]=x",
    "format.x=1",
    "description.x.y=1",
    "robot = [1, 2]",
    "world=1",
    "x" * 5000 + "=1",
    "robot.goal=" + "[" * 2000,
    "robot.goal=[1.0, 2.0",
    "robot.goal={x = 1}",
    "name=" + "a" * 10_000,
    "description=" + "ü🚀" * 2000,
    "sensors.noise_std=1e999",
    "robot.start_yaw_deg=-nan",
    "run.seed=0x10",
    "run.seed=1_000",
    "run.seed=99999999999999999999999999",
    "planner.name=",
    "planner.name=\x00",
]
"""Overrides that are malformed or out of place (the error names them, or `--set`)."""


@st.composite
def override_lists(draw) -> tuple[list[str], list[str]]:
    """1-3 `--set` texts and the key paths they touch ("--set" for keys that cannot be named)."""
    doc = base_doc("h")
    candidates = [s for s in slots(doc) if s[0][:2] not in EXPENSIVE and s[1] is not TABLE]
    texts, touched = [], []
    for _ in range(draw(st.integers(1, 3))):
        how = draw(st.sampled_from(["malformed", "valid", "hostile", "extreme", "unknown"]))
        if how == "malformed":
            text = draw(st.sampled_from(MALFORMED_SETS))
            key = text.partition("=")[0].strip()
            touched += [key or "--set", "--set"]
            texts.append(text)
            continue
        path, spec = draw(st.sampled_from(candidates))
        if how == "unknown":
            path = (*path[:-1], draw(st.from_regex(r"[a-z_][a-z0-9_]{0,12}", fullmatch=True)))
        key = _canonical(path, draw(st.booleans()))
        value = draw_value(draw, "hostile" if how == "unknown" else how, spec, path)
        if value is None:
            continue
        try:
            shown = tomli_w.dumps({"v": value})[len("v = ") :].strip()
        except (TypeError, ValueError):
            continue
        if draw(st.booleans()) and isinstance(value, str):
            shown = value  # a bare string: --set name=abc
        texts.append(f"{key}={shown}")
        touched.append(key_path(path))
    return texts, touched


@pytest.mark.slow
def test_run_accepts_or_rejects_fuzzed_overrides_cleanly(capsys):
    """`run --set ...`: a finished run, or exit 2 naming the override's key path, and nothing written."""
    tally: Counter = Counter()
    with tempfile.TemporaryDirectory() as tmp:
        scenario_path = write_doc(Path(tmp), base_doc("h"))

        @settings(FUZZ, max_examples=150)
        @given(override_lists())
        def run_one(case):
            texts, touched = case
            with tempfile.TemporaryDirectory() as out:
                out_dir = Path(out)
                sets = [arg for text in [*texts, RUN_TIME_LIMIT] for arg in ("--set", text)]
                argv = ["run", str(scenario_path), *sets, "--out", str(out_dir), "--no-log", "--no-render"]
                code, _, err = run_cli(capsys, *argv)
                if code in (0, 1):
                    assert_run_outputs(out_dir, code)
                    tally["ran"] += 1
                    return
                assert code == 2, (code, err)
                assert list(out_dir.iterdir()) == []
                key = reported_key(err, str(scenario_path))
                if key is None:
                    assert "--set" in touched and "--set" in err, (err, texts)
                else:
                    assert related(key, touched) or key in touched, (err, texts)
                tally["rejected"] += 1
                event("rejected")

        run_one()
    report(capsys, "override fuzz", tally)
    assert tally["ran"] > 0 and tally["rejected"] > 0


ONCE_CRASHED = [
    ("planner.map_cell_m=1e-300", "planner.map_cell_m"),  # a local map of 1e302 cells
    ("planner.map_size_m=1e6", "planner.map_size_m"),
    ("planner.sector_deg=1e-300", "planner.sector_deg"),  # a histogram of 1e302 sectors
    (f"planner.echo_memory={2**1000}", "planner.echo_memory"),  # deque(maxlen=...) overflow
    ("planner.clearance_m=1e6", "planner.clearance_m"),  # a dilation disc of 1e7 cells
    ("planner.attract_gain=1e308", "planner.attract_gain"),  # inf force: outcome error
    ("sensors.noise_std=1e308", "sensors.noise_std"),  # inf ranges in the sonar map
    ("world.size=[100, 181]", "world.size"),  # MuJoCo: camera fovy >= 180
    ("name=" + "a" * 300, "name"),  # output file name too long, after the run
    ("run.control_hz=1e-300", "run.control_hz"),  # one control tick of 1e300 s
    ("world.obstacles[1].width=1e308", "world.obstacles[1].width"),  # MuJoCo: zero-size geom
    ("world.obstacles[1].thickness=1e-13", "world.obstacles[1].thickness"),
    ("world.obstacles[0].size=[5e-324, 5e-324]", "world.obstacles[0].size"),  # half size rounds to 0
    ("world.obstacles[1].center=[1e308, 2.0]", "world.obstacles[1].center"),
]


@pytest.mark.parametrize("override, key", ONCE_CRASHED, ids=[key for _, key in ONCE_CRASHED])
def test_values_that_once_crashed_a_run_are_rejected(tmp_path, capsys, override, key):
    """Values that once ended a run in a traceback or outcome `error`: now invalid (exit 2, the
    override and its key named)."""
    scenario = write_doc(tmp_path, base_doc("u"))
    out_dir = tmp_path / "out"
    out_dir.mkdir()
    argv = ["run", str(scenario), "--set", override, "--out", str(out_dir), "--no-log", "--no-render"]
    code, _, err = run_cli(capsys, *argv)
    assert code == 2 and err.startswith(f"error: --set {key}: "), err[:300]
    assert err.endswith(f" (applied to {scenario})\n"), err[-300:]
    assert list(out_dir.iterdir()) == []


AT_THE_EDGE = [
    ["planner.stuck_window_s=1e-300", "run.time_limit_s=2.5"],  # once: max() of an empty window
    ["planner.map_cell_m=0.05", "planner.map_size_m=20", "planner.sector_deg=0.5"],
    ["planner.attract_gain=1e6", "planner.repulse_gain=1e6"],
    ["sensors.noise_std=10", "sensors.count=128", "sensors.rays_per_sonar=15", "sensors.range_max=20"],
    ["run.control_hz=1", "run.physics_dt_s=0.01"],
    ["run.control_hz=200", "sensors.rate_hz=20"],  # the slowest sensor for the fastest control
    ["world.size=[150, 4]", "name=" + "a" * 100],
    [  # a 1 km cup with 1 mm walls, far outside the arena
        "world.obstacles[1].width=1000",
        "world.obstacles[1].depth=1000",
        "world.obstacles[1].thickness=0.001",
        "world.obstacles[1].center=[900, 900]",
    ],
]


@pytest.mark.parametrize("overrides", AT_THE_EDGE, ids=lambda overrides: overrides[0].split("=")[0])
def test_values_at_the_edge_of_the_bounds_run_cleanly(tmp_path, capsys, overrides):
    """The most extreme values still accepted: the run finishes (not in error) and writes its summary."""
    scenario = write_doc(tmp_path, base_doc("u"))
    sets = [arg for text in overrides for arg in ("--set", text)]
    argv = ["run", str(scenario), *sets, "--out", str(tmp_path), "--no-log", "--no-render"]
    code, _, err = run_cli(capsys, *argv)
    assert code in (0, 1), err[:300]
    (summary_path,) = tmp_path.glob("*.json")
    summary = json.loads(summary_path.read_text())
    assert summary["outcome"] in OUTCOMES, summary.get("message")


# --------------------------------------------------------------------------- 2. extreme worlds


def scenario_text(size, obstacles: list[dict], start, goal, time_limit_s: float, name: str) -> str:
    """A scenario file's text from its parts."""
    doc = {
        "format": 1,
        "name": name,
        "world": {"size": list(size), "obstacles": obstacles},
        "robot": {"start": list(start), "goal": list(goal)},
        "run": {"time_limit_s": time_limit_s},
    }
    return tomli_w.dumps(doc)


def assert_finished(summary: RunSummary, outcomes=OUTCOMES) -> None:
    """The run ended normally, with one of `outcomes`."""
    assert summary.outcome in outcomes, (summary.outcome, summary.message)
    assert summary.sim_time_s > 0 and math.isfinite(summary.path_length_m)


def test_a_thousand_obstacles_run_and_have_a_reference_path():
    """A 40 x 25 lattice of small boxes and cylinders, 1 m apart: 1000 obstacles (1010 geoms)."""
    obstacles = []
    for i in range(40):
        for j in range(25):
            centre = [1.5 + i, 1.5 + j]
            if (i + j) % 2:
                obstacles.append({"kind": "cylinder", "center": centre, "radius": 0.1})
            else:
                box = {"kind": "box", "center": centre, "size": [0.2, 0.2], "yaw_deg": 7.0 * i + j}
                obstacles.append(box)
    text = scenario_text((42.0, 27.0), obstacles, (0.5, 0.5), (41.0, 26.0), 2.0, "lattice")
    scenario = parse_scenario(text, "lattice.toml")
    assert len(scenario.world.obstacles) == 1000
    summary = run_scenario(scenario).summary
    assert_finished(summary, {"timeout"})
    # Through the lattice's 0.8 m aisles the way is at least the straight line, and not much more.
    straight = math.dist((0.5, 0.5), (41.0, 26.0))
    assert straight - 0.15 <= summary.optimal_length_m <= 1.1 * straight


@pytest.mark.slow
def test_a_100_m_arena_runs_and_its_reference_path_stays_small():
    """100 x 100 m, a 90 m wall to go round: the reference grid is bounded in memory (and time)."""
    wall = {"kind": "wall", "from": [0.0, 50.0], "to": [90.0, 50.0], "thickness": 0.2}
    text = scenario_text((100.0, 100.0), [wall], (5.0, 5.0), (5.0, 95.0), 2.0, "big_arena")
    scenario = parse_scenario(text, "big_arena.toml")
    tracemalloc.start()
    started = time.process_time()
    try:
        reference = shortest_path(scenario, robot_radius_m())
        seconds = time.process_time() - started
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert reference is not None
    # Round the wall's inflated end: two straight legs to (90 + r, 50) and back, plus a short arc.
    legs = 2 * math.hypot(90.0 + robot_radius_m() - 5.0, 45.0)
    assert legs - 0.01 <= reference.length_m <= legs * 1.005
    assert peak < 512 * 2**20, f"reference path peak memory {peak / 2**20:.0f} MiB"
    assert seconds < 20, f"reference path took {seconds:.1f} s CPU"  # ~3.5 s; unbounded: ~27 s
    print(f"\n100 m arena reference path: {seconds:.2f} s CPU, peak {peak / 2**20:.0f} MiB")
    summary = run_scenario(scenario).summary
    assert_finished(summary, {"timeout"})
    assert summary.optimal_length_m == pytest.approx(reference.length_m - scenario.robot.goal_tolerance)


@pytest.mark.parametrize("planner", sorted(registry.PLANNERS))
def test_a_gap_narrower_than_the_robot_is_never_passed(planner):
    """Two boxes 0.05 m apart close the arena: the robot (0.22 m wide) stays on its side."""
    half = (4.0 - 0.05) / 2
    obstacles = [
        {"kind": "box", "center": [half / 2, 2.0], "size": [half, 0.2]},
        {"kind": "box", "center": [4.0 - half / 2, 2.0], "size": [half, 0.2]},
    ]
    text = scenario_text((4.0, 4.0), obstacles, (2.0, 0.8), (2.0, 3.2), 10.0, "narrow_gap")
    result = run_scenario(parse_scenario(text, "narrow_gap.toml", [f"planner.name={planner}"]))
    assert_finished(result.summary, {"timeout", "stuck"})
    assert result.summary.optimal_length_m is None  # no way through for the reference either
    assert result.final_pose[1] < 2.0


@pytest.mark.parametrize(
    "obstacles, goal",
    [
        ([], (3.8, 2.0)),  # 0.2 m from the east border wall
        ([{"kind": "wall", "from": [1.0, 3.0], "to": [3.0, 3.0], "thickness": 0.1}], (2.0, 2.75)),
    ],
    ids=["border", "inner_wall"],
)
def test_a_goal_two_decimetres_from_a_wall_is_reached_without_collision(obstacles, goal):
    """The default planner reaches a goal 0.2 m from a wall (repulsion must not hold it off)."""
    text = scenario_text((4.0, 4.0), obstacles, (0.6, 0.6), goal, 60.0, "goal_by_wall")
    scenario = parse_scenario(text, "goal_by_wall.toml")
    assert scenario.planner == registry.DEFAULT_PLANNER
    summary = run_scenario(scenario).summary
    assert summary.outcome == "reached", summary.message
    assert summary.collisions == 0 and summary.success


# --------------------------------------------------------------------------- 3. output directories


def unusable_out_dirs(tmp_path: Path) -> dict[str, Path]:
    """Directories that cannot be created or written, even by root."""
    blocker = tmp_path / "file.txt"
    blocker.write_text("not a directory")
    dirs = {"below_a_file": blocker / "out" / "nested", "a_file": blocker}
    if os.geteuid() != 0:
        locked = tmp_path / "locked"
        locked.mkdir()
        locked.chmod(0o500)
        dirs["read_only"] = locked
    elif Path("/sys/kernel").is_dir():  # root ignores permissions, not sysfs's refusal
        dirs["read_only"] = Path("/sys/kernel")
    return dirs


@pytest.mark.parametrize("which", ["below_a_file", "a_file", "read_only"])
@pytest.mark.parametrize("command", ["run", "bench"])
def test_unusable_out_directory_exits_2_naming_it_and_writes_nothing(tmp_path, capsys, command, which):
    """`run` and `bench` check --out before any work, name it, and leave everything as it was."""
    out_dir = unusable_out_dirs(tmp_path).get(which)
    if out_dir is None:
        pytest.skip("no read-only directory on this system")
    scenario = write_doc(tmp_path, base_doc())
    before = sorted(tmp_path.rglob("*"))
    argv = [command, str(scenario), "--out", str(out_dir)]
    if command == "bench":
        argv += ["--planners", "apf", "--seeds", "0", "--jobs", "1"]
    try:
        code, out, err = run_cli(capsys, *argv)
    finally:
        if out_dir.is_relative_to(tmp_path) and out_dir.is_dir():
            out_dir.chmod(0o700)
    assert code == 2
    assert err.startswith(f"error: {out_dir}: ") and err.count("\n") == 1, err
    assert "directory" in err
    assert out == ""
    assert sorted(tmp_path.rglob("*")) == before
    assert not list(Path("logs").glob("fuzz-*"))  # nor did it fall back to the default directory


# --------------------------------------------------------------------------- 4. planners that raise

RAISING_PLANNERS = """
from vplane_mj.planning import Decision, Planner, PlannerParams


class Boom(Planner):
    name = "boom"
    summary = "toward the goal for a second, then a bug"
    citation = "none"
    Params = PlannerParams

    def step(self, obs):
        if obs.time_s >= 1.0:
            self.explode()
        return Decision(force=obs.goal - obs.position, mode="normal")

    def explode(self):
        raise RuntimeError("kaboom")


class BoomAtBirth(Boom):
    name = "boom_at_birth"

    def __init__(self, params, robot_radius_m):
        raise RuntimeError("kaboom")
"""


@pytest.mark.parametrize(
    "planner, log, raised_at_s",
    [("Boom", True, 1.0), ("Boom", False, 1.0), ("BoomAtBirth", True, 0.0)],
    ids=["in_step", "in_step_no_log", "in_constructor"],
)
def test_a_planner_that_raises_ends_its_run_in_error_and_keeps_the_log(tmp_path, planner, log, raised_at_s):
    """`run --planner file.py:Class` whose planner raises: outcome `error`, its own exit status
    (3), the exception and the planner's traceback in the summary, the log closed cleanly up to
    the failing tick, and one line on stderr that says where they are."""
    (tmp_path / "boom.py").write_text(RAISING_PLANNERS)
    argv = ["run", "open_field", "--planner", f"boom.py:{planner}", "--out", "out", "--no-render"]
    done = subprocess.run(
        [sys.executable, "-m", "vplane_mj", *argv, *([] if log else ["--no-log"])],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 3, done.stderr
    name = "boom" if planner == "Boom" else "boom_at_birth"
    base = Path("out") / f"open_field-{name}-0"
    summary = json.loads((tmp_path / base.with_suffix(".json")).read_text())
    assert summary["outcome"] == "error" and summary["sim_time_s"] == raised_at_s
    where = tmp_path / "boom.py"
    raised = f"planner {name!r} raised at t = {raised_at_s:.3f} s: RuntimeError: kaboom (at {where}:"
    assert summary["message"].startswith(raised)
    trace = summary["traceback"]
    assert trace.startswith("Traceback (most recent call last):")
    assert trace.rstrip().endswith("RuntimeError: kaboom") and "vplane_mj/sim.py" not in trace
    line = f"error: {summary['message']}; the exception and the planner's traceback are in {base}.json"
    assert done.stderr == line + (f", the log up to it in {base}.mcap\n" if log else "\n")
    assert (tmp_path / base.with_suffix(".mcap")).exists() == log
    if log:
        contents = read_log(tmp_path / base.with_suffix(".mcap"))
        assert contents.complete and contents.summary == summary
        assert contents.times_ns[-1] == round(raised_at_s * 1e9)  # up to the failing tick
        assert contents.events[-1].text == summary["message"]


def test_the_python_api_returns_the_run_of_a_planner_that_raises(tmp_path, own_registry):
    """`vplane_mj.run` does not raise: the record holds the error, and the files are written."""
    namespace: dict = {}
    exec(compile(RAISING_PLANNERS, "raising_planners.py", "exec"), namespace)
    register_planner(namespace["Boom"])
    record = run(load_scenario("open_field", ["planner.name=boom"]), out=tmp_path, render=False)
    assert record.summary.outcome == "error" and not record.reached
    assert record.summary.message.startswith("planner 'boom' raised at t = 1.000 s: RuntimeError: kaboom")
    assert 'File "raising_planners.py"' in record.summary.traceback
    assert sorted(record.files) == ["log", "summary"]
    assert read_log(record.files["log"]).summary == record.summary.to_dict()
    assert record.summary.sim_time_s == 1.0 and record.trajectory.times[-1] == pytest.approx(0.95)


# --------------------------------------------------------------------------- 5. mistaken names

MISTAKES = [
    (
        ["run", "paper_c_escape", "--planner", "vplan"],
        "error: --planner: unknown planner 'vplan'; available: apf, bug2, dwa, vfh, vobs, vplane, ",
        "vplane_plus; did you mean 'vplane'?",
    ),
    (
        ["run", "paper_c_escape", "--set", "planner.influense=0.6"],
        "error: --set planner.influense: not a parameter of planner 'vplane' (attract_gain, ",
        "; did you mean 'influence'? (applied to SCENARIO)",
    ),
    (
        ["run", "paper_c_escape", "--set", "planner.name=vplane_pls"],
        "error: --set planner.name: unknown planner 'vplane_pls'; available: ",
        "; did you mean 'vplane_plus'? (applied to SCENARIO)",
    ),
    (
        ["run", "paper_c_escape", "--set", "robot.gaol=[8, 2]"],
        "error: --set robot.gaol: unknown key (allowed here: profile, start, ",
        "; did you mean 'goal'? (applied to SCENARIO)",
    ),
    (
        ["run", "paper_c_escape", "--set", "robto.goal=[8, 2]"],
        "error: --set robto.goal: unknown key (allowed here: format, ",
        "; did you mean 'robot'? (applied to SCENARIO)",
    ),
    (
        ["run", "paper_c_escape", "--set", "world.obstacles[0].kind=boz"],
        "error: --set world.obstacles[0].kind: unknown obstacle kind 'boz' (known: ",
        "; did you mean 'box'? (applied to SCENARIO)",
    ),
    (
        ["run", "paper_c_escape", "--set", "sensors.pose=odometri"],
        "error: --set sensors.pose: must be one of 'truth', 'odometry', 'ekf', got 'odometri'",
        "; did you mean 'odometry'? (applied to SCENARIO)",
    ),
    (
        ["run", "paper_c_escape", "--set", "run.sede=3"],
        "error: --set run.sede: unknown key (allowed here: seed, ",
        "; did you mean 'seed'? (applied to SCENARIO)",
    ),
    (
        ["run", "paper_c_escape", "--seed", "-1"],
        "error: --seed: must be at least 0, got -1",
        " (applied to SCENARIO)",
    ),
    (
        ["run", "paper_c_escap"],
        "error: paper_c_escap: no such file or built-in scenario (built-in: ",
        "; did you mean 'paper_c_escape'?",
    ),
    (
        ["check", "paper_h_avoyd"],
        "error: paper_h_avoyd: no such file or built-in scenario (built-in: ",
        "; did you mean 'paper_h_avoid'?",
    ),
    (
        ["bench", "open_field", "--planners", "apf,vpalne"],
        "error: --planners: unknown planner 'vpalne'; available: ",
        "; did you mean 'vplane'?",
    ),
    (
        ["list", "--planner", "dwaa"],
        "error: --planner: unknown planner 'dwaa'; available: ",
        "; did you mean 'dwa'?",
    ),
    (
        ["generate", "trap", "--out", "OUT"],
        "error: family: unknown family 'trap' (known: barn, clutter, corridors, traps)",
        "; did you mean 'traps'?",
    ),
]
"""Mistakes on the command line, with how each message starts and ends: the option that
was mistyped is named (not the scenario file it was applied to, for which SCENARIO stands),
with the closest known name."""


@pytest.mark.parametrize("argv, start, end", MISTAKES, ids=[" ".join(argv) for argv, *_ in MISTAKES])
def test_a_mistaken_name_is_blamed_where_it_was_made_with_the_closest_known_one(
    tmp_path, capsys, argv, start, end
):
    argv = [str(tmp_path / "out") if arg == "OUT" else arg for arg in argv]
    if argv[0] in ("run", "bench"):
        argv += ["--out", str(tmp_path / "out")]
    code, out, err = run_cli(capsys, *argv)
    scenario = load_scenario("paper_c_escape").source if "paper_c_escape" in argv else ""
    end = end.replace("SCENARIO", scenario)
    assert code == 2 and out == "" and err.count("\n") == 1, err
    assert err.startswith(start) and err.rstrip("\n").endswith(end), err
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())


@pytest.mark.parametrize(
    "table, key, value, hint",
    [
        ("", "robto", {"goal": GOAL}, "did you mean 'robot'?"),
        ("robot", "gaol", GOAL, "did you mean 'goal'?"),
        ("world", "boarder", True, "did you mean 'border'?"),
        ("world.obstacles[0]", "centre", [2.0, 2.0], "did you mean 'center'?"),
        ("sensors", "nois_std", 0.1, "did you mean 'noise_std'?"),
        ("run", "time_limt_s", 10, "did you mean 'time_limit_s'?"),
        ("planner", "plane_gian", 1.0, "did you mean 'plane_gain'?"),
        ("planner", "name", "VPlane", "did you mean 'vplane'?"),
    ],
)
def test_a_mistaken_name_in_a_file_is_blamed_on_the_file_with_the_closest_known_one(
    tmp_path, capsys, table, key, value, hint
):
    """A mistyped key (or planner name) in any table of a file: the file, the key, the closest one."""
    doc = base_doc()
    target = doc["world"]["obstacles"][0] if table == "world.obstacles[0]" else doc.get(table, doc)
    target[key] = value
    scenario = write_doc(tmp_path, doc)
    code, _, err = run_cli(capsys, "check", str(scenario))
    where = f"{table}.{key}" if table else key
    assert code == 2 and err.startswith(f"error: {scenario}: {where}: "), err
    assert err.rstrip().endswith(hint), err


def test_file_names_that_are_not_utf8_work_and_are_shown_with_escapes(tmp_path):
    """Linux gives such names as bytes (Python keeps them with lone surrogates): the run works,
    its messages and its log's metadata show the bytes as backslash escapes."""
    name = os.fsdecode(b"caf\xe9")
    scenario = tmp_path / f"{name}.toml"
    scenario.write_text(load_scenario("single_box").to_toml(), encoding="utf-8")
    out = tmp_path / f"out-{name}"
    done = subprocess.run(
        [sys.executable, "-m", "vplane_mj", "run", str(scenario), "--out", str(out), "--no-render"],
        capture_output=True,
        env={**os.environ, "PYTHONIOENCODING": "utf-8"},
        timeout=300,
    )
    assert done.returncode == 0 and b"Traceback" not in done.stderr
    assert b"wrote " + os.fsencode(tmp_path) + b"/out-caf\\xe9/single_box-vplane-0.mcap" in done.stdout
    log = read_log(out / "single_box-vplane-0.mcap")
    assert log.metadata[METADATA_NAME]["scenario_source"].endswith("caf\\xe9.toml")
    assert log.summary == json.loads((out / "single_box-vplane-0.json").read_text())
