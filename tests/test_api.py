"""The public face of issue 13: one options object, verbs split by type, names resolved only at the edge,
couplings handed on by the reduction, one RK4 for the engine and the fit."""
from __future__ import annotations

import os
import re
import subprocess
import sys

import numpy as np
import pytest
import sympy as sp

import gearsym
from conftest import compiled, system
from gearsym import FirstOrderSystem, GearsymError, Integration
from gearsym.model.backlash import g
from gearsym.files.paths import REPO_ROOT
from gearsym.model.symbols import parameter_symbol

SHORT = Integration(periods=40, discard=10)


# ------------------------------------------------------------------ Integration
@pytest.mark.parametrize("kwargs, words", [
    ({"backend": "gpu"}, "unknown backend 'gpu'; choose one of auto, compiled, in-process"),
    ({"periods": 100, "discard": 100}, r"transient \(discard=100\) must be shorter than the run \(periods=100\)"),
    ({"periods": 50}, r"discard=100.*periods counts every forcing period, the discarded ones included"),
    ({"periods": 2.5}, "periods must be a whole number, got 2.5"),
    ({"discard": "10"}, "discard must be a whole number, got '10'"),
    ({"steps_per_period": 200.0}, "steps per period must be a whole number"),
    ({"steps_per_period": 0}, "steps per period must be at least 1"),
    ({"discard": -1}, "discard must be at least 0"),
    ({"locate_crossings": "yes"}, "locate_crossings must be True or False"),
])
def test_bad_integration_options_are_one_line_errors(kwargs, words):
    with pytest.raises(GearsymError, match=words) as caught:
        Integration(**kwargs)
    assert "\n" not in str(caught.value)


def test_integration_counts_every_period_and_the_paper_scheme_is_plain_rk4():
    assert Integration() == Integration(periods=400, discard=100, steps_per_period=200, locate_crossings=True,
                                        backend="auto")
    assert Integration(periods=140, discard=100).measured == 40
    assert Integration.paper(periods=160) == Integration(periods=160, locate_crossings=False, integrator="rk4")
    assert Integration.paper().run(periods=30, discard=10) == Integration(30, 10, locate_crossings=False,
                                                                          integrator="rk4")


# ------------------------------------------------------------------ names are resolved by gearsym.load
@pytest.mark.parametrize("verb, args", [
    ("lyapunov_spectrum", ()), ("poincare_samples", ()), ("phase_trajectory", ()), ("find_attractors", ()),
    ("run_sweep", (["omega=1,1.1"],)), ("simulate_measurements", ()),
])
def test_a_verb_given_a_model_name_says_to_load_it_first(verb, args):
    with pytest.raises(GearsymError, match=rf"{verb} takes a compiled model or a FirstOrderSystem, got str; "
                                           rf"resolve the name first: {verb}\(gearsym\.load\('one_stage'\), \.\.\.\)"):
        getattr(gearsym, verb)("one_stage", *args)


def test_compile_model_derive_and_load_measurements_given_a_name_say_what_to_call(tmp_path):
    with pytest.raises(GearsymError, match=r"use gearsym\.load\(\.\.\.\) first"):
        gearsym.compile_model("one_stage")
    with pytest.raises(GearsymError, match=r"derive\(gearsym\.load_model\('one_stage'\)\)"):
        gearsym.derive("one_stage")
    with pytest.raises(GearsymError, match=r"resolve a name with gearsym\.load"):
        gearsym.load_measurements(tmp_path / "m.csv", "one_stage")


# ------------------------------------------------------------------ a compiled model and the options of a run
def test_a_compiled_model_runs_any_length_but_refuses_options_that_need_other_code():
    cm = compiled("one_stage")  # Integration(): 200 steps per period, crossings located
    r = gearsym.lyapunov_spectrum(cm, options=Integration(periods=30, discard=10, backend="auto"), omega=1.3)
    assert (r.periods, r.discard, r.strobe.shape) == (30, 10, (2, 20))
    assert gearsym.lyapunov_spectrum(cm, omega=1.3).periods == 400  # no options: the ones it was compiled with
    # an integrator left to choose ("auto") with fewer steps than the model's takes the model's own choice
    assert gearsym.poincare_samples(cm, options=Integration(30, 10, steps_per_period=100)).strobe.shape[-1] == 20
    for other in (Integration.paper(periods=30, discard=10), Integration(30, 10, steps_per_period=100, integrator="rk4"),
                  Integration(30, 10, steps_per_period=400), Integration(periods=30, discard=10, backend="in-process")):
        with pytest.raises(GearsymError, match=r"compile the system with these options "
                                               r"\(compile_model\(system, options\)\)") as caught:
            gearsym.poincare_samples(cm, options=other)
        assert "\n" not in str(caught.value)
    with pytest.raises(GearsymError, match="options must be a gearsym.Integration, got dict"):
        gearsym.lyapunov_spectrum(cm, options={"periods": 30})


# ------------------------------------------------------------------ the high-level call on a system
@pytest.mark.parametrize("options", [SHORT, Integration.paper(periods=40, discard=10)])
def test_a_verb_on_a_system_is_the_verb_on_the_system_compiled_with_the_same_options(options):
    one_stage = system("one_stage")
    high = gearsym.lyapunov_spectrum(one_stage, options=options, omega=1.3)
    low = gearsym.lyapunov_spectrum(gearsym.compile_model(one_stage, options), omega=1.3)
    assert np.array_equal(high.exponents, low.exponents) and np.array_equal(high.strobe, low.strobe)
    assert high.final_state == low.final_state and (high.periods, high.discard) == (40, 10)
    assert high.info["locate_crossings"] == options.locate_crossings
    orbit = gearsym.poincare_samples(one_stage, options=options, omega=1.3)
    assert np.array_equal(orbit.strobe, low.strobe)


@pytest.mark.slow
def test_a_system_is_compiled_for_each_verbs_own_run_when_no_options_are_given():
    duffing = FirstOrderSystem.from_equations(
        "weak_duffing", ["x", "v"], ["v", "-d*v + x - x**3 + F*cos(w*t)"], {"d": 0.3, "F": 0.1, "w": 1.2},
        time="t", period="2*pi/w", initial={"x": 1.0})
    found = gearsym.find_attractors(duffing, initial_states=[[1.0, 0.0]])
    assert (found.periods, found.discard, found.measured) == (500, 300, 200)  # 500 periods in all, 300 a transient
    table = gearsym.simulate_measurements(duffing, samples_per_period=25)
    assert table.rows == 40 * 25 + 1 and table.steps_per_period == 200  # 40 periods recorded after 100
    spectrum = gearsym.lyapunov_spectrum(duffing)
    assert (spectrum.periods, spectrum.discard, spectrum.steps_per_period) == (400, 100, 200)


# ------------------------------------------------------------------ the public face
def run_python(code: str) -> str:
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(REPO_ROOT), os.environ.get("PYTHONPATH")]))}
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, env=env,
                          cwd=REPO_ROOT).stdout


def test_import_gearsym_is_cheap_and_every_public_name_resolves():
    out = run_python(
        "import sys, gearsym\n"
        "print('casadi' in sys.modules, 'gearsym.codegen' in sys.modules, 'matplotlib' in sys.modules)\n"
        "gearsym.compile_model; gearsym.lyapunov_spectrum; gearsym.run_sweep\n"
        "print('casadi' in sys.modules)\n"
        "missing = [n for n in gearsym.__all__ if getattr(gearsym, n, None) is None]\n"
        "print(missing, sorted(set(gearsym.__all__) - set(dir(gearsym))))\n")
    assert out.splitlines() == ["False False False", "True", "[] []"]


def test_gearsym_reduce_stays_the_function_once_its_subpackage_is_imported():
    out = run_python("import gearsym, gearsym.reduction.nondimensional, gearsym.registry\n"
                     "from gearsym.reduction import reduce\n"
                     "print(gearsym.reduce is reduce, callable(gearsym.reduce))\n")
    assert out.split() == ["True", "True"]


def test_the_code_generator_resolves_no_model_names():
    """codegen takes a FirstOrderSystem: it imports neither the registry of models nor the reduction."""
    codegen = sorted((REPO_ROOT / "gearsym" / "codegen").glob("*.py"))
    assert len(codegen) > 5
    found = [f"{path.name}:{number}: {line.strip()}" for path in codegen
             for number, line in enumerate(path.read_text().splitlines(), 1)
             if re.search(r"registry|from \.\.reduce", line)]
    assert found == []


# ------------------------------------------------------------------ the couplings the reduction hands on
@pytest.mark.parametrize("name", ["flexible_shaft", "two_stage", "rich"])
def test_the_couplings_carried_by_a_system_are_those_of_its_equations(name):
    """For every coupling and every velocity equation, the coefficient of the coupling's law in it (the law:
    k(tau) g(x, eta)/omega^2 for a mesh, kS x/omega^2 for a shaft) is -factor of its row, 0 outside its rows."""
    reduced = system(name)
    states = dict(zip(reduced.state_names, reduced.states))
    omega = parameter_symbol("omega")
    velocity_rows = [i for i, f in enumerate(reduced.rhs) if f not in reduced.states]
    law = sp.Dummy("law")
    meshes = [c for c in reduced.couplings if c.kind == "mesh"]
    assert {c.kind for c in reduced.couplings} == {"mesh", "shaft"}
    assert {g(c.contact, c.backlash) for c in meshes} == {a for f in reduced.rhs for a in f.atoms(g)}
    for c in reduced.couplings:
        x, v = states[c.coordinate], states[c.velocity]
        assert reduced.rhs[reduced.states.index(x)] == v  # dx/dtau = v: its coordinate and rate
        assert (c.backlash == 0) == (c.kind == "shaft") and c.contact == x
        handle = g(c.contact, c.backlash) if c.kind == "mesh" else x
        rows = dict(c.rows)
        assert set(rows) <= set(velocity_rows) and rows
        for i in velocity_rows:
            coefficient = sp.diff(reduced.rhs[i].xreplace({handle: law}), law)
            assert sp.cancel(coefficient + rows.get(i, 0) * c.stiffness / omega**2) == 0, (c.name, i)  # exact
    if name == "flexible_shaft":  # Eq. 9: the mesh drives both rows, beta_3 in the second; the shaft beta_1, beta_2
        I1, I2, I3, r1, r2 = (parameter_symbol(n) for n in ("I1", "I2", "I3", "r1", "r2"))
        mesh, shaft = reduced.coupling("x1"), reduced.coupling("x2")
        assert (mesh.backlash, mesh.order, shaft.stiffness) == (parameter_symbol("eta"), 1, parameter_symbol("kS"))
        assert [i for i, _ in mesh.rows] == [1, 3] == [i for i, _ in shaft.rows]
        assert sp.cancel(dict(mesh.rows)[3] - (r2**2 / I2) / (r1**2 / I1 + r2**2 / I2)) == 0
        assert sp.cancel(dict(shaft.rows)[1] - 1 / I2) == 0
        assert sp.cancel(dict(shaft.rows)[3] - (1 / I2 + 1 / I3)) == 0


# ------------------------------------------------------------------ one RK4
def test_the_fits_window_integrator_is_the_engines_rk4_bit_for_bit():
    """The fit's windows and the engine's plain loops step with the one rk4_step. On a system whose equations
    the engine takes as they are (no tables, no constants: nothing evaluated another way) and whose step
    h = 1/128 is exact, the two trajectories agree to the last bit, across the backlash's kinks."""
    from gearsym.fit.shooting import Segment, simulate_segment

    t, x, v = sp.symbols("t x v", real=True)
    kinked = FirstOrderSystem("kinked", t, (x, v), (v, -v / 10 - g(x, 1) + sp.Rational(1, 2)), {}, sp.Integer(1),
                              initial={"x": -2.0, "v": 0.3})
    scheme = Integration.paper(periods=3, discard=0, steps_per_period=128, backend="in-process")
    engine = gearsym.phase_trajectory(kinked, options=scheme)
    assert engine["x"].min() < -1 and engine["x"].max() > 0  # through the whole gap: both kinks crossed
    window = simulate_segment(kinked, Segment(engine.time, {}, {}), engine.states[:, 0], period=1.0, options=scheme)
    assert np.array_equal(window, engine.states)


def test_an_integration_option_passed_as_a_parameter_value_says_where_it_belongs():
    with pytest.raises(gearsym.GearsymError, match=r"periods is how to integrate.*options=gearsym.Integration"):
        gearsym.lyapunov_spectrum(system("one_stage"), periods=60)
