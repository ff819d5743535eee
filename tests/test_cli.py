"""The ``gearsym`` command line: list, derive, docs, and how errors are reported."""
from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

import gearsym.derivation
from gearsym import GearsymError, available_models
from gearsym.registry import pregenerated_models
from gearsym.cli import COMMANDS, main
from gearsym.derivation import derive
from gearsym.files.paths import REPO_ROOT
from conftest import SLOW_MODELS


@pytest.fixture(autouse=True, scope="module")
def cached_derivations():
    """The CLI derives (reduces) a model per call; reuse one derivation per model in this module (the
    declared models are shared objects, not hashable: keyed by identity, each kept alive by its entry)."""
    derived = {}

    def cached(model):
        if id(model) not in derived:
            derived[id(model)] = (model, derive(model))
        return derived[id(model)][1]

    patch = pytest.MonkeyPatch()
    patch.setattr(gearsym.derivation, "derive", cached)  # (the commands import it when they run)
    yield
    patch.undo()


def run(capsys, *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_every_module_of_the_cli_is_a_subcommand_named_as_its_module():
    assert [m.NAME for m in COMMANDS] == ["basins", "campbell", "compile", "derive", "docs", "explain", "fmu", "list",
                                          "lyap", "modes", "orbits", "poincare", "reproduce", "simulate", "spectrum",
                                          "stability", "stiffness", "sweep"]
    assert [m.NAME for m in COMMANDS] == [{"list_models": "list"}.get(m.__name__.rpartition(".")[2], m.__name__.rpartition(".")[2])
                                          for m in COMMANDS]


def test_list_shows_every_model_with_its_title(capsys):
    code, out, _ = run(capsys, "list")
    assert code == 0
    lines = out.splitlines()
    assert [line.split()[0] for line in lines] == available_models()
    assert any(line.startswith("flexible_shaft") and "Gear pair with a flexible shaft and disk" in line for line in lines)
    assert any(line.startswith("lorenz") and "Lorenz system" in line for line in lines)


def test_derive_json_of_flexible_shaft(capsys):
    code, out, err = run(capsys, "derive", "flexible_shaft", "--format", "json")
    assert code == 0 and err == ""
    data = json.loads(out)
    for key in ("model", "title", "states", "parameters", "equations", "groups", "conditions", "coordinates", "period"):
        assert key in data, key
    assert data["model"] == "flexible_shaft"
    assert data["states"] == ["x1", "v1", "x2", "v2"]
    kinds = {g["name"]: g["kind"] for g in data["groups"]}
    assert kinds == {"beta_1": "derived", "beta_2": "derived", "beta_3": "derived",
                     "zeta": "free", "B0": "free", "B1": "free"}
    groups = {g["name"]: g for g in data["groups"]}
    assert groups["beta_1"]["definition"] == "1/I2"
    assert groups["beta_1"]["latex"] == r"\frac{1}{I_{2}}"
    assert groups["beta_3"]["value"] == 0.5
    assert all(set(g) >= {"name", "definition", "latex", "kind", "description"} for g in data["groups"])
    params = data["parameters"]
    assert params["omega"]["default"] == 1.5 and isinstance(params["kS"]["default"], float)
    assert params["kS"]["description"].startswith("torsional stiffness")
    assert [c["name"] for c in data["coordinates"]] == ["x1", "x2"]
    assert data["coordinates"][1]["definition"] == "-r2*psi_2(t) + r2*psi_3(t)"
    assert len(data["equations"]) == 2 and "beta_1*kS*x2(tau)/omega**2" in data["equations"][0]
    assert [c["equation"] for c in data["conditions"]] == [
        "Eq(kZ*(r2**2/I2 + r1**2/I1), 1)", "Eq(0, -M3*r2/I3 + M2*r2/I2)",
    ]
    assert data["period"] == "2*pi"


def test_derive_text_is_the_default(capsys):
    code, out, _ = run(capsys, "derive", "one_stage")
    assert code == 0
    assert out.startswith("one_stage: One-stage gear pair (Eqs. 1-2)\n")
    assert "Nondimensional equations" in out and "Coefficient groups" in out
    assert "[free] damping ratio of mesh 'mesh'" in out


def test_derive_latex(capsys):
    code, out, _ = run(capsys, "derive", "one_stage", "--format", "latex")
    assert code == 0
    assert r"g\left(x, \eta\right)" in out
    assert r"B_{1} &= \frac{M_{1a} r_{1}}{I_{1}}" in out
    assert out.count(r"\begin{aligned}") == out.count(r"\end{aligned}") == 4


def test_derive_unknown_model_suggests_the_name(capsys):
    code, out, err = run(capsys, "derive", "flexible_shat")
    assert code == 2 and out == ""
    assert err.startswith("gearsym: error: unknown model 'flexible_shat'.")
    assert "Did you mean 'flexible_shaft'?" in err
    assert "Traceback" not in err


def test_derive_missing_model_file(capsys):
    code, _, err = run(capsys, "derive", "no/such/model.py")
    assert code == 2 and err == "gearsym: error: model file no/such/model.py does not exist\n"


def test_bad_format_is_a_usage_error(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["derive", "one_stage", "--format", "html"])
    assert exc.value.code == 2


def test_errors_exit_2_without_traceback_in_a_real_process():
    env = {**os.environ, "PYTHONIOENCODING": "utf-8"}
    proc = subprocess.run([sys.executable, "-m", "gearsym.cli", "derive", "flexible_shat"],
                          capture_output=True, text=True, env=env, cwd=REPO_ROOT)
    assert proc.returncode == 2
    assert proc.stderr.startswith("gearsym: error: unknown model 'flexible_shat'. Did you mean 'flexible_shaft'?")
    assert "Traceback" not in proc.stderr


@pytest.mark.slow
def test_docs_check_passes_on_the_committed_pages(capsys, monkeypatch):
    monkeypatch.chdir(REPO_ROOT)  # (the pages are checked where they would be written: the current folder's)
    fast = [m for m in pregenerated_models("page") if m not in SLOW_MODELS]
    code, out, err = run(capsys, "docs", *fast, "--check")
    assert code == 0, err
    assert f"{len(fast)} page(s) up to date" in out


@pytest.mark.slow
def test_docs_check_all_passes_on_the_committed_pages(capsys, monkeypatch):
    monkeypatch.chdir(REPO_ROOT)
    code, out, err = run(capsys, "docs", "--all", "--check")
    assert code == 0, err
    assert f"{len(pregenerated_models('page'))} page(s) up to date" in out


def test_docs_writes_then_checks(tmp_path, capsys):
    code, out, _ = run(capsys, "docs", "one_stage", "lorenz", "--out", str(tmp_path))
    assert code == 0
    assert [line.rsplit("/", 1)[-1] for line in out.splitlines()] == ["one_stage.md", "lorenz.md"]
    committed = REPO_ROOT / "docs" / "derivations"
    for name in ("one_stage", "lorenz"):
        assert (tmp_path / f"{name}.md").read_bytes() == (committed / f"{name}.md").read_bytes()
    assert run(capsys, "docs", "one_stage", "lorenz", "--out", str(tmp_path), "--check")[0] == 0

    (tmp_path / "lorenz.md").write_text("edited by hand\n", encoding="utf-8")
    (tmp_path / "one_stage.md").unlink()
    code, out, err = run(capsys, "docs", "one_stage", "lorenz", "--out", str(tmp_path), "--check")
    assert code == 1 and out == ""
    assert "one_stage.md is out of date" in err and "lorenz.md is out of date" in err
    assert (tmp_path / "lorenz.md").read_text(encoding="utf-8") == "edited by hand\n"  # --check writes nothing
    assert not (tmp_path / "one_stage.md").exists()


def test_docs_needs_models_or_all(capsys, tmp_path):
    assert run(capsys, "docs", "--out", str(tmp_path))[0] == 2
    assert run(capsys, "docs", "one_stage", "--all", "--out", str(tmp_path))[0] == 2
    assert list(tmp_path.iterdir()) == []


def test_docs_unknown_model(capsys, tmp_path):
    code, _, err = run(capsys, "docs", "one_stag", "--out", str(tmp_path))
    assert code == 2 and "Did you mean 'one_stage'" in err
    assert list(tmp_path.iterdir()) == []


def test_a_model_whose_code_alone_is_pre_generated_is_left_out_of_the_pages():
    # Lin & Parker's set declares PREGENERATED = "code": its C is committed, its page (a megabyte) not
    assert "planetary_translational" in available_models()
    assert "planetary_translational" in pregenerated_models()
    assert set(pregenerated_models("page")) == set(available_models()) - {"planetary_translational"}


def test_a_model_that_is_not_pre_generated_is_listed_but_left_out_of_every_all(monkeypatch, tmp_path):
    models = tmp_path / "models"  # (the working directory's models/ is the one gearsym lists)
    models.mkdir()
    (models / "__init__.py").write_text("")
    (models / "derived_on_use.py").write_text("PREGENERATED = False\nraise SystemExit('listing runs no model file')\n")
    (models / "code_only.py").write_text("PREGENERATED: str = 'code'\nraise SystemExit('listing runs no model file')\n")
    (models / "committed.py").write_text("raise SystemExit('listing runs no model file')\n")
    monkeypatch.chdir(tmp_path)
    assert available_models() == ["code_only", "committed", "derived_on_use"]
    assert pregenerated_models() == ["code_only", "committed"] and pregenerated_models("page") == ["committed"]


@pytest.mark.parametrize("line", ["PREGENERATED = 1", "PREGENERATED = 'page'", "PREGENERATED = bool(1)"])
def test_a_pre_generated_flag_that_is_not_written_as_true_false_or_code_is_said_with_its_line(monkeypatch, tmp_path,
                                                                                                line):
    (tmp_path / "models").mkdir()
    (tmp_path / "models" / "__init__.py").write_text("")
    (tmp_path / "models" / "odd.py").write_text(f"# a model\n{line}\n")
    monkeypatch.chdir(tmp_path)
    with pytest.raises(GearsymError, match=r"odd.py, line 2: PREGENERATED is True, False or \"code\""):
        pregenerated_models()
