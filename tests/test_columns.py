"""A large model's tangent matrix by column (gearsym/codegen/columns.py) gives the unrolled functions' numbers."""
from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

import gearsym
import gearsym.codegen.loops as loops
from gearsym.codegen.compiler import compile_library, find_compiler
from gearsym.codegen.functions import LoopOptions, build_functions
from gearsym.codegen.generate import code_hash, write_code
from gearsym.codegen.native import load_native

#: without fused multiply-adds the C does each operation as CasADi's virtual machine does
NO_FMA = ("-O3", "-ffp-contract=off")
#: the loops that carry the tangent matrix: Gram-Schmidt (the Lyapunov loops) and the located substeps (all three)
TANGENT_LOOPS = ("lyapunov_chunk", "lyapunov_period", "monodromy_period")


def _functions(name: str, options: LoopOptions, by_column: bool, monkeypatch):
    """The model's functions, its tangent matrix by column (a small model forced to take that form) or unrolled."""
    with monkeypatch.context() as patch:
        patch.setattr(loops, "BY_COLUMN_FROM", 1 if by_column else 10**6)
        system = gearsym.load(name)
        return system, build_functions(system, options)


def _inputs(system, F):
    """Each tangent loop's inputs: a start that crosses the backlash within the first period."""
    p = np.array(list(system.parameters.values()), dtype=float)
    c, _ = F["constants"](p)
    table, _ = F["table"](0.0, p)
    n = system.dimension
    y, Q = ca.DM([-2.0, -0.5] + [0.1 * i for i in range(2, n)]), ca.DM.eye(n)
    return {loop: (y, Q, table, c) for loop in TANGENT_LOOPS}


def _crossings(system, mf, y, table, c) -> int:
    states = np.array(mf.functions["trajectory"](y, table, c))
    starts = np.column_stack([np.array(y), states[:, :-1]])
    return sum(float(mf.steps["state_try"](starts[:, k], table[:, k], c)[-1]) for k in range(starts.shape[1]))


@pytest.mark.parametrize("method", ["rk4", "stiff"])
def test_the_tangent_matrix_by_column_gives_the_unrolled_exponents_and_monodromy(method, monkeypatch):
    options = LoopOptions(steps_per_period=45, chunk_periods=3, locate_crossings=True, method=method)
    system, unrolled = _functions("two_stage", options, False, monkeypatch)
    _, columns = _functions("two_stage", options, True, monkeypatch)
    assert {"tangent_mode_state", "gram_schmidt_project"} <= set(columns.steps)  # the form asked for
    assert not {"tangent_mode_state", "gram_schmidt_project"} & set(unrolled.steps)
    inputs = _inputs(system, unrolled.functions)
    y, _, table, c = inputs["lyapunov_chunk"]
    assert 0 < _crossings(system, unrolled, y, table, c)  # the located substeps ran
    for loop, args in inputs.items():
        expected = [np.array(v) for v in unrolled.functions[loop].call(list(args))]
        got = [np.array(v) for v in columns.functions[loop].call(list(args))]
        for name, a, b in zip(unrolled.functions[loop].name_out(), expected, got):
            assert np.all(np.isfinite(a))
            assert b == pytest.approx(a, rel=1e-12, abs=1e-12 * max(1.0, np.max(np.abs(a)))), (loop, name)


@pytest.mark.slow
@pytest.mark.skipif(find_compiler() is None, reason="needs a C compiler")
def test_the_printed_loops_over_the_columns_give_the_bits_of_casadis_loops(monkeypatch, tmp_path):
    options = LoopOptions(steps_per_period=45, chunk_periods=3, locate_crossings=True)
    system, mf = _functions("two_stage", options, True, monkeypatch)
    with monkeypatch.context() as patch:  # (the printer asks the same question of the options)
        patch.setattr(loops, "BY_COLUMN_FROM", 1)
        code = write_code(mf, tmp_path / system.name, code_hash(system, options))
    text = code.source.read_text()
    assert "for (i = 0; i < j; ++i) { gs_gram_schmidt_project(v, R0 + 6*i, w);" in text
    assert "for (j = 0; j < 6; ++j) gs_tangent_mode_vector(A1 + 6*j, J, A2, A3, R1 + 6*j);" in text
    assert "static GEARSYM_NOINLINE void gs_tangent_step(" in text  # (one copy of the step in the span)
    path = str(compile_library(code.source, system.name, flags=NO_FMA).path)
    native = load_native(path, TANGENT_LOOPS)
    for loop, args in _inputs(system, mf.functions).items():
        expected = [np.array(v) for v in mf.functions[loop].call(list(args))]
        got = native[loop](*[np.array(a) for a in args])
        for name, a, b in zip(mf.functions[loop].name_out(), expected, got):
            assert np.array_equal(a, b), (loop, name, np.max(np.abs(a - b)))
