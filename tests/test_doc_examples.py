"""Every shell and Python block of README.md and docs/*.md runs as printed, from an empty folder, with nothing
but the installed gearsym (`tests/doc_blocks.py` says how blocks are found, marked and run).

Each page's blocks run once, in order, in a folder of its own, when the first of its blocks is tested; the
compiled libraries are shared through the session's cache. The blocks of a page are one group for pytest-xdist
(``--dist loadgroup``): the pages run in parallel, each on one worker. A page added later is picked up by itself.
"""
from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

import doc_blocks
from doc_blocks import REPO

PAGES = doc_blocks.pages()
BLOCKS = [b for page in PAGES for b in doc_blocks.blocks(page)]
_RAN: dict[str, dict[str, doc_blocks.Ran]] = {}  # page -> block name -> what happened (this worker's pages)


@pytest.fixture(scope="session")
def user_folders(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("user")


def ran(page: str, scratch: Path) -> dict[str, doc_blocks.Ran]:
    """The page's blocks, run (once per process): block name -> what happened."""
    if page not in _RAN:
        _RAN[page] = {r.block.name: r for r in doc_blocks.run_page(REPO / page, scratch)}
    return _RAN[page]


def test_the_pages_have_examples_and_only_a_few_are_not_run():
    assert sum(b.runs for b in BLOCKS) >= 20
    assert sum(b.language == "python" and b.runs for b in BLOCKS) >= 6
    not_run = [b for b in BLOCKS if b.not_run is not None]
    assert len(not_run) <= 10, [f"{b.name}: {b.not_run}" for b in not_run]  # few, each with its reason


@pytest.mark.parametrize("block", BLOCKS, ids=lambda b: b.name)
def test_every_block_runs_or_says_why_not(block):
    assert doc_blocks.unmarked(block) is None, f"{block.name}: {doc_blocks.unmarked(block)}"


@pytest.mark.parametrize("block", [pytest.param(b, marks=(pytest.mark.xdist_group(b.page), pytest.mark.slow))
                                   for b in BLOCKS if b.runs or b.output_of], ids=lambda b: b.name)
def test_a_block_runs_as_printed(block, user_folders):
    page = ran(block.page, user_folders)
    assert block.name in page, f"{block.name} did not run: a block before it on its page failed"
    r = page[block.name]
    assert r.status == 0, f"{block.name} failed (exit {r.status}):\n{block.code}\n---\n{r.output[-4000:]}"
    assert r.listing_missing == [], (f"{block.name}: `{block.output_of}` no longer prints these lines of the "
                                     f"listing: {r.listing_missing}")


@pytest.mark.parametrize("block", [b for b in BLOCKS if b.runs_in is not None], ids=lambda b: b.name)
def test_a_block_shown_again_is_run_on_the_page_it_names(block):
    """The README's overview of a verb shows the commands its docs page runs: each is run once, there, word for word."""
    named = [REPO / p.strip() for p in block.runs_in.split(",")]
    assert all(p.is_file() for p in named), f"{block.name}: 'runs in' names no page: {block.runs_in}"
    run_there = {c for p in named for b in doc_blocks.blocks(p) if b.runs and b.language == "bash" for c in b.commands}
    assert block.commands, f"{block.name}: no command to look up"
    missing = [c for c in block.commands if c not in run_there]
    assert not missing, f"{block.name}: not run on {block.runs_in}: {missing}"


def test_the_test_command_and_the_main_command_are_marked_as_the_clones_own():
    readme = {b.line: b for b in doc_blocks.blocks(REPO / "README.md")}
    text = (REPO / "README.md").read_text().split("\n")
    for marker in ("<!-- test-command -->", "<!-- main-command -->"):
        at = text.index(marker) + 1
        fence = next(i for i in range(at, len(text)) if text[i].startswith("```")) + 1
        assert readme[fence].not_run, f"the block after {marker} runs in the clone only: it needs a marker"


# ------------------------------------------------------------------ numbers the docs quote from committed outputs
def _minus(text: str) -> str:
    return text.replace("−", "-")


def test_the_data_loop_page_quotes_the_committed_rig_report():
    """It said 0.355 -> 0.0105 where the run and the committed report give 0.3696 -> 0.01053."""
    report = json.loads((REPO / "docs/examples/explain-rig-accelerometer/report.json").read_text())
    page = _minus(" ".join((REPO / "docs/data-loop.md").read_text().split()))
    harmonic = report["harmonics"]["torque_harmonic_2"]
    quoted = (f"held-out error {report['error_before']:.4g} → {report['error_after']:.4g}",
              f"amplitude {harmonic['amplitude']:.4g} ± {harmonic['amplitude_stderr']:.2g}",
              f"phase {harmonic['phase']:.4g} ± {harmonic['phase_stderr']:.2g}")
    for text in quoted:
        assert text in page, f"docs/data-loop.md should quote the committed report: {text!r}"
    assert report["verdict"] == "explained" and report["effects"] == ["torque_harmonic_2"]
    assert re.search(r"\*explained\* by\s+`torque_harmonic_2`", page)
