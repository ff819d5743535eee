"""Nothing lost, nothing stuck: a sweep killed or stopped (SIGTERM) leaves no process behind and resumes; its lock
names a live holder, is taken over from a dead one and is removed at the end; written files honour the umask."""
from __future__ import annotations

import json
import multiprocessing
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

import conftest
import gearsym.files.lock as lock_module
from conftest import interrupt_after
from gearsym import Integration, run_sweep
from gearsym.cli import main
from gearsym.errors import GearsymError
from gearsym.files.atomic import write_atomically
from gearsym.sweep import SweepInterrupted
from gearsym.files.lock import lock_path, release_lock, take_lock
from gearsym.sweep.store import sidecar

ROOT = Path(__file__).resolve().parents[1]
SHORT = dict(options=Integration(periods=60, discard=20))
#: three continuation lines of 27 points, one per worker (the sweep's process and two forked from it), about 1 s in
#: all: time to kill it half-way
SLOW = ["one_stage", "--param", "omega=0.8:1.06:0.01", "--param", "B1=3.5,3.75,4", "--periods", "1500", "--discard",
        "100", "--jobs", "3", "--parallel", "processes", "--quiet"]
PLANNED = 81
#: gearsym on a machine of three cores or more, whatever this one has (it runs no more workers than cores; these
#: tests are about three workers' processes, not their speed)
THREE_CORES = "import sys, gearsym.sweep.workers as workers; cores = workers.cores; workers.cores = lambda: max(3, cores()); "
COMMAND = ("-c", THREE_CORES + "from gearsym.cli import main; sys.exit(main(sys.argv[1:]))")
#: a gearsym whose workers cannot ask the kernel to end them: the portable way (macOS) is used
WITHOUT_PDEATHSIG = (THREE_CORES + "import gearsym.sweep.processes as processes; "
                     "processes._kernel_ends_orphans = lambda: False; "
                     "from gearsym.cli import main; sys.exit(main(sys.argv[1:]))")

needs_fork = pytest.mark.skipif("fork" not in multiprocessing.get_all_start_methods() or not Path("/proc").is_dir(),
                                reason="forked workers, and /proc to find them")


@pytest.fixture(scope="module")
def one_stage():
    return conftest.compiled("one_stage")


def gearsym(*args: str, python: tuple[str, ...] = COMMAND, **kwargs) -> subprocess.Popen:
    """``gearsym ARGS`` in a process of its own, on this checkout and the session's library cache."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))}
    return subprocess.Popen([sys.executable, *python, *args], env=env, text=True, **kwargs)


def rows_on_disk(path: Path) -> int:
    return max(0, len(path.read_text().splitlines()) - 1) if path.exists() else 0


@pytest.fixture
def sweep_process(tmp_path):
    """Start the slow sweep as a command and return it once it has put a first row on disk, with its
    worker processes. Its output goes to files: a pipe would be held open by a worker that outlived it.
    Workers still alive at the end (a failed test) are killed, not left to run on."""
    workers: list[int] = []

    def start(out: Path, python=COMMAND) -> tuple[subprocess.Popen, list[int], Path]:
        err = out.with_suffix(".stderr")
        with open(err, "w") as stderr:
            proc = gearsym("sweep", *SLOW, "--out", str(out), python=python, stdout=subprocess.DEVNULL,
                           stderr=stderr)
        deadline = time.monotonic() + 120
        while rows_on_disk(out) < 1:
            assert proc.poll() is None, f"the sweep ended early: {err.read_text()}"
            assert time.monotonic() < deadline, "no row after 120 s"
            time.sleep(0.02)
        workers.extend(children(proc.pid))
        return proc, list(workers), err

    yield start
    for pid in filter(alive, workers):
        os.kill(pid, signal.SIGKILL)


def children(pid: int) -> list[int]:
    tasks = Path(f"/proc/{pid}/task")
    return [int(c) for task in tasks.iterdir() for c in (task / "children").read_text().split()]


def alive(pid: int) -> bool:
    """Running, or stopped: neither gone nor a zombie waiting to be reaped."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except FileNotFoundError:
        return False
    return state not in "ZX"


def left_alive(pids: list[int], seconds: float = 5.0) -> list[int]:
    deadline = time.monotonic() + seconds
    while any(map(alive, pids)) and time.monotonic() < deadline:
        time.sleep(0.05)
    return [p for p in pids if alive(p)]


@pytest.fixture(scope="module")
def whole(tmp_path_factory) -> Path:
    """The slow sweep, run through without interruption."""
    out = tmp_path_factory.mktemp("whole") / "whole.csv"
    assert main(["sweep", *SLOW, "--out", str(out)]) == 0
    return out


# ------------------------------------------------------------------ processes
@needs_fork
@pytest.mark.slow
def test_sweep_workers_die_with_a_killed_parent_and_the_sweep_resumes(tmp_path, sweep_process, whole):
    out = tmp_path / "part.csv"
    proc, workers, _ = sweep_process(out)
    assert len(workers) == 2
    proc.kill()  # kill -9: no handler runs
    proc.wait()
    assert 0 < rows_on_disk(out) < PLANNED, "killed before it finished"
    assert left_alive(workers) == []
    assert lock_path(out).exists()  # left by the kill, and taken over:
    again = gearsym("sweep", *SLOW, "--out", str(out), stderr=subprocess.PIPE)
    _, err = again.communicate(timeout=300)
    assert again.returncode == 0, err
    assert out.read_bytes() == whole.read_bytes()
    assert sidecar(out, ".poincare.csv").read_bytes() == sidecar(whole, ".poincare.csv").read_bytes()
    assert not lock_path(out).exists()


@pytest.mark.slow
@needs_fork
def test_without_the_kernels_help_workers_still_die_with_their_parent(tmp_path, sweep_process):
    """The portable way (macOS): a thread in each worker waits for its parent's end of a pipe to close."""
    proc, workers, _ = sweep_process(tmp_path / "part.csv", python=("-c", WITHOUT_PDEATHSIG))
    proc.kill()
    proc.wait()
    assert len(workers) == 2 and left_alive(workers) == []


@pytest.mark.slow
@needs_fork
def test_sigterm_stops_a_sweep_like_ctrl_c(tmp_path, sweep_process):
    out = tmp_path / "part.csv"
    proc, workers, stderr = sweep_process(out)
    proc.terminate()  # a plain kill
    proc.wait(timeout=60)
    assert proc.returncode == 128 + signal.SIGTERM
    kept, err = rows_on_disk(out), stderr.read_text()
    assert f"interrupted: kept {kept} of {PLANNED} points in {out}; run the same command again to resume" in err
    assert 0 < kept < PLANNED and "Traceback" not in err  # (nor one from a worker stopped by its parent)
    record = json.loads(out.with_suffix(".json").read_text())
    assert record["status"] == "interrupted" and record["points"] == {"planned": PLANNED, "done": kept}
    assert [p for p in workers if alive(p)] == []  # stopped before the parent returned
    assert not lock_path(out).exists()


def test_sigterm_stops_any_command_with_one_line(monkeypatch, capsys):
    from gearsym.cli import lyap

    def terminated(args):
        os.kill(os.getpid(), signal.SIGTERM)
        time.sleep(5)  # interrupted here
        return 0

    def ignored(signum, frame):  # what a caller of main may have (and, were main's missing, what saves pytest)
        pass

    previous = signal.signal(signal.SIGTERM, ignored)
    try:
        monkeypatch.setattr(lyap, "run", terminated)
        assert main(["lyap", "one_stage"]) == 128 + signal.SIGTERM
        assert capsys.readouterr().err == "gearsym: interrupted\n"
        assert signal.getsignal(signal.SIGTERM) is ignored  # restored for whoever called main
    finally:
        signal.signal(signal.SIGTERM, previous)


# ------------------------------------------------------------------ the lock
def holder(*code: str) -> subprocess.Popen:
    """A Python process that runs ``code`` and then waits, until it is killed."""
    proc = gearsym(python=("-c", "\n".join([*code, "print('ready', flush=True)", "import time; time.sleep(120)"])),
                   stdout=subprocess.PIPE)
    assert proc.stdout.readline() == "ready\n", proc.communicate()
    return proc


def test_a_live_writer_is_named_with_its_pid(tmp_path, one_stage, capsys):
    out = tmp_path / "s.csv"
    proc = holder("from pathlib import Path", "from gearsym.files.lock import take_lock",
                  f"take_lock(Path({str(out)!r}))")
    try:
        code = main(["sweep", "one_stage", "--param", "omega=1,1.1", "--out", str(out), "--quiet"])
        err = capsys.readouterr().err
        assert code == 2 and err.count("\n") == 1
        assert err.startswith(f"gearsym: error: {out} is being written by gearsym process {proc.pid} (started ")
        assert f"wait for it or stop it (kill {proc.pid})" in err
    finally:
        proc.kill()
        proc.communicate()
    run_sweep(one_stage, ["omega=1,1.1"], out=out, **SHORT)  # its lock died with it


def test_a_lock_kept_by_a_leftover_of_a_dead_writer_says_so(tmp_path, one_stage):
    out = tmp_path / "s.csv"
    gone = _dead_pid()
    proc = holder("import fcntl, json", f"lock = open({str(lock_path(out))!r}, 'w')",  # as an older gearsym's
                  "fcntl.flock(lock, fcntl.LOCK_EX)",  # orphaned worker held it
                  f"lock.write(json.dumps({{'pid': {gone}, 'host': __import__('socket').gethostname()}})); lock.flush()")
    try:
        with pytest.raises(GearsymError, match=rf"locked by a process left behind by gearsym process {gone}, "
                                               rf"which has ended .*`fuser -v {re.escape(str(lock_path(out)))}`"):
            run_sweep(one_stage, ["omega=1,1.1"], out=out, **SHORT)
    finally:
        proc.kill()
        proc.communicate()


def _dead_pid() -> int:
    proc = subprocess.Popen(["true"])
    proc.wait()
    return proc.pid


def test_a_stale_lock_file_is_taken_over(tmp_path, one_stage):
    out = tmp_path / "s.csv"
    lock_path(out).write_text(json.dumps({"pid": _dead_pid(), "host": "here", "started": "yesterday"}))
    run_sweep(one_stage, ["omega=1,1.1"], out=out, **SHORT)
    assert not lock_path(out).exists()


def test_the_lock_file_is_removed_when_a_sweep_ends_in_any_way(tmp_path, one_stage):
    out = tmp_path / "s.csv"
    run_sweep(one_stage, ["omega=1,1.1"], out=out, **SHORT)
    assert not lock_path(out).exists()  # finished
    with pytest.raises(SweepInterrupted):
        run_sweep(one_stage, ["omega=1:1.3:0.1"], out=tmp_path / "i.csv", on_point=interrupt_after(1), **SHORT)
    assert not lock_path(tmp_path / "i.csv").exists()  # interrupted
    with pytest.raises(GearsymError, match="non-finite"):
        run_sweep(conftest.system("lorenz"), ["sigma=1000"], out=tmp_path / "f.csv",
                  options=Integration(periods=10, discard=2))
    assert not lock_path(tmp_path / "f.csv").exists()  # failed


def test_a_lock_file_removed_as_it_is_taken_is_taken_again_at_its_path(tmp_path, monkeypatch):
    """The holder removes the file between our open and our lock: what we locked is no longer the lock."""
    sweep = tmp_path / "s.csv"
    first = take_lock(sweep)
    real_flock = lock_module.fcntl.flock

    def holder_finishes_first(fd, operation):
        monkeypatch.setattr(lock_module.fcntl, "flock", real_flock)
        release_lock(sweep, first)
        return real_flock(fd, operation)

    monkeypatch.setattr(lock_module.fcntl, "flock", holder_finishes_first)
    second = take_lock(sweep)
    assert os.path.samestat(os.fstat(second), os.stat(lock_path(sweep)))
    with pytest.raises(GearsymError, match=f"being written by gearsym process {os.getpid()}"):
        take_lock(sweep)  # held, at its path
    release_lock(sweep, second)


@needs_fork
def test_a_forked_child_does_not_keep_the_lock(tmp_path):
    sweep = tmp_path / "s.csv"
    fd = take_lock(sweep)
    fork = multiprocessing.get_context("fork")
    running = fork.Event()

    def child_work():
        running.set()
        time.sleep(30)

    child = fork.Process(target=child_work)
    child.start()
    try:
        assert running.wait(30)
        os.close(fd)  # as if this process died: only the child could still hold it
        lock_module._HELD_LOCKS.discard(fd)
        release_lock(sweep, take_lock(sweep))
    finally:
        child.kill()
        child.join()


# ------------------------------------------------------------------ permissions
@pytest.fixture
def umask():
    previous = os.umask(0o022)
    yield os.umask
    os.umask(previous)


@pytest.mark.parametrize("mask, mode", [(0o022, 0o644), (0o077, 0o600), (0o002, 0o664)], ids=["022", "077", "002"])
def test_written_files_honour_the_umask(tmp_path, one_stage, umask, mask, mode):
    umask(mask)
    assert write_atomically(tmp_path / "page.md", "text").stat().st_mode & 0o777 == mode
    run_sweep(one_stage, ["omega=1,1.1"], out=tmp_path / "s.csv", **SHORT)
    for name in ("s.csv", "s.json", "s.poincare.csv"):
        assert (tmp_path / name).stat().st_mode & 0o777 == mode, name


def test_a_replaced_file_keeps_its_mode(tmp_path, umask):
    page = tmp_path / "page.md"
    page.write_text("old")
    page.chmod(0o640)
    umask(0o077)
    write_atomically(page, "new")
    assert page.read_text() == "new" and page.stat().st_mode & 0o777 == 0o640
