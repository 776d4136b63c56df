"""A run recomputed from its MCAP log alone: `vplane-mj summary` and `vplane-mj render`."""

import json

import matplotlib.image
import numpy as np
import pytest

from vplane_mj.cli import main
from vplane_mj.viz import palette


def run_logged(tmp_path, capsys, *argv):
    code = main(["run", *argv, "--out", str(tmp_path)])
    capsys.readouterr()
    return code


@pytest.mark.parametrize(
    "argv, base",
    [
        (["paper_c_escape"], "paper_c_escape-vplane-0"),
        (["paper_h_avoid", "--planner", "apf"], "paper_h_avoid-apf-0"),
        (
            [
                "single_box",
                "--planner",
                "apf",
                "--set",
                "planner.repulse_gain=0",
                "--set",
                "run.time_limit_s=20",
            ],
            "single_box-apf-0",
        ),
        (  # a rectangular robot: the clearance of its footprint, not of its circumscribed disc
            ["paper_c_avoid", "--set", "robot.profile=jackal", "--set", "run.time_limit_s=15"],
            "paper_c_avoid-vplane-0",
        ),
    ],
)
def test_summary_from_the_log_agrees_with_the_run(tmp_path, capsys, argv, base):
    run_logged(tmp_path, capsys, *argv)
    code = main(["summary", str(tmp_path / f"{base}.mcap")])
    out = capsys.readouterr().out
    assert code == 0 and "agrees with the run's stored summary" in out
    recomputed = json.loads(out[: out.index("\nevents:")])
    stored = json.loads((tmp_path / f"{base}.json").read_text())
    for key in ("outcome", "collisions", "local_minima", "escapes", "reached"):
        assert recomputed[key] == stored[key]
    assert recomputed["path_length_m"] == pytest.approx(stored["path_length_m"], abs=0.01)
    assert recomputed["min_clearance_m"] == pytest.approx(stored["min_clearance_m"], abs=0.01)


def test_render_from_the_log_matches_the_run_render(tmp_path, capsys):
    run_logged(tmp_path, capsys, "paper_c_escape")
    target = tmp_path / "again.png"
    assert main(["render", str(tmp_path / "paper_c_escape-vplane-0.mcap"), "-o", str(target)]) == 0
    original = matplotlib.image.imread(tmp_path / "paper_c_escape-vplane-0.png")
    again = matplotlib.image.imread(target)
    assert original.shape == again.shape
    differing = np.mean(np.any(np.abs(original - again) > 0.1, axis=-1))
    assert differing < 0.002  # the same picture but for a few pixels


def test_render_colours_the_path_by_planner_mode(tmp_path, capsys):
    run_logged(tmp_path, capsys, "paper_c_escape")
    image = matplotlib.image.imread(tmp_path / "paper_c_escape-vplane-0.png")[..., :3]
    pixels = {
        mode: (np.abs(image - palette.MODE_RGBA[mode][:3]) < 0.02).all(axis=-1).sum()
        for mode in ("normal", "escaping", "avoiding")
    }
    assert pixels["normal"] > 200 and pixels["escaping"] > 50 and pixels["avoiding"] > 100, pixels


@pytest.mark.parametrize("content", [None, b"not an mcap file"])
def test_a_missing_or_foreign_log_is_a_clear_error(tmp_path, capsys, content):
    path = tmp_path / "x.mcap"
    if content is not None:
        path.write_bytes(content)
    assert main(["summary", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"error: {path}") and "Traceback" not in err
    assert main(["render", str(path), "-o", str(tmp_path / "x.png")]) == 2
    assert not (tmp_path / "x.png").exists()


@pytest.mark.slow
def test_plot_from_the_log(tmp_path, capsys):
    run_logged(tmp_path, capsys, "paper_c_escape")
    target = tmp_path / "plot.png"
    assert main(["plot", str(tmp_path / "paper_c_escape-vplane-0.mcap"), "-o", str(target)]) == 0
    image = matplotlib.image.imread(target)
    assert image.shape[1] > 1000 and image.shape[0] > 400
    # the field panel's colour map and the path colours are there, not a blank canvas
    assert np.std(image[..., :3]) > 0.1
    log = str(tmp_path / "paper_c_escape-vplane-0.mcap")
    assert main(["plot", log, "-o", str(tmp_path / "missing" / "x.png")]) == 2


@pytest.mark.slow
@pytest.mark.parametrize("planner", ["vfh", "bug2", "dwa"])
def test_plot_of_a_planner_without_a_potential_field(tmp_path, capsys, planner):
    """The field panel falls back to APF's gains for planners that have none of their own."""
    run_logged(tmp_path, capsys, "open_field", "--planner", planner, "--set", "run.time_limit_s=3")
    target = tmp_path / "plot.png"
    assert main(["plot", str(tmp_path / f"open_field-{planner}-0.mcap"), "-o", str(target)]) == 0
    assert np.std(matplotlib.image.imread(target)[..., :3]) > 0.1
