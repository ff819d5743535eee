"""Sweeps on a Dask cluster: the same bytes as one process, the library shipped or rebuilt, clear errors."""
from __future__ import annotations

import json
import logging
import pickle
import socket
import sys
import time
from dataclasses import replace

import numpy as np
import pytest

import conftest
from conftest import interrupt_after
from gearsym import Execution, Integration, ModelError, lyapunov_spectrum, read_sweep, run_sweep
from gearsym.cli import main
from gearsym.codegen import CompilerError
from gearsym.codegen import compiler, portable
from gearsym.codegen.portable import load_shipped, ship
from gearsym.errors import GearsymError
from gearsym.sweep import SweepInterrupted
from gearsym.sweep import distributed as dsweep

distributed = pytest.importorskip("distributed")

SHORT = dict(options=Integration(periods=60, discard=20))


@pytest.fixture(scope="module")
def one_stage():
    return conftest.compiled("one_stage")


@pytest.fixture(scope="module")
def worker_cache(tmp_path_factory):
    return tmp_path_factory.mktemp("worker-cache")


@pytest.fixture(scope="module")
def cluster(worker_cache):
    """Two single-threaded worker processes with a library cache of their own (empty): what they run
    reached them through the scheduler, not through the client's cache."""
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                                  scheduler_kwargs={"dashboard_address": ":0"}, silence_logs=logging.ERROR,
                                  env={"GEARSYM_CACHE": str(worker_cache)}) as lc:
        with distributed.Client(lc) as client:
            yield client


def _same_files(a, b):
    for suffix in (".csv", ".poincare.csv"):
        assert a.with_name(a.stem + suffix).read_bytes() == b.with_name(b.stem + suffix).read_bytes(), suffix


# ------------------------------------------------------------------ bit for bit
@pytest.mark.parametrize("model, axes, mode, direction", [
    ("flexible_shaft", ["omega=1.2:1.6:0.1", "kS=0.1,0.5"], "independent", "up"),
    ("one_stage", ["omega=0.9:1.3:0.1", "B1=3.5,4"], "continuation", "both"),  # 2 lines, up and back down
])
@pytest.mark.slow
def test_a_cluster_sweep_equals_the_single_process_sweep_bit_for_bit(tmp_path, cluster, worker_cache, monkeypatch,
                                                                     model, axes, mode, direction):
    monkeypatch.setattr(dsweep, "POINTS_PER_TASK", 3)  # several chunks, and lines handed from task to task
    kw = dict(mode=mode, direction=direction, **SHORT)
    system = conftest.system(model)
    run_sweep(system, axes, execution=Execution(jobs=1), out=tmp_path / "one.csv", **kw)
    result = run_sweep(system, axes, execution=Execution(scheduler=cluster), out=tmp_path / "dask.csv", **kw)
    _same_files(tmp_path / "one.csv", tmp_path / "dask.csv")
    assert len(result) == 10 * (2 if direction == "both" else 1)
    assert read_sweep(tmp_path / "dask.csv").record == read_sweep(tmp_path / "one.csv").record
    assert json.loads((tmp_path / "dask.json").read_text())["dask"]["workers"] == 2
    library = conftest.compiled(model).library  # the workers' cache holds the client's library, byte for byte
    assert (worker_cache / "lib" / library.name).read_bytes() == library.read_bytes()


def test_the_in_process_backend_runs_on_workers_too(tmp_path, cluster):
    kw = dict(mode="independent", options=Integration(periods=20, discard=5, backend="in-process"))
    system = conftest.system("one_stage")
    run_sweep(system, ["omega=1.0,1.2,1.4"], execution=Execution(jobs=1), out=tmp_path / "one.csv", **kw)
    run_sweep(system, ["omega=1.0,1.2,1.4"], execution=Execution(scheduler=cluster), out=tmp_path / "dask.csv", **kw)
    _same_files(tmp_path / "one.csv", tmp_path / "dask.csv")


def test_interrupted_on_the_cluster_cancels_its_tasks_and_resumes_to_the_same_files(tmp_path, cluster, one_stage,
                                                                                  monkeypatch):
    monkeypatch.setattr(dsweep, "POINTS_PER_TASK", 2)
    axes = ["omega=0.9:1.3:0.1", "B1=3.5,4"]
    run_sweep(one_stage, axes, execution=Execution(jobs=1), out=tmp_path / "whole.csv", **SHORT)
    part = tmp_path / "part.csv"
    with pytest.raises(SweepInterrupted) as info:
        run_sweep(one_stage, axes, execution=Execution(scheduler=cluster), out=part, on_point=interrupt_after(3), **SHORT)
    assert len(part.read_text().splitlines()) - 1 == info.value.done >= 3
    deadline = time.monotonic() + 10
    while cluster.run_on_scheduler(lambda dask_scheduler: len(dask_scheduler.tasks)) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert cluster.run_on_scheduler(lambda dask_scheduler: len(dask_scheduler.tasks)) == 0  # nothing left behind
    run_sweep(one_stage, axes, execution=Execution(scheduler=cluster), out=part, **SHORT)  # the client is still usable
    _same_files(tmp_path / "whole.csv", part)


@pytest.mark.slow
def test_sweep_command_with_a_local_cluster(tmp_path, capsys):
    args = ["sweep", "one_stage", "--param", "omega=1:1.3:0.1", "--mode", "independent", "--periods", "40",
            "--discard", "10", "--quiet"]
    assert main([*args, "--jobs", "1", "--out", str(tmp_path / "one.csv")]) == 0
    assert main([*args, "--dask", "--jobs", "2", "--out", str(tmp_path / "dask.csv")]) == 0
    assert "4 points" in capsys.readouterr().out
    _same_files(tmp_path / "one.csv", tmp_path / "dask.csv")
    assert json.loads((tmp_path / "dask.json").read_text())["dask"]["scheduler"] == "local"


def test_an_error_on_a_worker_reaches_the_client_as_it_would_on_a_thread(tmp_path, cluster, one_stage):
    with pytest.raises(GearsymError, match=r"at omega=1e-08 \(independent\): one_stage: the solution became non-finite"):
        run_sweep(one_stage, ["omega=1e-8,1.1,1.2"], mode="independent", execution=Execution(scheduler=cluster),
                  out=tmp_path / "s.csv", **SHORT)
    run_sweep(one_stage, ["omega=1.1,1.2"], mode="independent", execution=Execution(scheduler=cluster), **SHORT)  # goes on


# ------------------------------------------------------------------ what a worker does with the shipped model
def test_a_worker_like_the_client_writes_the_shipped_bytes_and_needs_no_compiler(tmp_path, monkeypatch, one_stage):
    shipped = pickle.loads(pickle.dumps(ship(one_stage)))
    monkeypatch.setenv("GEARSYM_CACHE", str(tmp_path))

    def no_compiler(*args, **kwargs):
        raise AssertionError("compiled although the shipped library runs here")

    monkeypatch.setattr(portable, "compile_library", no_compiler)
    model = load_shipped(shipped)
    assert model.library == tmp_path / "lib" / one_stage.library.name  # the name compile_library gives it
    assert model.library.read_bytes() == one_stage.library.read_bytes()
    assert "compile" not in model.timings and model.integration == one_stage.integration
    assert model.system.constraints == one_stage.system.constraints  # the parameter checks travel with the system
    with pytest.raises(ModelError, match="zeta"):
        model.parameter_vector(zeta=-0.1)
    a, b = (lyapunov_spectrum(m, options=Integration(periods=30, discard=10), omega=1.3) for m in (one_stage, model))
    assert np.array_equal(a.exponents, b.exponents) and a.final_state == b.final_state


@pytest.mark.slow
def test_a_worker_on_another_kind_of_machine_compiles_the_shipped_source(tmp_path, monkeypatch, one_stage):
    elsewhere = replace(ship(one_stage), binary_key="0ther0machine", library=b"not for this machine")
    monkeypatch.setenv("GEARSYM_CACHE", str(tmp_path))
    model = load_shipped(elsewhere)
    assert model.timings["compile"] > 0  # compiled here, from the C that travelled
    assert (tmp_path / "code" / f"one_stage-{one_stage.hash[:16]}" / "one_stage.c").read_bytes() == elsewhere.source
    assert model.library.parent == tmp_path / "lib" and model.library.read_bytes() != elsewhere.library
    a, b = (lyapunov_spectrum(m, options=Integration(periods=30, discard=10), omega=1.3) for m in (one_stage, model))
    assert np.array_equal(a.exponents, b.exponents)  # this machine's compiler and CPU: the same bits


def test_a_worker_that_must_compile_without_a_compiler_says_so(tmp_path, monkeypatch, one_stage):
    monkeypatch.setenv("GEARSYM_CACHE", str(tmp_path))
    monkeypatch.setattr(compiler, "find_compiler", lambda: None)
    with pytest.raises(CompilerError, match="built for another system, CPU or C library.*no C compiler found"):
        load_shipped(replace(ship(one_stage), binary_key="0ther0machine"))


def test_a_worker_with_other_versions_is_refused(one_stage):
    with pytest.raises(GearsymError, match=r"the client gearsym 0\.0\.1 .*install the same versions"):
        load_shipped(replace(ship(one_stage), versions=("0.0.1", "3.8.2")))


def test_workers_keep_one_model_per_process_and_a_clone_per_thread(one_stage):
    shipped = ship(one_stage)
    first = dsweep.worker_model(shipped)
    assert dsweep.worker_model(shipped) is first
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(1) as pool:
        other = pool.submit(dsweep.worker_model, shipped).result()
    assert other is not first and other.native is not first.native and other.library == first.library


# ------------------------------------------------------------------ errors
def test_without_dask_the_error_names_the_extra(monkeypatch, capsys, tmp_path, one_stage):
    monkeypatch.setitem(sys.modules, "distributed", None)  # as if not installed
    with pytest.raises(GearsymError, match=r'needs the distributed extra: pip install "gearsym\[distributed\]"'):
        run_sweep(one_stage, ["omega=1,1.1"], execution=Execution(scheduler="local"), **SHORT)
    code = main(["sweep", "one_stage", "--param", "omega=1,1.1", "--dask", "--out", str(tmp_path / "s.csv")])
    assert code == 2 and 'pip install "gearsym[distributed]"' in capsys.readouterr().err
    assert not (tmp_path / "s.csv").exists()  # refused before any work


def test_an_unreachable_scheduler_is_named(monkeypatch, one_stage):
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]  # free once closed: nobody listens there
    monkeypatch.setattr(dsweep, "CONNECT_TIMEOUT", 0.5)
    with pytest.raises(GearsymError, match=rf"could not reach a Dask scheduler at tcp://127\.0\.0\.1:{port} "
                                           r"within 0\.5 s.*dask scheduler"):
        run_sweep(one_stage, ["omega=1,1.1"], execution=Execution(scheduler=f"tcp://127.0.0.1:{port}"), **SHORT)


@pytest.mark.parametrize("scheduler, jobs, words", [
    ("tcp://127.0.0.1:8786", 2, "has its own workers: drop --jobs"),
    ("somewhere", 0, "expected a Dask scheduler address"),
])
def test_bad_scheduler_arguments_are_refused_before_any_work(one_stage, scheduler, jobs, words):
    with pytest.raises(GearsymError, match=words):
        run_sweep(one_stage, ["omega=1,1.1"], execution=Execution(scheduler=scheduler, jobs=jobs), **SHORT)
