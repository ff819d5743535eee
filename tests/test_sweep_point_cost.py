"""What a sweep spares at each point: tables of time kept while they stay the same, files written once."""
from __future__ import annotations

import numpy as np
import pytest

import conftest
from gearsym import Execution, Integration, run_sweep
from gearsym.sweep.store import SweepStore

RUN = Integration(periods=30, discard=10)


@pytest.fixture(scope="module")
def one_stage():
    return conftest.compiled("one_stage")


def test_a_next_point_keeps_the_tables_only_while_no_timed_parameter_changes(one_stage):
    names = list(one_stage.parameter_names)
    assert "omega" not in one_stage.timed_parameters and "B1" in one_stage.timed_parameters
    p = one_stage.parameter_vector()
    first = one_stage.prepare(p)
    p[names.index("omega")] = 1.1  # in place, as a caller may
    second = one_stage.prepare(p)
    assert second.table is first.table
    fresh = one_stage.clone()._tables(p, 0.0)  # (a clone remembers no earlier inputs)
    assert np.array_equal(second.constants, fresh.constants) and second.period == fresh.period
    p[names.index("B1")] = 2.5  # a parameter in the tables, changed in place too
    third = one_stage.prepare(p)
    assert third.table is not first.table
    assert np.array_equal(third.table, one_stage.clone()._tables(p, 0.0).table)
    assert not np.array_equal(third.table, first.table)


def test_a_fresh_sweep_whose_points_finish_in_order_writes_its_tables_once(tmp_path, one_stage, monkeypatch):
    written = []
    original = SweepStore._write_table

    def counting(path, columns, rows, text=""):
        written.append(path.name)
        return original(path, columns, rows, text)

    monkeypatch.setattr(SweepStore, "_write_table", staticmethod(counting))
    run_sweep(one_stage, {"omega": [1.0, 1.2, 1.4]}, options=RUN, out=tmp_path / "s.csv")
    assert sorted(written) == ["s.csv", "s.poincare.csv"]  # started, then appended to; not rewritten at the end
    rows = (tmp_path / "s.csv").read_text().splitlines()
    assert len(rows) == 4 and rows[0].startswith("omega,direction")


def test_a_batch_of_runs_is_summarised_exactly_as_each_run_alone(one_stage):
    """The sweep summarises its points in batches; every number must be the bits lyapunov_spectrum gives."""
    from gearsym import lyapunov_spectrum
    from gearsym.analysis.lyapunov import summarise_runs
    from gearsym.codegen import TangentRuns

    omegas = [0.6, 0.95, 1.4, 1.75]  # periodic and chaotic points
    runs = TangentRuns(one_stage.dimension, len(one_stage.observed), RUN.periods, len(omegas))
    ps, periods = [], []
    for i, omega in enumerate(omegas):
        inputs = one_stage.prepare(one_stage.parameter_vector(omega=omega))
        one_stage.tangent_run_into(runs, i, one_stage.initial_state(), inputs)
        ps.append(inputs.p.copy())
        periods.append(inputs.period)
    batch = summarise_runs(one_stage, runs, np.array(ps), np.array(periods), RUN.discard)
    for i, omega in enumerate(omegas):
        run = one_stage.tangent_run(None, RUN.periods, one_stage.prepare(one_stage.parameter_vector(omega=omega)))
        measured = run.log_stretch[:, RUN.discard:] / periods[i]  # the definitions, written out independently
        order = np.argsort(-measured.mean(axis=1))
        means = np.array([b.mean(axis=1) for b in np.array_split(measured, 10, axis=1)])
        expected, errors = measured.mean(axis=1)[order], means.std(axis=0, ddof=1)[order] / np.sqrt(10)
        alone_ = [k for k in range(len(order)) if not any(k in pair for pair in batch.pairs[i])]
        for a, b in batch.pairs[i]:  # one rotating pair: both its exponents are the pair's mean (analysis/pairs.py)
            expected[[a, b]] = expected[[a, b]].mean()
        assert np.allclose(batch.exponents[i], expected, rtol=1e-13, atol=1e-16)
        assert np.allclose(batch.stderr[i][alone_], errors[alone_], rtol=1e-10, atol=1e-16)
        assert batch.amplitude[i].tolist() == ((run.high[:, RUN.discard:].max(axis=1)
                                                - run.low[:, RUN.discard:].min(axis=1)) / 2).tolist()
        alone = lyapunov_spectrum(one_stage, options=RUN, omega=omega)
        assert batch.exponents[i].tobytes() == alone.exponents.tobytes()
        assert batch.stderr[i].tobytes() == alone.stderr.tobytes()
        assert batch.amplitude[i].tolist() == list(alone.amplitude.values())
        assert batch.regimes[i] == alone.regime and batch.pairs[i] == list(alone.pairs)
        assert runs.strobe[i, RUN.discard:].T.tobytes() == alone.strobe.tobytes()


def test_an_autonomous_batch_names_its_rest_points_as_each_run_alone():
    from gearsym import lyapunov_spectrum
    from gearsym.analysis.lyapunov import summarise_runs
    from gearsym.codegen import TangentRuns

    lorenz, run = conftest.compiled("lorenz"), Integration(periods=40, discard=10)
    starts = [np.zeros(3), lorenz.initial_state()]  # at rest on the (unstable) origin, and chaos
    runs = TangentRuns(3, len(lorenz.observed), run.periods, 2)
    inputs = lorenz.prepare(lorenz.parameter_vector(rho=28.0))
    for i, y0 in enumerate(starts):
        lorenz.tangent_run_into(runs, i, y0, inputs)
    batch = summarise_runs(lorenz, runs, np.array([inputs.p] * 2), np.array([inputs.period] * 2), run.discard)
    alone = [lyapunov_spectrum(lorenz, options=run, y0=y0, rho=28.0) for y0 in starts]
    assert batch.regimes == [a.regime for a in alone] == ["equilibrium", "chaotic"]
    assert np.array_equal(batch.eigenvalues[0], alone[0].eigenvalues) and batch.eigenvalues[1] is None
    assert batch.exponents[0].tobytes() == alone[0].exponents.tobytes()
    assert batch.stderr.tobytes() == np.array([a.stderr for a in alone]).tobytes()


def test_regimes_of_many_spectra_at_once_are_those_of_each_alone():
    from gearsym.analysis.regime import classify_regime, classify_regimes

    rng = np.random.default_rng(7)
    exponents = rng.normal(0, 0.05, (400, 3))
    stderr = np.where(rng.random((400, 3)) < 0.2, np.nan, rng.uniform(0, 0.02, (400, 3)))
    measured = rng.uniform(50, 5000, 400)
    for autonomous in (False, True):
        alone = [classify_regime(e, s, t, autonomous) for e, s, t in zip(exponents, stderr, measured)]
        assert classify_regimes(exponents, stderr, measured, autonomous) == alone
        assert len(set(alone)) >= 3  # (the draw covers several regimes)


def test_batches_of_any_size_write_the_same_files(tmp_path, one_stage, monkeypatch):
    import gearsym.sweep.point_runs as point_runs

    axes = {"omega": [0.8, 0.9, 1.0, 1.1, 1.2]}
    run_sweep(one_stage, axes, direction="both", options=RUN, out=tmp_path / "a.csv")
    monkeypatch.setattr(point_runs, "POINTS_PER_BATCH", 2)  # batches of 2, 2, 1 each way
    run_sweep(one_stage, axes, direction="both", options=RUN, out=tmp_path / "b.csv")
    for name in ("{}.csv", "{}.poincare.csv"):
        assert (tmp_path / name.format("a")).read_bytes() == (tmp_path / name.format("b")).read_bytes()


def test_a_point_that_fails_keeps_the_points_of_its_batch_before_it(tmp_path):
    from gearsym.errors import GearsymError
    from gearsym.sweep import read_sweep

    out = tmp_path / "s.csv"
    with pytest.raises(GearsymError, match=r"at sigma=1000 \(up\): .*non-finite"):
        run_sweep(conftest.compiled("lorenz"), ["sigma=8,10,1000,12"], options=Integration(periods=10, discard=2),
                  execution=Execution(jobs=1), out=out)
    assert read_sweep(out)["sigma"].tolist() == [8.0, 10.0, 12.0]  # (the grid runs in ascending order)


def test_an_error_of_the_writer_thread_is_raised_not_lost(tmp_path, one_stage, monkeypatch):
    from gearsym.errors import GearsymError
    from gearsym.files.lock import lock_path
    from gearsym.sweep.store import PoincareRows

    import threading

    text = PoincareRows.text

    def full_disk(self):
        if threading.current_thread().name == "gearsym-sweep-writer":  # (only where the appended points go)
            raise OSError(28, "No space left on device")
        return text(self)

    monkeypatch.setattr(PoincareRows, "text", full_disk)
    with pytest.raises(GearsymError, match="No space left on device; the 0 points before are kept whole"):
        run_sweep(one_stage, {"omega": [1.0, 1.2]}, options=RUN, out=tmp_path / "s.csv")  # (one line)
    assert not lock_path(tmp_path / "s.csv").exists()  # the lock is let go all the same


def test_independent_points_are_dealt_out_in_shrinking_tasks_that_cover_them_in_order():
    from gearsym.sweep.grid import INDEPENDENT, Point
    from gearsym.sweep.threads import guided

    start = np.zeros(2)
    points = [Point(INDEPENDENT, (float(v),)) for v in range(191)]
    tasks = guided([([p], start) for p in points], workers=2)
    sizes = [len(t) for t, _ in tasks]
    assert [p for t, _ in tasks for p in t] == points and all(s is start for _, s in tasks)
    assert sizes[0] == 48 and sizes == sorted(sizes, reverse=True) and sizes[-3:] == [1, 1, 1]
    assert guided([([p], start) for p in points], workers=1) == [(points, start)]  # one worker: one batch run
    line = [([Point("up", (1.0,)), Point("up", (2.0,))], start)]
    assert guided(line, workers=2) is line  # continuation lines stay whole


def test_a_batch_checked_at_once_names_the_point_and_period_that_became_non_finite(tmp_path, one_stage,
                                                                                    monkeypatch):
    """The sweep checks a batch's records with one sum; the error still names the first bad point and period,
    and keeps the points before it."""
    from gearsym.codegen import CompiledModel
    from gearsym.errors import GearsymError
    from gearsym.sweep import read_sweep

    run_into = CompiledModel.tangent_run_into

    def poisoned(self, runs, i, y, inputs, check_finite=True):
        run_into(self, runs, i, y, inputs, check_finite)
        if inputs.p[list(self.parameter_names).index("omega")] == 1.2:
            runs.log_stretch[i, 6, 1] = np.nan  # period 7, second exponent

    monkeypatch.setattr(CompiledModel, "tangent_run_into", poisoned)
    out = tmp_path / "s.csv"
    with pytest.raises(GearsymError, match=r"at omega=1.2 \(up\): one_stage: the solution became non-finite in "
                                           r"period 7 "):
        run_sweep(one_stage, {"omega": [1.0, 1.1, 1.2, 1.3]}, options=RUN, out=out)
    assert read_sweep(out)["omega"].tolist() == [1.0, 1.1]
