"""The tangent matrix of a large model column by column: what keeps its generated C small.

Two functions carry the whole n x n tangent matrix at once: the located step's substep (``tangent_mode_step``, RK4
or RODAS4 of the state and of every tangent vector along a leg of a step that crosses a backlash surface) and the
Gram-Schmidt re-orthonormalisation (``gram_schmidt``). As one SX function each they are straight-line code of
order n^2 and n^3 operations: for Lin & Parker's translational planetary set (34 states) 4.8 MB of C, which gcc
took more than 14 minutes to compile. From :data:`~.loops.BY_COLUMN_FROM` states on (:meth:`.LoopOptions.by_column`)
each is made of SX pieces that work on one column (keep the step in SX), composed in MX (compose loops in MX: the
in-process backend and the reference of the printed C), and printed in C as a loop over the pieces
(:func:`.printed.print_loops`):

* ``tangent_mode_step`` is ``tangent_mode_state`` (the state's substep and the nonzeros of each stage's Jacobian
  that are not constants: :func:`.rk4.by_vector`; of the stiff step, the nonzeros of its map) then
  ``tangent_mode_vector`` on each column of the tangent matrix, given those;
* ``gram_schmidt`` is, for each column in turn, ``gram_schmidt_project`` on every column before it (remove its
  component along that one), then ``gram_schmidt_normalise`` (divide by the norm, keep the norm's log).

Each piece does on its column the operations the one function does, in the same order: the numbers are the
same (tests/test_columns.py compares the two forms on a small model forced to take this one).
"""
from __future__ import annotations

import casadi as ca

from .casadi_symbols import SX_OPTIONS

#: a function made of pieces by column, and its pieces (the state's or the column's first): the printer prints
#: it as a loop over them (:mod:`.printed`) where the model's steps hold the pieces
PARTS = {"tangent_mode_step": ("tangent_mode_state", "tangent_mode_vector"),
         "gram_schmidt": ("gram_schmidt_project", "gram_schmidt_normalise")}


def gram_schmidt_by_column(n: int) -> list[ca.Function]:
    """``gram_schmidt`` (MX: modified Gram-Schmidt, orthonormal columns and the log of each column's stretch, as
    :func:`.period_loops.gram_schmidt_function`), then its two SX pieces."""
    v, q = ca.SX.sym("v", n), ca.SX.sym("q", n)
    project = ca.Function("gram_schmidt_project", [v, q], [v - ca.dot(q, v) * q], SX_OPTIONS)
    norm = ca.norm_2(v)
    normalise = ca.Function("gram_schmidt_normalise", [v], [v / norm, ca.log(norm)], SX_OPTIONS)
    Q = ca.MX.sym("Q", n, n)
    cols, logs = [], []
    for j in range(n):
        w = Q[:, j]
        for c in cols:
            w = project(w, c)
        col, log = normalise(w)
        cols.append(col)
        logs.append(log)
    whole = ca.Function("gram_schmidt", [Q], [ca.horzcat(*cols), ca.vertcat(*logs)])
    return [whole, project, normalise]


def mode_step_by_column(state: ca.Function, vector: ca.Function) -> ca.Function:
    """``tangent_mode_step`` (MX, the inputs and outputs of the one SX function: y, Q, leg, c -> y1, Q1) from
    ``tangent_mode_state`` (y, leg, c -> y1, the Jacobians' nonzeros) and ``tangent_mode_vector`` (a column of Q,
    those nonzeros, leg, c -> the column of Q1), mapped over the columns."""
    n = state.size1_in(0)
    y, leg, c = (ca.MX.sym(name, state.sparsity_in(i)) for i, name in enumerate(("y", "leg", "c")))
    Q = ca.MX.sym("Q", n, n)
    y1, jacobians = state(y, leg, c)
    return ca.Function("tangent_mode_step", [y, Q, leg, c], [y1, vector.map(n)(Q, jacobians, leg, c)])


def printed(name: str, n: int, steps: dict[str, ca.Function]) -> str:
    """The C of ``name`` (one of :data:`PARTS`) as a loop over its pieces' C (``gs_<piece>``, printed before it),
    for ``n`` states; ``steps``: the model's step functions, the pieces among them."""
    if name == "gram_schmidt":
        return ("/* gram_schmidt, column by column (gearsym/codegen/columns.py): each column made orthogonal to\n"
                "   those before it, then normalised */\n"
                "static void gs_gram_schmidt(const casadi_real* restrict A0, casadi_real* restrict R0, "
                "casadi_real* restrict R1) {\n"
                f"  casadi_real v[{n}], w[{n}]; casadi_int i, j;\n"
                f"  for (j = 0; j < {n}; ++j) {{\n"
                f"    gs_copy(A0 + {n}*j, {n}, v);\n"
                f"    for (i = 0; i < j; ++i) {{ gs_gram_schmidt_project(v, R0 + {n}*i, w); gs_copy(w, {n}, v); }}\n"
                f"    gs_gram_schmidt_normalise(v, R0 + {n}*j, R1 + j);\n"
                "  }\n}\n")
    jacobians = steps["tangent_mode_state"].nnz_out(1)  # (what the state's piece passes to each column)
    return ("/* tangent_mode_step, column by column (gearsym/codegen/columns.py): the state's substep and its\n"
            "   stages' Jacobians, then each column of the tangent matrix */\n"
            "static GEARSYM_NOINLINE void gs_tangent_mode_step(const casadi_real* restrict A0, "
            "const casadi_real* restrict A1, const casadi_real* restrict A2, const casadi_real* restrict A3, "
            "casadi_real* restrict R0, casadi_real* restrict R1) {\n"
            f"  casadi_real J[{max(1, jacobians)}]; casadi_int j;\n"
            "  gs_tangent_mode_state(A0, A2, A3, R0, J);\n"
            f"  for (j = 0; j < {n}; ++j) gs_tangent_mode_vector(A1 + {n}*j, J, A2, A3, R1 + {n}*j);\n"
            "}\n")
