"""`vplane-mj generate`: seeded, valid, solvable scenario files."""

import numpy as np
import pytest

from vplane_mj.cli import main
from vplane_mj.geometry.reference import shortest_path_length
from vplane_mj.robots.facts import robot_radius_m
from vplane_mj.scenario import load_scenario
from vplane_mj.worlds.families import BARN_CELL_M, FAMILIES, barn_cells, cell_rectangles

pytestmark = pytest.mark.slow  # a long suite: `python -m pytest -m slow` runs it


@pytest.mark.parametrize("family", ["traps", "clutter", "corridors", "barn"])
def test_a_family_is_deterministic_valid_and_solvable(tmp_path, capsys, family):
    first, second = tmp_path / "a", tmp_path / "b"
    first.mkdir()
    second.mkdir()
    assert main(["generate", family, "--count", "4", "--seed", "7", "--out", str(first)]) == 0
    assert main(["generate", family, "--count", "4", "--seed", "7", "--out", str(second)]) == 0
    files = sorted(first.glob("*.toml"))
    assert len(files) == 4
    for path in files:
        assert path.read_text() == (second / path.name).read_text()
        scenario = load_scenario(str(path))
        clearance = FAMILIES[family].clearance_m
        assert shortest_path_length(scenario, robot_radius_m(), clearance) is not None
    other = tmp_path / "c"
    other.mkdir()
    main(["generate", family, "--count", "4", "--seed", "8", "--out", str(other)])
    assert [p.read_text() for p in sorted(other.glob("*.toml"))] != [p.read_text() for p in files]
    capsys.readouterr()


@pytest.mark.parametrize("argv", [["spirals"], ["traps", "--count", "0"], ["traps", "--seed", "-1"]])
def test_bad_arguments_exit_2_and_write_nothing(tmp_path, capsys, argv):
    assert main(["generate", *argv, "--out", str(tmp_path)]) == 2
    assert list(tmp_path.iterdir()) == []
    assert "Traceback" not in capsys.readouterr().err


def test_barn_rectangles_cover_exactly_the_filled_cells():
    rng = np.random.default_rng(3)
    for _ in range(20):
        grid = barn_cells(rng)
        covered = np.zeros(grid.shape, dtype=int)
        for row0, col0, rows, cols in cell_rectangles(grid):
            covered[row0 : row0 + rows, col0 : col0 + cols] += 1
        np.testing.assert_array_equal(covered, grid.astype(int))  # every cell once, no overlap


def test_barn_worlds_span_the_difficulty_of_the_original(tmp_path, capsys):
    """Open fields and dense ones with only narrow passages: the fill and smoothing vary."""
    assert main(["generate", "barn", "--count", "12", "--seed", "0", "--out", str(tmp_path)]) == 0
    capsys.readouterr()
    scenarios = [load_scenario(str(p)) for p in sorted(tmp_path.glob("*.toml"))]
    filled = []
    for scenario in scenarios:
        assert scenario.world.size == pytest.approx((4.2, 10.5))
        assert scenario.robot.goal[1] - scenario.robot.start[1] == pytest.approx(8.7)
        filled.append(sum(ob.size[0] * ob.size[1] for ob in scenario.world.obstacles) / BARN_CELL_M**2)
    assert min(filled) < 0.1 * 28 * 30 < 0.25 * 28 * 30 < max(filled)
