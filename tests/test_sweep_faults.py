"""A sweep's files under faults: a lock file that is a planted symlink, the disk full mid-sweep (one-line
error, a record that says so, no line cut off), and a resume that takes only whole points."""
from __future__ import annotations

import csv
import errno
import json
import os
import subprocess
import sys

import pytest

import conftest
from gearsym import Execution, Integration, run_sweep
from gearsym.cli import main
from gearsym.errors import GearsymError
from gearsym.files.paths import REPO_ROOT
from gearsym.sweep import store as store_module

RUN = Integration(periods=70, discard=20)
SAMPLES = 50  # Poincare samples per point
SHORT = dict(options=RUN, execution=Execution(jobs=1), mode="independent")
AXES = ["omega=0.6:1.38:0.02"]  # 40 points: more than one batch of 32
PLANNED = 40


@pytest.fixture(scope="module")
def one_stage():
    return conftest.compiled("one_stage")


@pytest.fixture(scope="module")
def clean(one_stage, tmp_path_factory):
    """The files of the sweep run without a fault."""
    out = tmp_path_factory.mktemp("clean") / "s.csv"
    run_sweep(one_stage, AXES, out=out, **SHORT)
    return {suffix: out.with_name(out.stem + suffix).read_bytes() for suffix in (".csv", ".poincare.csv")}


def files(out):
    return {suffix: out.with_name(out.stem + suffix).read_bytes() for suffix in (".csv", ".poincare.csv")}


# ------------------------------------------------------------------ the lock
@pytest.mark.parametrize("target", ["a file", "nothing"])
def test_a_lock_file_that_is_a_symlink_is_never_written_through(one_stage, tmp_path, target):
    victim = tmp_path / "victim.txt"
    if target == "a file":
        victim.write_text("someone's file\n")
    out = tmp_path / "s.csv"
    (tmp_path / "s.csv.lock").symlink_to(victim)
    with pytest.raises(GearsymError, match=r"s\.csv\.lock, the sweep's lock file, is a symlink \(to .*victim\.txt\); "
                                           "gearsym never writes through one"):
        run_sweep(one_stage, AXES, out=out, **SHORT)
    assert (victim.read_text() == "someone's file\n") if target == "a file" else not victim.exists()
    assert not out.exists()


# ------------------------------------------------------------------ the disk full
@pytest.fixture
def full_disk(monkeypatch):
    """The disk fills at the ``n``-th write of a batch (``at(n)``): that write puts part of its bytes on disk,
    then fails with ENOSPC, as every later write of a whole file (the record) does."""
    calls, full = [], []
    write_all, write_atomically = store_module._write_all, store_module.write_atomically

    def failing_write_all(fd, data):
        calls.append(len(data))
        if full or len(calls) == failing.at:
            full.append(True)
            os.write(fd, data[:len(data) // 2])  # (part of a line)
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        write_all(fd, data)

    def failing_write_atomically(path, data):
        if full:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(path))
        return write_atomically(path, data)

    def failing(at):
        failing.at = at

    monkeypatch.setattr(store_module, "_write_all", failing_write_all)
    monkeypatch.setattr(store_module, "write_atomically", failing_write_atomically)
    return failing


def whole_lines(path, fields):
    text = path.read_text()
    assert text.endswith("\n")
    rows = list(csv.reader(text.splitlines()))
    assert {len(r) for r in rows} == {fields}
    return rows[1:]


@pytest.mark.parametrize("at, where", [(3, "the Poincare table"), (4, "the table")])
def test_a_disk_full_mid_sweep_keeps_whole_points_says_so_and_resumes_to_the_same_files(one_stage, tmp_path, clean,
                                                                                      full_disk, monkeypatch, at,
                                                                                      where):
    out = tmp_path / "s.csv"
    full_disk(at)  # (each batch writes the Poincare table, then the table: the 2nd batch fails in ``where``)
    with pytest.raises(GearsymError) as failed:
        run_sweep(one_stage, AXES, out=out, **SHORT)
    message = str(failed.value)
    assert "\n" not in message and "No space left on device" in message and "run the same command again" in message
    record = json.loads(out.with_suffix(".json").read_text())
    assert record["status"] == "failed" and record["error"] == message
    rows = whole_lines(out, len(clean[".csv"].decode().splitlines()[0].split(",")))
    samples = whole_lines(out.with_name("s.poincare.csv"), 5)
    assert 0 < len(rows) < PLANNED and record["points"] == {"planned": PLANNED, "done": len(rows)}
    assert f"the {len(rows)} points before are kept whole" in message
    assert len(samples) == SAMPLES * len(rows)  # (every kept point has all its samples, and no other point any)
    monkeypatch.undo()
    run_sweep(one_stage, AXES, out=out, **SHORT)
    assert files(out) == clean
    assert json.loads(out.with_suffix(".json").read_text())["status"] == "complete"


def test_a_disk_full_as_the_sweep_completes_is_a_one_line_error_the_record_says_failed_and_a_rerun_completes(
        one_stage, tmp_path, clean, monkeypatch):
    out = tmp_path / "s.csv"
    write_atomically = store_module.write_atomically

    def full_at_the_end(path, data):
        if '"complete"' in data or '"failed"' in data:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(path))
        return write_atomically(path, data)

    monkeypatch.setattr(store_module, "write_atomically", full_at_the_end)
    with pytest.raises(GearsymError) as failed:
        run_sweep(one_stage, AXES, out=out, **SHORT)
    record_file = out.with_suffix(".json")
    assert str(failed.value).startswith(f"writing the sweep {out} failed: No space left on device ({record_file})")
    record = json.loads(out.with_suffix(".json").read_text())
    assert record["status"] == "failed" and record["error"] == str(failed.value)
    monkeypatch.undo()
    run_sweep(one_stage, AXES, out=out, **SHORT)
    assert files(out) == clean and json.loads(out.with_suffix(".json").read_text())["status"] == "complete"


def test_a_point_whose_poincare_samples_were_cut_off_is_computed_again_on_resume(one_stage, tmp_path, clean):
    out = tmp_path / "s.csv"
    run_sweep(one_stage, AXES, out=out, **SHORT)
    strobe = out.with_name("s.poincare.csv")
    lines = strobe.read_text().splitlines(keepends=True)
    strobe.write_text("".join(lines[:2 - SAMPLES]))  # the last point keeps 2 of its samples
    with pytest.warns(UserWarning, match=r"1 point\(s\) lack some of their 50 Poincare samples"):
        run_sweep(one_stage, AXES, out=out, **SHORT)
    assert files(out) == clean


@pytest.mark.skipif(os.geteuid() != 0 or not sys.platform.startswith("linux"), reason="mounting a tmpfs needs root")
@pytest.mark.slow
def test_a_real_full_disk(tmp_path):
    """The same on a 200 KiB tmpfs, from the command line: the disk really full."""
    disk = tmp_path / "disk"
    disk.mkdir()
    if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=200k", "tmpfs", str(disk)], capture_output=True).returncode:
        pytest.skip("cannot mount a tmpfs here")
    try:
        command = [sys.executable, "-m", "gearsym.cli", "sweep", "one_stage", "--param", "omega=0.5:1.7:0.01",
                   "--mode", "independent", "--periods", "70", "--discard", "20"]
        env = {**os.environ, "PYTHONPATH": str(REPO_ROOT)}
        full = subprocess.run([*command, "--out", str(disk / "s.csv")], capture_output=True, text=True, env=env,
                              timeout=300)
        assert full.returncode == 2, full.stderr
        said = [line for line in full.stderr.splitlines()  # (not the progress bar, nor the step the sweep takes)
                if line.startswith("gearsym:") and not line.startswith("gearsym: step: ")]
        assert len(said) == 1 and said[0].startswith("gearsym: error: writing ") and "No space left" in said[0]
        assert "Traceback" not in full.stderr
        assert json.loads((disk / "s.json").read_text())["status"] == "failed"
        kept = whole_lines(disk / "s.csv", len((disk / "s.csv").read_text().splitlines()[0].split(",")))
        assert len(whole_lines(disk / "s.poincare.csv", 5)) == SAMPLES * len(kept)
        subprocess.run(["mount", "-o", "remount,size=8m", str(disk)], check=True)
        # the resumed run and the uninterrupted one to compare with: the same command in this process (another
        # interpreter would only import gearsym again; the failing run above is the one whose process is checked)
        assert main([*command[3:], "--out", str(disk / "s.csv"), "--quiet"]) == 0
        assert main([*command[3:], "--out", str(tmp_path / "s.csv"), "--quiet"]) == 0
        assert files(disk / "s.csv") == files(tmp_path / "s.csv")
    finally:
        subprocess.run(["umount", str(disk)])
