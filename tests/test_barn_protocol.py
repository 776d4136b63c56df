"""`vplane-mj generate barn --protocol`: seeded worlds in the BARN challenge's layout, every one
passable for the Jackal."""

import tomllib

import numpy as np
import pytest

from vplane_mj.cli import main
from vplane_mj.geometry.reference import shortest_path_length
from vplane_mj.scenario import parse_document
from vplane_mj.worlds.barn_layout import JACKAL_RADIUS_M
from vplane_mj.worlds.barn_protocol import JACKAL_CELLS, connect_ends, field_cylinders, open_windows


def _generate(out, seed, count=12):
    assert (
        main(
            ["generate", "barn", "--protocol", "--count", str(count), "--seed", str(seed), "--out", str(out)]
        )
        == 0
    )
    return {path.name: path.read_text() for path in sorted(out.glob("*.toml"))}


@pytest.fixture(scope="module")
def seed_0(tmp_path_factory):
    """Twelve worlds of seed 0: {file name: TOML text}."""
    return _generate(tmp_path_factory.mktemp("seed_0"), 0)


def test_the_documents_hold_the_challenges_layout(seed_0):
    assert len(seed_0) == 12
    for name, text in seed_0.items():
        doc = tomllib.loads(text)
        assert f"{doc['name']}.toml" == name and name.startswith("barn_protocol_0_")
        assert doc["world"]["size"] == [4.2, 14.0] and doc["world"]["border"] is True
        assert doc["robot"] == {
            "profile": "jackal",
            "start": [2.1, 2.85],
            "start_yaw_deg": 90.0,
            "goal": [2.1, 12.85],
            "goal_tolerance": 1.0,
        }
        assert doc["run"] == {"time_limit_s": 100.0}


def test_the_obstacles_are_cells_of_the_field(seed_0):
    for text in seed_0.values():
        obstacles = tomllib.loads(text)["world"]["obstacles"]
        assert obstacles and all(ob["kind"] == "cylinder" and ob["radius"] == 0.075 for ob in obstacles)
        centers = np.array([ob["center"] for ob in obstacles])
        columns, rows = centers[:, 0] / 0.15 - 0.5, (centers[:, 1] - 4.95) / 0.15 - 0.5
        np.testing.assert_allclose(columns, np.round(columns), atol=1e-9)
        np.testing.assert_allclose(rows, np.round(rows), atol=1e-9)
        columns, rows = np.round(columns), np.round(rows)
        assert columns.min() >= 0 and columns.max() <= 27 and rows.min() >= 0 and rows.max() <= 30
        assert len({tuple(c) for c in centers}) == len(centers)


def test_every_world_lets_the_jackal_through(seed_0):
    assert JACKAL_RADIUS_M >= 0.33
    for name, text in seed_0.items():
        scenario = parse_document(tomllib.loads(text), name)
        assert shortest_path_length(scenario, JACKAL_RADIUS_M) is not None


def test_the_same_seed_gives_the_same_files_and_another_seed_others(tmp_path, seed_0, capsys):
    assert _generate(tmp_path / "again", 0) == seed_0
    assert set(_generate(tmp_path / "other", 1, 4).values()).isdisjoint(seed_0.values())
    capsys.readouterr()


def test_the_difficulty_varies_from_sparse_to_dense(seed_0):
    filled, reference = [], []
    for name, text in seed_0.items():
        doc = tomllib.loads(text)
        filled.append(len(doc["world"]["obstacles"]) / (28 * 31))
        reference.append(shortest_path_length(parse_document(doc, name), JACKAL_RADIUS_M))
    assert min(filled) < 0.1 and max(filled) > 0.2  # scattered cells to dense blobs
    assert max(reference) - min(reference) > 0.3  # some worlds make the Jackal wind through


def test_protocol_is_for_the_barn_family_only(tmp_path, capsys):
    assert main(["generate", "traps", "--protocol", "--count", "1", "--out", str(tmp_path / "out")]) == 2
    assert "--protocol: only the barn family" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


def test_a_corridor_is_carved_between_the_ends_when_they_are_apart():
    grid = np.zeros((31, 28), dtype=bool)
    grid[14:17, :] = True  # a band across the whole field
    carved, was_carved = connect_ends(grid)
    assert was_carved and grid[14:17].all()  # the input is left as it was
    opened = ~carved[14:17]
    assert opened.any(axis=0).sum() == JACKAL_CELLS and opened.all(axis=0).sum() == JACKAL_CELLS
    assert connect_ends(carved) == (carved, False)  # now one region: nothing more to carve


def test_a_field_closed_at_an_end_is_refused():
    grid = np.zeros((31, 28), dtype=bool)
    grid[0, ::4] = True  # no 5 x 5 window free at the near end
    assert not open_windows(grid)[0].any()
    assert connect_ends(grid) is None


def test_cells_that_nothing_can_reach_get_no_cylinder():
    grid = np.zeros((31, 28), dtype=bool)
    grid[10:13, 10:13] = True  # a 3 x 3 blob: its centre is enclosed
    grid[20:23, 0:2] = True  # against the left wall, which counts as filled: (21, 0) is enclosed
    centers = {tuple(ob["center"]) for ob in field_cylinders(grid)}
    assert len(centers) == 8 + 5
    assert (round(0.15 * 11.5, 6), round(4.95 + 0.15 * 11.5, 6)) not in centers
    assert (0.075, round(4.95 + 0.15 * 21.5, 6)) not in centers
