"""The integration loops printed by gearsym (gearsym/codegen/printed.py) compute what CasADi's MX loops compute."""
from __future__ import annotations

import re
import shutil
import subprocess

import casadi as ca
import numpy as np
import pytest

import gearsym
from gearsym import Integration, lyapunov_spectrum
from gearsym.codegen.compiler import DEFAULT_FLAGS, compile_library, find_compiler
from gearsym.codegen.functions import LoopOptions, build_functions
from gearsym.codegen.generate import code_hash, write_code
from gearsym.codegen.native import load_native
from gearsym.codegen.printed import LOOP_NAMES, _inline

needs_cc = pytest.mark.skipif(find_compiler() is None, reason="needs a C compiler")

#: without fused multiply-adds the C does each operation as CasADi's virtual machine does
NO_FMA = ("-O3", "-ffp-contract=off")


def _library(name: str, options: LoopOptions, tmp_path):
    system = gearsym.load(name)
    mf = build_functions(system, options)
    code = write_code(mf, tmp_path / name, code_hash(system, options))
    path = str(compile_library(code.source, name, flags=NO_FMA).path)
    return system, mf, load_native(path, LOOP_NAMES)


@needs_cc
@pytest.mark.parametrize("name, located", [("one_stage", False), ("one_stage", True), ("flexible_shaft", False),
                                           ("flexible_shaft", True), ("lorenz", True)])
@pytest.mark.slow
def test_the_printed_loops_give_the_bits_of_casadis_loops_evaluated_in_process(name, located, tmp_path):
    # 45 steps in blocks of 3 (plain): odd numbers of blocks per period and per shooting piece (3 of 15 steps)
    options = LoopOptions(steps_per_period=45, chunk_periods=3, block_steps=3, locate_crossings=located)
    system, mf, native = _library(name, options, tmp_path)
    F = mf.functions
    p = np.array(list(system.parameters.values()), dtype=float)
    c, _ = F["constants"](p)
    table, _ = F["table"](0.0, p)
    n = system.dimension
    y, Q = ca.DM([-2.0, -0.5] + [0.1 * i for i in range(2, n)]), ca.DM.eye(n)
    width = F["monodromy_segment"].size_in(2)[1]
    inputs = {"lyapunov_chunk": (y, Q, table, c), "lyapunov_period": (y, Q, table, c), "orbit_chunk": (y, table, c),
              "orbit_period": (y, table, c), "monodromy_period": (y, Q, table, c),
              "monodromy_segment": (y, Q, table[:, width:2 * width], c), "trajectory": (y, table, c)}
    for loop, args in inputs.items():
        expected = [np.array(v) for v in F[loop].call(list(args))]
        got = native[loop](*[np.array(a) for a in args])
        for i, (a, b) in enumerate(zip(expected, got)):
            assert np.array_equal(a, b), (loop, F[loop].name_out(i), np.max(np.abs(a - b)))
    if located and name == "one_stage":  # the split ran: some step of the first period crosses
        states = np.array(F["trajectory"](y, table, c))
        starts = np.column_stack([np.array(y), states[:, :-1]])
        flags = [float(mf.steps["state_try"](starts[:, k], table[:, k], c)[1]) for k in range(starts.shape[1])]
        assert 0 < sum(flags) < len(flags)


def test_the_default_engine_gives_the_spectrum_of_casadis_loops_on_a_periodic_orbit():
    """With the default flags (fused multiply-adds across what were calls) the bits move, the spectrum not."""
    system = gearsym.load("one_stage")
    runs = [lyapunov_spectrum(system, options=Integration(periods=24, discard=4, backend=backend))
            for backend in ("compiled", "in-process")]
    assert runs[0].exponents[0] < -1e-3  # periodic: errors do not grow
    assert runs[0].exponents == pytest.approx(runs[1].exponents, abs=1e-9)
    assert list(runs[0].final_state.values()) == pytest.approx(list(runs[1].final_state.values()), abs=1e-9)


def test_the_printed_steps_read_no_pointer_array_and_keep_the_state_in_local_arrays(tmp_path):
    system, options = gearsym.load("one_stage"), LoopOptions(locate_crossings=True)
    text = write_code(build_functions(system, options), tmp_path, code_hash(system, options)).source.read_text()
    span = re.search(r"void gs_tangent_span\(.*?\n}\n", text, re.S).group(0)
    assert "gs_tangent_step(ya, Qa, loa, hia, T + 6*(k), c, yb, Qb, lob, hib);" in span
    for piece in ("tangent_state", "tangent_vector", "state_keep", "tangent_keep", "gram_schmidt"):
        body = re.search(rf"void gs_{piece}\(.*?\n}}\n", text, re.S).group(0)
        assert not re.search(r"\b(arg|res|w|iw)\[", body), piece
    assert "/* tangent_switch:" not in text and "tangent_segment_50" not in text  # CasADi's loops are gone


def test_the_split_calls_one_mode_rk4_step_for_every_substep_and_the_trajectory_is_printed_too(tmp_path):
    system, options = gearsym.load("two_stage"), LoopOptions(locate_crossings=True)
    text = write_code(build_functions(system, options), tmp_path, code_hash(system, options)).source.read_text()
    calls = {}
    for kind in ("tangent", "state"):
        split = re.search(rf"void gs_{kind}_split\(.*?\) {{\n(.*?)\n}}\n", text, re.S).group(1).splitlines()
        assert all(re.fullmatch(r"  (casadi_(real|int) .*;|(for \(.*\) )?gs_\w+\(.*\);)", line) for line in split), split
        calls[kind] = re.findall(r"gs_(\w+)\(", "\n".join(split))
    assert calls["tangent"].count("tangent_mode_step") == 3 and calls["tangent"].count("state_mode_step") == 1
    assert calls["state"].count("state_mode_step") == 4 and calls["state"].count("first_zero") == 2
    for piece in ("tangent_mode_step", "state_mode_step", "first_zero"):  # each compiled once
        assert text.count(f"static GEARSYM_NOINLINE void gs_{piece}(") == 1
    trajectory = re.search(r"/\* trajectory:.*?\n}\n", text, re.S).group(0)
    assert "gs_state_span(y, lo, hi, T + 9*p, c, 1);" in trajectory
    assert "/* step_split:" not in text and "/* state_switch:" not in text  # CasADi's trajectory is gone


def _plain_code(name: str, tmp_path) -> str:
    system, options = gearsym.load(name), LoopOptions(locate_crossings=False)
    return write_code(build_functions(system, options), tmp_path, code_hash(system, options)).source.read_text()


def test_the_plain_tangent_step_is_the_states_step_then_a_loop_over_the_tangent_vectors(tmp_path):
    text = _plain_code("one_stage", tmp_path)
    step = re.search(r"void gs_tangent_step\(.*?\n}\n", text, re.S).group(0)
    assert "gs_tangent_state(y, lo, hi, T, c, y1, lo1, hi1, J);" in step
    assert "for (j = 0; j < 2; ++j) gs_tangent_vector(Q + j, J, c, Q1 + j);" in step
    # in the span the vectors are side by side: a vector's second entry is 2 further on (S: 1 here, the lanes'
    # width on a lane of the lanes' arrays)
    vector = re.search(r"void gs_tangent_vector_strided\(.*?\n}\n", text, re.S).group(0)
    assert re.findall(r"A0\[(?:S\*)?(\d+)\]", vector) == ["0", "2"]
    assert sorted(re.findall(r"R0\[(?:S\*)?(\d+)\]", vector)) == ["0", "2"]
    assert "gs_tangent_vector_strided(A0, A1, A2, R0, 1);" in text
    span = re.search(r"void gs_tangent_span\(.*?\n}\n", text, re.S).group(0)
    assert "gs_transpose(Q, 2, Qa);" in span and span.count("gs_transpose(Qa, 2, Q);") == 1
    assert span.count("gs_transpose(Qb, 2, Q);") == 1
    assert "gs_tangent_block" not in text


def test_the_located_tangent_try_is_the_states_then_a_loop_over_the_tangent_vectors_and_the_split_sees_columns(
        tmp_path):
    system, options = gearsym.load("one_stage"), LoopOptions(locate_crossings=True)
    text = write_code(build_functions(system, options), tmp_path, code_hash(system, options)).source.read_text()
    step = re.search(r"void gs_tangent_step\(.*?\n}\n", text, re.S).group(0)
    assert "gs_tangent_state(y, T, c, yt, &flag, J);" in step
    assert "for (j = 0; j < 2; ++j) gs_tangent_vector(Q + j, J, c, Q1 + j);" in step
    assert "gs_state_keep(y, lo, hi, yt, T, c, y1, lo1, hi1);" in step
    split = step[step.index("if (GEARSYM_UNLIKELY"):step.index("} else {")]
    assert re.findall(r"gs_(\w+)\(", split) == ["transpose", "tangent_split", "transpose"]
    span = re.search(r"void gs_tangent_span\(.*?\n}\n", text, re.S).group(0)
    assert "gs_transpose(Q, 2, Qa);" in span
    assert "gs_tangent_try" not in text and "gs_tangent_block" not in text


@pytest.mark.skipif(shutil.which("gcc") is None, reason="needs gcc")
def test_gcc_vectorises_the_loop_over_the_tangent_vectors_even_of_two(tmp_path):
    """(gcc unrolls a loop of two iterations before its vectoriser sees it, unless told not to.)"""
    source = tmp_path / "one_stage.c"
    source.write_text(_plain_code("one_stage", tmp_path / "code"))
    line = 1 + source.read_text()[:source.read_text().index("for (j = 0; j < 2; ++j)")].count("\n")
    report = subprocess.run(["gcc", *DEFAULT_FLAGS, "-fopt-info-vec-optimized", "-c", "-o", str(tmp_path / "o.o"),
                             str(source)], capture_output=True, text=True, check=True).stderr
    assert re.search(rf"one_stage\.c:{line}:\d+: optimized: loop vectorized", report), report


def test_a_step_in_a_form_the_printer_does_not_rewrite_fails_loudly():
    x = ca.SX.sym("x")
    f = ca.Function("odd", [x], [x])
    with pytest.raises(AssertionError, match="odd: CasADi's C has a form the printer does not rewrite"):
        _inline("odd", "  a0=w[3];\n  if (res[0]!=0) res[0][0]=a0;\n  return 0;", f)
