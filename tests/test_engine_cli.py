"""``gearsym lyap`` and ``gearsym compile``."""
from __future__ import annotations

import json

import numpy as np
import pytest

from conftest import SLOW_MODELS, compiled, paper_rk4_spectrum, slow_models_group
from gearsym import Integration, available_models, lyapunov_spectrum
from gearsym.registry import pregenerated_models
from gearsym.cli import main
from gearsym.files.paths import REPO_ROOT


def run(capsys, *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_lyap_json_has_the_documented_keys(capsys):
    code, out, _ = run(capsys, "lyap", "flexible_shaft", "--set", "omega=1.5", "--set", "kS=0.1", "--periods", "200",
                       "--discard", "50", "--steps-per-period", "200", "--format", "json")
    assert code == 0
    data = json.loads(out)
    assert len(data["exponents"]) == 4 and len(data["stderr"]) == 4
    assert data["exponents"] == sorted(data["exponents"], reverse=True)
    # the sum rule (trace of J = -2 zeta/omega) at ten times the error measured, 5.0e-9 of it: an exponent
    # averaged over one period too many or few is off by ~1/150
    assert sum(data["exponents"]) == pytest.approx(-2 * 0.08 / 1.5, rel=5e-8, abs=0)
    assert set(data["amplitude"]) == {"x1", "x2"} and all(a > 0 for a in data["amplitude"].values())
    assert set(data["final_state"]) == {"x1", "v1", "x2", "v2"}
    assert data["parameters"]["kS"] == 0.1 and data["periods"] == 200 and data["discard"] == 50


def test_lyap_locates_the_crossings_unless_told_plain_as_the_python_api_does(capsys):
    import gearsym
    from conftest import system

    argv = ("lyap", "one_stage", "--set", "omega=1.5", "--periods", "60", "--discard", "20")
    for flags, options in (((), gearsym.Integration(periods=60, discard=20)),
                           (("--locate-crossings",), gearsym.Integration(periods=60, discard=20)),  # the old flag
                           (("--plain",), gearsym.Integration.paper(periods=60, discard=20))):
        code, out, _ = run(capsys, *argv, *flags, "--format", "json")
        assert code == 0
        expected = gearsym.lyapunov_spectrum(system("one_stage"), options=options, omega=1.5)
        assert json.loads(out)["exponents"] == list(expected.exponents), flags
    code, out, _ = run(capsys, *argv, "--plain")
    assert "200 RK4 steps/period, plain, compiled" in out
    code, out, _ = run(capsys, *argv)
    assert "200 RK4 steps/period, crossings located" in out


@pytest.mark.slow
def test_lyap_accepts_a_new_stiffness_formula(capsys):
    """The exponents with k = 1 + 0.3 cos(tau) are those of Eq. 2 with that k typed in NumPy (the paper's plain
    RK4, as --plain runs it), not those of the model's own k(tau)."""
    argv = ("lyap", "one_stage", "--set", "omega=0.5", "--periods", "60", "--discard", "20", "--plain",
            "--format", "json")
    code, out, _ = run(capsys, *argv, "--set", "k=1+0.3*cos(tau)")
    assert code == 0
    data = json.loads(out)
    assert "k_a" not in data["parameters"]  # the default k(tau) and its amplitude are gone
    reference, final, _ = paper_rk4_spectrum(0.5, 60, 20, 200, a=0.3)
    assert reference[0] < -1e-3, "the comparison point must be periodic (errors do not grow)"
    # measured 1e-16 apart; a constant k is 0.02 off, the model's own 0.018
    assert data["exponents"] == pytest.approx(np.sort(reference)[::-1].tolist(), abs=1e-9)
    assert [data["final_state"]["x"], data["final_state"]["v"]] == pytest.approx(final.tolist(), abs=1e-9)
    code, out, _ = run(capsys, *argv)
    assert code == 0 and np.abs(np.array(json.loads(out)["exponents"]) - data["exponents"]).max() > 1e-2


def test_lyap_text_output_and_initial_state(capsys):
    """--y0 is where the run starts: the text shows the spectrum and final state of the Python run from it."""
    code, out, _ = run(capsys, "lyap", "lorenz", "--periods", "30", "--discard", "10", "--y0", "x=1,y=2,z=20")
    assert code == 0
    options = Integration(periods=30, discard=10)
    expected, default = (lyapunov_spectrum(compiled("lorenz"), options=options, y0=y0) for y0 in ([1, 2, 20], None))
    lines = [f"  lambda_{i} = {lam:+.6f} +- {err:.6f}" for i, (lam, err) in
             enumerate(zip(expected.exponents, expected.stderr), 1)]
    lines.append("final state: " + ", ".join(f"{k}={v:.6g}" for k, v in expected.final_state.items()))
    missing = [line for line in lines if line not in out.splitlines()]
    assert not missing, f"{missing} not in\n{out}"
    assert lines[-1] != "final state: " + ", ".join(f"{k}={v:.6g}" for k, v in default.final_state.items())



def test_lyap_text_names_the_regime_and_what_it_means(capsys):
    code, out, _ = run(capsys, "lyap", "one_stage", "--set", "omega=1.2", "--periods", "200", "--discard", "50")
    assert code == 0 and "regime: chaotic: exactly one exponent above zero" in out
    code, out, _ = run(capsys, "lyap", "lorenz", "--periods", "60", "--discard", "10", "--format", "json")
    regime = json.loads(out)["regime"]
    code, out, _ = run(capsys, "lyap", "lorenz", "--periods", "60", "--discard", "10")
    line = next(line for line in out.splitlines() if line.startswith("regime:"))
    assert line.startswith(f"regime: {regime}: lambda_") and "the exponent along the flow" in line
    assert "autonomous" in line and "left out" in line


def test_lyap_plot_shows_the_coordinate_asked_for(capsys, tmp_path, monkeypatch):
    import gearsym.cli.lyap as command

    drawn = []
    real = command.plot_point
    monkeypatch.setattr(command, "plot_point", lambda *a, **k: drawn.append((a, real(*a, **k))) or drawn[-1][1])
    code, _, _ = run(capsys, "lyap", "flexible_shaft", "--periods", "40", "--discard", "10", "--plot",
                     str(tmp_path / "p.png"), "--coordinate", "x2")
    assert code == 0
    (spectrum, trajectory, *_), fig = drawn[0]
    portrait = fig.axes[1]
    trajectory_line, points = portrait.lines[:2]
    assert np.array_equal(trajectory_line.get_xdata(), trajectory["x2"])
    assert np.array_equal(trajectory_line.get_ydata(), trajectory["v2"])  # against the state after it
    assert np.array_equal(points.get_xdata(), spectrum.strobe[trajectory.state_names.index("x2")])
    assert (portrait.get_xlabel(), portrait.get_ylabel()) == ("x2", "v2")


def test_lyap_refuses_an_unknown_coordinate_before_any_work(capsys, tmp_path, monkeypatch):
    import gearsym.cli.lyap as lyap_command

    monkeypatch.setattr(lyap_command, "lyapunov_spectrum", lambda *a, **k: pytest.fail("the spectrum ran"))
    code, _, err = run(capsys, "lyap", "flexible_shaft", "--plot", str(tmp_path / "p.png"), "--coordinate", "v1")
    assert code == 2 and "--coordinate v1: no such coordinate" in err and "x1, x2" in err
    code, _, err = run(capsys, "lyap", "flexible_shaft", "--coordinate", "x2")
    assert code == 2 and "add --plot" in err


@pytest.mark.parametrize("argv,message", [
    (["lyap", "one_stage", "--set", "omgea=1.5"], "Did you mean 'omega'"),
    (["lyap", "one_stage", "--set", "omega"], "expected NAME=VALUE"),
    (["lyap", "one_stage", "--set", "zeta=-1"], "zeta"),
    (["lyap", "one_stage", "--periods", "10", "--discard", "10"], "discard < periods"),
    (["lyap", "one_stage", "--y0", "x:1"], "NAME=NUMBER"),
    (["lyap", "one_stage", "--y0", "q=1"], "unknown states"),
    (["lyap", "one_stage", "--y0", "x=1,x=2"], "gives x twice"),
    (["lyap", "one_stage", "--set", "omega=1e400"], "finite"),
    (["lyap", "lorenz", "--set", "rho=1+x"], "only drivetrain models accept a formula"),
    (["lyap", "nosuchmodel"], "unknown model"),
])
def test_lyap_errors_are_one_line_messages(capsys, argv, message):
    code, _, err = run(capsys, *argv)
    assert code == 2
    assert message in err and "Traceback" not in err


@pytest.mark.slow
def test_compile_check_reports_up_to_date(capsys, monkeypatch):
    monkeypatch.chdir(REPO_ROOT)  # (the C is checked where it would be written: the current folder's)
    fast = [m for m in pregenerated_models() if m not in SLOW_MODELS]
    code, out, _ = run(capsys, "compile", *fast, "--check")
    assert code == 0 and f"up to date ({len(fast)} models)" in out


@pytest.mark.slow
@slow_models_group()  # (it reduces every model: with the other tests that reduce the slow ones)
def test_compile_check_all_reports_up_to_date(capsys, monkeypatch):
    monkeypatch.chdir(REPO_ROOT)
    code, out, _ = run(capsys, "compile", "--all", "--check")
    assert code == 0 and f"up to date ({len(pregenerated_models())} models)" in out


def test_compile_writes_source_manifest_and_library(capsys, tmp_path):
    code, out, _ = run(capsys, "compile", "one_stage", "--out", str(tmp_path))
    assert code == 0
    assert (tmp_path / "one_stage" / "one_stage.c").is_file() and (tmp_path / "one_stage" / "manifest.json").is_file()
    assert "library" in out
    code, out, _ = run(capsys, "compile", "one_stage", "--out", str(tmp_path))
    assert "(cached)" in out  # the same source is never compiled twice


def test_compile_check_detects_a_hand_edited_file(capsys, tmp_path):
    run(capsys, "compile", "lorenz", "--out", str(tmp_path), "--no-compile")
    source = tmp_path / "lorenz" / "lorenz.c"
    source.write_text(source.read_text().replace("casadi_real", "double", 1))
    code, _, err = run(capsys, "compile", "lorenz", "--out", str(tmp_path), "--check")
    assert code == 1 and "lorenz.c" in err


def test_lyap_plot_writes_a_png(capsys, tmp_path):
    out = tmp_path / "fig" / "point.png"
    code, _, err = run(capsys, "lyap", "one_stage", "--set", "omega=1.2", "--periods", "60", "--discard", "20",
                       "--plot", str(out))
    assert code == 0 and f"wrote {out}" in err
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and out.stat().st_size > 20_000
