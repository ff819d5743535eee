"""Bad input is a one-line error before any long work starts, and a surprising choice is said in one line.

The "before the work" tests replace every entry into compiling and computing by one that fails the
test: the error must come from the check, not from the end of a run.
"""
from __future__ import annotations

import subprocess
import sys
import warnings
from pathlib import Path

import pytest

import gearsym
import gearsym.cli.compile
import gearsym.cached
import gearsym.codegen.generated
import gearsym.loading
import gearsym.registry
import gearsym.reproduce.compute  # likewise
import gearsym.cli.docs
import gearsym.cli.lyap
import gearsym.cli.poincare
import gearsym.cli.simulate
import gearsym.cli.sweep
import gearsym.codegen
import gearsym.reproduce
from gearsym.cli import main
from conftest import compiled
from gearsym.errors import GearsymError, GearsymWarning
from gearsym.files.paths import REPO_ROOT


def run(capsys, *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture
def no_work(monkeypatch):
    """Any compiling or computing fails the test."""
    def work(*args, **kwargs):
        raise AssertionError("the work started before the input was checked")

    for module, name in ((gearsym, "compile_model"), (gearsym.codegen.build, "compile_model"),
                         (gearsym.cli.sweep, "run_sweep"),
                         (gearsym.cli.simulate, "with_effects"),
                         (gearsym, "load"), (gearsym.loading, "load"), (gearsym.codegen.generated, "generate_model"),
                         (gearsym.cli.docs, "page"), (sys.modules["gearsym.reproduce"], "reproduce")):
        monkeypatch.setattr(module, name, work)


def error_line(capsys, *argv: str) -> str:
    code, _, err = run(capsys, *argv)
    assert code == 2 and err.startswith("gearsym: error: ") and err.count("\n") == 1, err
    return err


# --------------------------------------------------------------------------- model files
@pytest.mark.parametrize("source,line,kind", [
    ("from gearsym import Drivetrain\nmodel = Drivetrain('m'\nx = 1\n", 2, "SyntaxError"),
    ("import math\nfrom gearsym import Drivetrain, Gera\nmodel = None\n", 2, "ImportError"),
    ("import math\n\nimport no_such_module_anywhere\n", 3, "ModuleNotFoundError"),
    ("from gearsym import Drivetrain\nmodel = Drivetrain('m')\nmodel.add(undefined_gear)\n", 3, "NameError"),
])
def test_a_model_file_that_fails_to_run_is_named_with_its_line(capsys, tmp_path, monkeypatch, source, line, kind):
    (tmp_path / "broken.py").write_text(source)
    for where, path in ((REPO_ROOT, tmp_path / "broken.py"), (tmp_path, Path("broken.py"))):
        monkeypatch.chdir(where)
        err = error_line(capsys, "derive", str(path))
        assert f"broken.py, line {line}: {kind}" in err


# --------------------------------------------------------------------------- outputs
@pytest.mark.parametrize("argv", [
    ["lyap", "one_stage", "--plot", "p.txt"],
    ["sweep", "one_stage", "--param", "omega=1:1.2:0.1", "--out", "s.csv", "--plot", "p.txt"],
    ["poincare", "one_stage", "--plot", "p"],
])
def test_a_figure_matplotlib_cannot_write_is_refused_before_computing(capsys, no_work, tmp_path, monkeypatch, argv):
    monkeypatch.chdir(tmp_path)
    err = error_line(capsys, *argv)
    assert "--plot" in err and ".png" in err and ".pdf" in err and ".svg" in err


@pytest.mark.parametrize("command", [["lyap", "one_stage"], ["simulate", "one_stage", "--out", "m.csv"]])
def test_a_bad_start_is_refused_before_the_model_is_compiled(capsys, no_work, tmp_path, monkeypatch, command):
    monkeypatch.chdir(tmp_path)
    assert "--y0 'x=fast'" in error_line(capsys, *command, "--y0", "x=fast")


def unwritable_places(tmp_path: Path) -> list[Path]:
    blocker = tmp_path / "a-file"
    blocker.write_text("")
    places = [blocker / "below"]  # no folder can be made below a file
    if Path("/proc/self").is_dir():
        places.append(Path("/proc"))  # Linux: nobody, not even root, makes files there
    return places


@pytest.mark.parametrize("command", [
    ["lyap", "one_stage", "--plot", "{}/p.png"],
    ["poincare", "one_stage", "--plot", "{}/p.png"],
    ["sweep", "one_stage", "--param", "omega=1:1.2:0.1", "--out", "{}/x.csv"],
    ["simulate", "one_stage", "--out", "{}/x.csv"],
    ["explain", "m.csv", "--model", "one_stage", "--fit", "zeta", "--out", "{}/report"],
    ["reproduce", "--out", "{}/figures"],
    ["docs", "one_stage", "--out", "{}/docs"],
    ["compile", "one_stage", "--out", "{}/generated"],
])
def test_an_output_in_an_unwritable_place_is_refused_before_computing(capsys, no_work, tmp_path, command):
    for place in unwritable_places(tmp_path):
        err = error_line(capsys, *(word.format(place) for word in command))
        assert str(place) in err


def test_an_output_with_the_wrong_suffix_is_refused_before_computing(capsys, no_work):
    assert ".csv" in error_line(capsys, "sweep", "one_stage", "--param", "omega=1:1.2:0.1", "--out", "s.txt")
    assert ".csv" in error_line(capsys, "simulate", "one_stage", "--out", "m.txt")


def test_explain_refuses_an_existing_file_as_its_report_folder_before_fitting(capsys, no_work, tmp_path):
    existing = tmp_path / "report"
    existing.write_text("keep me\n")
    err = error_line(capsys, "explain", "m.csv", "--model", "one_stage", "--fit", "zeta", "--out", str(existing))
    assert "is a file, not a folder" in err and existing.read_text() == "keep me\n"


def test_a_writable_output_leaves_nothing_behind_when_checked(tmp_path):
    from gearsym.files.outputs import check_figure, check_folder

    check_figure(tmp_path / "new" / "p.png")
    check_folder(tmp_path / "out")
    assert list(tmp_path.iterdir()) == []


# --------------------------------------------------------------------------- run lengths
@pytest.mark.parametrize("argv,message", [
    (["lyap", "one_stage", "--steps-per-period", "3"], "cannot resolve the forcing"),
    (["sweep", "one_stage", "--param", "omega=1:1.2:0.1", "--out", "s.csv", "--steps-per-period", "3"],
     "cannot resolve the forcing"),
    (["poincare", "one_stage", "--steps-per-period", "3"], "cannot resolve the forcing"),
    (["simulate", "one_stage", "--out", "m.csv", "--samples-per-period", "3", "--steps-per-period", "3"],
     "cannot resolve the forcing"),
    (["compile", "one_stage", "--steps-per-period", "3"], "cannot resolve the forcing"),
    (["lyap", "one_stage", "--periods", "5", "--discard", "0"], "5 measured periods"),
    (["sweep", "one_stage", "--param", "omega=1:1.2:0.1", "--out", "s.csv", "--periods", "105"],
     "5 measured periods"),
    (["poincare", "one_stage", "--periods", "305"], "5 measured periods"),  # --discard 300 by default
])
def test_a_run_too_coarse_or_too_short_to_mean_anything_is_refused(capsys, no_work, tmp_path, monkeypatch, argv,
                                                                  message):
    monkeypatch.chdir(tmp_path)
    assert message in error_line(capsys, *argv)


def test_a_coarse_or_short_run_is_warned_in_one_line_each():
    from gearsym.cli.arguments.integration import check_run

    with pytest.warns(GearsymWarning) as seen:
        check_run(steps_per_period=12, measured=20, discard=0)
    messages = [str(w.message) for w in seen]
    assert len(messages) == 3 and all("\n" not in m for m in messages)
    assert "12 RK4 steps" in messages[0] and "20 measured periods" in messages[1] and "--discard 0" in messages[2]
    with warnings.catch_warnings():
        warnings.simplefilter("error", GearsymWarning)
        check_run(steps_per_period=200, measured=300, discard=100)  # the defaults: nothing to say


def test_the_command_line_prints_a_warning_as_one_line(capsys):
    code, _, err = run(capsys, "lyap", "lorenz", "--periods", "30", "--discard", "0", "--y0", "x=1,y=2,z=20")
    assert code == 0
    assert "gearsym: warning: only 30 measured periods" in err
    assert "gearsym: warning: no transient discarded" in err
    assert "Traceback" not in err and "GearsymWarning" not in err and "warn(" not in err


# --------------------------------------------------------------------------- simulate, --y0, explain
@pytest.mark.parametrize("argv,needs", [
    (["--effect", "cubic_stiffness"], "--set k3=VALUE"),
    (["--effect", "cubic_stiffness", "--set", "k3=0"], "--set k3=VALUE"),
    (["--effect", "mesh_stiffness_harmonic_2", "--set", "k_c2=0"], "--set k_c2=VALUE and/or --set k_s2=VALUE"),
])
def test_simulating_an_effect_without_its_strength_is_refused(capsys, no_work, argv, needs):
    assert needs in error_line(capsys, "simulate", "one_stage", "--out", "m.csv", *argv)


def test_an_initial_state_that_leaves_out_a_state_says_it_starts_at_zero(capsys):
    model = compiled("one_stage")
    with pytest.warns(GearsymWarning, match=r"does not name v, so it starts at 0, not at the model's v=-0.5"):
        assert list(model.initial_state({"x": 1.0})) == [1.0, 0.0]
    with warnings.catch_warnings():
        warnings.simplefilter("error", GearsymWarning)
        model.initial_state({"x": 1.0, "v": 0.0})
    code, _, err = run(capsys, "lyap", "one_stage", "--y0", "x=1", "--periods", "60", "--discard", "10")
    assert code == 0 and "gearsym: warning: one_stage: the initial state does not name v" in err


def test_fitting_a_parameter_the_records_set_differently_is_refused_before_fitting(tmp_path, monkeypatch):
    model = compiled("one_stage")
    path = tmp_path / "m.csv"
    gearsym.simulate_measurements(model, options=model.integration.run(periods=14, discard=10), samples_per_period=20,
                                  records=[{"omega": 1.2}, {"omega": 1.6}], out=path)
    measurements = gearsym.load_measurements(path, model.system)
    monkeypatch.setattr(sys.modules["gearsym.fit.selection"], "fit_windows", lambda *a, **k: pytest.fail("fitted anyway"))
    with pytest.raises(GearsymError, match=r"cannot fit omega: the records set it to different values \(1.2, 1.6\)"):
        gearsym.explain(model.system, measurements, ["zeta", "omega"])


# --------------------------------------------------------------------------- a closed stdout
def test_a_closed_stdout_ends_the_command_quietly():
    proc = subprocess.Popen([sys.executable, "-m", "gearsym.cli", "list"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, cwd=REPO_ROOT)
    proc.stdout.close()  # as `gearsym list | head -0`: the reader is gone before anything is written
    err = proc.stderr.read().decode()
    assert proc.wait() == 141 and err == ""


# --------------------------------------------------------------------------- checks from the declaration alone
@pytest.fixture
def no_reduction(no_work, monkeypatch):
    """Any reduction of a model (the SymPy derivation: half a minute for a planetary set on bearings) or
    linearisation fails the test too: the check must come from the model's declaration."""
    import gearsym.stability

    def work(*args, **kwargs):
        raise AssertionError("the model was reduced before the input was checked")

    for module, name in ((gearsym.loading, "reduce"), (gearsym.stability, "compile_linearisation")):
        monkeypatch.setattr(module, name, work)


def test_a_spectrum_run_too_short_for_the_sidebands_is_refused_from_the_declaration(capsys, no_reduction):
    err = error_line(capsys, "spectrum", "spur_pair_bearings", "--periods", "140")
    assert "holds 40 mesh periods, less than the 2 revolutions of pinion (28 teeth" in err
    assert "give at least --periods 156" in err


@pytest.mark.parametrize("about", ["static", "orbit"])
def test_a_chart_along_a_model_option_is_refused_before_the_model_is_reduced(capsys, no_reduction, about):
    err = error_line(capsys, "stability", "spur_pair_bearings", "--param", "speed=4000rpm,6000rpm", "--param",
                     "dof=4,6", "--about", about, "--quiet")
    assert "dof is a model option of spur_pair_bearings" in err and "--set dof=4" in err
