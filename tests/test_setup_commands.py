"""The README's two set-up commands: what CI runs is the README's test command, verbatim."""

import re
from pathlib import Path

ROOT = Path(__file__).parents[1]


def setup_commands() -> list[str]:
    """The shell blocks of the README's set-up section."""
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    section = readme.split("## Set up", 1)[1].split("\n## ", 1)[0]
    return re.findall(r"```sh\n(.*?)\n```", section, flags=re.DOTALL)


def test_two_one_line_commands_into_a_virtual_environment():
    commands = setup_commands()
    assert len(commands) == 2 and all("\n" not in command for command in commands)
    run, tests = commands
    for command in commands:
        # PEP 668: the system Python refuses pip outside a virtual environment.
        assert "python3 -m venv .venv && . .venv/bin/activate && pip install -e " in command
        assert command.startswith("apt-get update && apt-get install -y libosmesa6 python3-venv && ")
    assert run.endswith("&& vplane-mj run paper_c_escape")
    assert tests.endswith('pip install -e ".[dev]" && python -m pytest -q')


def test_ci_runs_the_readme_test_command_verbatim():
    ci_lines = (ROOT / ".ci" / "run").read_text(encoding="utf-8").splitlines()
    test_command = setup_commands()[1]
    assert f"{test_command} || status=$?" in ci_lines
