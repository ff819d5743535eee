"""An explain report is replaced whole or not at all: a failure, Ctrl-C or SIGTERM while it is written leaves the
previous report as it was (never a new report.json beside an old report.md with the opposite verdict), and a
kill that cannot be held back while the files are renamed leaves a marker that says the folder is partial."""
from __future__ import annotations

import errno
import os

import pytest

import conftest
from gearsym import Integration, explain, load_measurements, simulate_measurements
from gearsym.errors import GearsymError
from gearsym.fit import augment
from gearsym.figures import fit_report as report_module
from gearsym.figures.fit_report import write_report
from gearsym.fit.report import PARTIAL_MARKER, REPORT_FILES

RECORD = Integration(periods=116, discard=100, backend="in-process")


@pytest.fixture(scope="module")
def explanations(tmp_path_factory):
    """Two explanations of the same data with opposite verdicts: (the model, the 'explained' one, the other)."""
    one_stage = conftest.system("one_stage")
    data = tmp_path_factory.mktemp("data") / "cubic.csv"
    simulate_measurements(augment(one_stage, ["cubic_stiffness"], values={"k3": 0.02}), options=RECORD,
                          samples_per_period=40, noise=0.01, seed=1, records=[{"omega": 1.2}, {"omega": 1.6}], out=data)
    measured = load_measurements([data], one_stage)
    explained = explain(one_stage, measured, ["zeta", "B1"], candidates=["cubic_stiffness"])
    unexplained = explain(one_stage, measured, ["zeta", "B1"], candidates=["coulomb_friction"], propose=False)
    assert explained.verdict == "explained" and unexplained.verdict != "explained"
    return one_stage, explained, unexplained


def contents(folder):
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir())}


@pytest.fixture(scope="module")
def previous(explanations, tmp_path_factory):
    """The report of the 'explained' run, written once: its folder's files."""
    system, explained, _ = explanations
    folder = tmp_path_factory.mktemp("previous")
    write_report(explained, system, folder)
    assert sorted(contents(folder)) == sorted(REPORT_FILES)
    assert "## Verdict: explained" in (folder / "report.md").read_text()
    return contents(folder)


@pytest.mark.parametrize("failure", [GearsymError("a figure failed"), KeyboardInterrupt(),  # (SIGTERM: as Ctrl-C)
                                     OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))])
@pytest.mark.slow
def test_a_report_that_fails_while_it_is_written_leaves_the_previous_one_as_it_was(explanations, previous, tmp_path,
                                                                                   monkeypatch, failure):
    system, _, unexplained = explanations
    for name, data in previous.items():
        (tmp_path / name).write_bytes(data)

    def fails(*args, **kwargs):  # (the first figure, as its builder writes it: report.json is written by then)
        raise failure

    monkeypatch.setattr(report_module, "finish", fails)
    expected = GearsymError if isinstance(failure, OSError) else type(failure)
    with pytest.raises(expected) as raised:
        write_report(unexplained, system, tmp_path)
    assert contents(tmp_path) == previous  # (no new report.json beside the old report.md, no staging folder)
    if isinstance(failure, OSError):
        assert str(raised.value) == (f"writing the report into {tmp_path} failed: No space left on device; what was "
                                     "there before is unchanged")


@pytest.mark.slow
def test_a_run_killed_while_the_files_are_renamed_leaves_a_marker_that_says_the_report_is_partial(
        explanations, previous, tmp_path, monkeypatch):
    system, _, unexplained = explanations
    for name, data in previous.items():
        (tmp_path / name).write_bytes(data)
    renamed = []
    replace = os.replace

    def killed_after_one(src, dst):
        if os.path.dirname(os.fspath(dst)) == os.fspath(tmp_path):  # (a file of the report put in place; each
            if renamed:                                             # written whole in the staging folder first)
                raise SystemExit("killed")  # (what kill -9 leaves: one file renamed, the rest not)
            renamed.append(dst)
        replace(src, dst)

    monkeypatch.setattr(os, "replace", killed_after_one)
    with pytest.raises(SystemExit):
        write_report(unexplained, system, tmp_path)
    monkeypatch.undo()
    marker = (tmp_path / PARTIAL_MARKER).read_text()
    assert "parts of two runs" in marker and "report.md" in marker
    write_report(unexplained, system, tmp_path)  # the next run makes it whole again
    assert sorted(contents(tmp_path)) == sorted(REPORT_FILES)


def test_a_report_file_name_taken_by_a_folder_changes_nothing(explanations, previous, tmp_path):
    system, _, unexplained = explanations
    for name, data in previous.items():
        (tmp_path / name).write_bytes(data)
    (tmp_path / "derived_model.md").unlink()
    (tmp_path / "derived_model.md").mkdir()  # (renamed last but one: the other files would be replaced by then)
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir() if p.is_file()}
    with pytest.raises(GearsymError, match="derived_model.md is a folder, so the report cannot be written there"):
        write_report(unexplained, system, tmp_path)
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir() if p.is_file()} == before
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(REPORT_FILES)
