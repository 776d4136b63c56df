"""The documentation says what is true: the getting-started page's commands, run as a user types
them after the set-up, exit 0 and print and write what the page shows; its set-up commands are
the README's; every relative link of README.md, CHANGELOG.md and docs/ points at a file (and
a heading) that exists; every benchmark table a page includes is a result file that says how and
when it was measured; the figures the README quotes are those tables' (or, where no script
writes a table, the figures of the dated record a page keeps); every
public name of `vplane_mj` and `vplane_mj.planning` has its entry on a reference page; and
what those entries show is whole: every field of a documented dataclass in its docstring's
table, every member of a documented enum with its docstring."""

from __future__ import annotations

import ast
import dataclasses
import enum
import importlib
import inspect
import itertools
import json
import os
import re
import shutil
import subprocess
import sysconfig
import textwrap
from dataclasses import dataclass
from datetime import datetime
from decimal import ROUND_HALF_UP, Decimal
from pathlib import Path
from typing import Any

import imageio_ffmpeg
import numpy as np
import pytest
from PIL import Image

import vplane_mj
import vplane_mj.planning
from vplane_mj.bench.tables import Measurement

ROOT = Path(__file__).parents[1]
GETTING_STARTED = ROOT / "docs" / "getting-started.md"
PAGES = sorted([ROOT / "README.md", ROOT / "CHANGELOG.md", *(ROOT / "docs").rglob("*.md")])
REPOSITORY_DATA = ("scenarios", "examples", "tests/data/barn")
"""What the page's commands read from the repository, copied beside them (a user runs them in
the repository's directory, where the set-up installed the package)."""
FENCE = re.compile(r"^([ \t]*)```(\w*)[^\n]*\n(.*?)^\1```[ \t]*$", re.M | re.S)
"""A fenced code block, at the margin or indented in a list item."""
NUMBER = re.compile(r"-?\d+(?:\.\d+)?")
OMITTED = "..."
"""In a page's output: a line of its own skips any lines; within a line, any text."""
LINK = re.compile(r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
INLINE_CODE = re.compile(r"(`+)(?:(?!\1).)+?\1", re.S)
INCLUDE = re.compile(r'^--8<-- "(benchmarks/results/[^"]+)"$', re.M)
"""A page's include of a benchmark's result table (pymdownx.snippets)."""
FIGURE = r"([0-9.]+)%?"
RESULTS = "benchmarks/results/"
RANGE = rf"{FIGURE}-{FIGURE}"
"""Two figures of the README, "1.47-1.50"."""
TARGETS = {
    "vplane": ("`vplane` on a U escape and a BARN world",),
    "vplane_plus": ("`vplane_plus` on the same",),
    "dwa": ("`dwa` on the same",),
    "jackal": ("Jackal, laser, `vplane_plus` on a protocol world",),
}
"""The rows of the run-loop overhead's targets (docs/benchmarks/overhead.md, a dated record)."""
TRAINING = "mean BARN score (BARN's OT)"
README_FIGURES = (
    (
        RESULTS + "barn_protocol_ten_seeds/barn_protocol.md",
        rf"`vplane_plus` reached the goal without a collision in all {FIGURE} runs, "
        rf"mean BARN score {FIGURE}; the footprint-aware `dwa` {FIGURE}, {FIGURE} collisions, {FIGURE}; "
        rf"BARN's own DWA baseline reports {FIGURE}, {FIGURE} collisions, {FIGURE}",
        [
            (("vplane_plus",), "runs"),
            (("vplane_plus",), "mean_score"),
            (("dwa",), "success_rate"),
            (("dwa",), "collision_rate"),
            (("dwa",), "mean_score"),
            (("BARN: DWA baseline",), "success_rate"),
            (("BARN: DWA baseline",), "collision_rate"),
            (("BARN: DWA baseline",), "mean_score"),
        ],
    ),
    (
        "docs/barn.md",
        rf"`vplane_plus` reaches {FIGURE} of the goals without a collision, mean score {FIGURE} "
        rf"\({FIGURE} on the EKF pose a real stack drives on, `--set sensors.pose=ekf`\), "
        rf"beside the 2024 challenge winner's {FIGURE} on the test worlds' leaderboard",
        [
            (("`vplane_plus`, true pose (seeds 0-2)",), "success"),
            (("`vplane_plus`, true pose (seeds 0-2)",), TRAINING),
            (("`vplane_plus`, EKF (seeds 0-2)",), TRAINING),
            (("BARN 2024 winner (leaderboard; test worlds)",), TRAINING),
        ],
    ),
    (
        RESULTS + "dynabarn/dynabarn.md",
        rf"`apf` reached the goal without a collision in {FIGURE} of the runs "
        rf"\({FIGURE} on the hard third\), `vplane_plus` {FIGURE} \({FIGURE}\), `dwa` {FIGURE}; "
        rf"DynaBARN's own DWA baseline reports {FIGURE} / {FIGURE} / {FIGURE} on its easy, medium and hard "
        rf"thirds. The best planners still collide in {FIGURE} of their runs",
        [
            (("apf", "all"), "success_rate"),
            (("apf", "hard"), "success_rate"),
            (("vplane_plus", "all"), "success_rate"),
            (("vplane_plus", "hard"), "success_rate"),
            (("dwa", "all"), "success_rate"),
            (("DynaBARN: DWA", "easy"), "success_rate"),
            (("DynaBARN: DWA", "medium"), "success_rate"),
            (("DynaBARN: DWA", "hard"), "success_rate"),
            (("apf", "all"), "collision_rate"),
        ],
    ),
    (
        "docs/benchmarks/overhead.md",
        rf"A `vplane` run of `paper_c_escape` costs {RANGE} times MuJoCo's bare physics of the same "
        rf"world and steps \({RANGE} with its MCAP log\), `vplane_plus` {RANGE} and `dwa` {FIGURE}; "
        rf"the Jackal's governed, laser-mapping `vplane_plus` {RANGE} on BARN protocol worlds "
        rf"\({RANGE} with its log\)",
        [
            (TARGETS["vplane"], "measured without log", 0),  # paper_c_escape, then the BARN world
            (TARGETS["vplane"], "measured without log", 1),
            (TARGETS["vplane"], "measured with log", 0),
            (TARGETS["vplane"], "measured with log", 1),
            (TARGETS["vplane_plus"], "measured without log", 0),
            (TARGETS["vplane_plus"], "measured without log", 1),
            (TARGETS["dwa"], "measured without log", 0),
            (TARGETS["jackal"], "measured without log", 0),  # the least of world 1, the most of world 10
            (TARGETS["jackal"], "measured without log", 3),
            (TARGETS["jackal"], "measured with log", 0),
            (TARGETS["jackal"], "measured with log", 3),
        ],
    ),
    (
        RESULTS + "overhead_dynabarn/overhead.md",
        rf"Among DynaBARN's moving cylinders a run costs more, {RANGE} times its floor for `apf` "
        rf"and {RANGE} for `vplane_plus`",
        [
            (("dynabarn_0_hard_041", "`apf`"), "run / floor"),
            (("dynabarn_0_medium_020", "`apf`"), "run / floor"),
            (("dynabarn_0_hard_041", "`vplane_plus`"), "run / floor"),
            (("dynabarn_0_medium_020", "`vplane_plus`"), "run / floor"),
        ],
    ),
)
"""What the README quotes from a table: the file that holds it (a result table, or the page that
keeps it as a dated record), the README's sentence with each figure as a group, and for each
group the table's cell it quotes (the leading cells of its row, its column, and which of the
cell's numbers when it holds several, the first by default)."""


@dataclass(frozen=True)
class Step:
    """A shell block of the page and the output shown right under it (lines, maybe none)."""

    command: str
    output: tuple[str, ...]


def fenced_blocks(text: str) -> list[tuple[str, str, int, int]]:
    """The page's fenced code blocks: (language, body (dedented), start, end offset)."""
    return [(m[2], textwrap.dedent(m[3]), m.start(), m.end()) for m in FENCE.finditer(text)]


def page_steps(text: str) -> list[Step]:
    """The commands a user types after the set-up: every `sh` block but the set-up's (those
    install with apt-get), each with the `text` block that directly follows it, if any."""
    blocks = fenced_blocks(text)
    found = []
    for k, (language, body, _, end) in enumerate(blocks):
        if language != "sh" or "apt-get" in body:
            continue
        output: tuple[str, ...] = ()
        if k + 1 < len(blocks):
            next_language, next_body, next_start, _ = blocks[k + 1]
            if next_language == "text" and not text[end:next_start].strip():
                output = tuple(next_body.splitlines())
        found.append(Step(body, output))
    return found


def setup_blocks(text: str) -> list[str]:
    """The set-up commands of a page: its `sh` blocks that install with apt-get."""
    blocks = fenced_blocks(text)
    return [body.strip() for language, body, _, _ in blocks if language == "sh" and "apt-get" in body]


COMMAND_PAGES = {"getting-started": GETTING_STARTED, "own-planner": ROOT / "docs" / "own-planner.md"}
"""The pages whose every command is run as a user types it, each page in a home of its own."""
STEPS = {name: page_steps(page.read_text(encoding="utf-8")) for name, page in COMMAND_PAGES.items()}
COMMANDS = [(name, index) for name, steps in STEPS.items() for index in range(len(steps))]


def normalised(line: str) -> str:
    """A line with its runs of white space made one space."""
    return " ".join(line.split())


def line_pattern(shown: str) -> re.Pattern[str]:
    """What a line the page shows stands for: its text, with any number in place of each number
    (times and the last digits of floating point vary between machines) and any text in place of
    `...`."""

    def literal(part: str) -> str:
        pieces, last = [], 0
        for number in NUMBER.finditer(part):
            pieces += [re.escape(part[last : number.start()]), NUMBER.pattern]
            last = number.end()
        return "".join([*pieces, re.escape(part[last:])])

    return re.compile(".*".join(literal(part) for part in normalised(shown).split(OMITTED)))


def unmatched(shown: tuple[str, ...], printed: str) -> list[str]:
    """The lines the page shows that the command did not print, in the page's order."""
    lines = [normalised(line) for line in printed.splitlines()]
    missing, at = [], 0
    for line in shown:
        if normalised(line) == OMITTED or not line.strip():
            continue
        pattern = line_pattern(line)
        found = next((k for k in range(at, len(lines)) if pattern.fullmatch(lines[k])), None)
        if found is None:
            missing.append(line)
        else:
            at = found + 1
    return missing


def user_environment(home: Path) -> dict[str, str]:
    """The environment of a shell after the set-up: the package's console script on the PATH,
    this checkout's package imported, and an empty reference-path cache of its own."""
    scripts = Path(sysconfig.get_path("scripts"))
    assert (scripts / "vplane-mj").is_file(), f"no vplane-mj in {scripts}: set up as the README says"
    return {
        **os.environ,
        "PATH": f"{scripts}{os.pathsep}{os.environ.get('PATH', '')}",
        "PYTHONPATH": str(ROOT),
        "VPLANE_MJ_CACHE": str(home / ".cache" / "vplane-mj"),
    }


@pytest.fixture(scope="module")
def sessions(tmp_path_factory) -> Any:
    """A page's commands run one after the other in a temporary copy of the repository's data,
    as one user would: (that directory, what each command did), each page once."""
    done: dict[str, tuple[Path, list[subprocess.CompletedProcess[str]]]] = {}

    def session(name: str) -> tuple[Path, list[subprocess.CompletedProcess[str]]]:
        if name not in done:
            home = tmp_path_factory.mktemp(f"user-{name}")
            done[name] = home, run_steps(STEPS[name], home)
        return done[name]

    return session


def run_steps(steps: list[Step], home: Path) -> list[subprocess.CompletedProcess[str]]:
    """Run `steps` one after the other in `home`, a copy of the repository's data."""
    for data in REPOSITORY_DATA:
        shutil.copytree(ROOT / data, home / data)
    environment = user_environment(home)
    done = []
    for step in steps:
        done.append(
            subprocess.run(
                ["bash", "-e", "-o", "pipefail", "-c", step.command],
                cwd=home,
                env=environment,
                stdout=subprocess.PIPE,
                stderr=subprocess.STDOUT,
                text=True,
                timeout=600,
            )
        )
    return done


def test_the_pages_have_commands_with_their_output():
    started = STEPS["getting-started"]
    assert len(started) >= 10
    assert sum(1 for step in started if step.output) >= 8
    assert any(step.command.startswith("vplane-mj run paper_c_escape\n") for step in started)
    own = STEPS["own-planner"]
    assert len(own) >= 3 and sum(1 for step in own if step.output) >= 2
    assert any("planner.governor=false" in step.command for step in own)


@pytest.mark.slow  # the pages' commands as processes, one after another: about a minute
@pytest.mark.parametrize(
    ("page", "index"),
    COMMANDS,
    ids=[f"{page}: {STEPS[page][index].command.split(chr(10))[0][:60]}" for page, index in COMMANDS],
)
def test_a_command_of_the_page_exits_0_and_prints_and_writes_what_it_shows(sessions, page, index):
    home, done = sessions(page)
    step, result = STEPS[page][index], done[index]
    assert result.returncode == 0, f"$ {step.command}\n{result.stdout}"
    assert "Traceback" not in result.stdout, result.stdout
    assert unmatched(step.output, result.stdout) == [], f"$ {step.command}\n{result.stdout}"
    for line in step.output:
        if line.startswith("wrote "):
            path = home / line.removeprefix("wrote ")
            assert path.is_file() and path.stat().st_size > 0, path


@pytest.mark.slow  # the page's commands, as above
def test_getting_started_takes_a_frame_and_a_gif_out_of_a_video_with_the_installed_ffmpeg(sessions):
    home, _ = sessions("getting-started")
    assert any("imageio_ffmpeg.get_ffmpeg_exe()" in step.command for step in STEPS["getting-started"])
    reader = imageio_ffmpeg.read_frames(str(home / "run.mp4"))
    width, height = next(reader)["size"]
    (fifth_second,) = itertools.islice(reader, 5 * 25, 5 * 25 + 1)  # the frame at 5 s, 25 a second
    reader.close()
    with Image.open(home / "frame.png") as png:
        assert png.format == "PNG" and png.size == (width, height)
        frame = np.asarray(png.convert("RGB"))
    assert np.array_equal(frame, np.frombuffer(fifth_second, np.uint8).reshape(height, width, 3))
    with Image.open(home / "clip.gif") as gif:
        assert gif.format == "GIF" and gif.size[0] == 480 and gif.info.get("loop") == 0
        assert gif.n_frames == 4 * 10  # 4 s at 10 frames a second


def test_shown_output_must_match_what_was_printed():
    printed = "run [vplane, seed 2]: reached after 30.00 s\nwrote logs/a.json\n"
    assert unmatched(("run [vplane, seed 0]: reached after 31.5 s", "wrote logs/a.json"), printed) == []
    assert unmatched(("run [vplane, seed 0]: stuck after 31.5 s",), printed) != []
    assert unmatched(("wrote logs/a.json", "run ... reached after 1 s"), printed) != []  # order
    assert unmatched(("...", "wrote logs/a.json"), printed) == []
    assert unmatched(("wrote logs/b.json",), printed) != []


def test_the_set_up_commands_are_the_readme_s():
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    page = GETTING_STARTED.read_text(encoding="utf-8")
    assert setup_blocks(page) == setup_blocks(readme)
    assert len(setup_blocks(page)) == 2


def without_code(text: str) -> str:
    """Markdown without its code blocks and code spans (where brackets are code, not links)."""
    return INLINE_CODE.sub("", FENCE.sub("", text))


def heading_anchors(page: Path) -> set[str]:
    """The anchors of a Markdown page's headings, as GitHub and MkDocs make them."""
    anchors = set()
    for line in without_code(page.read_text(encoding="utf-8")).splitlines():
        if re.match(r"#{1,6} ", line):
            title = re.sub(r"[^\w\- ]", "", line.lstrip("#").strip().lower())
            anchors |= {title.replace(" ", "-"), re.sub(r"[-\s]+", "-", title).strip("-")}
    return anchors


def relative_links(page: Path) -> list[str]:
    """The targets of a page's links and images that are neither web addresses nor anchors alone."""
    targets = LINK.findall(without_code(page.read_text(encoding="utf-8")))
    return [target for target in targets if not re.match(r"[a-z][a-z0-9+.-]*:", target) and target[0] != "#"]


@pytest.mark.parametrize("page", PAGES, ids=[str(page.relative_to(ROOT)) for page in PAGES])
def test_every_relative_link_points_at_a_file_that_exists(page):
    assert [link for link in relative_links(page) if not points_at_something(page, link)] == []


def points_at_something(page: Path, link: str) -> bool:
    """Whether a relative link of `page` names a file that exists and, in a Markdown file, a
    heading that exists."""
    path, _, anchor = link.partition("#")
    target = (page.parent / path).resolve()
    if not target.exists():
        return False
    return not (anchor and target.suffix == ".md" and anchor not in heading_anchors(target))


def test_links_are_found_and_judged():
    assert "images/paper_c_escape-vplane-0.png" in relative_links(GETTING_STARTED)
    assert "your-own-planner" in heading_anchors(GETTING_STARTED)
    assert points_at_something(GETTING_STARTED, "robots.md#the-laser")
    assert not points_at_something(GETTING_STARTED, "robots.md#no-such-heading")
    assert not points_at_something(GETTING_STARTED, "no-such-page.md")


def test_the_own_planner_page_s_half_speed_planner_reads_the_robot_it_drives(doc_examples, own_registry):
    import vplane_mj

    script = doc_examples("own-planner.md", "Parameters and class attributes")
    names: dict[str, Any] = {}
    exec(compile(script, "docs/own-planner.md", "exec"), names)
    own_registry.register(names["HalfSpeedPlanner"])
    times = {}
    for profile in ("default", "turtlebot3_burger", "pioneer3dx"):
        overrides = ["planner.name=half_speed", f"robot.profile={profile}"]
        summary = vplane_mj.run(vplane_mj.load_scenario("open_field", overrides), out=None).summary
        assert summary.reached, profile
        times[profile] = summary.time_to_goal_s
    # top speeds 0.5, 0.22 and 1.2 m/s: half of each over the same 5.5 m
    assert times["pioneer3dx"] < times["default"] < times["turtlebot3_burger"]


INCLUDED = sorted({match for page in PAGES for match in INCLUDE.findall(page.read_text(encoding="utf-8"))})


def table_cells(text: str) -> list[dict[str, str]]:
    """The rows of every Markdown table in `text`, each as its header's cells -> its cells."""
    lines = text.splitlines()
    rows, header = [], []
    for k, line in enumerate(lines):
        if not line.startswith("|") or line.startswith("|---"):
            continue
        cells = [cell.strip() for cell in line.strip().strip("|").split("|")]
        if k + 1 < len(lines) and lines[k + 1].startswith("|---"):
            header = cells
        else:
            rows.append(dict(zip(header, cells, strict=True)))
    return rows


def result_cell(table: str, row: tuple[str, ...], column: str) -> str:
    """The cell of a result table's row (its leading cells) and column."""
    (found,) = [cells for cells in table_cells(table) if tuple(cells.values())[: len(row)] == row]
    return found[column]


CELL_NUMBER = re.compile(r"\d+(?:\.\d+)?")
"""A number of a table's cell ("1.47-1.50, 1.62-1.67" holds four, none negative)."""


def quotes(figure: str, cell: str, which: int = 0) -> bool:
    """Whether a figure the README quotes is the `which`-th number of a table's cell, as the cell
    writes it or rounded half up to the figure's decimals ("3.2" quotes "3.15")."""
    quoted = Decimal(figure)
    return Decimal(CELL_NUMBER.findall(cell)[which]).quantize(quoted, rounding=ROUND_HALF_UP) == quoted


def test_the_pages_include_the_benchmarks_result_tables():
    assert len(INCLUDED) >= 20


@pytest.mark.parametrize("included", INCLUDED)
def test_an_included_result_table_exists_and_says_how_and_when_it_was_measured(included):
    table = ROOT / included
    sidecar = json.loads(table.with_suffix(".json").read_text(encoding="utf-8"))
    assert sidecar["command"].startswith("python benchmarks/"), sidecar["command"]
    datetime.fromisoformat(sidecar["date"])  # a date, UTC ISO 8601
    measurement = Measurement(sidecar["command"], sidecar["date"], sidecar["machine"])
    text = table.read_text(encoding="utf-8")
    assert text.rstrip("\n").endswith("\n\n" + measurement.line())
    assert table_cells(text) and table.with_suffix(".csv").is_file()


@pytest.mark.parametrize(
    ("source", "sentence", "cells"), README_FIGURES, ids=[source for source, _, _ in README_FIGURES]
)
def test_the_readme_quotes_its_figures_from_the_tables(source, sentence, cells):
    readme = " ".join((ROOT / "README.md").read_text(encoding="utf-8").split())
    quoted = re.search(sentence, readme)
    assert quoted is not None, sentence
    table = (ROOT / source).read_text(encoding="utf-8")
    for figure, (row, column, *which) in zip(quoted.groups(), cells, strict=True):
        cell = result_cell(table, row, column)
        assert quotes(figure, cell, *which), (figure, row, column, cell)


def test_result_cells_are_found_by_row_and_column():
    table = "| planner | third | rate |\n|---|---|---|\n| apf | easy | 50.0% |\n| apf | all | 7.0% |\n"
    assert result_cell(table, ("apf", "all"), "rate") == "7.0%"
    with pytest.raises(ValueError):  # two rows
        result_cell(table, ("apf",), "rate")
    assert quotes("7.0", "7.0%") and quotes("7", "7.0%") and not quotes("7.1", "7.0%")
    assert quotes("3.2", "3.15") and quotes("2.8", "2.81") and not quotes("3.1", "3.15")
    assert quotes("1.94", "1.85-1.89, 1.87-1.94", 3) and not quotes("1.89", "1.85-1.89, 1.87-1.94", 3)


REFERENCE_PAGES = sorted((ROOT / "docs" / "reference").glob("*.md"))
DIRECTIVE = re.compile(r"^::: ([\w.]+)[ \t]*$", re.M)
"""A reference page's mkdocstrings entry: `::: dotted.path` of the object it documents."""
PUBLIC = [(vplane_mj, name) for name in vplane_mj.__all__] + [
    (vplane_mj.planning, name) for name in vplane_mj.planning.__all__
]


def reference_entries() -> list[str]:
    """The dotted paths of every `:::` entry of the reference pages."""
    return [path for page in REFERENCE_PAGES for path in DIRECTIVE.findall(page.read_text(encoding="utf-8"))]


def documented_object(path: str) -> object:
    """The object an entry's dotted path names: its longest importable module, then attributes."""
    parts = path.split(".")
    for split in range(len(parts), 0, -1):
        try:
            found: object = importlib.import_module(".".join(parts[:split]))
        except ModuleNotFoundError:
            continue
        for attribute in parts[split:]:
            found = getattr(found, attribute)
        return found
    raise ModuleNotFoundError(path)


@pytest.mark.parametrize(("module", "name"), PUBLIC, ids=[f"{m.__name__}.{n}" for m, n in PUBLIC])
def test_every_public_name_has_an_entry_on_a_reference_page(module, name):
    exported = getattr(module, name)
    entries = [path for path in reference_entries() if path.rsplit(".", 1)[-1] == name]
    assert any(documented_object(path) is exported for path in entries), (
        f"{module.__name__}.{name}: no `::: ...{name}` entry in docs/reference/ documents it"
    )


def test_reference_entries_are_found_and_resolved():
    assert "vplane_mj.runner.run" in reference_entries()
    assert documented_object("vplane_mj.runner.run") is vplane_mj.run
    assert "vplane_mj.files.OutputBusy" not in DIRECTIVE.findall("Text ::: vplane_mj.files.OutputBusy\n")


SECTION_ENTRY = re.compile(r"^    (\w+)(?: \([^)]*\))?: ?(.*)$")
"""An entry of a Google-style docstring section: `name: text` or `name (type): text`."""


def docstring_section(doc: str, title: str) -> dict[str, str]:
    """The entries of a docstring's section (`Attributes`, `Args`, ...): name -> its text, its
    continuation lines joined, in the docstring's order; empty without the section."""
    entries: dict[str, str] = {}
    inside, name = False, None
    for line in inspect.cleandoc(doc).splitlines():
        if not line.startswith(" "):
            inside, name = line == f"{title}:", None
            continue
        if inside:
            entry = SECTION_ENTRY.match(line)
            if entry:
                name = entry[1]
                entries[name] = entry[2]
            elif name is not None and line.startswith("        "):
                entries[name] += " " + line.strip()
    return entries


def field_table(cls: type) -> dict[str, str]:
    """The entries of a dataclass's docstring that stand for its fields: its Attributes section,
    or for a dataclass the caller fills in (`Decision`), its Args section."""
    doc = cls.__doc__ or ""
    return docstring_section(doc, "Attributes") or docstring_section(doc, "Args")


def member_docstrings(cls: type) -> dict[str, str | None]:
    """Each attribute assigned in a class's body -> the string literal right under it, if any."""
    (node,) = ast.parse(textwrap.dedent(inspect.getsource(cls))).body
    assert isinstance(node, ast.ClassDef)
    found: dict[str, str | None] = {}
    for statement, after in zip(node.body, [*node.body[1:], None], strict=True):
        if isinstance(statement, ast.Assign | ast.AnnAssign):
            targets = statement.targets if isinstance(statement, ast.Assign) else [statement.target]
            docstring = None
            if isinstance(after, ast.Expr) and isinstance(after.value, ast.Constant):
                docstring = str(after.value.value)
            for target in targets:
                if isinstance(target, ast.Name):
                    found[target.id] = docstring
    return found


DOCUMENTED = {path: documented_object(path) for path in reference_entries()}
DATACLASSES = sorted(
    path
    for path, found in DOCUMENTED.items()
    if isinstance(found, type) and dataclasses.is_dataclass(found) and dataclasses.fields(found)
)
"""The dataclasses the reference pages document that have fields."""
ENUMS = sorted(path for path, found in DOCUMENTED.items() if isinstance(found, enum.EnumMeta))
"""The enums the reference pages document."""


@pytest.mark.parametrize("path", DATACLASSES)
def test_a_documented_dataclass_lists_every_field_in_its_docstring_s_table(path):
    cls = DOCUMENTED[path]
    fields = [item.name for item in dataclasses.fields(cls)]
    assert list(field_table(cls)) == fields, f"{path}: its Attributes section, in the fields' order"


@pytest.mark.parametrize("path", [path for path in DATACLASSES if hasattr(DOCUMENTED[path], "table")])
def test_a_documented_parameter_group_gives_each_parameter_s_unit(path):
    entries = field_table(DOCUMENTED[path])
    for name, spec in DOCUMENTED[path].table().items():
        if spec.unit:
            assert f"({spec.unit})" in entries[name], f"{path}.{name}: ({spec.unit}) in its entry"


def parameters_to_document(found: object) -> list[str]:
    """The parameters a documented function, or a class that is not a dataclass (its
    constructor), takes: those its Args section must name."""
    target = found.__init__ if isinstance(found, type) else found  # type: ignore[misc]
    if isinstance(found, type) and (dataclasses.is_dataclass(found) or target is object.__init__):
        return []
    try:
        signature = inspect.signature(target)
    except (TypeError, ValueError):
        return []
    skipped = (inspect.Parameter.VAR_POSITIONAL, inspect.Parameter.VAR_KEYWORD)
    return [
        name
        for name, p in signature.parameters.items()
        if name not in ("self", "cls") and p.kind not in skipped
    ]


CALLABLES = sorted(
    path
    for path, found in DOCUMENTED.items()
    if callable(found) and not isinstance(found, enum.EnumMeta) and parameters_to_document(found)
)
"""The functions and classes the reference pages document that take parameters."""


@pytest.mark.parametrize("path", CALLABLES)
def test_a_documented_callable_names_every_parameter_in_its_args(path):
    found = DOCUMENTED[path]
    documented = docstring_section(found.__doc__ or "", "Args")
    if isinstance(found, type) and not documented:
        documented = docstring_section(found.__init__.__doc__ or "", "Args")
    missing = [name for name in parameters_to_document(found) if name not in documented]
    assert missing == [], f"{path}: parameters without an Args entry"


@pytest.mark.parametrize("path", ENUMS)
def test_every_member_of_a_documented_enum_has_its_docstring(path):
    members = member_docstrings(DOCUMENTED[path])
    assert list(members) == [member.name for member in DOCUMENTED[path]]
    assert [name for name, doc in members.items() if not doc] == [], f"{path}: members without docstring"


def test_docstring_tables_are_read_and_judged():
    @dataclass
    class Pair:
        """Two numbers.

        Attributes:
            first: The first (m), on a line
                and the next.
            second (float): The second.

        Raises:
            ValueError: never.
        """

        first: float
        second: float
        third: float = 0.0

    assert docstring_section(Pair.__doc__ or "", "Attributes") == {
        "first": "The first (m), on a line and the next.",
        "second": "The second.",
    }
    assert list(field_table(Pair)) != [item.name for item in dataclasses.fields(Pair)]  # third
    assert "vplane_mj.planning.planners.groups.FieldParams" in DATACLASSES
    assert "vplane_mj.planning.protocol.events.EventKind" in ENUMS

    class Kind(enum.StrEnum):
        A = "a"
        """Documented."""
        B = "b"

    assert member_docstrings(Kind) == {"A": "Documented.", "B": None}
