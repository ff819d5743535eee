"""Code generation: translation, splitting, determinism, the committed generated/, cache, fallback."""
from __future__ import annotations

import ctypes
import os
import subprocess
import sys

import casadi as ca
import numpy as np
import pytest
import sympy as sp

import gearsym
import gearsym.codegen.build as build_module
import gearsym.codegen.loaded as loaded_module
import gearsym.codegen.library as library_module
import gearsym.codegen.compiler as compiler
import gearsym.codegen.functions
from conftest import model_params, slow_models_group, system
from gearsym import FirstOrderSystem, GearsymError, Integration, ModelError, UnknownParameterError, compile_model
from gearsym.model.backlash import G, g, g_slope
from gearsym.codegen import CompilerError
from gearsym.codegen.generated import generate_model
from gearsym.codegen.native import load_native
from gearsym.codegen.on_arrays import evaluate_on_samples, numpy_program
from gearsym.codegen.time_tables import split_rhs
from gearsym.codegen.translate import to_casadi
from gearsym.files.paths import REPO_ROOT
from gearsym.registry import available_models, pregenerated_models


# ------------------------------------------------------------------ SymPy -> CasADi
@pytest.mark.parametrize("x", [5.0, 0.0, -0.5, -9.99, -10.0, -12.5])
def test_backlash_translation_matches_sympy_on_every_branch(x):
    xs, es = sp.Symbol("x", real=True), sp.Symbol("eta", real=True)
    X, E = ca.SX.sym("x"), ca.SX.sym("eta")
    exprs = [g(xs, es), g_slope(xs, es), G(xs, es), sp.Piecewise((xs**2, xs > 1), (sp.cos(xs), True))]
    f = ca.Function("f", [X, E], to_casadi(exprs, {xs: X, es: E}))
    for expr, value in zip(exprs, f(x, 10.0)):
        expected = float(expr.subs({xs: x, es: 10.0}).rewrite(sp.Piecewise))
        assert float(value) == pytest.approx(expected, abs=1e-15)


def test_casadi_jacobian_of_backlash_is_the_slope():
    X, E = ca.SX.sym("x"), ca.SX.sym("eta")
    xs, es = sp.Symbol("x", real=True), sp.Symbol("eta", real=True)
    (gx,) = to_casadi([g(xs, es)], {xs: X, es: E})
    slope = ca.Function("s", [X, E], [ca.jacobian(gx, X)])
    assert [float(slope(x, 10.0)) for x in (3.0, -4.0, -11.0)] == [1.0, 0.0, 1.0]


def test_untranslatable_function_is_a_clear_error():
    xs = sp.Symbol("x", real=True)
    with pytest.raises(ModelError, match="cannot generate code for besselj"):
        to_casadi([sp.besselj(0, xs)], {xs: ca.SX.sym("x")}, "m")


# ------------------------------------------------------------------ tables and constants
def test_split_puts_all_time_dependence_into_tables_and_parameters_into_constants():
    shaft = system("flexible_shaft")
    split = split_rhs(shaft)
    states = set(shaft.states)
    for f in split.rhs:
        assert shaft.time not in f.free_symbols
        assert all(s in states or s.name.startswith(("table_", "const_")) for s in f.free_symbols)
    # substituting the entries back gives the model's rhs exactly
    back = {sym: expr for sym, expr in split.tables + split.constants}
    for f, original in zip(split.rhs, shaft.rhs):
        assert sp.simplify(f.xreplace(back) - original) == 0


def test_time_dependence_that_is_not_periodic_is_rejected():
    bad = FirstOrderSystem.from_equations("drift", ["x"], ["-x + t"], {}, time="t", period=1)
    with pytest.raises(ModelError, match="not periodic with the declared period"):
        compile_model(bad, Integration(backend="in-process"))


# ------------------------------------------------------------------ generated/ is what the models give
@pytest.mark.parametrize("name", model_params(pregenerated_models()))
@pytest.mark.slow
@slow_models_group()  # (with `gearsym compile --all --check`, which then compares with the C made here: made once)
def test_committed_generated_code_is_regenerated_byte_for_byte(name):
    import json
    made_with = json.loads((REPO_ROOT / "generated" / name / "manifest.json").read_text())["casadi_version"]
    assert made_with == ca.__version__, (f"generated/ was made with CasADi {made_with}, this is {ca.__version__}: "
                                         "install the pinned version (pyproject.toml) or regenerate")
    report = generate_model(system(name), REPO_ROOT / "generated", check=True)  # the default: crossings located
    assert report.stale == [], f"stale: {report.stale}; run `gearsym compile --all` and commit generated/"


@pytest.mark.slow
def test_generated_code_does_not_depend_on_the_hash_seed(tmp_path):
    """One_stage loaded, reduced and generated in a process of a hash seed other than this one's, and in this
    process (the session's reduction: made with this process's seed): the same bytes."""
    script = ("import sys, gearsym; from gearsym.codegen.generated import generate_model; "
              "generate_model(gearsym.load('one_stage'), sys.argv[1], compile=False)")
    other = "2" if os.environ.get("PYTHONHASHSEED") == "1" else "1"  # (this one's: random, or the one it was given)
    env = {**os.environ, "PYTHONHASHSEED": other}
    subprocess.run([sys.executable, "-c", script, str(tmp_path / "other")], check=True, env=env)
    generate_model(system("one_stage"), tmp_path / "this", compile=False)
    for fname in ("one_stage.c", "manifest.json"):
        other_bytes, these = ((tmp_path / made / "one_stage" / fname).read_bytes() for made in ("other", "this"))
        assert other_bytes == these, fname


def test_manifest_records_hash_options_and_casadi_version():
    import json
    manifest = json.loads((REPO_ROOT / "generated" / "flexible_shaft" / "manifest.json").read_text())
    assert manifest["casadi_version"] == ca.__version__
    assert manifest["options"]["steps_per_period"] == 200
    assert manifest["options"]["locate_crossings"] is True  # the default scheme is committed
    assert manifest["states"] == ["x1", "v1", "x2", "v2"]
    assert len(manifest["hash"]) == 64
    assert "omega" in manifest["parameters"] and "kS" in manifest["parameters"]


# ------------------------------------------------------------------ compiled == in-process
@pytest.mark.parametrize("scheme,points", [
    (Integration.paper, ({"omega": 0.2}, {"omega": 1.7, "kS": 1.0})),
    # located crossings: at omega=0.2 the two backends' rounding, through the located steps, parts by 1.2e-12
    # in the log stretches after 60 periods; the periodic point keeps the 1e-12
    (Integration, ({"omega": 1.7, "kS": 1.0},)),
])
@pytest.mark.slow
def test_compiled_and_in_process_agree(scheme, points):
    compiled = compile_model(system("flexible_shaft"), scheme(backend="compiled"))
    inproc = compile_model(system("flexible_shaft"), scheme(backend="in-process"))
    assert compiled.backend == "compiled" and inproc.backend == "in-process"
    for cm_pair_p in points:
        runs = []
        for cm in (compiled, inproc):
            inputs = cm.prepare(cm.parameter_vector(cm_pair_p))
            runs.append(cm.tangent_run(None, 60, inputs))
        a, b = runs
        assert np.max(np.abs(a.strobe - b.strobe)) < 1e-12
        assert np.max(np.abs(a.log_stretch - b.log_stretch)) < 1e-12
        assert np.max(np.abs(a.low - b.low)) < 1e-12
    y, p = np.array([0.3, -0.2, 1.1, 0.4]), compiled.parameter_vector(omega=1.3)
    assert compiled.rhs(0.7, y, p) == pytest.approx(inproc.rhs(0.7, y, p), abs=1e-14)
    assert compiled.jacobian(0.7, y, p) == pytest.approx(inproc.jacobian(0.7, y, p), abs=1e-14)


def test_chunks_and_single_periods_give_the_same_run():
    cm = compile_model(system("one_stage"))
    inputs = cm.prepare(cm.parameter_vector(omega=0.8))
    whole = cm.tangent_run(None, 53, inputs)  # one chunk of 50 and three single periods
    first = cm.tangent_run(None, 3, inputs)
    rest = cm.tangent_run(first.strobe[:, -1], 50, inputs, Q0=first.Q)
    assert whole.strobe.shape == (2, 53)
    assert np.array_equal(whole.strobe, np.hstack([first.strobe, rest.strobe]))
    assert np.array_equal(whole.log_stretch, np.hstack([first.log_stretch, rest.log_stretch]))


# ------------------------------------------------------------------ parameters are inputs; cache
def test_changing_parameters_never_rebuilds(monkeypatch):
    cm = compile_model(system("one_stage"))
    calls = []
    monkeypatch.setattr(gearsym.codegen.functions, "build_functions", lambda *a, **k: calls.append(1))
    monkeypatch.setattr(build_module, "compile_library", lambda *a, **k: calls.append(1))
    again = compile_model(system("one_stage").with_values(omega=0.7, zeta=0.05))
    assert calls == [] and again.functions is cm.functions
    assert again.parameter_vector()[list(again.parameter_names).index("omega")] == 0.7


@pytest.mark.slow
def test_library_cache_survives_a_new_process_and_misses_on_a_new_model(monkeypatch):
    compile_model(system("lorenz"))
    monkeypatch.setattr(loaded_module, "LOADED", {})  # as in a fresh process
    again = compile_model(system("lorenz"))
    assert "compile" not in again.timings and again.library.is_file()
    other = compile_model(system("lorenz"), Integration(steps_per_period=100))
    assert other.hash != again.hash and other.library != again.library


def test_unknown_or_unphysical_parameter_values_are_rejected():
    cm = compile_model(system("one_stage"))
    with pytest.raises(UnknownParameterError, match="Did you mean 'omega'"):
        cm.parameter_vector(omgea=1.0)
    with pytest.raises(ModelError, match="zeta"):
        cm.parameter_vector(zeta=-0.1)


def test_without_a_compiler_auto_falls_back_and_compiled_explains(monkeypatch, capsys):
    monkeypatch.setenv("CC", "no-such-compiler-gearsym")
    compiler.find_compiler.cache_clear()
    monkeypatch.setattr(library_module, "_WARNED", set())
    try:
        cm = compile_model(system("lorenz"), Integration(backend="auto", steps_per_period=100))
        assert cm.backend == "in-process"
        assert "no C compiler found" in capsys.readouterr().err
        assert gearsym.lyapunov_spectrum(cm, options=cm.integration.run(20, 5)).sum == pytest.approx(-13.6667, abs=1e-3)
        monkeypatch.setattr(loaded_module, "LOADED", {})
        with pytest.raises(CompilerError, match="apt install gcc"):
            compile_model(system("lorenz"), Integration(backend="compiled", steps_per_period=100))
    finally:
        compiler.find_compiler.cache_clear()


def test_a_failing_compiler_reports_its_output(monkeypatch, tmp_path):
    src = tmp_path / "broken.c"
    src.write_text("this is not C\n")
    with pytest.raises(CompilerError, match="compiling .*broken.c failed"):
        compiler.compile_library(src, "broken")


# ------------------------------------------------------------------ what the split must get right, end to end
def _numpy_orbit(system, p, y0, t0, periods, steps):
    """Plain NumPy RK4 of the state from the SymPy equations (lambdify): the reference for the split."""
    import math
    names = list(system.parameters)
    args = (system.time, *system.states, *[sp.Symbol(n, real=True) for n in names])
    f = sp.lambdify(args, [e.subs({s: sp.Symbol(s.name, real=True) for s in e.free_symbols
                                   if s.name in names}) for e in system.rhs], "math")
    period = float(system.period.subs({sp.Symbol(n, real=True): v for n, v in zip(names, p)}))
    h = period / steps
    y, out = np.array(y0, dtype=float), []
    for k in range(periods):
        for i in range(steps):
            t = t0 + k * period + i * h

            def F(tt, yy):
                return np.array(f(tt, *yy, *p), dtype=float)

            k1 = F(t, y)
            k2 = F(t + h / 2, y + h / 2 * k1)
            k3 = F(t + h / 2, y + h / 2 * k2)
            k4 = F(t + h, y + h * k3)
            y = y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        out.append(y.copy())
    assert math.isfinite(period)
    return np.array(out).T


@pytest.mark.slow
@pytest.mark.parametrize("backend", ["compiled", "in-process"])
def test_piecewise_min_max_powers_and_time_conditions_survive_the_split(backend):
    odd = FirstOrderSystem.from_equations(
        "odd", ["x", "v"],
        ["v", "-d*v - Piecewise((x**3, x > 0), (x, True)) + 0.1*Max(x, -1) + 0.01*Abs(x)**a "
              "+ F*cos(t) + Piecewise((0.3, sin(t) > 0), (0, True)) + Piecewise((-x, x > 2), (0.1*sin(2*t), True))"],
        {"d": 0.3, "a": 1.5, "F": 0.4}, time="t", period="2*pi", initial={"x": 0.5})
    cm = compile_model(odd, Integration.paper(backend=backend, steps_per_period=100))  # the reference's plain RK4
    p = cm.parameter_vector(F=0.5)
    inputs = cm.prepare(p, t0=0.7)
    strobe, _, _ = cm.orbit_run([0.5, 0.1], 4, inputs)
    reference = _numpy_orbit(odd, p, [0.5, 0.1], 0.7, 4, 100)
    assert strobe == pytest.approx(reference, abs=1e-9)


def test_time_inside_a_function_of_the_state_is_explained():
    slip = FirstOrderSystem.from_equations("slip", ["x"], ["-x + sin(x - t)"], {}, time="t", period="2*pi")
    with pytest.raises(ModelError, match="keep time out of functions of the state"):
        compile_model(slip, Integration(backend="in-process"))


def test_periodicity_is_checked_at_the_values_of_each_run():
    forced = FirstOrderSystem.from_equations("forced", ["x"], ["-x + cos(w*t)"], {"w": 1.0}, time="t",
                                             period="2*pi")
    cm = compile_model(forced)
    cm.prepare(cm.parameter_vector(w=2.0))  # still 2 pi periodic
    with pytest.raises(ModelError, match="not periodic .* at w=1.5"):
        cm.prepare(cm.parameter_vector(w=1.5))


def test_generated_names_never_clash_with_user_names():
    clash = FirstOrderSystem.from_equations("clash", ["x"], ["-const_0*x + table_0*cos(t)"],
                                            {"const_0": 0.5, "table_0": 1.0}, time="t", period="2*pi")
    cm = compile_model(clash, Integration(steps_per_period=50))
    r = cm.tangent_run([1.0], 3, cm.prepare())
    assert r.log_stretch.sum() / (3 * 2 * np.pi) == pytest.approx(-0.5, abs=1e-6)


# ------------------------------------------------------------------ the native calls and their inputs
def test_initial_state_may_be_any_array_view_and_Q0_is_not_changed():
    cm = compile_model(system("flexible_shaft"))
    inputs = cm.prepare(cm.parameter_vector(omega=0.8))
    y = np.array([-2.0, -0.5, 0.0, 0.0])
    base = cm.tangent_run(y, 7, inputs)
    strided = np.zeros((4, 3), order="C")
    strided[:, 1] = y
    assert np.array_equal(cm.tangent_run(strided[:, 1], 7, inputs).strobe, base.strobe)
    assert np.array_equal(cm.tangent_run(y[::-1][::-1], 7, inputs).strobe, base.strobe)
    Q0 = np.asfortranarray(base.Q)
    kept = Q0.copy()
    again = cm.tangent_run(base.strobe[:, -1], 3, inputs, Q0=Q0)
    assert np.array_equal(Q0, kept) and again.Q is not Q0


def test_every_load_places_the_work_arrays_and_the_stack_the_same_way():
    """Where the arrays sit modulo 4 KiB decides the speed of every step (bench/speed/notes.md): one page-aligned
    block, each array on cache lines of its own, and the call through the stack-anchoring entry of the library."""
    cm = compile_model(system("one_stage"))
    f = cm.clone().native["lyapunov_chunk"]
    spans = sorted((address, address + size) for address, size in [
        (f._arg_ptr, ctypes.sizeof(f._arg)), (f._res_ptr, ctypes.sizeof(f._res)),
        (f._iw_ptr, f._iw.nbytes), (f._w_ptr, f._w.nbytes)])
    assert f.base % 4096 == 0 and spans[0][0] == f.base
    assert all(start % 64 == 0 for start, _ in spans)
    assert all(end <= next_start for (_, end), (next_start, _) in zip(spans, spans[1:]))
    assert f._aligned is not None  # (a library without the anchoring entry would run with the stack anywhere)
    inputs = cm.prepare(cm.parameter_vector(omega=1.5))
    anchored = cm.tangent_run(None, 60, inputs)
    for g in cm.native.values():
        g._aligned = None
    direct = cm.tangent_run(None, 60, inputs)
    assert np.array_equal(anchored.log_stretch, direct.log_stretch) and np.array_equal(anchored.Q, direct.Q)


def test_a_library_tells_its_functions_sizes_as_casadi_reads_them():
    """The native calls read each function's inputs, outputs and work sizes from the library's own exports (no
    CasADi at a cached start-up): what casadi.external reads from the same library."""
    for name in ("one_stage", "flexible_shaft"):
        cm = compile_model(system(name))
        for fname, f in cm.native.items():
            g = cm.functions[fname]
            assert (f.n_in, f.n_out) == (g.n_in(), g.n_out()), fname
            assert f.shapes_in == [g.size_in(i) for i in range(g.n_in())], fname
            assert f.shapes_out == [g.size_out(i) for i in range(g.n_out())], fname
            assert f.dense_out == [g.sparsity_out(i).is_dense() for i in range(g.n_out())], fname
            sizes = [ctypes.sizeof(f._arg) // 8, ctypes.sizeof(f._res) // 8, f._iw.size, f._w.size]
            assert sizes == [max(n, 1) for n in (g.sz_arg(), g.sz_res(), g.sz_iw(), g.sz_w())], fname


def test_a_sparse_pattern_is_read_from_a_library_as_casadi_has_it(tmp_path):
    """CasADi's C gives a dense pattern as (rows, columns, 1) and a sparse one with its column offsets: a sparse
    output is said as such (its native call is not used for a dense array), a sparse input is refused."""
    x, y = ca.SX.sym("x", 3), ca.SX.sym("y", 2)
    diagonal = ca.SX(ca.Sparsity.diag(3))
    for i in range(3):
        diagonal[i, i] = x[i] * x[i]
    functions = [ca.Function("diagonal", [x], [diagonal, ca.vertcat(x, 1)]),
                 ca.Function("sparse_in", [ca.SX.sym("s", ca.Sparsity.diag(2)), y], [y])]
    source = tmp_path / "patterns.c"
    generator = ca.CodeGenerator(source.name)
    for f in functions:
        generator.add(f)
    generator.generate(str(tmp_path) + os.sep)
    library = tmp_path / "patterns.so"
    subprocess.run([compiler.find_compiler() or "cc", "-shared", "-fPIC", "-O0", "-o", str(library), str(source)],
                   check=True)
    f = load_native(library, ["diagonal"])["diagonal"]
    assert (f.n_in, f.n_out, f.shapes_in, f.shapes_out, f.dense_out) == (1, 2, [(3, 1)], [(3, 3), (4, 1)],
                                                                         [False, True])
    with pytest.raises(GearsymError, match="sparse_in: input 0 is sparse"):
        load_native(library, ["sparse_in"])


def test_inputs_prepared_for_another_model_are_refused():
    one, two = compile_model(system("one_stage")), compile_model(system("flexible_shaft"))
    with pytest.raises(GearsymError, match="prepared by another model"):
        two.tangent_run(None, 2, one.prepare())


def test_non_finite_values_and_formulas_on_a_built_model_are_refused():
    cm = compile_model(system("one_stage"))
    with pytest.raises(GearsymError, match="finite"):
        cm.parameter_vector(B0=float("inf"))
    with pytest.raises(GearsymError, match="finite"):
        cm.initial_state([np.nan, 0.0])
    with pytest.raises(GearsymError, match=r"gearsym\.load\(model, k=\.\.\.\)"):
        cm.parameter_vector(k="1 + 0.3*cos(tau)")
    with pytest.raises(GearsymError, match="whole number"):
        cm.tangent_run(None, 2.5, cm.prepare())


def test_a_diverging_orbit_names_the_period_and_the_values():
    with pytest.raises(GearsymError, match=r"non-finite in period 1 \(sigma=1000"):
        gearsym.lyapunov_spectrum(system("lorenz"), options=Integration(periods=10, discard=2), sigma=1000)


def test_a_stiffness_formula_may_not_use_the_state():
    with pytest.raises(ModelError, match="uses the state"):
        system("one_stage", k="1 + 0.1*x")


def test_editing_the_code_generator_changes_the_hash(monkeypatch):
    import gearsym.codegen.generate as generate
    from gearsym.codegen import LoopOptions, code_hash
    one_stage = system("one_stage")
    before = code_hash(one_stage, LoopOptions())
    monkeypatch.setattr(generate, "generator_digest", lambda: "edited")
    assert code_hash(one_stage, LoopOptions()) != before


# ------------------------------------------------------------------ long periods: bounded code
def _period_run(options, monkeypatch=None, segment=None):
    import gearsym.codegen.functions as functions
    import gearsym.codegen.period_loops as period_loops

    if segment is not None:
        monkeypatch.setattr(period_loops, "SEGMENT_STEPS", segment)
    mf = functions.build_functions(system("one_stage"), options)
    p = np.array([1.5, 0.08, 1.0, 4.0, 0.0, 10.0, 0.2])
    c, _ = mf.functions["constants"](p)
    table, _ = mf.functions["table"](0.0, p)
    y, Q = ca.DM([-2.0, -0.5]), ca.DM.eye(2)
    out = []
    for _ in range(3):
        y, Q, logs, low, high = mf.functions["lyapunov_period"](y, Q, table, c)
        out.append(np.concatenate([np.array(v).ravel() for v in (y, Q, logs, low, high)]))
    return mf, np.array(out)


@pytest.mark.parametrize("steps", [400, 410])  # whole segments; and a remainder segment
def test_long_periods_run_in_segments_with_the_same_bits(monkeypatch, steps):
    from gearsym.codegen.loops import LoopOptions
    from gearsym.codegen.period_loops import SEGMENT_STEPS

    assert SEGMENT_STEPS == 50

    options = LoopOptions(steps_per_period=steps, chunk_periods=1)
    segmented, a = _period_run(options)
    _, b = _period_run(options, monkeypatch, segment=10_000)  # everything written out in one function
    assert np.array_equal(a, b)
    period = segmented.functions["lyapunov_period"]
    names = {period.instruction_MX(i).which_function().name() for i in range(period.n_instructions())
             if period.instruction_id(i) == ca.OP_CALL}
    # (the tangent steps re-orthonormalised every 25 steps: pieces of 25 steps, segments of pieces, and a piece of
    # the remaining 10 steps at the end of a period of 410)
    assert any(name.startswith("orthonormalised_segment_") for name in names), names
    assert ("orthonormalised_10" in names) == (steps == 410)


def test_generated_code_size_does_not_grow_with_the_steps_per_period(tmp_path):
    from gearsym.codegen.functions import LoopOptions, build_functions
    from gearsym.codegen.generate import code_hash, write_code

    one_stage = system("one_stage")
    sizes = {}
    for steps in (200, 3200):
        options = LoopOptions(steps_per_period=steps)
        write_code(build_functions(one_stage, options), tmp_path / str(steps), code_hash(one_stage, options))
        sizes[steps] = (tmp_path / str(steps) / "one_stage.c").stat().st_size
    # written out, 3200 steps were 16x the code (24 s of gcc); what still grows is data (the 2N+1 sample
    # times of the table function) and a few dozen segment calls
    assert sizes[3200] < 2 * sizes[200], sizes


def test_the_backlash_term_of_a_sum_is_added_last_so_each_stage_waits_for_one_operation():
    # the tabulated one-stage right-hand side: forcing T1, damping b v, stiffness T0 times g
    x, v, b, T0, T1, eta = sp.symbols("x v b T0 T1 eta")
    symbols = {s: ca.SX.sym(s.name) for s in (x, v, b, T0, T1, eta)}
    for expr in (T1 + b * v + T0 * g(x, eta), T1 + b * v + T0 * (g(x, eta) + 1)):
        out = to_casadi([expr], symbols)[0]
        last, rest = out.dep(1), out.dep(0)
        assert ca.depends_on(last, symbols[x]) and not ca.depends_on(rest, symbols[x]), expr


def test_a_function_of_tau_on_arrays_gives_casadis_numbers():
    """A mesh's k(tau) over a trajectory's samples all at once, one NumPy operation per instruction: CasADi's numbers
    (within an ulp: NumPy's own sin and cos on some CPUs); an instruction NumPy lacks (erf) goes to CasADi's map."""
    tau = ca.SX.sym("tau")
    forms = [1 + 0.2 * ca.cos(tau) - 0.05 * ca.sin(3 * tau + 0.5),  # a planet mesh's variation
             ca.if_else(ca.fmod(tau, 1.0) < 0.3, 1 - 0.2 * ca.sin(tau) ** 2, 1 / (1 + tau)),  # a fault's window
             ca.fmin(ca.fabs(ca.sin(3 * tau)), 0.5) + ca.floor(tau / 7) * ca.sign(ca.cos(tau)) - ca.sqrt(tau),
             ca.logic_and(tau > 1, tau < 5) + ca.logic_or(tau <= 2, tau >= 100) + ca.logic_not(tau == 3),
             ca.erf(tau / 100), ca.SX(1.5)]
    samples = np.linspace(0.0, 120.0, 1201)
    for form in forms:
        f = ca.Function("k", [tau], [form])
        expected = np.asarray(f.map(samples.size)(samples.reshape(1, -1))).reshape(-1)
        assert evaluate_on_samples(f, samples) == pytest.approx(expected, rel=1e-14, abs=1e-15)
    assert [numpy_program(ca.Function("k", [tau], [form])) is None for form in forms] == [False] * 4 + [True, False]
