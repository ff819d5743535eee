"""A scalar CasADi SX function of one input evaluated over a NumPy array of samples: each of its instructions once,
as one NumPy operation over every sample.

CasADi's ``map`` runs the function's instructions sample after sample in its virtual machine: about half a
microsecond a sample for a mesh's stiffness variation k(tau) (a few cosines), milliseconds per mesh for the
thousands of steps of the trajectory a point's mesh forces are read from (start-up of ``gearsym lyap``, issue 39).
NumPy's sin, cos, exp, log, sqrt, pow, atan and fmod gave CasADi's bits on an x86-64 with AVX2 (a stiffness
variation of cosines: the same forces to the last digit); tanh there, and NumPy's own kernels elsewhere
(AVX-512), agree within an ulp. A function with an instruction not in :data:`UNARY` or :data:`BINARY` (erf, a
call) is evaluated by CasADi's ``map``, as before.

The instructions are plain data (:func:`numpy_program`: each operation by its name, its inputs, its output, its
constant), so that a program kept as JSON (the start-up cache keeps each mesh's k(tau)) is evaluated by
:func:`evaluate_program` without importing CasADi.
"""
from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    import casadi as ca

#: CasADi's unary operations (by their names there, ``OP_SQRT`` -> "sqrt") and NumPy's of the same definition
UNARY = {
    "assign": np.positive, "neg": np.negative, "sq": np.square, "twice": lambda x: x + x,
    "inv": np.reciprocal, "sqrt": np.sqrt, "exp": np.exp, "log": np.log, "sin": np.sin,
    "cos": np.cos, "tan": np.tan, "asin": np.arcsin, "acos": np.arccos, "atan": np.arctan,
    "sinh": np.sinh, "cosh": np.cosh, "tanh": np.tanh, "fabs": np.fabs, "sign": np.sign,
    "floor": np.floor, "ceil": np.ceil, "not": lambda x: (x == 0).astype(float),
}
#: CasADi's binary operations (comparisons and logic give 1.0 or 0.0, as in CasADi)
BINARY = {
    "add": np.add, "sub": np.subtract, "mul": np.multiply, "div": np.divide,
    "pow": np.power, "constpow": np.power, "fmod": np.fmod, "atan2": np.arctan2,
    "fmin": np.fmin, "fmax": np.fmax, "copysign": np.copysign, "hypot": np.hypot,
    "lt": lambda x, y: (x < y).astype(float), "le": lambda x, y: (x <= y).astype(float),
    "eq": lambda x, y: (x == y).astype(float), "ne": lambda x, y: (x != y).astype(float),
    "and": lambda x, y: ((x != 0) & (y != 0)).astype(float),
    "or": lambda x, y: ((x != 0) | (y != 0)).astype(float),
    "if_else_zero": lambda c, x: np.where(c != 0, x, 0.0),
}
#: the instructions that move values: a constant, the input, the output
PLACES = ("const", "input", "output")

#: one instruction: (operation's name, the work places it reads, the place it writes or None, its constant or None)
Instruction = tuple[str, tuple[int, ...], int | None, float | None]


def evaluate_on_samples(function: ca.Function, samples: np.ndarray) -> np.ndarray:
    """``function`` (SX, one scalar input, one scalar output) at every value of ``samples``, an array of that
    shape."""
    samples = np.asarray(samples, dtype=float)
    program = numpy_program(function)
    if program is None:  # (an instruction NumPy does not have: CasADi's map, sample after sample)
        mapped = function.map(samples.size)(samples.reshape(1, -1))
        return np.asarray(mapped, dtype=float).reshape(samples.shape)
    return evaluate_program(program, samples)


def evaluate_program(program: Sequence[Instruction], samples: np.ndarray) -> np.ndarray:
    """A :func:`numpy_program` at every value of ``samples``, an array of that shape."""
    samples = np.asarray(samples, dtype=float)
    work: dict[int, object] = {}
    result = None
    with np.errstate(all="ignore"):  # (as in C: a branch if_else does not take may divide by zero)
        for op, inputs, output, constant in program:
            if op == "const":
                work[output] = constant
            elif op == "input":
                work[output] = samples
            elif op == "output":
                result = work[inputs[0]]
            elif op in UNARY:
                work[output] = UNARY[op](work[inputs[0]])
            else:
                work[output] = BINARY[op](work[inputs[0]], work[inputs[1]])
    return np.broadcast_to(np.asarray(result, dtype=float), samples.shape).copy()


def numpy_program(function: ca.Function) -> tuple[Instruction, ...] | None:
    """The function's instructions as (operation's name, inputs, output, constant), or None if one has no NumPy
    twin (or the function is not of one scalar to one scalar)."""
    if not function.is_a("SXFunction") or (function.n_in(), function.n_out()) != (1, 1) \
            or function.nnz_in(0) != 1 or function.nnz_out(0) != 1:
        return None
    names = _operation_names()
    program = []
    for k in range(function.n_instructions()):
        op = names.get(function.instruction_id(k))
        if op is None:
            return None
        outputs = function.instruction_output(k)
        constant = float(function.instruction_constant(k)) if op == "const" else None
        program.append((op, tuple(function.instruction_input(k)), outputs[0] if outputs else None, constant))
    return tuple(program)


def stored_program(stored) -> tuple[Instruction, ...]:
    """A :func:`numpy_program` as JSON gives it back (lists for tuples), checked: an operation it does not know,
    or a place that is not a whole number, is a ValueError (a summary not to use)."""
    program = []
    for op, inputs, output, constant in stored:
        if op not in UNARY and op not in BINARY and op not in PLACES:
            raise ValueError(f"unknown operation {op!r}")
        program.append((str(op), tuple(_place(i) for i in inputs), None if output is None else _place(output),
                        None if constant is None else float(constant)))
    return tuple(program)


def _place(value) -> int:
    if not isinstance(value, int) or isinstance(value, bool):
        raise ValueError(f"a work place {value!r} is not a whole number")
    return value


def _operation_names() -> dict[int, str]:
    """CasADi's operation codes of the operations NumPy evaluates, by their names here."""
    import casadi as ca

    return {getattr(ca, f"OP_{name.upper()}"): name for name in (*UNARY, *BINARY, *PLACES)}
