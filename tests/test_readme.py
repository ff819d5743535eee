"""The README's code runs as printed: where a newcomer starts must not fail.

Every ```python block is run, each in a fresh namespace, from an empty working directory (so that
it finds the models as an installed gearsym does). The ```bash blocks start long jobs (the
reproduction, the test suite, sweeps), so they are not run; every ``gearsym`` command in them is
parsed by the real argument parser instead, which catches an option that no longer exists.
"""
from __future__ import annotations

import re
import shlex

import pytest

from gearsym.cli import build_parser
from gearsym.paths import REPO_ROOT

README = (REPO_ROOT / "README.md").read_text(encoding="utf-8")


def blocks(language: str) -> list[str]:
    return re.findall(rf"^```{language}\n(.*?)^```", README, flags=re.S | re.M)


def gearsym_commands() -> list[list[str]]:
    """The ``gearsym ...`` commands of the bash blocks, continuation lines joined, comments dropped."""
    commands = []
    for block in blocks("bash"):
        for line in block.replace("\\\n", " ").splitlines():
            for part in line.split("&&"):
                words = shlex.split(part, comments=True)
                if words[:1] == ["gearsym"]:
                    commands.append(words[1:])
    return commands


def test_the_readme_has_python_and_gearsym_examples():
    assert len(blocks("python")) >= 2 and len(gearsym_commands()) >= 10


@pytest.mark.parametrize("number", range(len(blocks("python"))))
def test_a_python_block_of_the_readme_runs_as_printed(number, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    exec(compile(blocks("python")[number], f"README.md python block {number + 1}", "exec"), {})


@pytest.mark.parametrize("argv", gearsym_commands(), ids=" ".join)
def test_a_gearsym_command_of_the_readme_parses(argv):
    args = build_parser().parse_args(argv)
    assert args.command == argv[0]
