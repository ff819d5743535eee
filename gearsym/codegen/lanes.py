"""The lanes: L trajectories integrated at once, printed from the same SX step pieces as the scalar loops.

A basin map, an attractor search or a sweep of independent points runs the same loop from thousands of
starts. The scalar loops (:mod:`.printed`) keep one trajectory in registers and are bound by the latency of
the chain from one RK4 stage to the next; here L trajectories sit in the lanes of SIMD registers (structure of
arrays: entry k of lane l at ``k*GS_L + l``), and every operation of CasADi's step runs on all of them at once:

* each per-step SX piece of the model's C (``gs_<piece>_strided``, :data:`.printed.LANE_PIECES`: its entries a
  stride apart) is called in a ``for`` over the lanes, on lane l's entries (``A0[S*j]`` -> ``A0[GS_L*j + l]``:
  the tables of time too, so that the lanes may be points of a sweep whose tables differ); inlined, gcc
  vectorises that loop across the lanes (the bodies are arithmetic, comparisons and selects);
* with crossings located, the try runs on every lane; a lane whose try flags a crossing takes the split,
  scalar (``gs_{kind}_split``, the scalar loops' own function), and its results replace the kept try's in
  that lane; the other lanes go on;
* Gram-Schmidt (``sqrt``, ``log``) runs per lane, scalar, the scalar loops' own function;
* L comes from the target at compile time: one AVX-512 register (8 doubles), two AVX registers (8: the second
  register's operations fill the latency of the first's, the RK4 stages being a chain; 1.8x over one register,
  measured on AVX2), with ``-march=native`` (the default flags); without those macros on x86-64 Linux (a portable
  build, e.g. ``GEARSYM_CFLAGS=-O3``) the entry points are cloned for AVX2 and the baseline (``target_clones``:
  the CPU picks at load time) with L = 8; two SSE2 registers (4) elsewhere on x86; 1 (a plain loop) otherwise.

Each lane computes the scalar loop's operations in the scalar loop's order: the same bits, as long as the
compiler contracts the same multiply-adds in both (``-ffp-contract``; the tests compare the lanes with the
scalar loop to the bit under the default flags and without FMA). The file stands beside the model's C
(``<model>_lanes.c``) and includes it up to its step pieces (``GEARSYM_STEP_PIECES_ONLY``: CasADi's helpers,
the pieces, the splits; not its loops and functions), so that generated/ holds each piece once; it is compiled
into a library of its own the first time lanes are asked for, so that no other command pays its compile time.
"""
from __future__ import annotations

from .code_files import source_file
from .functions import ModelFunctions
from .printed import _CLOSING, LANE_PIECES, PIECES_ONLY, _Shape

#: the entry points of a lanes library (plain C, called through ctypes)
ENTRY_POINTS = ("gearsym_lanes", "gearsym_lanes_orbit", "gearsym_lanes_lyapunov")

_LANES_PREAMBLE = r"""
/* gearsym: the lanes, L trajectories at once (see gearsym/codegen/lanes.py) */
#if defined(__GNUC__) && !defined(__clang__)
/* a comparison's 0/1 times a value is a select: gcc may speculate it (if-convert the lane loop) only if floating
   point does not trap (the values are the same; clang assumes so by default) */
#pragma GCC optimize ("no-trapping-math")
#endif
/* GS_L trajectories per call: one AVX-512 register of doubles, two AVX ones (the second register's operations
   fill the latency of the first's: the RK4 stages are a chain; measured 1.8x over one register on AVX2) */
#if defined(__AVX512F__)
#define GS_L 8
#define GS_TARGETS
#elif defined(__AVX__)
#define GS_L 8
#define GS_TARGETS
#elif defined(__x86_64__) && defined(__GNUC__) && defined(__linux__) && defined(__has_attribute)
#if __has_attribute(target_clones)
/* a portable build: AVX2 chosen at load time where the CPU has it (no FMA: the baseline's bits) */
#define GS_L 8
#define GS_TARGETS __attribute__((target_clones("avx2", "default")))
#endif
#endif
#if !defined(GS_L) && defined(__SSE2__)
#define GS_L 4
#define GS_TARGETS
#endif
#ifndef GS_L
#define GS_L 1
#define GS_TARGETS
#endif
/* the loop over the lanes, left to the vectoriser (no dependence between lanes) */
#if defined(__GNUC__) && !defined(__clang__)
#define GS_LANES _Pragma("GCC ivdep") for (l = 0; l < GS_L; ++l)
#else
#define GS_LANES for (l = 0; l < GS_L; ++l)
#endif
"""


def lanes_source(mf: ModelFunctions) -> str:
    """The C of the lanes of the model of ``mf``: the model's C (:func:`.printed.print_loops`) included up to its
    step pieces, and the lane loops printed around those."""
    s = _Shape(mf)
    out = [f"/* gearsym: the lanes of {mf.system.name}, L trajectories at once (see gearsym/codegen/lanes.py), "
           f"around the step pieces of {source_file(mf.system.name)} */", _LANES_PREAMBLE,
           f"#define {PIECES_ONLY}\n#include \"{source_file(mf.system.name)}\"\n"]
    out += [_lane_piece(name, mf.steps[name], s) for name in LANE_PIECES if name in mf.steps]
    out.append(_lane_piece("constants", mf.functions["constants"], s, constants=False))
    out += _lane_steps(s)
    out += _entries(s)
    out += [_points(s, len(mf.system.parameters), tangent) for tangent in (True, False)]
    return "\n".join(out) + "\n" + _CLOSING


def _lane_piece(name: str, f, s: _Shape, constants: bool = True) -> str:
    """``gsl_<name>``: the model's SX function ``f`` called in a loop over the lanes, on lane l's entries; every
    input and output (the table of time and the constants too) one value per lane, ``GS_L`` apart (a tangent
    vector's rows ``n*GS_L`` apart). ``constants``: a step piece, whose last input is the constants (``False``: the
    constants function itself, parameters in, constants out, which a chart of many parameter points evaluates per
    lane)."""
    if constants and f.numel_in(f.n_in() - 1) != s.nc:
        raise AssertionError(f"{name}: the last input is not the constants")
    args = [f"const casadi_real* restrict A{i}" for i in range(f.n_in())]
    args += [f"casadi_real* restrict R{i}" for i in range(f.n_out())]
    lanes = [f"A{i} + l" for i in range(f.n_in())] + [f"R{i} + l" for i in range(f.n_out())]
    return (f"/* {name} on every lane: the model's piece on lane l's entries */\n"
            f"static GEARSYM_INLINE void gsl_{name}({', '.join(args)}) {{\n"
            f"  casadi_int l;\n  GS_LANES gs_{name}_strided({', '.join(lanes)}, GS_L);\n}}\n")


def _lane_steps(s: _Shape) -> list[str]:
    """One step of L trajectories of each kind, and the span of a period's blocks (the state in local arrays,
    a -> b -> a, as the scalar span)."""
    n, o, L = s.n, len(s.observed), "GS_L"
    out = []
    for kind, carried in (("tangent", ("y", "Q")), ("state", ("y",))):
        state = [*carried, "lo", "hi"]
        ins = [f"const casadi_real* restrict {v}" for v in state] + ["const casadi_real* restrict T",
                                                                   "const casadi_real* restrict c"]
        outs = [f"casadi_real* restrict {v}1" for v in state]
        body = _lane_step(s, kind)
        out.append(f"/* one block of {kind} steps of every lane */\n"
                   f"static GEARSYM_INLINE void gsl_{kind}_step({', '.join(ins + outs)}) {{\n{body}}}\n")
        sizes = {"y": f"{s.size('y')}*{L}", "Q": f"{s.size('Q')}*{L}", "lo": f"{s.size('o')}*{L}",
                 "hi": f"{s.size('o')}*{L}"}
        length = {"y": f"{n}*{L}", "Q": f"{n * n}*{L}", "lo": f"{o}*{L}", "hi": f"{o}*{L}"}
        a, b = [f"{v}a" for v in state], [f"{v}b" for v in state]
        locals_ = " ".join(f"casadi_real {v}a[{sizes[v]}], {v}b[{sizes[v]}];" for v in state)
        table = (lambda k: f"T + {s.step}*GS_L*({k})") if s.step else (lambda k: "T")
        copy = lambda src, dst: " ".join(f"gs_copy({x}, {length[v]}, {y});" for v, x, y in zip(state, src, dst))
        out.append(
            f"/* blocks of {kind} steps of every lane from ({', '.join(state)}), in place, a -> b -> a */\n"
            f"static GEARSYM_INLINE void gsl_{kind}_span({', '.join(f'casadi_real* restrict {v}' for v in state)}, "
            "const casadi_real* restrict T, const casadi_real* restrict c, casadi_int blocks) {\n"
            f"  {locals_}\n  casadi_int k;\n  {copy(state, a)}\n"
            "  for (k = 0; k < blocks; k += 2) {\n"
            f"    gsl_{kind}_step({', '.join([*a, table('k'), 'c', *b])});\n"
            f"    if (k + 1 == blocks) {{ {copy(b, state)} return; }}\n"
            f"    gsl_{kind}_step({', '.join([*b, table('k + 1'), 'c', *a])});\n"
            "  }\n"
            f"  {copy(a, state)}\n}}\n")
    return out


def _gather(s: _Shape, names: list[tuple[str, str]]) -> str:
    """Copy lane l of lane arrays into scalar locals ((lane array, scalar array) pairs, ``GS_L`` apart)."""
    return "".join(f"    for (i = 0; i < {size}; ++i) {dst}[i] = {src}[GS_L*i + l];\n" for src, dst, size in names)


def _lane_step(s: _Shape, kind: str) -> str:
    """The body of one step of every lane: the pieces on all lanes, then the split of each lane that crosses."""
    n, o, nc, J = s.n, len(s.observed), s.nc, max(1, s.jacobians)
    vectors = (f"  for (j = 0; j < {n}; ++j) gsl_tangent_vector(Q + GS_L*j, J, c, Q1 + GS_L*j);\n"
               if kind == "tangent" else "")
    if not s.located:
        if kind == "tangent":
            return (f"  casadi_real J[{J}*GS_L]; casadi_int j;\n"
                    "  gsl_tangent_state(y, lo, hi, T, c, y1, lo1, hi1, J);\n" + vectors)
        return "  gsl_state_block(y, lo, hi, T, c, y1, lo1, hi1);\n"
    y, O, Qn = s.size("y"), s.size("o"), s.size("Q")
    if kind == "tangent":
        head = (f"  casadi_real yt[{y}*GS_L], flag[GS_L], J[{J}*GS_L]; casadi_int j, l, i; int any, finite;\n"
                "  gsl_tangent_state(y, T, c, yt, flag, J);\n" + vectors)
    else:
        head = (f"  casadi_real yt[{y}*GS_L], flag[GS_L]; casadi_int l, i; int any, finite;\n"
                "  gsl_state_try(y, T, c, yt, flag);\n")
    head += "  gsl_state_keep(y, lo, hi, yt, T, c, y1, lo1, hi1);\n"
    gathered = [("y", "ys", n), ("lo", "los", o), ("hi", "his", o), ("yt", "yts", n), ("c", "cs", nc),
                ("T", "Ts", s.step)]
    declare = (f"    casadi_real ys[{y}], los[{O}], his[{O}], yts[{y}], cs[{nc}], Ts[{max(1, s.step)}], y1s[{y}], "
               f"lo1s[{O}], hi1s[{O}];\n")
    scatter = "".join(f"    for (i = 0; i < {size}; ++i) {dst}[GS_L*i + l] = {src}[i];\n"
                      for src, dst, size in (("y1s", "y1", n), ("lo1s", "lo1", o), ("hi1s", "hi1", o)))
    if kind == "tangent":  # the split takes the tangent vectors as columns: (r, j) of lane l at GS_L*(r*n + j) + l
        declare += f"    casadi_real Qc[{Qn}], Qc1[{Qn}];\n"
        columns = (f"    for (i = 0; i < {n * n}; ++i) Qc[(i % {n})*{n} + i / {n}] = Q[GS_L*i + l];\n"
                   "    gs_tangent_split(ys, Qc, los, his, yts, Qc, Ts, cs, y1s, Qc1, lo1s, hi1s);\n"
                   f"    for (i = 0; i < {n * n}; ++i) Q1[GS_L*i + l] = Qc1[(i % {n})*{n} + i / {n}];\n")
    else:
        columns = "    gs_state_split(ys, los, his, yts, Ts, cs, y1s, lo1s, hi1s);\n"
    return (head + "  any = 0;\n  GS_LANES any |= flag[l] != 0;\n"
            "  if (GEARSYM_UNLIKELY(any)) for (l = 0; l < GS_L; ++l) if (flag[l] != 0) {  /* this lane crosses */\n"
            + declare + _gather(s, gathered)
            + f"    for (i = 0, finite = 1; i < {n}; ++i) finite &= ys[i] - ys[i] == 0;\n"
            "    if (!finite) continue;  /* a lane that diverged keeps the try (every flag of it would split) */\n"
            + columns + scatter + "  }\n")


def _entries(s: _Shape) -> list[str]:
    """The exported entry points: the lanes' width, and whole periods of L trajectories with and without
    tangent vectors, writing each period's strobe, extremes (and log stretches) where the caller asks."""
    n, o = s.n, len(s.observed)
    observed = " ".join(f"lo[GS_L*{i} + l] = y[GS_L*{j} + l]; hi[GS_L*{i} + l] = y[GS_L*{j} + l];"
                        for i, j in enumerate(s.observed))
    start = f"    for (l = 0; l < GS_L; ++l) {{ {observed} }}\n" if observed else ""
    store = (f"    if (strobe) gs_copy(y, {n}*GS_L, strobe + {n}*GS_L*p);\n"
             f"    if (low) gs_copy(lo, {o}*GS_L, low + {o}*GS_L*p);\n"
             f"    if (high) gs_copy(hi, {o}*GS_L, high + {o}*GS_L*p);\n")
    O = s.size("o")
    return [
        "/* the lanes of this build */\n"
        "CASADI_SYMBOL_EXPORT int gearsym_lanes(void) { return GS_L; }\n",
        "/* `periods` periods of the state of GS_L trajectories from y (n x GS_L, lane fastest; in place), with the\n"
        "   constants c (nc x GS_L) and the tables of a period T (steps x rows x GS_L: entry j of step k of lane l at\n"
        "   GS_L*(rows*k + j) + l), one of each per lane; each period's strobe, low and high written where given\n"
        "   (periods x n x GS_L, periods x observed x GS_L) */\n"
        "CASADI_SYMBOL_EXPORT GS_TARGETS int gearsym_lanes_orbit(const casadi_real* restrict T, "
        "const casadi_real* restrict c, casadi_int periods, casadi_real* restrict y, casadi_real* strobe, "
        "casadi_real* low, casadi_real* high) {\n"
        f"  casadi_real lo[{O}*GS_L], hi[{O}*GS_L]; casadi_int p, l;\n"
        "  for (p = 0; p < periods; ++p) {\n" + start
        + f"    gsl_state_span(y, lo, hi, T, c, {s.blocks});\n" + store + "  }\n  return 0;\n}\n",
        "/* the same with n tangent vectors (Q: (r, j), row r of vector j, at GS_L*(r*n + j) + l; in place),\n"
        "   re-orthonormalised every period per lane (the scalar loops' Gram-Schmidt); each period's log\n"
        "   stretches written where given (periods x n x GS_L) */\n"
        "CASADI_SYMBOL_EXPORT GS_TARGETS int gearsym_lanes_lyapunov(const casadi_real* restrict T, "
        "const casadi_real* restrict c, casadi_int periods, casadi_real* restrict y, casadi_real* restrict Q, "
        "casadi_real* strobe, casadi_real* logs, casadi_real* low, casadi_real* high) {\n"
        f"  casadi_real lo[{O}*GS_L], hi[{O}*GS_L], Qc[{s.size('Q')}], Qn[{s.size('Q')}], lg[{s.size('y')}], "
        f"acc[{s.size('y')}*GS_L];\n"
        "  casadi_int p, l, i, g;\n"
        "  for (p = 0; p < periods; ++p) {\n" + start
        + f"    for (i = 0; i < {n}*GS_L; ++i) acc[i] = 0;\n"
        + "".join(f"    {loop}{{\n"
                  f"      gsl_tangent_span(y, Q, lo, hi, {table}, c, {blocks});\n"
                  "      for (l = 0; l < GS_L; ++l) {  /* Gram-Schmidt of each lane's vectors, as columns */\n"
                  f"        for (i = 0; i < {n * n}; ++i) Qc[(i % {n})*{n} + i / {n}] = Q[GS_L*i + l];\n"
                  "        gs_gram_schmidt(Qc, Qn, lg);\n"
                  f"        for (i = 0; i < {n * n}; ++i) Q[GS_L*i + l] = Qn[(i % {n})*{n} + i / {n}];\n"
                  f"        for (i = 0; i < {n}; ++i) acc[GS_L*i + l] += lg[i];\n"
                  "      }\n    }\n" for loop, table, blocks in _pieces(s))
        + f"    if (logs) for (i = 0; i < {n}*GS_L; ++i) logs[{n}*GS_L*p + i] = acc[i];\n"
        + store + "  }\n  return 0;\n}\n",
    ]


def _points(s: _Shape, parameters: int, tangent: bool) -> str:
    """The entry points of many parameter points (:mod:`gearsym.stability`): each point's constants from its own
    parameters, its tables from a pool of tables (points that share their tables share one), and ``periods``
    periods of its state and (``tangent``) of the tangent map from the identity, without re-orthonormalisation:
    the monodromy matrix, L points per pass through the period. Without the tangent (``gearsym_lanes_states``),
    the state alone, and with ``columns`` = n the lanes take each point n times from the columns of the identity:
    for a linear system, whose state is its own tangent, the columns of its monodromy matrix at the cost of one
    vector each."""
    n, size, P = s.n, s.rows * s.N, max(1, parameters)
    observed = " ".join(f"lo[GS_L*{i} + l] = yl[GS_L*{j} + l]; hi[GS_L*{i} + l] = yl[GS_L*{j} + l];"
                        for i, j in enumerate(s.observed))
    if tangent:
        name, args = "gearsym_lanes_monodromies", "casadi_real* restrict y, casadi_real* restrict M, "
        what = ("the state after them is written over y + n*i, the tangent map to M + n*n*i (row r of column j at\n"
                "   r*n + j: d y_r / d y0_j)")
        lanes, start = "count", f"      for (i = 0; i < {n}; ++i) yl[GS_L*i + l] = y[{n}*g + i];\n" \
            f"      for (i = 0; i < {n * n}; ++i) Ql[GS_L*i + l] = i % {n + 1} == 0;\n"
        point, span = "g", f"gsl_tangent_span(yl, Ql, lo, hi, work, cl, {s.blocks})"
        store = (f"      for (i = 0; i < {n}; ++i) y[{n}*(b + l) + i] = yl[GS_L*i + l];\n"
                 f"      for (i = 0; i < {n * n}; ++i) M[{n * n}*(b + l) + i] = Ql[GS_L*i + l];\n")
    else:
        name, args = "gearsym_lanes_states", "long long columns, casadi_real* restrict y, "
        what = ("with columns = 0 it starts at y + n*i and its state after them is written there; with columns = c,\n"
                "   lane g runs point g / c from the column g % c of the identity and writes its state to y + n*g")
        lanes = "(columns ? count * columns : count)"
        start = (f"      for (i = 0; i < {n}; ++i) yl[GS_L*i + l] = columns ? (i == g % columns) : y[{n}*g + i];\n")
        point, span = "(columns ? g / columns : g)", f"gsl_state_span(yl, lo, hi, work, cl, {s.blocks})"
        store = f"      for (i = 0; i < {n}; ++i) y[{n}*(b + l) + i] = yl[GS_L*i + l];\n"
    return (
        f"/* `periods` periods of `count` parameter points{', state and tangent' if tangent else ', the state alone'}, "
        "GS_L lanes at a time: point i has the parameters\n"
        f"   p + {parameters}*i, its tables at pool + {size}*tix[i] (rows x steps of one period, column-major, as the\n"
        "   scalar loops read them: points whose tables are the same share one), its constants computed here from\n"
        f"   its parameters; {what}. work: room for GS_L tables. */\n"
        f"CASADI_SYMBOL_EXPORT GS_TARGETS int {name}(const casadi_real* restrict pool, "
        "const long long* restrict tix, const casadi_real* restrict p, long long count, long long periods, "
        f"{args}casadi_real* restrict work) {{\n"
        f"  casadi_real pl[{P}*GS_L], cl[{s.nc}*GS_L], per[GS_L], yl[{s.size('y')}*GS_L], "
        + (f"Ql[{s.size('Q')}*GS_L], " if tangent else "")
        + f"lo[{s.size('o')}*GS_L], hi[{s.size('o')}*GS_L];\n"
        f"  long long last[GS_L], b, k, g, q, total = {lanes}; casadi_int l, i;\n"
        "  for (l = 0; l < GS_L; ++l) last[l] = -1;\n"
        "  for (b = 0; b < total; b += GS_L) {\n"
        "    for (l = 0; l < GS_L; ++l) {  /* (lanes past the end repeat the last one: finite numbers) */\n"
        f"      g = b + l < total ? b + l : total - 1;\n      q = {point};\n"
        f"      for (i = 0; i < {parameters}; ++i) pl[GS_L*i + l] = p[{parameters}*q + i];\n"
        + start
        + "      if (tix[q] != last[l]) {  /* a table of another point: copied into this lane */\n"
        f"        const casadi_real* t = pool + {size}*tix[q];\n"
        f"        for (i = 0; i < {size}; ++i) work[GS_L*i + l] = t[i];\n"
        "        last[l] = tix[q];\n"
        "      }\n"
        "    }\n"
        "    gsl_constants(pl, cl, per);\n"
        "    for (k = 0; k < periods; ++k) {\n"
        + (f"      for (l = 0; l < GS_L; ++l) {{ {observed} }}\n" if observed else "")
        + f"      {span};\n"
        "    }\n"
        "    for (l = 0; l < GS_L && b + l < total; ++l) {\n"
        + store
        + "    }\n"
        "  }\n"
        "  return 0;\n}\n")


def _pieces(s: _Shape) -> list[tuple[str, str, int]]:
    """The pieces of a period between Gram-Schmidt steps (the scalar loops' :func:`.printed._orthonormalised`):
    (the C loop over them, the table at each one's start, its blocks)."""
    table = (lambda at: f"T + {s.step}*GS_L*({at})") if s.step else (lambda at: "T")
    if not s.every:
        return [("", "T", s.blocks)]
    whole = s.blocks // s.every
    out = [(f"for (g = 0; g < {whole}; ++g) ", table(f"{s.every}*g"), s.every)]
    if s.rest:
        out.append(("", table(whole * s.every), s.rest))
    return out

