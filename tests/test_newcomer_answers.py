"""Right answers where a newcomer starts: a model without a start or defaults, a drive through a shaft,
a model file of one's own."""
from __future__ import annotations

import json
import shutil
import subprocess
import warnings

import numpy as np
import pytest

import gearsym
from gearsym import (Disk, Drivetrain, FirstOrderSystem, Gear, Integration, Mesh, Shaft, Torque, lyapunov_spectrum,
                     reduce)
from gearsym.cli import main
from gearsym.errors import GearsymWarning, ModelError
from gearsym.files.paths import REPO_ROOT
from gearsym.registry import output_root
from gearsym.model.symbols import parameter_symbol

LORENZ = (["x", "y", "z"], ["sigma*(y - x)", "x*(rho - z) - y", "x*y - beta*z"],
          {"sigma": 10.0, "rho": 28.0, "beta": 8.0 / 3.0})


def run(capsys, *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


# --------------------------------------------------------------------------- a fixed point is no chaos
def test_lorenz_started_on_its_fixed_point_is_an_equilibrium_with_its_eigenvalues_not_chaos():
    lorenz = FirstOrderSystem.from_equations("lorenz_at_origin", *LORENZ)  # no initial: all states 0
    with pytest.warns(GearsymWarning, match=r"initial state \(x=0, y=0, z=0\) is a fixed point"):
        r = lyapunov_spectrum(lorenz, options=Integration(periods=60, discard=10))
    assert r.regime == "equilibrium" and r.at_rest
    # the exponents of the origin are its eigenvalues: -beta and (-(sigma+1) -+ sqrt((sigma-1)^2 + 4 sigma rho))/2
    root = np.sqrt(81 + 4 * 10 * 28)
    expected = [(-11 + root) / 2, -8 / 3, (-11 - root) / 2]
    assert np.allclose(r.exponents, expected, rtol=1e-12, atol=0)
    assert np.allclose(r.eigenvalues, expected, rtol=1e-12, atol=0) and list(r.stderr) == [0, 0, 0]
    report = r.as_dict()
    assert report["regime"] == "equilibrium" and report["equilibrium"]["stable"] is False
    assert [e["re"] for e in report["equilibrium"]["eigenvalues"]] == list(r.exponents)


def test_a_lorenz_run_that_leaves_the_fixed_point_is_still_chaotic_and_says_nothing():
    lorenz = FirstOrderSystem.from_equations("lorenz_at_origin", *LORENZ)
    with warnings.catch_warnings():
        warnings.simplefilter("error", GearsymWarning)
        r = lyapunov_spectrum(lorenz, options=Integration(periods=60, discard=10), y0=[1e-6, 0.0, 0.0])
    assert r.regime == "chaotic" and not r.at_rest and r.as_dict()["equilibrium"] is None


def test_gearsym_lyap_says_equilibrium_in_text_and_json(capsys, tmp_path):
    path = tmp_path / "lorenz0.py"
    path.write_text("from gearsym import FirstOrderSystem\n"
                    f"model = FirstOrderSystem.from_equations('lorenz0', *{LORENZ!r})\n")
    code, out, err = run(capsys, "lyap", str(path), "--periods", "60", "--discard", "10")
    assert code == 0 and "gearsym: warning: lorenz0: the initial state (x=0, y=0, z=0) is a fixed point" in err
    assert "regime: equilibrium, unstable (the run never left a fixed point" in out
    code, out, _ = run(capsys, "lyap", str(path), "--periods", "60", "--discard", "10", "--format", "json")
    data = json.loads(out)
    assert data["regime"] == "equilibrium" and data["equilibrium"]["state"] == {"x": 0.0, "y": 0.0, "z": 0.0}


# --------------------------------------------------------------------------- values and symbols
BARE_SHAFT = """from gearsym import Disk, Drivetrain, Gear, Harmonic, Mesh, Shaft, Torque

model = Drivetrain("bare_shaft")  # the README's flexible shaft before any set_defaults
g1 = model.add(Gear("gear1", inertia="I1", base_radius="r1"))
g2 = model.add(Gear("gear2", inertia="I2", base_radius="r2"))
d3 = model.add(Disk("disk3", inertia="I3"))
model.add(Mesh("mesh", g1, g2, stiffness="kZ", damping="cZ", backlash="eta", coordinate="x1"))
model.add(Shaft("shaft", g2, d3, stiffness="kS", coordinate="x2", forced=False))
model.add(Torque("M1", on=g1, mean="M1", harmonics=(Harmonic("M1a", phase="Theta", group="B1"),)))
model.add(Torque("M2", on=g2, mean="M2", load=True))
model.add(Torque("M3", on=d3, mean="M3", load=True))
"""


@pytest.fixture(scope="module")
def bare_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("bare") / "bare_shaft.py"
    path.write_text(BARE_SHAFT)
    return path


@pytest.fixture(scope="module")
def bare(bare_file):
    return reduce(gearsym.load_model(bare_file))


def test_the_missing_defaults_message_leaves_out_the_values_passed(bare):
    with pytest.raises(ModelError) as exc:
        bare.system(omega=1.2, zeta=0.1)
    message = str(exc.value)
    assert "parameters without a default value: B0" in message
    assert "omega" not in message.split(". Add")[0] and "zeta" not in message.split(". Add")[0]


def test_every_value_passed_is_enough_without_defaults(bare):
    values = dict(omega=1.2, zeta=0.1, B0=1.0, B1=4.0, Theta=0.0, eta=10.0, k_a=0.2, kS=0.1,
                  I1=1.0, I2=1.0, I3=1.0, r1=1.0, r2=1.0)
    assert bare.system(**values).parameters["omega"] == 1.2


def test_derive_prints_the_equations_of_a_model_without_defaults(capsys, bare_file):
    code, out, err = run(capsys, "derive", str(bare_file))
    assert code == 0 and err == ""
    assert "Nondimensional equations" in out and "omega      no default" in out
    code, out, _ = run(capsys, "derive", str(bare_file), "--format", "json")
    data = json.loads(out)
    assert data["parameters"]["omega"]["default"] is None
    assert len(data["equations"]) == 2 and "beta_1*kS*x2(tau)/omega**2" in data["equations"][0]


# --------------------------------------------------------------------------- a drive through a shaft
def motor_shaft_pinion_gear(**shaft) -> Drivetrain:
    m = Drivetrain("motor_drive")
    motor = m.add(Disk("motor", inertia="Im"))
    pinion = m.add(Gear("pinion", inertia="I1", base_radius="r1"))
    gear = m.add(Gear("gear", inertia="I2", base_radius="r2"))
    m.add(Shaft("shaft", motor, pinion, stiffness="kS", coordinate="x1", **shaft))
    m.add(Mesh("mesh", pinion, gear, coordinate="x2"))
    m.add(Torque("Mm", on=motor, mean="Mm"))
    m.add(Torque("ML", on=gear, mean="ML", load=True))
    return m


def test_a_motor_torque_through_a_shaft_stays_in_the_reduced_equations_by_default():
    nd = reduce(motor_shaft_pinion_gear())
    forcing = {gr.name: gr.definition for gr in nd.groups if gr.role == "forcing"}
    shaft_row = nd.equations[0]  # x1, the twist
    assert parameter_symbol("Mm") in forcing["B0"].free_symbols and parameter_symbol("B0") in shaft_row.rhs.free_symbols
    assert [c.kind for c in nd.conditions] == ["time_unit"]  # nothing assumed away


def test_the_torque_balance_is_an_assumption_declared_on_the_shaft():
    nd = reduce(motor_shaft_pinion_gear(forced=False))
    balance = [c for c in nd.conditions if c.kind == "torque_balance"]
    assert len(balance) == 1 and parameter_symbol("Mm") in balance[0].equation.free_symbols
    assert nd.equations[0].rhs == 0


# --------------------------------------------------------------------------- a user's model stays outside
USER_MODEL = """from gearsym import FirstOrderSystem

model = FirstOrderSystem.from_equations("my_oscillator", ["x", "v"], ["v", "-x - 2*zeta*v"], {"zeta": 0.1},
                                        initial={"x": 1.0})
"""


def repository_state() -> str:
    return subprocess.run(["git", "status", "--porcelain", "--untracked-files=all"],
                          cwd=REPO_ROOT, capture_output=True, text=True, check=True).stdout


@pytest.mark.slow
def test_a_user_model_writes_docs_and_c_beside_the_user_not_into_the_installed_tree(tmp_path, monkeypatch, capsys):
    models, work = tmp_path / "mymodels", tmp_path / "work"
    models.mkdir()
    work.mkdir()
    (models / "m.py").write_text(USER_MODEL)
    before = repository_state()
    monkeypatch.chdir(work)
    try:
        for command in (["docs", "../mymodels/m.py"], ["compile", "../mymodels/m.py", "--no-compile"]):
            assert main(command) == 0, capsys.readouterr().err
        assert (work / "docs" / "derivations" / "my_oscillator.md").is_file()
        assert (work / "generated" / "my_oscillator" / "my_oscillator.c").is_file()
        assert repository_state() == before
    finally:  # a failure must not leave the user's model in the checkout, where it would fail other tests
        (REPO_ROOT / "docs" / "derivations" / "my_oscillator.md").unlink(missing_ok=True)
        shutil.rmtree(REPO_ROOT / "generated" / "my_oscillator", ignore_errors=True)


@pytest.mark.slow
def test_shipped_models_run_from_a_scratch_folder_write_into_it_not_into_the_installed_tree(tmp_path, monkeypatch,
                                                                                           capsys):
    before = repository_state()
    monkeypatch.chdir(tmp_path)  # (the commands run here: the session's reductions of the models serve them)
    for command in (["docs", "flexible_shaft"], ["compile", "one_stage", "lorenz", "--no-compile"]):
        assert main(command) == 0, capsys.readouterr().err
    assert (tmp_path / "docs" / "derivations" / "flexible_shaft.md").read_bytes() == \
        (REPO_ROOT / "docs" / "derivations" / "flexible_shaft.md").read_bytes()  # (the committed page, here)
    for name in ("one_stage", "lorenz"):
        assert (tmp_path / "generated" / name / f"{name}.c").read_bytes() == \
            (REPO_ROOT / "generated" / name / f"{name}.c").read_bytes()
    assert repository_state() == before


def test_the_default_output_folder_is_the_current_one_for_every_model(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "m.py").write_text(USER_MODEL)
    for ref in ("one_stage", str(REPO_ROOT / "models" / "one_stage.py"), "m.py", gearsym.load_model("m.py")):
        assert output_root(ref) == tmp_path
