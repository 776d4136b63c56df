"""The peer planners in the same simulation: where each must succeed and where it is known to fail."""

import pytest

from vplane_mj.planning.protocol.registry import PLANNERS
from vplane_mj.sim.loop import run_scenario

pytestmark = pytest.mark.slow  # a long suite: `python -m pytest -m slow` runs it


@pytest.mark.parametrize(
    "planner, scenario",
    [
        ("vobs", "open_field"),
        ("vobs", "single_box"),
        ("vfh", "open_field"),
        ("vfh", "paper_c_escape"),
        ("vfh", "paper_h_avoid"),
    ],
)
def test_peer_planner_succeeds(shipped, planner, scenario):
    summary = run_scenario(shipped(scenario, f"planner.name={planner}")).summary
    assert summary.success, summary.outcome
    assert summary.path_ratio < 1.6


@pytest.mark.parametrize(
    "planner, scenario, outcome",
    [
        ("vobs", "paper_c_avoid", "stuck"),  # virtual obstacles push it around the cup, not out
        ("vfh", "corridor", "stuck"),  # a 20 degree sonar beam closes a 0.9 m corridor at range
        ("dwa", "paper_c_avoid", "stuck"),  # greedy for the goal, it enters the cup and circles in it
    ],
)
def test_peer_planner_known_failures(shipped, planner, scenario, outcome):
    summary = run_scenario(shipped(scenario, f"planner.name={planner}", "run.time_limit_s=120")).summary
    assert not summary.reached and summary.outcome == outcome
    assert summary.local_minima >= 1


def test_every_planner_is_documented_with_a_citation_and_parameters():
    for name, planner in PLANNERS.items():
        info = planner.info()
        assert info.name == name and info.citation and info.summary
        assert all(p.unit is not None and p.doc for p in info.params.values())
