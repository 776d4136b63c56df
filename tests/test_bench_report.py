"""The sweep's report: success heatmaps and the self-contained bench.html."""

import re
from html.parser import HTMLParser

import numpy as np
import pytest

from vplane_mj.bench import report as bench_report
from vplane_mj.bench.sweep import family_of, summarize
from vplane_mj.scenario import load_scenario


def row(scenario: str, planner: str, seed: int, success: bool, **extra) -> dict:
    return {
        "key": f"{scenario}|{planner}|{seed}",
        "scenario": scenario,
        "planner": planner,
        "seed": seed,
        "success": success,
        "reached": success,
        "outcome": "reached" if success else "stuck",
        "time_to_goal_s": 20.0 if success else None,
        "path_length_m": 8.0,
        "path_ratio": 1.2 if success else None,
        "collisions": 0,
        "escapes": 1,
        **extra,
    }


ROWS = [
    row("traps_1_000", "vplane", 0, True),
    row("traps_1_000", "vplane", 1, True),
    row("traps_1_001", "vplane", 0, False),
    row("traps_1_000", "apf", 0, False),
    row("traps_1_000", "apf", 1, True),
    row("clutter_1_000", "vplane", 0, True),
]


def test_success_per_planner_and_family():
    grid = bench_report.success_grid(ROWS, lambda r: family_of(r["scenario"]))
    assert grid.planners == ["vplane", "apf"] and grid.columns == ["traps", "clutter"]
    np.testing.assert_array_equal(grid.runs, [[3, 1], [2, 0]])
    np.testing.assert_array_equal(grid.successes, [[2, 1], [1, 0]])
    np.testing.assert_allclose(grid.rates, [[2 / 3, 1.0], [0.5, np.nan]])


def test_success_per_planner_and_scenario():
    grid = bench_report.success_grid(ROWS, lambda r: r["scenario"])
    assert grid.columns == ["traps_1_000", "traps_1_001", "clutter_1_000"]
    np.testing.assert_allclose(grid.rates, [[1.0, 0.0, 1.0], [0.5, np.nan, np.nan]])


def test_the_scenario_heatmap_grows_with_the_scenarios_up_to_its_limit():
    few = [row(f"traps_1_{i:03d}", p, 0, i % 3 > 0) for i in range(30) for p in ("apf", "vplane")]
    figure = bench_report.scenario_figure(few)
    width, height = figure.get_size_inches()
    assert height >= 0.24 * 30 and width < height  # one row of about 0.24 in per scenario
    texts = [t.get_text() for t in figure.axes[0].texts]
    assert len(texts) == 60 and set(texts) == {"yes", "no"}  # one seed: each cell says it
    bench_report.png_bytes(figure)


def test_of_300_scenarios_the_heatmap_shows_the_hardest_and_says_so():
    # Scenario i fails with both planners when i is a multiple of 7 (43 of them), with one when i % 7 == 1.
    rows = [
        row(f"barn_{i:03d}", p, 0, not (i % 7 == 0 or (i % 7 == 1 and p == "apf")))
        for i in range(300)
        for p in ("apf", "vplane")
    ]
    figure = bench_report.scenario_figure(rows)
    limit = bench_report.MAX_SCENARIO_ROWS
    assert figure.get_size_inches()[1] < 1.6 + 0.24 * limit + 1  # readable: at most `limit` rows tall
    assert figure.axes[0].get_title() == f"the {limit} of 300 scenarios with the lowest success"
    shown = [label.get_text() for label in figure.axes[0].get_yticklabels()]
    assert shown == [f"barn_{i:03d}" for i in range(0, 300, 7)][:limit]  # the first 40 that both failed
    assert {t.get_text() for t in figure.axes[0].texts} == {"no"}
    bench_report.png_bytes(figure)


class Tags(HTMLParser):
    """Every start tag with its attributes, and the text."""

    def __init__(self):
        super().__init__()
        self.tags: list[tuple[str, dict]] = []
        self.text: list[str] = []

    def handle_starttag(self, tag, attrs):
        self.tags.append((tag, dict(attrs)))

    def handle_data(self, data):
        self.text.append(data)


@pytest.fixture(scope="module")
def page():
    scenario = load_scenario("paper_c_escape")
    tomls = {r["key"]: scenario.to_toml() for r in ROWS[:5]}  # the last run's scenario is unknown
    rows = [dict(r, path_xy=[[4.2, 5.2], [3.8, 5.2], [3.7, 6.1]]) for r in ROWS[:-1]] + [ROWS[-1]]
    table = [{"planner": "vplane", "runs": 4, "success_rate": 0.75}, {"planner": "apf", "runs": 2}]
    text = bench_report.write_html_text(
        rows, table, summarize(rows, by_scenario=True), tomls, {"a figure": b"\x89PNG fake"}
    )
    parser = Tags()
    parser.feed(text)
    return text, parser


def test_the_page_loads_nothing_from_anywhere(page):
    text, parser = page
    for tag, attrs in parser.tags:
        assert tag not in ("script", "link", "iframe", "object", "embed"), tag
        for name in ("src", "href"):
            value = attrs.get(name, "")
            assert not re.match(r"\s*(https?:)?//", value), (tag, value)
            assert not value or value.startswith(("data:", "#")), (tag, value)
    assert "@import" not in text and "url(" not in text
    (image,) = [attrs for tag, attrs in parser.tags if tag == "img"]
    assert image["src"].startswith("data:image/png;base64,")


def test_every_run_opens_to_its_summary_and_path(page):
    text, parser = page
    assert text.count("<details") == len(ROWS) == text.count("<summary>")
    for r in ROWS:
        assert f"<span>{r['scenario']}</span><span>{r['planner']}</span><span>{r['seed']}</span>" in text
    cells = "".join(parser.text)
    assert cells.count('"outcome": ') == cells.count('"escapes": 1') == len(ROWS)  # each summary, once
    assert '"key"' not in cells and "path_xy" not in cells  # shown as the picture, not as text
    symbols = [attrs["id"] for tag, attrs in parser.tags if tag == "symbol"]
    assert symbols == ["world0"]  # one drawing of the world, shared by its runs
    uses = [attrs["href"] for tag, attrs in parser.tags if tag == "use"]
    assert uses == ["#world0"] * 5
    assert text.count("<polyline") == 5 and "no picture: the scenario is unknown" in text
    assert "success_rate" in cells and "0.75" in cells
