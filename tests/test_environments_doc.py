"""docs/environments.md, "dm_control on the dm_env environment": its Python examples run in order,
as a reader runs them, and print what the page says; the viewer's window is replaced by
dm_control's runtime, which resets and steps the environment with the policy as the viewer does."""

import re
import warnings
from pathlib import Path

import pytest

from vplane_mj.scenario import load_scenario
from vplane_mj.sim.loop import run_scenario

DOC = Path(__file__).parents[1] / "docs" / "environments.md"
SECTION = "dm_control on the dm_env environment"

with warnings.catch_warnings():  # importing the viewer loads GLFW, which finds no display
    warnings.simplefilter("ignore")
    from dm_control import viewer
    from dm_control.viewer import runtime


@pytest.mark.slow
def test_the_examples_run_and_print_what_the_page_says(tmp_path, monkeypatch, capsys, doc_examples):
    watched = []

    def launch_without_a_window(environment_loader, policy=None, **_):
        environment = environment_loader() if callable(environment_loader) else environment_loader
        steps = runtime.Runtime(environment, policy)
        steps.simulation_time_budget = 10.0  # simulated seconds a frame
        while steps.state is not runtime.State.STOPPED:
            steps.tick(10.0, paused=False)
        watched.append(environment.info["summary"])

    monkeypatch.setattr(viewer, "launch", launch_without_a_window)
    monkeypatch.chdir(tmp_path)
    exec(compile(doc_examples("environments.md", SECTION), "docs/environments.md", "exec"), {})
    printed = capsys.readouterr().out

    moved = re.search(r"^physics: t = 1\.00 s, base_link at \(([\d.]+), ([\d.]+)\) m$", printed, re.M)
    start_x, _ = load_scenario("paper_c_escape").robot.start
    assert moved and float(moved[1]) > start_x + 0.2  # pushed along +x for a second
    pixels = "pixels: ['chase', 'echo', 'goal', 'pixels', 'ranges', 'velocity'] (84, 84, 3) uint8"
    assert pixels in printed.splitlines()
    assert "scaled: [-1. -1.] [1. 1.]" in printed.splitlines()
    expected = run_scenario(load_scenario("paper_c_escape", ["run.seed=0"])).summary
    assert f"policy: reached {expected.trajectory_sha256}" in printed.splitlines()
    assert len(watched) == 1 and watched[0]["outcome"] == "reached"
    assert watched[0]["trajectory_sha256"] == expected.trajectory_sha256


@pytest.mark.parametrize("image", ["pixel-strip.png", "viewer-chase.png"])
def test_the_pictures_it_shows_are_there(image):
    assert f"(images/{image})" in DOC.read_text(encoding="utf-8")
    assert (DOC.parent / "images" / image).stat().st_size > 10_000
