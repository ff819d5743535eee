"""The integration loops printed by gearsym itself, around CasADi's C of one step.

CasADi's C of an MX loop calls the SX step once per step through pointer arrays: every input is read as
``arg[i]? arg[i][j] : 0`` and every output written behind ``if (res[i]!=0)``, and the state makes a round
trip through the work vector between steps: about 10-15 % of a step next to a hand-written C loop
(bench/speed/notes.md). So the loop functions (:data:`LOOP_NAMES`, the trajectory too) are printed here instead:

* CasADi still writes the whole file: everything else as before, and for each loop function a *stand-in*
  with its name, input/output names and shapes (:func:`stand_in`), so that the external API
  (``NAME_n_in``, ``NAME_sparsity_in``, ``NAME_work``, ...) is CasADi's own. Its body calls each SX step
  piece once, only so that CasADi writes their C (with the helpers they use);
* each SX piece's C body is copied into a ``static inline`` function of restrict pointers
  (``arg[i]? arg[i][j] : 0`` -> ``A<i>[j]``, ``if (res[i]!=0) res[i][j]=`` -> ``R<i>[j]=``);
* the stand-ins' bodies are replaced by loops over those functions with the state in local arrays,
  double-buffered (two steps per iteration, a -> b -> a), computing what the MX functions of
  :mod:`.functions` compute, operation for operation (the same bits without FMA; the tests compare);
* CasADi's static functions nothing calls any more are removed.

With crossings located, the ``try`` is inline on every step and the ``split`` (about 1 % of steps) a
separate function behind a real ``if``, marked unlikely: the calls of :data:`~.crossing.SPLIT_CALLS` (the MX
function's), so that the C holds the mode-RK4 step and the root search once each, not once per substep.

The plain tangent step is not CasADi's one function of the state and all tangent vectors (``tangent_block``),
whose flat scalar code the compiler neither vectorises nor keeps in registers (on the flexible shaft: 654
instructions a step, 260 of them loads, stores and copies of spilled values), but its two pieces
(:func:`.rk4.tangent_by_vector`): the state's step, which also gives each RK4 stage's Jacobian, and one
tangent vector's step, applied to each vector in a loop that gcc vectorises across them, the vectors being
stored side by side in the span (343 instructions a step; the same bits). The located tangent step is split
the same way (:meth:`.crossing.CrossingStep.tried_by_vector`): the state's try, with its crossing flag and its
stages' Jacobians, then, if it does not cross, the loop over the vectors and ``state_keep``; a step that crosses
runs the split on the vectors as columns, transposed there and back.
"""
from __future__ import annotations

import re

import casadi as ca

from .columns import PARTS
from .columns import printed as by_column
from .crossing import SPLIT_INPUTS, SPLIT_OUTPUTS, SPLIT_PER_SURFACE, split_calls, split_names
from .functions import ModelFunctions
from .loops import shooting_segments

#: the loop functions printed here (everything else in the file is CasADi's)
LOOP_NAMES = ("lyapunov_chunk", "lyapunov_period", "orbit_chunk", "orbit_period", "monodromy_segment",
              "monodromy_period", "trajectory")
#: the per-step pieces the lanes (:mod:`.lanes`) run on all lanes at once: printed with their entries a stride
#: apart (``gs_<piece>_strided``: 1 for one trajectory, the lanes' width on one lane of the lanes' arrays)
LANE_PIECES = ("tangent_state", "tangent_vector", "state_try", "state_keep", "state_block")
#: what the lanes also run on each lane beside the step pieces: the constants from each lane's own parameters
#: (a stability chart's points), printed strided with them
LANE_FUNCTIONS = ("constants",)
#: defined by the lanes' C before it includes the model's: the file then ends after its step pieces
PIECES_ONLY = "GEARSYM_STEP_PIECES_ONLY"

_HEADER = r"/\* (?P<name>\w+):\(.*?\)->\(.*?\) \*/\n"
_SIGNATURE = (r"static int (?P<c>casadi_f\d+)\(const casadi_real\*\* arg, casadi_real\*\* res, casadi_int\* iw, "
              r"casadi_real\* w, int mem\) \{\n")
_DEFINITION = re.compile(_HEADER + _SIGNATURE + r"(?P<body>.*?)\n\}\n\n", re.S)


def pieces(mf: ModelFunctions, loop: str) -> list[ca.Function]:
    """The SX step functions the printed ``loop`` calls."""
    kind = "state" if loop.startswith(("orbit", "trajectory")) else "tangent"
    located = "state_try" in mf.steps
    if kind == "tangent":
        names = ["tangent_state", "tangent_vector"]
        if located:  # (the step that does not cross keeps the state's try and its extremes)
            names += ["state_keep", *(piece for piece, _, _ in split_calls(kind))]
    elif not located:
        names = [f"{kind}_block", *(["trajectory_step"] if loop == "trajectory" and "trajectory_step" in mf.steps
                                   else [])]
    else:
        names = [f"{kind}_try", *(piece for piece, _, _ in split_calls(kind))]
    if loop.startswith("lyapunov"):
        names.append("gram_schmidt")
    # a function made of pieces by column (a large model's, columns.py) is printed from its pieces' C
    names = [part for name in names for part in (_parts(mf, name) or (name,))]
    return [mf.steps[name] for name in dict.fromkeys(names)]


def _parts(mf: ModelFunctions, name: str) -> tuple[str, ...]:
    """The pieces by column of the step ``name`` (:data:`.columns.PARTS`) if the model's steps are made of them,
    else ()."""
    parts = PARTS.get(name, ())
    return parts if parts and all(part in mf.steps for part in parts) else ()


def stand_in(f: ca.Function, calls: list[ca.Function]) -> ca.Function:
    """A Function with ``f``'s name, input and output names and shapes, whose body (replaced after code
    generation) calls each of ``calls`` once, so that CasADi writes their C into the file."""
    inputs = [ca.MX.sym(f.name_in(i), f.sparsity_in(i)) for i in range(f.n_in())]
    anchor, x = 0, inputs[0][0]
    for g in calls:  # (on a symbol: on constant inputs CasADi left some of the calls out)
        anchor += g.call([x * ca.MX.ones(g.sparsity_in(i)) for i in range(g.n_in())])[0][0]
    outputs = [ca.MX.zeros(f.sparsity_out(i)) for i in range(f.n_out())]
    rows, cols = f.size_out(0)
    outputs[0] = ca.reshape(ca.vertcat(anchor, ca.MX.zeros(rows * cols - 1, 1)), rows, cols)
    standin = ca.Function(f.name(), inputs, outputs, f.name_in(), f.name_out())
    for i in range(f.n_out()):
        if standin.sparsity_out(i) != f.sparsity_out(i):
            raise AssertionError(f"the stand-in of {f.name()} has another shape for output {i}")
    return standin


def print_loops(text: str, mf: ModelFunctions) -> str:
    """CasADi's C ``text`` (written with :func:`stand_in` for the :data:`LOOP_NAMES`) with the loops printed."""
    definitions = {m.group("name"): m for m in _DEFINITION.finditer(text)}
    composed = [name for name in mf.steps if _parts(mf, name)]  # (printed from their pieces by column)
    missing = [name for name in (*LOOP_NAMES, *mf.steps, *LANE_FUNCTIONS)
               if name not in definitions and name not in composed]
    if missing:
        raise AssertionError(f"no C definition of {', '.join(missing)} in the generated code")
    shape = _Shape(mf)
    steps = [_PREAMBLE.format(zeros=max(1, shape.rows * shape.N))]
    steps += [_inline(name, definitions[name].group("body"), mf.steps[name],
                      shape.n if name == "tangent_vector" else 1) for name in mf.steps if name not in composed]
    steps += [by_column(name, shape.n, mf.steps) for name in composed]
    steps += [_inline(name, definitions[name].group("body"), mf.functions[name]) for name in LANE_FUNCTIONS]
    steps += [_split(mf, kind) for kind in ("tangent", "state") if shape.located]
    # the spans go before the first stand-in; each stand-in's body becomes its loop
    first = min(definitions[name].start() for name in LOOP_NAMES)
    for name in sorted(LOOP_NAMES, key=lambda name: -definitions[name].start()):
        d = definitions[name]
        loop = _LOOPS[name](shape)
        text = text[:d.start()] + d.group(0)[:d.start("body") - d.start()] + loop + "\n}\n\n" + text[d.end():]
    text = text[:first] + "\n".join(_spans(mf, shape)) + "\n" + text[first:]
    # the step pieces right after CasADi's helpers, and what follows them behind PIECES_ONLY (the lanes' C
    # includes this file up to its step pieces: one copy of each in generated/)
    head = min(m.start() for m in definitions.values())
    end = text.rindex(_CLOSING)
    text = (text[:head] + "\n".join(steps) + f"\n#ifndef {PIECES_ONLY}  /* (the lanes' C includes the pieces above) */\n\n"
            + text[head:end] + f"#endif  /* {PIECES_ONLY} */\n\n" + text[end:])
    return _without_unused(text)


#: the end of CasADi's file (the lanes' C, which includes the model's up to its step pieces, ends alike)
_CLOSING = "#ifdef __cplusplus\n} /* extern \"C\" */\n#endif\n"


def _without_unused(text: str) -> str:
    """``text`` without CasADi's static functions that nothing calls any more (those the stand-ins called)."""
    while True:
        unused = [m for m in _DEFINITION.finditer(text) if text.count(m.group("c") + "(") == 1]
        if not unused:
            return text
        for m in reversed(unused):
            text = text[:m.start()] + text[m.end():]


def _inline(name: str, body: str, f: ca.Function, stride: int = 1) -> str:
    """The C body of the SX function ``f`` as ``gs_<name>``: inputs A0.., outputs R0.., restrict pointers;
    the first input and output ``stride`` entries apart (a tangent vector among others, row by row)."""
    body = re.sub(r"arg\[(\d+)\]\? arg\[\1\]\[(\d+)\] : 0", r"A\1[\2]", body)
    body = re.sub(r"if \(res\[(\d+)\]!=0\) res\[\1\]\[(\d+)\]=", r"R\1[\2]=", body)
    if stride != 1:
        body = re.sub(r"\b([AR])0\[(\d+)\]", lambda m: f"{m.group(1)}0[{int(m.group(2)) * stride}]", body)
    strided = name in LANE_PIECES or name in LANE_FUNCTIONS
    if strided:  # (entry k at S*k: S = 1 for one trajectory, the lanes' width for one lane of the lanes' arrays)
        body = re.sub(r"\b([AR]\d+)\[(\d+)\]", lambda m: f"{m[1]}[S*{m[2]}]" if m[2] != "0" else m[0], body)
    body = re.sub(r"\n  return 0;$", "", body)
    left = [line for line in body.splitlines() if re.search(r"\b(arg|res|iw|w)\[|\breturn\b|\bmem\b", line)]
    if left:
        raise AssertionError(f"{name}: CasADi's C has a form the printer does not rewrite: {left[:3]}")
    args = [f"const casadi_real* restrict A{i}" for i in range(f.n_in())]
    args += [f"casadi_real* restrict R{i}" for i in range(f.n_out())]
    # the split's pieces (about 1 % of steps) stay calls, each compiled once: not `cold`, whose size
    # optimisation (code hoisting) took gcc 20 s more on the largest model
    where = "GEARSYM_NOINLINE" if name in _OUT_OF_LINE else "GEARSYM_INLINE"
    if not strided:
        return f"/* {name}, from CasADi's C of it */\nstatic {where} void gs_{name}({', '.join(args)}) {{\n{body}\n}}\n"
    names = [f"A{i}" for i in range(f.n_in())] + [f"R{i}" for i in range(f.n_out())]
    return (f"/* {name}, from CasADi's C of it: every entry S apart (the lanes call it on each lane) */\n"
            f"static GEARSYM_INLINE void gs_{name}_strided({', '.join(args)}, casadi_int S) {{\n{body}\n}}\n"
            f"static {where} void gs_{name}({', '.join(args)}) {{ gs_{name}_strided({', '.join(names)}, 1); }}\n")


#: the split's pieces that are calls (the keep, also on the steps that do not cross, is inline)
_OUT_OF_LINE = {piece for kind in ("tangent", "state") for piece, _, _ in split_calls(kind)
                if not piece.endswith("_keep")}


def _split(mf: ModelFunctions, kind: str) -> str:
    """``gs_{kind}_split``, the located step that crosses (arguments those of ``gs_{kind}_keep``): the calls of
    :data:`~.crossing.SPLIT_CALLS`, as the MX function ``{kind}_split`` makes them, with locals between."""
    inputs, outputs = split_names(kind, SPLIT_INPUTS), split_names(kind, SPLIT_OUTPUTS)
    keep = mf.steps[f"{kind}_keep"]
    sizes, body = {v: keep.numel_in(i) for i, v in enumerate(inputs)}, []
    for piece, ins, outs in split_calls(kind):
        f = mf.steps[piece]
        count = sizes[ins[0]] // f.numel_in(0) if piece in SPLIT_PER_SURFACE else 1
        sizes.update({v: count * f.numel_out(i) for i, v in enumerate(outs)})
        if piece in SPLIT_PER_SURFACE:  # one call per column
            args = [f"{v} + {f.numel_in(i)}*i" for i, v in enumerate(ins)]
            args += [f"{v} + {f.numel_out(i)}*i" for i, v in enumerate(outs)]
            body.append(f"  for (i = 0; i < {count}; ++i) gs_{piece}({', '.join(args)});\n")
        else:
            body.append(f"  gs_{piece}({', '.join([*ins, *outs])});\n")
    locals_ = " ".join(f"casadi_real {v}[{max(1, sizes[v])}];" for v in sizes if v not in (*inputs, *outputs))
    args = [f"const casadi_real* restrict {v}" for v in inputs] + [f"casadi_real* restrict {v}" for v in outputs]
    return ("/* the located step that crosses: its legs, RK4 of the sides held fixed on each (calls of one\n"
            "   mode-RK4 step), as the MX function of the split (SPLIT_CALLS in gearsym/codegen/crossing.py) */\n"
            f"static GEARSYM_NOINLINE void gs_{kind}_split({', '.join(args)}) {{\n"
            f"  {locals_}\n  casadi_int i;\n{''.join(body)}}}\n")


class _Shape:
    """The sizes the printed loops are written for."""

    def __init__(self, mf: ModelFunctions):
        system = mf.system
        self.n = system.dimension
        self.observed = system.observed_indices
        self.nc = len(mf.split.constants) + 1
        self.N, K = mf.options.steps_per_period, mf.options.block(self.n)
        self.rows = 3 * len(mf.split.tables)  # table rows: one column per step
        self.step = self.rows * K  # table entries per block
        self.blocks = self.N // K
        self.P = mf.options.chunk_periods
        self.S = shooting_segments(self.N, K, system.cycles)
        #: blocks between two Gram-Schmidt steps and in the last piece of a period ((0, 0): once per period)
        self.every, self.rest = mf.options.orthonormalised(self.n)
        self.located = "state_try" in mf.steps
        #: a large model (columns.py): its step is compiled once and called from both halves of the span, not
        #: inlined in each (gcc's time halves; a call costs nothing next to a step of that size)
        self.by_column = mf.options.by_column(self.n)
        self.stepwise = "trajectory_step" in mf.steps  # (blocks of several steps: the trajectory steps alone)
        #: the tangent step (or try): the state's step, then each tangent vector's (:func:`_by_vector`)
        self.by_vector = "tangent_vector" in mf.steps
        state = mf.steps["tangent_state"] if self.by_vector else None
        self.jacobians = state.nnz_out(state.n_out() - 1) if state else 0  # (its last output)

    def size(self, what: str) -> int:
        """Array length of a local: at least 1 (C has no empty arrays)."""
        return max(1, {"y": self.n, "Q": self.n * self.n, "o": len(self.observed), "c": self.nc}[what])


_PREAMBLE = """/* gearsym: the integration loops, printed around CasADi's C of one step (see gearsym/codegen/printed.py) */
#if defined(__GNUC__)
#define GEARSYM_INLINE inline __attribute__((always_inline))
#define GEARSYM_NOINLINE __attribute__((noinline))
#define GEARSYM_UNLIKELY(x) __builtin_expect(!!(x), 0)
/* a loop left to the vectoriser (gcc unrolls a loop of 2 iterations before it, which then stays scalar) */
#define GEARSYM_NOT_UNROLLED _Pragma("GCC unroll 1")
#else
#define GEARSYM_INLINE inline
#define GEARSYM_NOINLINE
#define GEARSYM_UNLIKELY(x) (x)
#define GEARSYM_NOT_UNROLLED
#endif

static const casadi_real gs_zeros[{zeros}] = {{0.}};

/* an input as CasADi passes it (a null pointer: zeros) into a local array */
static inline void gs_load(const casadi_real* x, casadi_int n, casadi_real* y) {{
  casadi_int i;
  for (i = 0; i < n; ++i) y[i] = x ? x[i] : 0;
}}

static inline void gs_copy(const casadi_real* restrict x, casadi_int n, casadi_real* restrict y) {{
  casadi_int i;
  for (i = 0; i < n; ++i) y[i] = x[i];
}}

/* the n x n matrix x transposed into y (tangent vectors: from columns to side by side and back) */
static inline void gs_transpose(const casadi_real* restrict x, casadi_int n, casadi_real* restrict y) {{
  casadi_int i, j;
  for (i = 0; i < n; ++i) for (j = 0; j < n; ++j) y[j * n + i] = x[i * n + j];
}}

/* an output column (none if the caller passes a null pointer) */
static inline void gs_store(const casadi_real* x, casadi_int n, casadi_real* y, casadi_int at) {{
  casadi_int i;
  if (y) for (i = 0; i < n; ++i) y[at + i] = x[i];
}}
"""


def _spans(mf: ModelFunctions, s: _Shape) -> list[str]:
    """One step of each kind (try, then split or keep; or the plain block) and the loop over a period's
    blocks, with the state in local arrays, two steps per iteration (two copies of the inline step: a
    third for an odd number of blocks cost compile time)."""
    out = []
    for kind, carried in (("tangent", ("y", "Q")), ("state", ("y",))):
        state = [*carried, "lo", "hi"]
        decl = [f"casadi_real* restrict {v}" for v in state]
        ins = [f"const casadi_real* restrict {v}" for v in state] + ["const casadi_real* restrict T",
                                                                   "const casadi_real* restrict c"]
        nexts = [f"{v}1" for v in state]
        outs = [f"casadi_real* restrict {v}" for v in nexts]
        args = ", ".join([*state, "T", "c", *nexts])
        if s.located and kind == "tangent" and s.by_vector:
            body = _located_by_vector(s)
        elif s.located:
            tried = [f"{v}t" for v in carried]
            declare = " ".join(f"casadi_real {v}[{s.size(v[0])}];" for v in tried)
            split_args = ", ".join([*state, *tried, "T", "c", *nexts])
            body = (f"  {declare} casadi_real flag;\n"
                    f"  gs_{kind}_try({', '.join([*carried, 'T', 'c', *tried])}, &flag);\n"
                    f"  if (GEARSYM_UNLIKELY(flag != 0)) gs_{kind}_split({split_args});\n"
                    f"  else gs_{kind}_keep({split_args});\n")
        elif kind == "tangent" and s.by_vector:
            body = _by_vector(s)
        else:
            body = f"  gs_{kind}_block({args});\n"
        where = "GEARSYM_NOINLINE" if s.by_column else "GEARSYM_INLINE"
        out.append(f"/* one block of {kind} steps (the SX functions' step, as CasADi's Switch runs it) */\n"
                   f"static {where} void gs_{kind}_step({', '.join(ins + outs)}) {{\n{body}}}\n")
        sizes = {"y": s.size("y"), "Q": s.size("Q"), "lo": s.size("o"), "hi": s.size("o")}
        a = [f"{v}a" for v in state]
        b = [f"{v}b" for v in state]
        locals_ = " ".join(f"casadi_real {v}a[{sizes[v]}], {v}b[{sizes[v]}];" for v in state)
        table = (lambda k: f"T + {s.step}*({k})") if s.step else (lambda k: "T")
        copy = lambda src, dst: " ".join(
            f"gs_transpose({x}, {s.n}, {y});" if v == "Q" and s.by_vector else f"gs_copy({x}, {sizes[v]}, {y});"
            for v, x, y in zip(state, src, dst))
        out.append(
            f"/* blocks of {kind} steps from ({', '.join(state)}), in place: the state in local arrays, a -> b -> a */\n"
            f"static GEARSYM_NOINLINE void gs_{kind}_span({', '.join(decl)}, const casadi_real* restrict T, "
            "const casadi_real* restrict c, casadi_int blocks) {\n"
            f"  {locals_}\n  casadi_int k;\n  {copy(state, a)}\n"
            "  for (k = 0; k < blocks; k += 2) {  /* (an odd number of blocks ends in the middle) */\n"
            f"    gs_{kind}_step({', '.join([*a, table('k'), 'c', *b])});\n"
            f"    if (k + 1 == blocks) {{ {copy(b, state)} return; }}\n"
            f"    gs_{kind}_step({', '.join([*b, table('k + 1'), 'c', *a])});\n"
            "  }\n"
            f"  {copy(a, state)}\n}}\n")
    return out


def _by_vector(s: _Shape) -> str:
    """The plain tangent step: the state's, which gives the Jacobian of every stage, then each tangent
    vector's, in a loop that the C compiler vectorises across the vectors: in the span they are stored side by
    side (row r of vector j at r*n + j), so that one vector instruction does the same operation of CasADi's
    code on several of them (its bits: the operations of each vector are those of ``tangent_block``)."""
    return (f"  casadi_real J[{max(1, s.jacobians)}]; casadi_int j;\n"
            "  gs_tangent_state(y, lo, hi, T, c, y1, lo1, hi1, J);\n"
            f"  GEARSYM_NOT_UNROLLED for (j = 0; j < {s.n}; ++j) gs_tangent_vector(Q + j, J, c, Q1 + j);\n")


def _located_by_vector(s: _Shape) -> str:
    """The located tangent step, by vector as the plain one (:func:`_by_vector`): the state's try (its flag and
    the Jacobians of its stages), then, if it does not cross, each tangent vector's try and the extremes (what
    ``tangent_keep`` keeps), else the split, on the tangent vectors as columns (transposed there and back)."""
    n, y, Q = s.n, s.size("y"), s.size("Q")
    return (f"  casadi_real yt[{y}], flag, J[{max(1, s.jacobians)}]; casadi_int j;\n"
            "  gs_tangent_state(y, T, c, yt, &flag, J);\n"
            "  if (GEARSYM_UNLIKELY(flag != 0)) {\n"
            f"    casadi_real Qc[{Q}], Qc1[{Q}];  /* (the try's tangent, an input the split does not read: Qc) */\n"
            f"    gs_transpose(Q, {n}, Qc);\n"
            "    gs_tangent_split(y, Qc, lo, hi, yt, Qc, T, c, y1, Qc1, lo1, hi1);\n"
            f"    gs_transpose(Qc1, {n}, Q1);\n"
            "  } else {\n"
            f"    GEARSYM_NOT_UNROLLED for (j = 0; j < {n}; ++j) gs_tangent_vector(Q + j, J, c, Q1 + j);\n"
            "    gs_state_keep(y, lo, hi, yt, T, c, y1, lo1, hi1);\n"
            "  }\n")


def _observed_start(s: _Shape, lo: str = "lo", hi: str = "hi") -> str:
    """lo and hi reset to the observed states (a period's or a segment's start)."""
    return " ".join(f"{lo}[{i}] = y[{j}]; {hi}[{i}] = y[{j}];" for i, j in enumerate(s.observed))


def _locals(s: _Shape, tangent: bool) -> str:
    """A loop's locals: its inputs y0 (Q0) and c copied in, the table by pointer."""
    table, c = (2, 3) if tangent else (1, 2)
    q = f" casadi_real Q[{s.size('Q')}];" if tangent else ""
    load_q = f" gs_load(arg[1], {s.n * s.n}, Q);" if tangent else ""
    return (f"  casadi_real y[{s.size('y')}], lo[{s.size('o')}], hi[{s.size('o')}], c[{s.size('c')}];{q}\n"
            f"  const casadi_real* T = arg[{table}] ? arg[{table}] : gs_zeros;\n"
            "  casadi_int p;\n"
            f"  gs_load(arg[0], {s.n}, y);{load_q} gs_load(arg[{c}], {s.nc}, c);\n")


def _orthonormalised(s: _Shape) -> str:
    """A period of tangent steps, Gram-Schmidt every ``s.every`` blocks (and after the rest), the logs summed in
    ``logs`` (as :func:`.period_loops.orthonormalised_period`: 0 + the first piece's, then each in turn)."""
    if not s.every:
        return (f"    gs_tangent_span(y, Q, lo, hi, T, c, {s.blocks});\n"
                "    gs_gram_schmidt(Q, Qn, logs);\n"
                f"    gs_copy(Qn, {s.n * s.n}, Q);\n")
    whole = s.blocks // s.every
    table = (lambda at: f"T + {s.step}*({at})") if s.step else (lambda at: "T")
    piece = lambda at, blocks: (f"gs_tangent_span(y, Q, lo, hi, {table(at)}, c, {blocks}); "
                                f"gs_gram_schmidt(Q, Qn, piece); gs_copy(Qn, {s.n * s.n}, Q); "
                                f"for (i = 0; i < {s.n}; ++i) logs[i] += piece[i];")
    rest = f"    {piece(whole * s.every, s.rest)}\n" if s.rest else ""
    return (f"    for (i = 0; i < {s.n}; ++i) logs[i] = 0;\n"
            f"    for (g = 0; g < {whole}; ++g) {{ {piece(f'{s.every}*g', s.every)} }}\n" + rest)


def _lyapunov(s: _Shape, periods: int) -> str:
    o = len(s.observed)
    pieces = f" casadi_real piece[{s.size('y')}]; casadi_int g, i;" if s.every else ""
    return (_locals(s, True)
            + f"  casadi_real Qn[{s.size('Q')}], logs[{s.size('y')}];{pieces}\n"
            f"  for (p = 0; p < {periods}; ++p) {{\n"
            f"    {_observed_start(s)}\n"
            + _orthonormalised(s) +
            f"    gs_store(y, {s.n}, res[0], {s.n}*p); gs_store(logs, {s.n}, res[2], {s.n}*p);\n"
            f"    gs_store(lo, {o}, res[3], {o}*p); gs_store(hi, {o}, res[4], {o}*p);\n"
            "  }\n"
            f"  gs_store(Q, {s.n * s.n}, res[1], 0);\n"
            "  return 0;")


def _orbit(s: _Shape, periods: int) -> str:
    o = len(s.observed)
    return (_locals(s, False)
            + f"  for (p = 0; p < {periods}; ++p) {{\n"
            f"    {_observed_start(s)}\n"
            f"    gs_state_span(y, lo, hi, T, c, {s.blocks});\n"
            f"    gs_store(y, {s.n}, res[0], {s.n}*p); gs_store(lo, {o}, res[1], {o}*p); "
            f"gs_store(hi, {o}, res[2], {o}*p);\n"
            "  }\n"
            "  return 0;")


def _monodromy_end(s: _Shape) -> str:
    o = len(s.observed)
    return (f"  gs_store(y, {s.n}, res[0], 0); gs_store(Q, {s.n * s.n}, res[1], 0);\n"
            f"  gs_store(lo, {o}, res[2], 0); gs_store(hi, {o}, res[3], 0);\n"
            "  return 0;")


def _monodromy_segment(s: _Shape) -> str:
    return (_locals(s, True) + f"  (void) p;\n  {_observed_start(s)}\n"
            f"  gs_tangent_span(y, Q, lo, hi, T, c, {s.blocks // s.S});\n" + _monodromy_end(s))


def _monodromy_period(s: _Shape) -> str:
    """The period's pieces in turn, each with its own extremes, combined by the selects of the MX function
    ((a < b ? a : 0) + (!(a < b) ? b : 0): the same bits, signed zeros included)."""
    width = s.N // s.S
    select = "    {lo}[{i}] = ({a} {op} {b} ? {a} : 0) + ({a} {op} {b} ? 0 : {b});\n"
    combine = "".join(select.format(lo=w, i=i, a=f"{part}[{i}]", b=f"{w}[{i}]", op=op)
                      for i in range(len(s.observed)) for w, part, op in (("lk", "lo", "<"), ("hk", "hi", ">")))
    return (_locals(s, True) + f"  casadi_real lk[{s.size('o')}], hk[{s.size('o')}];\n"
            f"  {_observed_start(s, 'lk', 'hk')}\n"
            f"  for (p = 0; p < {s.S}; ++p) {{\n"
            f"    {_observed_start(s)}\n"
            f"    gs_tangent_span(y, Q, lo, hi, {f'T + {s.rows * width}*p' if s.rows else 'T'}, c, "
            f"{s.blocks // s.S});\n" + combine + "  }\n"
            f"  gs_copy(lk, {s.size('o')}, lo); gs_copy(hk, {s.size('o')}, hi);\n" + _monodromy_end(s))


def _trajectory(s: _Shape) -> str:
    """Every step of a period, one block (one step) at a time; the extremes unused."""
    table = f"T + {s.rows}*p" if s.rows else "T"
    step = (f"gs_trajectory_step(y, {table}, c, y1); gs_copy(y1, {s.n}, y);" if s.stepwise else
            f"gs_state_span(y, lo, hi, {table}, c, 1);")
    y1 = f"  casadi_real y1[{s.size('y')}];\n" if s.stepwise else ""
    return (_locals(s, False) + y1 + f"  {_observed_start(s)}\n"
            f"  for (p = 0; p < {s.N}; ++p) {{\n"
            f"    {step}\n"
            f"    gs_store(y, {s.n}, res[0], {s.n}*p);\n"
            "  }\n"
            "  return 0;")


_LOOPS = {
    "lyapunov_chunk": lambda s: _lyapunov(s, s.P),
    "lyapunov_period": lambda s: _lyapunov(s, 1),
    "orbit_chunk": lambda s: _orbit(s, s.P),
    "orbit_period": lambda s: _orbit(s, 1),
    "monodromy_segment": _monodromy_segment,
    "monodromy_period": _monodromy_period,
    "trajectory": _trajectory,
}
