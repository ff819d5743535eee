"""Inputs a careless or hostile user gives: each a one-line error with exit status 2 before any work (never a
traceback, nor exit 0), and nothing of a file that is not a measurement quoted back."""
from __future__ import annotations

import errno
import os
import shutil
import subprocess
import sys
import threading
import warnings

import pytest

import conftest
import gearsym as gearsym_api
from gearsym import Gear, ToothFault
from gearsym.cli import main
from gearsym.errors import GearsymError, GearsymWarning, ModelError
from gearsym.files.paths import REPO_ROOT
from gearsym.registry import model_path
from test_checks_before_work import no_work  # noqa: F401 (a fixture)

ARGS = ("--periods", "70", "--discard", "10", "--format", "json")


def run(capsys, *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def one_line_error(code: int, err: str) -> str:
    assert code == 2, err
    assert err.startswith("gearsym: error: ") and len(err.strip().splitlines()) == 1, err
    return err


def gearsym(*argv: str, cwd) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "gearsym.cli", *argv], capture_output=True, text=True, cwd=cwd,
                          env={**os.environ, "PYTHONPATH": str(REPO_ROOT)}, timeout=300)


@pytest.mark.parametrize("name", ["passwd", "notes.txt", "model.py.bak"])
def test_a_file_that_is_not_python_is_not_taken_for_a_model(tmp_path, capsys, name):
    (tmp_path / name).write_text("root:x:0:0:root:/root:/bin/bash\n")
    err = one_line_error(*run(capsys, "lyap", str(tmp_path / name))[::2])
    assert "is not a model file: a model file is Python, named *.py" in err


def test_a_model_name_of_thousands_of_characters_is_an_unknown_model_said_briefly(capsys):
    err = one_line_error(*run(capsys, "lyap", "a" * 5000)[::2])
    assert "unknown model 'aaaa" in err and "(5000 characters)" in err and len(err) < 1000


def test_a_model_file_that_exits_is_an_error_not_a_silent_success(tmp_path):
    (tmp_path / "exits.py").write_text("import sys\nsys.exit(0)\n")
    proc = gearsym("lyap", "exits.py", cwd=tmp_path)
    assert proc.returncode == 2 and proc.stdout == ""
    assert proc.stderr == (f"gearsym: error: {tmp_path / 'exits.py'}, line 2: the model file calls exit (0) while it "
                           "is loaded; a model file defines `model` and must not exit\n")


def test_a_model_file_beside_a_folder_named_like_a_model_and_a_broken_symlink_runs_and_keeps_running(tmp_path,
                                                                                                      capsys):
    shutil.copy(REPO_ROOT / "models" / "one_stage.py", tmp_path / "mine.py")
    (tmp_path / "x.py").mkdir()
    (tmp_path / "y.py").symlink_to(tmp_path / "nowhere.py")
    first = run(capsys, "lyap", str(tmp_path / "mine.py"), *ARGS)
    assert first[0] == 0, first[2]
    again = run(capsys, "lyap", str(tmp_path / "mine.py"), *ARGS)
    assert again[:2] == first[:2]
    err = one_line_error(*run(capsys, "lyap", str(tmp_path / "x.py"))[::2])
    assert err.endswith(" is a folder, not a file; a model file is a Python file (*.py)\n")


@pytest.fixture
def shadowing(tmp_path):
    """A working directory whose models/ package has its own one_stage (another omega) and a model of its own."""
    models = tmp_path / "models"
    models.mkdir()
    (models / "__init__.py").write_text("")
    text = (REPO_ROOT / "models" / "one_stage.py").read_text()
    assert "omega=1.5" in text
    (models / "one_stage.py").write_text(text.replace("omega=1.5", "omega=1.25"))
    (models / "my_own.py").write_text(text.replace('"one_stage"', '"my_own"'))
    return tmp_path


@pytest.mark.slow
def test_a_models_package_in_the_working_directory_that_replaces_a_shipped_model_is_named(shadowing):
    shadow = shadowing / "models" / "one_stage.py"
    for _ in range(2):  # (the second run from the cache, without loading the model: said all the same)
        proc = gearsym("lyap", "one_stage", *ARGS, cwd=shadowing)
        assert proc.returncode == 0, proc.stderr
        assert (f"gearsym: warning: model one_stage is {shadow} (the models/ of the working directory), not the "
                f"shipped {REPO_ROOT / 'models' / 'one_stage.py'}") in proc.stderr.splitlines()
        assert '"omega": 1.25' in proc.stdout


def test_a_model_of_the_working_directorys_own_is_found_there_without_a_warning(shadowing, monkeypatch):
    monkeypatch.chdir(shadowing)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert model_path("my_own") == shadowing / "models" / "my_own.py"
    with pytest.warns(GearsymWarning, match="model one_stage is .* not the shipped"):
        assert model_path("one_stage") == shadowing / "models" / "one_stage.py"


SHADOW = "root:$6$Zx9secretsalt$hashofthepasswordthatmustnotleak:19701:0:99999:7:::\n"


def test_an_error_about_a_file_that_is_no_measurement_quotes_nothing_of_it(tmp_path, capsys):
    (tmp_path / "shadow").write_text(SHADOW * 3)
    err = one_line_error(*run(capsys, "explain", str(tmp_path / "shadow"), "--model", "one_stage", "--fit", "zeta",
                              "--out", str(tmp_path / "report"))[::2])
    said = err.replace(str(tmp_path / "shadow"), "FILE")
    assert said.startswith("gearsym: error: FILE, line 1: none of the 1 column(s) of its header is one gearsym knows")
    assert not {"root", "$6$", "secret", "19701", "99999"} & set(said.replace(":", " ").replace(",", " ").split())
    assert "root" not in said and "secret" not in said


def test_a_binary_file_is_refused_by_the_position_of_its_first_bad_byte_not_its_value(tmp_path, capsys):
    (tmp_path / "data.csv").write_bytes(b"tau,x\n0,1\n\xfe\xed\n")
    err = one_line_error(*run(capsys, "explain", str(tmp_path / "data.csv"), "--model", "one_stage", "--fit", "zeta",
                              "--out", str(tmp_path / "report"))[::2])
    assert "cannot read it as UTF-8 text (byte 11, on line 3, is not UTF-8)" in err
    assert "0xfe" not in err and "\\xfe" not in err and "fe" not in err.split("data.csv")[-1]


def test_a_measurement_file_still_names_its_unknown_column(tmp_path, capsys):
    (tmp_path / "data.csv").write_text("tau,x,xx\n0,1,2\n")
    err = one_line_error(*run(capsys, "explain", str(tmp_path / "data.csv"), "--model", "one_stage", "--fit", "zeta",
                              "--out", str(tmp_path / "report"))[::2])
    assert "line 1, column 'xx': unknown column" in err


# --------------------------------------------------------------------------- issue 35's battery
# (each a case the battery found: a traceback, a hang, a misleading message or a wrong answer with exit status 0)
STIFFNESS = ["stiffness", "--teeth", "28,28", "--module", "3.175 mm", "--face-width", "6.35 mm", "--pressure-angle",
             "20 deg", "--bore", "20 mm"]  # (a bore in Sainsot's range: no warning)


@pytest.mark.slow
@pytest.mark.parametrize("argv", [["list"], [*STIFFNESS, "--format", "json"]])
def test_a_full_or_closed_stdout_is_one_line_not_a_traceback(argv):
    command = " ".join(f"'{a}'" for a in [sys.executable, "-m", "gearsym.cli", *argv])
    env = {**os.environ, "PYTHONPATH": str(REPO_ROOT)}
    for redirect, said in (("> /dev/full", "gearsym: error: cannot write to standard output: No space left on device"),
                           (">&-", "gearsym: error: standard output is closed (>&-)")):
        proc = subprocess.run(["bash", "-c", f"{command} {redirect}"], capture_output=True, text=True, env=env,
                              timeout=300)
        said_lines = [line for line in proc.stderr.splitlines() if not line.startswith("gearsym: warning: ")]
        assert proc.returncode == 2 and len(said_lines) == 1 and said_lines[0].startswith(said), proc.stderr


@pytest.fixture
def full_disk(tmp_path, monkeypatch):
    """The disk under ``tmp_path`` fills at the first write of a file there: half the bytes land, then ENOSPC
    (the files gearsym writes elsewhere, its cache, are written)."""
    if not os.path.isdir("/proc/self/fd"):
        pytest.skip("needs /proc to tell which file a descriptor is")
    fdopen = os.fdopen

    def failing_fdopen(fd, *args, **kwargs):
        f = fdopen(fd, *args, **kwargs)
        if not os.readlink(f"/proc/self/fd/{fd}").startswith(str(tmp_path)):
            return f
        write = f.write

        def half_then_full(data):
            write(data[:len(data) // 2])
            f.flush()
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

        f.write = half_then_full
        return f

    monkeypatch.setattr(os, "fdopen", failing_fdopen)
    return tmp_path


@pytest.mark.parametrize("argv, name", [
    (["simulate", "one_stage", "--periods", "3", "--discard", "1", "--out"], "m.csv"),
    (["basins", "one_stage", "--grid", "x=-2,2", "--grid", "v=0", "--periods", "70", "--discard", "10", "--quiet",
      "--out"], "map.csv"),
    ([*STIFFNESS, "--plot"], "k.png"),
])
def test_a_full_disk_is_one_line_naming_the_file_and_leaves_no_half_of_it(full_disk, capsys, argv, name):
    code, out, err = run(capsys, *argv, str(full_disk / name))
    err = "".join(line for line in err.splitlines(keepends=True)  # (a first run's compile says so: progress)
                  if not line.startswith("gearsym: compiling "))
    assert one_line_error(code, err).startswith(f"gearsym: error: writing {full_disk / name} failed: No space left "
                                                 "on device; it is left as it was")
    assert not (full_disk / name).exists() and not list(full_disk.glob(".*.tmp"))  # (nothing half-written)


def test_a_compiler_that_fails_on_a_full_cache_disk_blames_the_disk_not_cc(tmp_path, monkeypatch):
    from gearsym.codegen import compiler

    source = tmp_path / "m.c"
    source.write_text("int gearsym_nothing(void) { return 0; }\n")
    monkeypatch.setenv("GEARSYM_CACHE", str(tmp_path / "cache"))
    monkeypatch.setattr(compiler, "no_room", lambda folder: True)  # (the compiler could not write its output)
    with pytest.raises(GearsymError) as failed:
        compiler.compile_library(source, "m", cc="false")
    assert "No space left on device" in str(failed.value) and "$GEARSYM_CACHE" in str(failed.value)
    assert "$CC" not in str(failed.value).replace("$GEARSYM_CACHE", "")


def test_an_output_that_is_a_symlink_is_refused_and_its_target_kept(tmp_path, capsys):
    victim = tmp_path / "victim.txt"
    victim.write_text("someone's file\n")
    (tmp_path / "m.csv").symlink_to(victim)
    err = one_line_error(*run(capsys, "simulate", "one_stage", "--periods", "3", "--discard", "1", "--out",
                              str(tmp_path / "m.csv"))[::2])
    assert f"--out {tmp_path / 'm.csv'} is a symlink (to {victim}); gearsym never writes through one" in err
    assert victim.read_text() == "someone's file\n"


def test_a_negative_number_after_an_option_is_its_value(capsys):
    code, out, err = run(capsys, *STIFFNESS, "--profile-shift", "-0.3,0.3")
    assert code == 0 and "profile shift -0.3/0.3" in out, err
    err = one_line_error(*run(capsys, "lyap", "one_stage", "--teeth", "-3,5")[::2])
    assert "--teeth '-3,5': give the tooth counts" in err
    err = one_line_error(*run(capsys, *STIFFNESS, "--rack", "-1,1.25,0.38")[::2])
    assert "expected one argument" not in err


@pytest.mark.parametrize("tooth", ["0", "2.5", "21"])
def test_a_faulty_tooth_that_is_no_tooth_is_refused(capsys, tmp_path, tooth):
    err = one_line_error(*run(capsys, "simulate", "one_stage", "--teeth", "20,53", "--effect", "tooth_fault_gear1",
                              "--set", "q_gear1=0.3", "--set", f"tooth_gear1={tooth}", "--out", str(tmp_path / "never.csv"))[::2])
    assert f"tooth_gear1': is the faulty tooth of gear1 (counted from tau = 0) and must be a whole number from 1 to 20, " \
           f"got {float(tooth):g}" in err


@pytest.mark.parametrize("depth", ["1.5", "-0.2", "1"])
def test_a_fault_depth_outside_0_to_1_is_refused_wherever_it_is_given(capsys, tmp_path, depth):
    err = one_line_error(*run(capsys, "simulate", "one_stage", "--teeth", "20,53", "--effect", "tooth_fault_gear1",
                              "--set", f"q_gear1={depth}", "--set", "tooth_gear1=3", "--out", str(tmp_path / "never.csv"))[::2])
    assert f"q_gear1': is the fraction of stiffness a fault of a tooth of gear1 takes from its pair and must be at " \
           f"least 0 and less than 1, got {float(depth):g}" in err
    with pytest.raises(ModelError, match=r"parameter 'q': is the fraction of the stiffness of the pair of tooth 7 of "
                                         r"'gear1' that its fault takes away and must be at least 0 and less than 1"):
        gearsym_api.load("cracked_pair", q=float(depth))
    with pytest.raises(ModelError, match=rf"ToothFault 'crack': depth {float(depth)!r} is a fraction of the pair's stiffness "
                                         r"lost: 0 <= depth < 1"):
        ToothFault("crack", "gear1", tooth=7, depth=float(depth))
    assert gearsym_api.load("cracked_pair", q=0.99).parameters["q"] == 0.99  # (below 1: a fault, however deep)


@pytest.mark.parametrize("teeth", [-5, 0, 2.5])
def test_a_tooth_count_that_is_no_count_is_refused_where_the_gear_is_declared(teeth):
    with pytest.raises(ModelError, match=rf"Gear 'g': a tooth count must be a whole number of at least 3, got {teeth}"):
        Gear("g", inertia="I", base_radius="r", teeth=teeth)


@pytest.mark.parametrize("grid, said", [
    (["x=-20s:20s:10s", "v=-500mm/s:500mm/s:250mm/s"], "x is a length of spur_pair ([length]), but s is [time]"),
    (["x=-20kg:20kg:10kg", "v=-500mm/s:500mm/s:250mm/s"], "but kg is [mass]"),
    (["x=-20um:20um:10um", "v=-500um:500um:250um"], "v is a velocity of spur_pair ([length] / [time]), but um is "
                                                    "[length]"),
])
def test_a_basins_grid_in_a_unit_of_another_dimension_is_refused_before_work(capsys, no_work, grid, said):
    err = one_line_error(*run(capsys, "basins", "spur_pair", "--grid", grid[0], "--grid", grid[1])[::2])
    assert said in err


@pytest.mark.parametrize("grid, said", [("x=-2:2:0", "--grid 'x=-2:2:0': the step must be nonzero"),
                                        ("x=abc", "--grid 'x=abc': expected NAME=START:STOP:STEP (e.g. x=-5:5:0.1)")])
def test_basins_grid_errors_name_grid(capsys, no_work, grid, said):
    err = one_line_error(*run(capsys, "basins", "one_stage", "--grid", grid, "--grid", "v=-1:1:1")[::2])
    assert said in err and "--param" not in err


@pytest.mark.parametrize("argv, said", [
    (["--param", "omega=0.5:1.5:0.00001", "--param", "zeta=0:1:0.00001"],
     "the sweep has 10000200001 points (100001 x 100001), more than the 1000000 one sweep may have"),
    (["--param", "omega=0:1:0.0000000001"], "10000000001 values, more than the 1000000 one --param may have"),
])
def test_a_grid_too_large_is_refused_at_once_with_its_size_and_the_limit(capsys, no_work, tmp_path, argv, said):
    err = one_line_error(*run(capsys, "sweep", "one_stage", *argv, "--out", str(tmp_path / "never.csv"))[::2])
    assert said in err and "typo" not in err


def test_more_poincare_samples_than_measured_periods_are_refused(capsys, tmp_path):
    err = one_line_error(*run(capsys, "sweep", "one_stage", "--param", "omega=1,1.1", "--poincare", "1000000000",
                              "--periods", "70", "--discard", "10", "--out", str(tmp_path / "s.csv"))[::2])
    assert "--poincare 1000000000: a point has one Poincare sample per measured period, 60 here" in err
    assert not (tmp_path / "s.csv").exists()


@pytest.fixture
def fifo(tmp_path, monkeypatch):
    """A named pipe nobody writes to (opened for writing at the end, so that a reader stuck on it returns)."""
    import gearsym.data.csvtext as csvtext

    monkeypatch.setattr(csvtext, "FIFO_WAIT", 0.2)
    path = tmp_path / "stream.csv"
    os.mkfifo(path)
    yield path
    try:
        os.close(os.open(path, os.O_WRONLY | os.O_NONBLOCK))
    except OSError:
        pass


@pytest.mark.parametrize("argv", [["explain", "{fifo}", "--model", "one_stage", "--fit", "zeta", "--out", "{out}"],
                                  ["spectrum", "one_stage", "--teeth", "20,53", "--data", "{fifo}"]])
def test_a_named_pipe_nobody_writes_to_is_refused_not_waited_on_for_ever(capsys, fifo, tmp_path, argv):
    argv = [a.format(fifo=fifo, out=tmp_path / "report") for a in argv]
    done = []
    worker = threading.Thread(target=lambda: done.append(run(capsys, *argv)), daemon=True)
    worker.start()
    worker.join(timeout=120)
    assert done, "the command waited on the named pipe"
    err = one_line_error(*done[0][::2])
    assert f"{fifo}: is a named pipe (FIFO) that nothing wrote to in 0.2 s: start its writer first" in err


def test_a_pipe_or_a_device_given_as_a_model_file_or_a_sweep_is_named_as_what_it_is(capsys, fifo, tmp_path):
    link = tmp_path / "m.py"
    link.symlink_to(fifo)
    err = one_line_error(*run(capsys, "lyap", str(link))[::2])
    assert err.endswith(f"model file {link} is a named pipe (FIFO), not a file; a model file is a Python file (*.py)\n")
    err = one_line_error(*run(capsys, "lyap", "/dev/zero")[::2])
    assert "model file /dev/zero is a device, not a file" in err
    err = one_line_error(*run(capsys, "orbits", "one_stage", "--param", "omega=1:1.2", "--sweep", str(fifo))[::2])
    assert f"{fifo}: is a named pipe (FIFO), not a file; a sweep is a CSV file" in err and "no such file" not in err


def test_a_local_dask_cluster_with_the_default_jobs_has_a_worker_per_core(tmp_path, monkeypatch):
    import gearsym.sweep.run as sweep_run
    from gearsym import Execution, run_sweep
    from gearsym.sweep.workers import cores

    pytest.importorskip("distributed")
    asked = []

    def cluster(run, tasks, scheduler, workers, ran):
        asked.append(workers)
        raise KeyboardInterrupt  # (no cluster started: the count asked is all this test wants)

    monkeypatch.setattr(sweep_run, "execute_on_dask", cluster)
    with pytest.raises(BaseException):
        run_sweep(conftest.compiled("one_stage"), {"omega": [1.0, 1.1]}, options=gearsym_api.Integration(
            periods=70, discard=10), mode="independent", execution=Execution(scheduler="local"),
            out=tmp_path / "s.csv")
    assert asked == [cores()] and cores() >= 1
