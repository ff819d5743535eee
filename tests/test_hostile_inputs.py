"""Inputs a careless or hostile user gives: each a one-line error with exit status 2 before any work (never a
traceback, nor exit 0), and nothing of a file that is not a measurement quoted back."""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
import warnings

import pytest

from gearsym.cli import main
from gearsym.errors import GearsymWarning
from gearsym.files.paths import REPO_ROOT
from gearsym.registry import model_path

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
    assert err.endswith(" is a folder\n")


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
