"""`vplane-mj generate`: seeded, valid, solvable scenario files."""

import pytest

from vplane_mj.cli import main
from vplane_mj.reference import shortest_path_length
from vplane_mj.robot import robot_radius_m
from vplane_mj.scenario import load_scenario


@pytest.mark.parametrize("family", ["traps", "clutter", "corridors"])
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
        assert shortest_path_length(scenario, robot_radius_m()) is not None
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
