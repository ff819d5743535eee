"""Bad input (issue 25): sizes that cannot fit, formulas that are not finite, data files that are not measurements,
and options that would be ignored or would change the answer are each one line before any work, exit status 2;
the message says the option as the caller writes it (``--time-scale`` on the command line, ``time_scale=`` in
Python).

Memory limits depend on the machine, so the tests that need one give the machine a known amount
(``gearsym.checks.available``) instead of asking for more than any machine has.
"""
from __future__ import annotations

import os
import re
import sys
import threading
import warnings

import numpy as np
import pytest

import conftest
import gearsym
import gearsym.data.csvtext as csvtext
import gearsym.data.grouping as grouping
import gearsym.checks
import gearsym.sweep.workers
from gearsym.sweep.workers import Workers
from gearsym import Execution, Integration, explain, find_attractors, load_measurements, run_sweep, simulate_measurements
from gearsym.cli import main
from gearsym.codegen.compiled import CompiledModel
from gearsym.data import DataError
from gearsym.errors import GearsymError, GearsymWarning, ModelError
from gearsym.fit import fit_windows
from gearsym.fit.selection import segments_of
from test_checks_before_work import error_line, no_work  # noqa: F401 (a fixture)

GIB = 2**30


@pytest.fixture
def one_gib(monkeypatch):
    """A machine with 1 GiB of memory available."""
    monkeypatch.setattr(gearsym.checks, "available", lambda: GIB)


@pytest.fixture(scope="module")
def one_stage():
    return conftest.compiled("one_stage")


def measurement_file(tmp_path, records=2, per_period=20, periods=3, name="m.csv", header="tau,record,x"):
    """``records`` records of a sine, each ``periods`` whole periods of ``per_period`` samples and the end point."""
    lines = [header]
    tau = (2 * np.pi / per_period) * np.arange(periods * per_period + 1)
    for r in range(1, records + 1):
        lines += [f"{float(t)!r},{r},{float(np.sin(t))!r}" for t in tau]
    path = tmp_path / name
    path.write_text("\n".join(lines) + "\n")
    return path


# --------------------------------------------------------------------------- sizes: checked before memory
def test_a_request_is_refused_exactly_where_it_stops_fitting(monkeypatch):
    monkeypatch.setattr(gearsym.checks, "available", lambda: 10 * GIB)
    per_item = 1000
    allowed = 10 * GIB // per_item
    gearsym.checks.check_fits(allowed, per_item, asked="n", item="item", what="test")
    with pytest.raises(GearsymError, match=rf"^n needs 10 GiB of memory \(test: 1000 B per item\), more than the "
                                           rf"10 GiB available: at most {allowed} items fit$"):
        gearsym.checks.check_fits(allowed + 1, per_item, asked="n", item="item", what="test")


@pytest.mark.parametrize("argv,said", [
    (["sweep", "one_stage", "--param", "omega=1:1.2:0.1", "--out", "s.csv", "--periods", "1000000000"],
     "--periods 1000000000 needs 44.7 GiB"),
    (["sweep", "one_stage", "--param", "omega=1:1.2:0.1", "--out", "s.csv", "--steps-per-period", "100000000"],
     "--steps-per-period 100000000: at most 1000000 RK4 steps per forcing period"),
    (["poincare", "one_stage", "--ics", "1000000000"], "--ics 1000000000 needs"),
    (["simulate", "one_stage", "--out", "m.csv", "--samples-per-period", "1000000000"],
     "--samples-per-period 1000000000: the samples are RK4 steps"),
    (["explain", "m.csv", "--model", "one_stage", "--fit", "zeta", "--out", "r", "--harmonics", "100000"],
     "--harmonics 100000: at most 32"),
])
def test_sizes_that_cannot_fit_are_refused_before_any_work(capsys, no_work, one_gib, tmp_path, monkeypatch, argv,
                                                           said):
    monkeypatch.chdir(tmp_path)
    err = error_line(capsys, *argv)
    assert said in err
    if "needs" in said:
        allowed = int(re.search(r"at most (\d+) ", err).group(1))
        assert 0 < allowed < int(re.search(r"--\w+ (\d+)", said).group(1))


def test_the_python_face_checks_the_same_sizes_where_they_enter(one_gib, one_stage, monkeypatch):
    with pytest.raises(GearsymError, match=r"^periods=1000000000 needs 44.7 GiB .*at most \d+ periods fit$"):
        Integration(periods=10**9)
    with pytest.raises(GearsymError, match=r"^steps_per_period=100000000: at most 1000000 RK4 steps"):
        Integration(steps_per_period=10**8)
    for method in ("tangent_run", "tangent_run_into", "orbit_run", "trajectory"):
        monkeypatch.setattr(CompiledModel, method, lambda *a, **k: pytest.fail("the run started"))
    # past the options' bound for any model (48 B a period) but not one_stage's own (80 B: two states, one observed)
    options = Integration(periods=15_000_000, discard=100)
    with pytest.raises(GearsymError, match=r"^periods=15000000 needs 1.12 GiB of memory \(one_stage's .* 80 B per "
                                           r"period\).*at most 13421772 periods fit$"):
        gearsym.lyapunov_spectrum(one_stage, options=options)
    with pytest.raises(GearsymError, match=r"^ics=10000000 needs .*at most \d+ initial states fit$"):
        find_attractors(one_stage, ics=10**7)
    with pytest.raises(GearsymError, match=r"^samples_per_period=1000000000: the samples are RK4 steps"):
        simulate_measurements(conftest.system("one_stage"), samples_per_period=10**9)


def test_a_sweep_counts_the_memory_of_every_worker(one_gib, one_stage, monkeypatch):
    monkeypatch.setattr(gearsym.sweep.workers, "cores", lambda: 4)
    monkeypatch.setattr(CompiledModel, "tangent_run_into", lambda *a, **k: pytest.fail("the run started"))
    options = Integration(periods=5_000_000, discard=100)  # 0.37 GiB for one point's records, 1.49 GiB for four
    with pytest.raises(GearsymError, match=r"^periods=5000000 needs 1.49 GiB .*4 workers'"):
        run_sweep(one_stage, ["omega=1:1.3:0.1"], options=options, execution=Execution(jobs=4, parallel="threads"))


def test_more_than_any_machine_has_is_refused_on_this_one():
    with pytest.raises(GearsymError, match=r"^periods=1000000000000000 needs [0-9.e+]+ TiB of memory"):
        Integration(periods=10**15)


# --------------------------------------------------------------------------- formulas and numbers
@pytest.mark.parametrize("value,said", [
    ("exp(exp(exp(exp(10))))", "the formula 'exp(exp(exp(exp(10))))' is not finite: exp(exp(exp(exp(10)))) overflows"),
    ("1/0", "the formula '1/0' is not finite: it divides by zero"),
    ("2*log(0)", "the formula '2*log(0)' is not finite: it divides by zero, or takes the log of 0"),
    ("1+exp(1000)*cos(tau)", "is not finite: exp(1000) is infinite or beyond what a double holds"),
    ("sqrt(-1)*cos(tau)", "the formula 'sqrt(-1)*cos(tau)' is not real: I is imaginary"),
    ("1e400", "k=1e400: not a finite number"),
    ("nan", "k=nan: not a finite number"),
])
def test_a_formula_that_is_not_finite_names_its_parameter(capsys, no_work, value, said):
    err = error_line(capsys, "lyap", "one_stage", "--set", f"k={value}")
    assert "--set k" in err and said in err


def test_the_python_face_refuses_the_same_formulas_and_numbers():
    for value in ("1/0", "exp(exp(exp(exp(10))))", float("inf")):
        with pytest.raises(ModelError, match=r"stiffness function k .*not (a )?finite"):
            gearsym.load("one_stage", k=value)


# --------------------------------------------------------------------------- data files
@pytest.mark.skipif(not os.path.exists("/dev/zero"), reason="a device that never ends")
def test_a_device_is_refused_before_it_is_read(capsys, one_stage, monkeypatch):
    monkeypatch.setattr(csvtext, "_lines", lambda *a: pytest.fail("read"))
    with pytest.raises(DataError, match=r"^/dev/zero: is a device, not a file of measurements"):
        load_measurements("/dev/zero", one_stage.system)
    err = error_line(capsys, "explain", "/dev/zero", "--model", "one_stage", "--fit", "zeta", "--out",
                     "/tmp/never-written", "--quiet")
    assert "is a device" in err


def test_a_pipe_longer_than_the_limit_is_cut_at_the_limit(one_stage, tmp_path, monkeypatch):
    """A pipe (or a device, or a file that grows) has no size to check first: its text is counted as it comes."""
    monkeypatch.setattr(csvtext, "MAX_FILE_BYTES", 100_000)
    fifo = tmp_path / "stream"
    os.mkfifo(fifo)

    def write():
        try:
            with open(fifo, "w") as f:
                f.write("tau,x\n")
                for i in range(30_000):  # 300 kB of samples
                    f.write(f"{i / 10:.1f},0.25\n")
        except (BrokenPipeError, OSError):
            pass  # the reader stopped

    writer = threading.Thread(target=write, daemon=True)
    writer.start()
    with pytest.raises(DataError, match="more than 97.7 KiB|more than 100000 bytes"):
        load_measurements(fifo, one_stage.system)
    writer.join(timeout=30)


@pytest.mark.parametrize("content,said,line", [
    (b"tau,x\n0,1\n\0\0\0\0", "holds NUL characters: a binary file", 3),
    (b"tau,x\n" + b"1" * 200_000 + b"\n", "the line is longer than 100000 characters", 2),
    (b"tau;record;omega;x\n0;1;1.2;0.5\n", "the columns are separated by semicolons (;), not commas (the header "
                                          "names tau, record, omega, x)", 1),
    (b"tau\tx\n0\t0.5\n", "the columns are separated by tabs", 1),
    (b"tau,x\n\xff\xfe,1\n", "cannot read it as UTF-8 text (byte 7, on line 2, is not UTF-8)", None),
])
def test_a_file_that_is_not_a_csv_of_measurements_says_what_it_is(one_stage, tmp_path, content, said, line):
    path = tmp_path / "f.csv"
    path.write_bytes(content)
    with pytest.raises(DataError, match=re.escape(said)) as caught:
        load_measurements(path, one_stage.system)
    assert caught.value.line == line


def test_a_file_too_large_is_refused_before_it_is_read(one_stage, tmp_path, monkeypatch):
    path = measurement_file(tmp_path)
    monkeypatch.setattr(csvtext, "MAX_FILE_BYTES", path.stat().st_size - 1)
    monkeypatch.setattr(csvtext, "_lines", lambda *a: pytest.fail("read"))
    with pytest.raises(DataError, match=r"is \d+ bytes, more than the \d+ bytes a measurement file may have: split"):
        load_measurements(path, one_stage.system)


def test_more_records_than_the_limit_are_refused_where_the_next_one_starts(one_stage, tmp_path, monkeypatch):
    path = measurement_file(tmp_path, records=3)
    monkeypatch.setattr(grouping, "MAX_RECORDS", 2)
    with pytest.raises(DataError, match="more than 2 records in one file") as caught:
        load_measurements(path, one_stage.system)
    assert caught.value.line == 2 + 2 * 61 and caught.value.column == "record"


def test_grouping_records_is_linear_in_the_rows(one_stage, tmp_path, monkeypatch):
    """The arrays made while loading hold a few times the file's numbers, however many records it has: grouping
    once made an array of every line number for each record (a 200 MB file of 6772 records did not load in 400 s)."""
    records, rows = 300, 61
    path = measurement_file(tmp_path, records=records)
    made = []
    array, asarray = np.array, np.asarray

    def counted(make):
        def wrapper(*args, **kwargs):
            out = make(*args, **kwargs)
            made.append(np.size(out))
            return out
        return wrapper

    monkeypatch.setattr(np, "array", counted(array))
    monkeypatch.setattr(np, "asarray", counted(asarray))
    data = load_measurements(path, one_stage.system)
    assert len(data) == records
    assert sum(made) <= 10 * records * rows, sum(made)


def test_a_physical_time_column_asks_for_the_option_as_the_caller_spells_it(capsys, one_stage, tmp_path):
    path = measurement_file(tmp_path, header="t,record,x")
    with pytest.raises(DataError, match=r"pass time_scale=\.\.\. "):
        load_measurements(path, one_stage.system)
    err = error_line(capsys, "explain", str(path), "--model", "one_stage", "--fit", "zeta", "--out",
                     str(tmp_path / "r"), "--quiet")
    assert "pass --time-scale ... " in err and "time_scale=" not in err


# --------------------------------------------------------------------------- what to fit
def test_a_parameter_named_twice_in_fit_is_refused(capsys, no_work, one_stage, tmp_path):
    err = error_line(capsys, "explain", "m.csv", "--model", "one_stage", "--fit", "zeta,zeta", "--out",
                     str(tmp_path / "r"))
    assert "--fit names zeta twice" in err
    data = load_measurements(measurement_file(tmp_path), one_stage.system)
    with pytest.raises(GearsymError, match="^fit names zeta twice"):
        explain(one_stage.system, data, ["zeta", "B1", "zeta"])
    segments, _ = segments_of(one_stage.system, data)
    with pytest.raises(GearsymError, match="zeta is named twice among the parameters to fit"):
        fit_windows(one_stage.system, segments, ["zeta", "zeta"])


def test_a_parameter_the_model_lacks_is_named_with_the_model_and_what_it_has(capsys, one_stage, tmp_path,
                                                                            monkeypatch):
    path = measurement_file(tmp_path)
    monkeypatch.setattr(sys.modules["gearsym.fit.selection"], "fit_windows", lambda *a, **k: pytest.fail("fitted"))
    err = error_line(capsys, "explain", str(path), "--model", "one_stage", "--fit", "zeta,B2", "--out",
                     str(tmp_path / "r"), "--quiet")
    assert "cannot fit B2: one_stage has no parameter B2. Did you mean 'B1' or 'B0'?" in err
    assert "Its parameters: omega, zeta, B0, B1, Theta, eta, k_a" in err and "candidates" not in err


@pytest.mark.parametrize("value", ["-1", "0"])
def test_harmonics_below_one_are_refused(capsys, no_work, value, one_stage, tmp_path):
    err = error_line(capsys, "explain", "m.csv", "--model", "one_stage", "--fit", "zeta", "--out", str(tmp_path / "r"),
                     "--harmonics", value)
    assert f"--harmonics must be at least 1, got {value}" in err
    data = load_measurements(measurement_file(tmp_path), one_stage.system)
    with pytest.raises(GearsymError, match=f"^harmonics must be at least 1, got {value}"):
        explain(one_stage.system, data, ["zeta"], harmonics=int(value))


def test_harmonics_the_data_cannot_resolve_are_refused(one_stage, tmp_path, monkeypatch):
    data = load_measurements(measurement_file(tmp_path, per_period=20), one_stage.system)
    monkeypatch.setattr(sys.modules["gearsym.fit.selection"], "fit_windows", lambda *a, **k: pytest.fail("fitted"))
    with pytest.raises(GearsymError, match=r"^harmonics=10: these data resolve orders up to 9 .*record has 20\)$"):
        explain(one_stage.system, data, ["zeta"], harmonics=10)


# --------------------------------------------------------------------------- options that would be ignored
@pytest.mark.parametrize("argv", [
    ["sweep", "one_stage", "--param", "omega=0.5:1.5:0.5", "--set", "omega=1", "--out", "s.csv"],
    ["orbits", "one_stage", "--param", "omega=0.5:1.5", "--set", "omega=1"],
])
def test_a_parameter_both_swept_and_set_is_refused(capsys, no_work, tmp_path, monkeypatch, argv):
    monkeypatch.chdir(tmp_path)
    err = error_line(capsys, *argv)
    assert "omega is both swept (--param omega=0.5:1.5" in err and "--set omega ignored" in err


def test_zero_steps_per_period_are_refused_not_replaced_by_the_default(capsys, no_work):
    err = error_line(capsys, "lyap", "one_stage", "--steps-per-period", "0")
    assert "0 RK4 steps per forcing period (--steps-per-period) cannot resolve the forcing" in err


def test_more_jobs_than_cores_run_on_the_cores_and_say_so(capsys, one_stage, tmp_path, monkeypatch):
    monkeypatch.setattr(gearsym.sweep.workers, "cores", lambda: 2)
    with pytest.warns(GearsymWarning, match=r"^jobs=1000: this machine has 2 cores; running 2 workers"):
        workers = Workers.of(Execution(jobs=1000))
    assert workers.count == 2
    with warnings.catch_warnings():
        warnings.simplefilter("error", GearsymWarning)
        assert Workers.of(Execution(jobs=2)).count == 2 and Workers.of(Execution()).count == 2
    monkeypatch.chdir(tmp_path)
    assert main(["sweep", "one_stage", "--param", "omega=1,1.1", "--out", "s.csv", "--jobs", "1000", "--periods",
                 "60", "--discard", "20", "--quiet"]) == 0
    assert capsys.readouterr().err.splitlines() == [
        "gearsym: warning: --jobs 1000: this machine has 2 cores; running 2 workers (more would only share them)",
        "gearsym: warning: only 40 measured periods (--periods minus --discard): an exponent within 5/(measured "
        "time) of zero counts as zero, so the regime is uncertain (50 or more are safer)"]


def test_a_sweep_says_how_to_start_again_as_the_caller_writes_it(capsys, one_stage, tmp_path, monkeypatch):
    """docs/sweeps.md: the Python example after the command line's on the same file."""
    monkeypatch.chdir(tmp_path)
    command = ["sweep", "one_stage", "--param", "omega=1,1.1", "--out", "d.csv", "--periods", "70", "--discard",
               "20", "--quiet"]
    assert main(command) == 0
    with pytest.raises(GearsymError, match=r"pass overwrite=True or choose another out$"):
        run_sweep(one_stage, {"omega": [1.2]}, out="d.csv", options=Integration(periods=70, discard=20))
    capsys.readouterr()
    command[3] = "omega=1.2"
    err = error_line(capsys, *command)
    assert err.endswith("pass --overwrite or choose another --out\n")
