"""A scalar CasADi SX function of one input evaluated over a NumPy array of samples: each of its instructions once,
as one NumPy operation over every sample.

CasADi's ``map`` runs the function's instructions sample after sample in its virtual machine: about half a
microsecond a sample for a mesh's stiffness variation k(tau) (a few cosines), milliseconds per mesh for the
thousands of steps of the trajectory a point's mesh forces are read from (start-up of ``gearsym lyap``, issue 39).
NumPy's sin, cos, exp, log, sqrt, pow, atan and fmod gave CasADi's bits on an x86-64 with AVX2 (a stiffness
variation of cosines: the same forces to the last digit); tanh there, and NumPy's own kernels elsewhere
(AVX-512), agree within an ulp. A function with an instruction not in :data:`UNARY` or :data:`BINARY` (erf, a
call) is evaluated by CasADi's ``map``, as before.
"""
from __future__ import annotations

import casadi as ca
import numpy as np

#: CasADi's unary operations and NumPy's of the same definition
UNARY = {
    ca.OP_ASSIGN: np.positive, ca.OP_NEG: np.negative, ca.OP_SQ: np.square, ca.OP_TWICE: lambda x: x + x,
    ca.OP_INV: np.reciprocal, ca.OP_SQRT: np.sqrt, ca.OP_EXP: np.exp, ca.OP_LOG: np.log, ca.OP_SIN: np.sin,
    ca.OP_COS: np.cos, ca.OP_TAN: np.tan, ca.OP_ASIN: np.arcsin, ca.OP_ACOS: np.arccos, ca.OP_ATAN: np.arctan,
    ca.OP_SINH: np.sinh, ca.OP_COSH: np.cosh, ca.OP_TANH: np.tanh, ca.OP_FABS: np.fabs, ca.OP_SIGN: np.sign,
    ca.OP_FLOOR: np.floor, ca.OP_CEIL: np.ceil, ca.OP_NOT: lambda x: (x == 0).astype(float),
}
#: CasADi's binary operations (comparisons and logic give 1.0 or 0.0, as in CasADi)
BINARY = {
    ca.OP_ADD: np.add, ca.OP_SUB: np.subtract, ca.OP_MUL: np.multiply, ca.OP_DIV: np.divide,
    ca.OP_POW: np.power, ca.OP_CONSTPOW: np.power, ca.OP_FMOD: np.fmod, ca.OP_ATAN2: np.arctan2,
    ca.OP_FMIN: np.fmin, ca.OP_FMAX: np.fmax, ca.OP_COPYSIGN: np.copysign, ca.OP_HYPOT: np.hypot,
    ca.OP_LT: lambda x, y: (x < y).astype(float), ca.OP_LE: lambda x, y: (x <= y).astype(float),
    ca.OP_EQ: lambda x, y: (x == y).astype(float), ca.OP_NE: lambda x, y: (x != y).astype(float),
    ca.OP_AND: lambda x, y: ((x != 0) & (y != 0)).astype(float),
    ca.OP_OR: lambda x, y: ((x != 0) | (y != 0)).astype(float),
    ca.OP_IF_ELSE_ZERO: lambda c, x: np.where(c != 0, x, 0.0),
}


def evaluate_on_samples(function: ca.Function, samples: np.ndarray) -> np.ndarray:
    """``function`` (SX, one scalar input, one scalar output) at every value of ``samples``, an array of that
    shape."""
    samples = np.asarray(samples, dtype=float)
    program = numpy_program(function)
    if program is None:  # (an instruction NumPy does not have: CasADi's map, sample after sample)
        mapped = function.map(samples.size)(samples.reshape(1, -1))
        return np.asarray(mapped, dtype=float).reshape(samples.shape)
    work: dict[int, object] = {}
    result = None
    with np.errstate(all="ignore"):  # (as in C: a branch if_else does not take may divide by zero)
        for op, inputs, output, constant in program:
            if op == ca.OP_CONST:
                work[output] = constant
            elif op == ca.OP_INPUT:
                work[output] = samples
            elif op == ca.OP_OUTPUT:
                result = work[inputs[0]]
            elif op in UNARY:
                work[output] = UNARY[op](work[inputs[0]])
            else:
                work[output] = BINARY[op](work[inputs[0]], work[inputs[1]])
    return np.broadcast_to(np.asarray(result, dtype=float), samples.shape).copy()


def numpy_program(function: ca.Function) -> list[tuple] | None:
    """The function's instructions as (operation, inputs, output, constant), or None if one has no NumPy twin
    (or the function is not of one scalar to one scalar)."""
    if not function.is_a("SXFunction") or (function.n_in(), function.n_out()) != (1, 1) \
            or function.nnz_in(0) != 1 or function.nnz_out(0) != 1:
        return None
    program = []
    for k in range(function.n_instructions()):
        op = function.instruction_id(k)
        if op not in UNARY and op not in BINARY and op not in (ca.OP_CONST, ca.OP_INPUT, ca.OP_OUTPUT):
            return None
        outputs = function.instruction_output(k)
        constant = function.instruction_constant(k) if op == ca.OP_CONST else None
        program.append((op, function.instruction_input(k), outputs[0] if outputs else None, constant))
    return program
