"""The fit's windows as compiled code: every window's outputs and their exact derivatives in one call.

The multiple-shooting fit (:mod:`gearsym.fit.shooting`) asks, at every Levenberg-Marquardt step,
for each window's model outputs at its sample times and their derivatives by the window's start
state and by the parameters. Here that is one C call for all windows:

* ``fit_step`` (SX): one RK4 step (:func:`~gearsym.codegen.rk4.rk4_step`, the one RK4) of the
  state y and of its tangent Q = [dy/dy0 | dy/dp], as RK4 of the augmented system z = (y, p),
  z' = (f(tau, y, p), 0): the tangent is the exact derivative of the discrete flow;
* ``fit_plain_step``: the same step without the tangent;
* ``fit_output``: the observation channels h(tau, y, p) (a state, a derivative dv/dtau = f_v, a
  combination) and dh/d(y0, p) = dh/dy Q + [0 | dh/dp];
* the same step by columns (:func:`column_functions`), on what depends on time and the parameters alone computed
  once per time point: ``fit_times`` (those values W, a shaft-order library's tooth windows and harmonics, and their
  derivatives D by the parameters), ``fit_stages`` (the state's step, its stage states and Jacobians),
  ``fit_state_step`` (the step alone), ``fit_column`` (a start state's column), ``fit_param_<j>`` (parameter j's
  forcing, df/dp_j at the four stages), ``fit_column_forced`` (a column from its forcing), ``fit_channel_<k>``; and for
  many columns at once ``fit_forcing`` (df/dp of every parameter at the four stages, its common subexpressions
  computed once);
* ``gearsym_fit_windows`` (hand-written C around the column functions): every window from its start
  state, its samples ``substeps`` RK4 steps apart, the outputs and the derivatives by the start state and
  the parameters asked for written into the caller's arrays.

Every parameter has its column function, and a fit asks for the columns it estimates, so the library of
candidate effects (all parameters at 0 but the tried ones) is compiled once for all candidates, and a fit
of three parameters in a library of forty pays for three (the whole tangent step is what the in-process
backend evaluates, mapped over the windows, and what the column functions are tested against). The time values
are computed at two new times a step (t + h/2, and t + h, which is the next step's t: the last stage takes the
time values of the next step's start as that step computes its time, which may differ from t + h in the last bit),
then read by every function of the step: before, each parameter's column computed a 9/13 pair's tooth windows again
at every step (a column 1000 operations, now 250; the 20/53 pair's library of docs/examples/explain-cracked-tooth:
921 kB of C, now 529 kB, gcc 10.5 -> 6.3 s. A step, 40 windows of 76 samples, min of 5, the two codes back to back:
9/13 library with three columns 4350 -> 2163 ns, every column 6307 -> 3181 ns, the state alone 2430 -> 1735 ns;
20/53 library 3226 -> 2690, 6817 -> 4257, 2173 -> 1730 ns). A call that asks for many columns, or for columns
that share a derivative of the state (a transmission error's or spacing errors' parameters each need the mesh
force's derivative at the four stages), takes them all from ``fit_forcing`` instead: the driver compares the
operations of the two ways (each function's count, written into the C) and takes the cheaper (a 9/13 pair's
library: its eight spacing errors 2264 operations a step one by one, 1626 all at once; the screen's 31 columns 7567
against 3719). The time values are computed by groups, and a window skips the groups that only matter while a
parameter it has at 0 (and does not ask the column of) is not (:mod:`.time_gates`): a fit or a tooth scan in a
library of candidates pays for the time values of the effects it tries (the 20/53 library's worked example: its
fits' and scans' window runs 15 -> 7.5 s of CPU, the same bits). The driver clears the vector registers' upper
halves before each window, step and sample's calls (``GS_CLEAN_UPPER``): the compiler copies the time values with
512-bit moves and, at the windows' -O1, does not clear them itself (gcc's vzeroupper pass runs from -O2), and with
them dirty every call into the maths library (pow, fmin) cost about ten times as much (the one-stage model's default
library, 40 windows of 76 samples: a step with three columns 6327 -> 577-871 ns, the state alone 3788 -> 377-700 ns,
the same bits).
The C is cached like the engine's (:mod:`.compiler`); without a compiler the same functions run in
CasADi's virtual machine, mapped over the windows.
"""
from __future__ import annotations

import ctypes
import hashlib
import json
import os
from concurrent.futures import ThreadPoolExecutor
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import casadi as ca
import numpy as np
import sympy as sp

from ..errors import GearsymError
from ..files.private import write_private
from ..system import FirstOrderSystem
from .compiler import WINDOW_FLAGS, cache_dir, compile_flags, compile_library, find_compiler
from .loaded import load_once, open_library
from .casadi_symbols import SystemSymbols
from .rk4 import rk4_step
from .time_gates import TimeGroup, time_groups
from .generate import generator_digest
from .translate import to_casadi
from .trust import record, trusted

#: bump when the generated window code changes for the same system and channels
WINDOWS_VERSION = 8
_OPTS = {"cse": True}
#: RK4 steps in a call below which its windows run in one thread
MIN_SHARED_STEPS = 20_000


@dataclass(frozen=True)
class WindowRun:
    """What :meth:`Windows.run` returns: per sample (column), the states, outputs and their derivatives."""

    states: np.ndarray  # (n, samples of all windows)
    outputs: np.ndarray  # (channels, samples)
    derivatives: np.ndarray | None  # (channels, n + parameters, samples): by [start state, parameters]


class WindowFunctions(dict):
    """The window functions by name, and the groups of time values they compute (:mod:`.time_gates`)."""

    def __init__(self, functions: dict[str, ca.Function], groups: Sequence[TimeGroup]):
        super().__init__(functions)
        self.groups = tuple(groups)


def _harmonics_of_time(exprs: Sequence[sp.Expr], time: sp.Symbol, t: ca.SX) -> tuple[list[sp.Expr], dict]:
    """``exprs`` with every cos(n time) and sin(n time) (n a whole number) replaced by a symbol, and the SX of
    those symbols from cos(t), sin(t) by the angle-addition recurrence: two trigonometric calls per
    evaluation instead of one per harmonic (a library of candidate harmonics has dozens; they dominated)."""
    found: dict[tuple[str, int], sp.Symbol] = {}

    def order(arg: sp.Expr) -> int | None:
        # arg = n time exactly: its derivative by time is the whole number n and nothing is left beside n time (an
        # expansion, not simplify(), which took seconds on each of a shaft-order window's phases)
        n = sp.diff(arg, time)
        return int(n) if n.is_Integer and n > 0 and sp.expand(arg - n * time) == 0 else None

    def replace_in(e: sp.Expr) -> sp.Expr:
        mapping = {}
        for f in e.atoms(sp.cos, sp.sin):
            n = order(f.args[0])
            if n is not None:
                kind = "cos" if isinstance(f, sp.cos) else "sin"
                mapping[f] = found.setdefault((kind, n), sp.Dummy(f"{kind}{n}", real=True))
        return e.xreplace(mapping) if mapping else e

    out = [replace_in(e) for e in exprs]
    top = max((n for _, n in found), default=0)
    cos, sin = [ca.SX(1), ca.cos(t)], [ca.SX(0), ca.sin(t)]
    for k in range(2, top + 1):
        cos.append(cos[k - 1] * cos[1] - sin[k - 1] * sin[1])
        sin.append(sin[k - 1] * cos[1] + cos[k - 1] * sin[1])
    return out, {d: (cos if kind == "cos" else sin)[n] for (kind, n), d in found.items()}


def window_functions(system: FirstOrderSystem, channels: Sequence[sp.Expr]) -> WindowFunctions:
    """``fit_step``, ``fit_plain_step`` and ``fit_output`` of ``system`` (the in-process backend's: see the module
    docstring), then the compiled driver's functions (:func:`column_functions`)."""
    sym = SystemSymbols.of(system)
    n, m = system.dimension, sym.p.numel()
    exprs, waves = _harmonics_of_time(list(system.rhs) + list(channels), system.time, sym.t)
    rhs_exprs, channels = exprs[:n], exprs[n:]
    mapping = {**sym.mapping, **waves}
    f = ca.vertcat(*to_casadi(rhs_exprs, mapping, system.name))
    rhs = ca.Function("f", [sym.t, sym.y, sym.p], [f, ca.jacobian(f, sym.y), ca.jacobian(f, sym.p)])
    y, t, h, p = sym.y, sym.t, ca.SX.sym("h"), sym.p
    Q = ca.SX.sym("Q", n, n + m)

    def f_aug(z, time):
        return ca.vertcat(rhs(time, z[:n], z[n:])[0], ca.SX(m, 1))

    def J_aug(z, time):
        _, Jy, Jp = rhs(time, z[:n], z[n:])
        return ca.vertcat(ca.horzcat(Jy, Jp), ca.SX(m, n + m))

    z = ca.vertcat(y, p)
    Qz = ca.vertcat(Q, ca.horzcat(ca.SX(m, n), ca.SX.eye(m)))  # the parameters' rows: constant
    z1, Qz1 = rk4_step(f_aug, J_aug, z, Qz, h, t, t + h / 2, t + h)
    step = ca.Function("fit_step", [y, Q, t, h, p], [z1[:n], Qz1[:n, :]], _OPTS)
    y1, _ = rk4_step(lambda x, time: rhs(time, x, p)[0], None, y, None, h, t, t + h / 2, t + h)
    plain_step = ca.Function("fit_plain_step", [y, t, h, p], [y1], _OPTS)
    out = ca.vertcat(*to_casadi(list(channels), mapping, f"{system.name}: observation channels"))
    dout = ca.mtimes(ca.jacobian(out, y), Q) + ca.horzcat(ca.SX(out.numel(), n), ca.jacobian(out, p))
    output = ca.Function("fit_output", [y, Q, t, p], [out, ca.densify(dout)], _OPTS)
    columns = column_functions(system, f, out, sym)
    return WindowFunctions({"fit_step": step, "fit_plain_step": plain_step, "fit_output": output, **columns},
                           columns.groups)


def column_functions(system: FirstOrderSystem, f: ca.SX, out: ca.SX, sym: SystemSymbols) -> WindowFunctions:
    """The same tangent step by columns, so that a fit pays only for the columns it asks for (see the module docstring).

    What depends on time and the parameters alone (a library's tooth windows, shaft- and mesh-order harmonics: most
    of a shaft-order library's operations, sines and tanh) is computed once per time point by ``fit_times`` (those
    values W and their derivatives by the parameters D) and passed to the step's functions, which work on the rest:
    ``fit_stages`` (the state's step, its RK4 stage states and each stage's Jacobian dy), ``fit_state_step`` (the
    step alone), ``fit_column`` (a start state's column: Q' = J Q at those stages), ``fit_param_<j>`` (parameter j's
    forcing df/dp_j = dF/dp_j + dF/dW D_j at the four stages), ``fit_forcing`` (every parameter's forcing at once),
    ``fit_column_forced`` (a parameter's column from its forcing: the augmented system's RK4, as ``fit_step``
    computes it), and ``fit_channel_<k>`` (channel k, dh/dy and dh/dp). The stages' times are t, t + h/2, t + h: W
    and D come as three columns (blocks), one per time. (A parameter's function is its forcing alone, the column's
    RK4 written once for all in ``fit_column_forced``: the same operations as a whole column per parameter, a fifth
    less C to compile: the one-stage model's library of every candidate 347 -> 287 kB, gcc 4.3 -> 3.4 s.) The
    driver computes W and D by groups (``fit_times_<g>``: a group's values and derivatives), skipping in a window
    the groups whose parameters leave them unused there (:mod:`.time_gates`: a candidate effect at 0 costs no time
    values)."""
    n, m = system.dimension, sym.p.numel()
    y, t, p, h = sym.y, sym.t, sym.p, ca.SX.sym("h")
    rest, symbols, parametric = ca.extract_parametric(f, ca.vertcat(t, p), {})
    w = ca.vertcat(*symbols) if symbols else ca.SX(0, 1)
    values = ca.vertcat(*parametric) if parametric else ca.SX(0, 1)
    nw = w.numel()
    d_values = ca.jacobian(values, p)  # (sparse: each value depends on a few parameters)
    times_fn = ca.Function("fit_times", [t, p], [ca.densify(values), d_values], _OPTS)
    groups = time_groups(rest, w, values, d_values, p)
    by_group = {}
    for g, group in enumerate(groups):
        rows = list(group.rows)
        by_group[f"fit_times_{g}"] = ca.Function(f"fit_times_{g}", [t, p], [ca.densify(values[rows]),
                                                                           d_values[rows, :]], _OPTS)
    dense = ca.Function("F", [y, p, w], [rest, ca.jacobian(rest, y), ca.jacobian(rest, p), ca.jacobian(rest, w)])
    W = ca.SX.sym("W", nw, 3)
    D = ca.SX.sym("D", ca.horzcat(*[d_values.sparsity()] * 3))
    Ds = [D[:, i * m:(i + 1) * m] for i in range(3)]
    at = (0, 1, 1, 2)  # each RK4 stage's time: t, t + h/2, t + h/2, t + h

    def rhs(x, i):
        return dense(x, p, W[:, at[i]])[0]

    k1 = rhs(y, 0)
    y2 = y + h / 2 * k1
    k2 = rhs(y2, 1)
    y3 = y + h / 2 * k2
    k3 = rhs(y3, 2)
    y4 = y + h * k3
    k4 = rhs(y4, 3)
    y_next = y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    jac = [dense(x, p, W[:, at[i]])[1] for i, x in enumerate((y, y2, y3, y4))]
    stages = ca.Function("fit_stages", [y, W, h, p], [ca.densify(y_next), ca.densify(ca.horzcat(y, y2, y3, y4)),
                                                      ca.densify(ca.horzcat(*jac))], _OPTS)  # (dense: C arrays)
    y_alone, _ = rk4_step(lambda x, values: dense(x, p, values)[0], None, y, None, h, W[:, 0], W[:, 1], W[:, 2])
    state_step = ca.Function("fit_state_step", [y, W, h, p], [ca.densify(y_alone)], _OPTS)  # (the one RK4)
    Y, J, q = ca.SX.sym("Y", n, 4), ca.SX.sym("J", n, 4 * n), ca.SX.sym("q", n)

    def column(forcing):
        Js = [J[:, i * n:(i + 1) * n] for i in range(4)]
        K1 = ca.mtimes(Js[0], q) + forcing[0]
        K2 = ca.mtimes(Js[1], q + h / 2 * K1) + forcing[1]
        K3 = ca.mtimes(Js[2], q + h / 2 * K2) + forcing[2]
        K4 = ca.mtimes(Js[3], q + h * K3) + forcing[3]
        return q + h / 6 * (K1 + 2 * K2 + 2 * K3 + K4)

    def dfdp(i):  # df/dp at stage i: directly and through the time values
        _, _, by_p, by_w = dense(Y[:, i], p, W[:, at[i]])
        return by_p + ca.mtimes(by_w, Ds[at[i]])

    zero = [ca.SX(n, 1)] * 4
    out_fns = {"fit_times": times_fn, **by_group, "fit_stages": stages,
               "fit_state_step": state_step,
               "fit_column": ca.Function("fit_column", [q, J, h], [ca.densify(column(zero))], _OPTS)}
    forcings = [dfdp(i) for i in range(4)]
    for j in range(m):  # parameter j's forcing at the four stages, (n, 4): its column is fit_column_forced's
        out_fns[f"fit_param_{j}"] = ca.Function(f"fit_param_{j}", [Y, W, D, p],
                                                [ca.densify(ca.horzcat(*[fi[:, j] for fi in forcings]))], _OPTS)
    # every parameter's forcing at the four stages at once, (n, 4 m): stage i's df/dp in columns i m ... i m + m - 1
    out_fns["fit_forcing"] = ca.Function("fit_forcing", [Y, W, D, h, p], [ca.densify(ca.horzcat(*forcings))], _OPTS)
    F = ca.SX.sym("F", n, 4)
    out_fns["fit_column_forced"] = ca.Function("fit_column_forced", [q, J, F, h],
                                               [ca.densify(column([F[:, i] for i in range(4)]))], _OPTS)
    for k in range(out.numel()):  # (one function a channel: a call computes only the channels it asks for)
        h_k = out[k]
        out_fns[f"fit_channel_{k}"] = ca.Function(f"fit_channel_{k}", [y, t, p], [
            ca.densify(h_k), ca.densify(ca.jacobian(h_k, y)), ca.densify(ca.jacobian(h_k, p))], _OPTS)
    return WindowFunctions(out_fns, groups)


class Windows:
    """The window integrator of one system and set of channels, compiled or in-process."""

    def __init__(self, system: FirstOrderSystem, channels: Sequence[sp.Expr], backend: str = "auto"):
        self.system, self.channels = system, tuple(channels)
        self.n, self.parameters = system.dimension, len(system.parameters)
        self.digest = windows_hash(system, self.channels)
        compiled = backend == "compiled" or (backend == "auto" and find_compiler() is not None)
        self.backend = "compiled" if compiled else "in-process"
        self._functions: WindowFunctions | None = None
        self._library = self._compile() if compiled else None

    @property
    def functions(self) -> WindowFunctions:
        if self._functions is None:
            self._functions = window_functions(self.system, self.channels)
        return self._functions

    def _compile(self):
        source = cache_dir("code") / f"{self.system.name}-windows-{self.digest[:16]}.c"
        describes = {"model": f"{self.system.name}_windows", "code": self.digest}
        if trusted(source, describes) is None:  # (missing, or not the C gearsym wrote)
            text = self._source().encode()
            record(source, text, describes)
            write_private(source, text)
        library = compile_library(source, f"{self.system.name}_windows", flags=compile_flags(WINDOW_FLAGS),
                                  describes=describes)
        lib = open_library(library.path)
        call = lib.gearsym_fit_windows
        call.restype = ctypes.c_int
        call.argtypes = ([ctypes.c_longlong] + [ctypes.c_void_p] * 6 + [ctypes.c_longlong] * 2
                         + [ctypes.c_void_p, ctypes.c_longlong] + [ctypes.c_void_p] * 4)
        return call

    def _source(self) -> str:
        gen = ca.CodeGenerator("windows.c", {"with_header": False, "verbose": False, "prefix": ""})
        for name, f in self.functions.items():
            if name not in _IN_PROCESS_ONLY:
                gen.add(f)
        functions = self.functions
        forced = functions["fit_column_forced"].n_instructions()
        params, chans = range(self.parameters), range(len(self.channels))
        table, works = _listed(f"fit_param_{j}" for j in params), _listed(f"fit_param_{j}_work" for j in params)
        costs = _listed(functions[f"fit_param_{j}"].n_instructions() + forced for j in params)
        channels = _listed(f"fit_channel_{k}" for k in chans)
        channel_works = _listed(f"fit_channel_{k}_work" for k in chans)
        times = functions["fit_times"]
        return gen.dump() + _DRIVER.format(n=self.n, p=self.parameters, c=len(self.channels), table=table,
                                           nw=times.nnz_out(0), nd=times.nnz_out(1),
                                           works=works, p1=max(1, self.parameters), costs=costs,
                                           channels=channels, channel_works=channel_works,
                                           c1=max(1, len(self.channels)),
                                           forcing=functions["fit_forcing"].n_instructions(),
                                           forced=forced, **_group_tables(functions))

    def run(self, starts: np.ndarray, t0: Sequence[float], dt: Sequence[float], samples: Sequence[int],
            substeps: Sequence[int], parameters: np.ndarray, tangent: bool = True,
            columns: Sequence[int] | None = None, channels: Sequence[int] | None = None) -> WindowRun:
        """Every window k from ``starts[:, k]`` at time ``t0[k]``: ``samples[k]`` samples ``dt[k]`` apart,
        ``substeps[k]`` RK4 steps between samples, parameter vector ``parameters[:, k]``. With ``tangent``, the
        derivatives by the start state and by the parameters ``columns`` (their indices; default every one), in
        that order: a fit pays only for the columns it asks for, and for the ``channels`` (indices into
        ``self.channels``; default every one), which are the outputs' rows in that order."""
        starts = np.asfortranarray(starts, dtype=float)
        parameters = np.asfortranarray(parameters, dtype=float)
        samples = np.ascontiguousarray(samples, dtype=np.int64)
        substeps = np.ascontiguousarray(substeps, dtype=np.int64)
        t0, dt = np.ascontiguousarray(t0, dtype=float), np.ascontiguousarray(dt, dtype=float)
        chosen = np.arange(self.parameters) if columns is None else np.asarray(columns, dtype=np.int64).reshape(-1)
        if chosen.size and (chosen.min() < 0 or chosen.max() >= self.parameters):
            raise GearsymError(f"parameter columns {chosen.tolist()} out of range (0 ... {self.parameters - 1})")
        chosen = np.ascontiguousarray(chosen, dtype=np.int64)
        observed = np.arange(len(self.channels)) if channels is None else np.asarray(channels, np.int64).reshape(-1)
        if observed.size and (observed.min() < 0 or observed.max() >= len(self.channels)):
            raise GearsymError(f"channels {observed.tolist()} out of range (0 ... {len(self.channels) - 1})")
        observed = np.ascontiguousarray(observed, dtype=np.int64)
        total, c, width = int(samples.sum()), observed.size, self.n + chosen.size
        states = np.zeros((self.n, total), order="F")
        outputs = np.zeros((c, total), order="F")
        derivatives = np.zeros((c, width, total), order="F") if tangent else None
        if self._library is not None:
            arrays = (samples, substeps, t0, dt, starts, parameters, chosen, observed, states, outputs, derivatives)
            pieces = _pieces(samples, substeps)
            if len(pieces) == 1:
                status = [self._call(*arrays, *pieces[0], tangent)]
            else:  # (the call releases the GIL and writes disjoint columns: the same bits as one call)
                with ThreadPoolExecutor(max_workers=len(pieces), thread_name_prefix="gearsym-windows") as pool:
                    status = list(pool.map(lambda piece: self._call(*arrays, *piece, tangent), pieces))
            if any(status):
                raise GearsymError("the compiled window integrator reported an error")
        else:
            every = np.zeros((len(self.channels), total), order="F")
            full = np.zeros((len(self.channels), self.n + self.parameters, total), order="F") if tangent else None
            self._run_in_process(starts, t0, dt, samples, substeps, parameters, tangent, states, every, full)
            outputs[...] = every[observed]
            if tangent:
                derivatives[...] = full[observed][:, np.concatenate([np.arange(self.n), self.n + chosen]), :]
        return WindowRun(states, outputs, derivatives)

    def _call(self, samples, substeps, t0, dt, starts, parameters, chosen, observed, states, outputs, derivatives,
              first: int, last: int, column: int, tangent: bool) -> int:
        """The compiled integrator on windows ``first`` ... ``last - 1``, whose samples start at ``column``."""
        f8, i8 = 8, 8  # (float64 and int64 arrays, Fortran order: window k's column is k times its height)
        width = derivatives.shape[1] if tangent else 0
        return self._library(last - first, samples.ctypes.data + i8 * first, substeps.ctypes.data + i8 * first,
                             t0.ctypes.data + f8 * first, dt.ctypes.data + f8 * first,
                             starts.ctypes.data + f8 * self.n * first,
                             parameters.ctypes.data + f8 * self.parameters * first, int(tangent), chosen.size,
                             chosen.ctypes.data, observed.size, observed.ctypes.data,
                             states.ctypes.data + f8 * self.n * column,
                             outputs.ctypes.data + f8 * observed.size * column,
                             derivatives.ctypes.data + f8 * observed.size * width * column if tangent else None)

    def _run_in_process(self, starts, t0, dt, samples, substeps, parameters, tangent, states, outputs, derivatives):
        """The same steps in CasADi's virtual machine, each group of windows with equal substeps mapped."""
        f = self.functions
        offsets = np.concatenate([[0], np.cumsum(samples)])
        n, width = self.n, self.n + self.parameters
        eye = np.hstack([np.eye(n), np.zeros((n, self.parameters))])
        for sub in np.unique(substeps):
            group = np.nonzero(substeps == sub)[0]
            K = group.size
            y = starts[:, group]
            Q = np.tile(eye, (1, K))
            h = dt[group] / sub
            step = f["fit_step"].map(K) if tangent else f["fit_plain_step"].map(K)
            output = f["fit_output"].map(K)
            for s in range(int(samples[group].max())):
                if s:
                    for j in range(int(sub)):
                        t = t0[group] + dt[group] * (s - 1) + h * j
                        if tangent:
                            y, Q = (np.array(a) for a in step(y, Q, t, h, parameters[:, group]))
                        else:
                            y = np.array(step(y, t, h, parameters[:, group]))
                live = np.nonzero(samples[group] > s)[0]
                out, dout = (np.array(a) for a in output(y, Q, t0[group] + dt[group] * s, parameters[:, group]))
                cols = offsets[group[live]] + s
                states[:, cols] = y[:, live]
                outputs[:, cols] = out[:, live]
                if tangent:
                    derivatives[:, :, cols] = dout.reshape(len(self.channels), width, K, order="F")[:, :, live]


def _pieces(samples: np.ndarray, substeps: np.ndarray) -> list[tuple[int, int, int]]:
    """The windows split into contiguous pieces of about equal work, one per core (first, last, first column),
    or one piece when there is too little work to share (a thread costs more than a few thousand steps)."""
    work = np.cumsum(np.maximum(samples - 1, 0) * substeps)
    cores = min(os.cpu_count() or 1, len(samples))
    if cores < 2 or work[-1] < MIN_SHARED_STEPS:
        return [(0, len(samples), 0)]
    cuts = [0, *(int(np.searchsorted(work, work[-1] * i / cores)) + 1 for i in range(1, cores)), len(samples)]
    cuts = sorted(set(min(c, len(samples)) for c in cuts))
    columns = np.concatenate([[0], np.cumsum(samples)])
    return [(a, b, int(columns[a])) for a, b in zip(cuts, cuts[1:]) if b > a]


def windows_hash(system: FirstOrderSystem, channels: Sequence[sp.Expr]) -> str:
    """What determines the window code: the equations, names, channels, this module and the versions."""
    description = {
        "version": WINDOWS_VERSION,
        # this module, its time values' groups and the step's own generator (translate, functions, ...): an edit to
        # any changes the C
        "generator": hashlib.sha256(Path(__file__).read_bytes()).hexdigest() + generator_digest()
        + hashlib.sha256((Path(__file__).parent / "time_gates.py").read_bytes()).hexdigest(),
        "casadi": ca.__version__,
        "name": system.name,
        "time": system.time.name,
        "states": [s.name for s in system.states],
        "rhs": [sp.srepr(f) for f in system.rhs],
        "parameters": list(system.parameters),
        "channels": [sp.srepr(c) for c in channels],
    }
    return hashlib.sha256(json.dumps(description, sort_keys=True).encode()).hexdigest()


def _group_tables(functions: WindowFunctions) -> dict[str, str]:
    """The driver's tables of the time values' groups: their functions, where each group's values and derivatives go
    in W and D (D's nonzeros in column order), and the sets of parameters that gate each (see :mod:`.time_gates`)."""
    d_rows, d_cols = functions["fit_times"].sparsity_out(1).get_triplet()
    nonzero = {(r, c): i for i, (r, c) in enumerate(zip(d_rows, d_cols))}
    w_index, d_index, w_start, d_start, gate_start, set_start, set_params = [], [], [0], [0], [0], [0], []
    for g, group in enumerate(functions.groups):
        rows, cols = functions[f"fit_times_{g}"].sparsity_out(1).get_triplet()
        w_index += group.rows
        d_index += [nonzero[group.rows[r], c] for r, c in zip(rows, cols)]
        w_start.append(len(w_index))
        d_start.append(len(d_index))
        for gate in group.gates:
            set_params += gate
            set_start.append(len(set_params))
        gate_start.append(len(set_start) - 1)
    count = len(functions.groups)
    return {"g": count, "g1": max(1, count),
            "times": _listed(f"fit_times_{g}" for g in range(count)),
            "times_work": _listed(f"fit_times_{g}_work" for g in range(count)),
            "w_start": _listed(w_start), "w_index": _listed(w_index), "d_start": _listed(d_start),
            "d_index": _listed(d_index), "gate_start": _listed(gate_start), "set_start": _listed(set_start),
            "set_params": _listed(set_params)}


def _listed(values) -> str:
    """A C initialiser's list (an empty one as ``0``: C has no empty array)."""
    return ", ".join(map(str, values)) or "0"


#: the whole tangent step and output of the in-process backend (the compiled driver goes column by column), and all
#: time values at once (the driver computes them by groups)
_IN_PROCESS_ONLY = ("fit_step", "fit_plain_step", "fit_output", "fit_times")

def compile_windows(system: FirstOrderSystem, channels: Sequence[sp.Expr], backend: str = "auto") -> Windows:
    """The window integrator of ``system`` observed through ``channels``: built once per process (found again by
    the equations themselves, whose hashes SymPy keeps), compiled once per machine (the C is cached by its hash)."""
    key = ("windows", system.name, system.time, system.states, system.rhs, tuple(system.parameters),
           tuple(channels), backend)
    return load_once(key, lambda: Windows(system, channels, backend))


#: the loop over windows, samples and RK4 steps around the generated functions (no per-step Python)
_DRIVER = r"""
/* gearsym: the fit's window loop (gearsym/codegen/windows.py): the state's RK4 stages once per step, then each
   asked-for column of the tangent [dy/dy0 | dy/dp] in turn */
#include <stdlib.h>
#include <string.h>
/* the upper halves of the vector registers cleared before the generated functions and the maths library run: the
   compiler copies W and D (fixed sizes) with 512-bit moves and leaves those halves dirty (at -O1 gcc inserts no
   vzeroupper of its own: that pass needs -fexpensive-optimizations, on from -O2), and every call into libm (pow,
   fmin) then ran about ten times slower (a candidate library's step with three columns 6300 -> 600-900 ns on a Xeon
   with AVX-512: the same instructions, the same bits) */
#if defined(__AVX__)
#include <immintrin.h>
#define GS_CLEAN_UPPER() _mm256_zeroupper()
#else
#define GS_CLEAN_UPPER() ((void)0)
#endif
#define GS_N {n}
#define GS_P {p}
#define GS_C {c}
/* the time values W (and the nonzeros of their derivatives D by the parameters) at one time */
#define GS_NW {nw}
#define GS_ND {nd}
/* ... computed by groups: a group's values go to W[gs_w_index[gs_w_start[g] ...]], its derivatives' nonzeros to
   D[gs_d_index[gs_d_start[g] ...]]; it is skipped in a window where every parameter of one of its gate sets (sets
   gs_gate_start[g] ... of the parameters gs_set_params[gs_set_start[s] ...]) is 0 and not asked for, as nothing
   depends on it there (gearsym/codegen/time_gates.py) */
#define GS_G {g}

typedef int (*gs_fn)(const casadi_real**, casadi_real**, casadi_int*, casadi_real*, int);
typedef int (*gs_work_fn)(casadi_int*, casadi_int*, casadi_int*, casadi_int*);
static const gs_fn gs_param[{p1}] = {{{table}}};
static const gs_work_fn gs_param_work[{p1}] = {{{works}}};
static const gs_fn gs_group_times[{g1}] = {{{times}}};
static const gs_work_fn gs_group_times_work[{g1}] = {{{times_work}}};
static const casadi_int gs_w_start[] = {{{w_start}}}, gs_w_index[] = {{{w_index}}};
static const casadi_int gs_d_start[] = {{{d_start}}}, gs_d_index[] = {{{d_index}}};
static const casadi_int gs_gate_start[] = {{{gate_start}}}, gs_set_start[] = {{{set_start}}};
static const casadi_int gs_set_params[] = {{{set_params}}};
/* operations a step: each parameter's column (its forcing, then a column from it), and every forcing at once */
static const casadi_int gs_param_cost[{p1}] = {{{costs}}};
/* each channel's value, dh/dy and dh/dp */
static const gs_fn gs_channel[{c1}] = {{{channels}}};
static const gs_work_fn gs_channel_work[{c1}] = {{{channel_works}}};
#define GS_FORCING_COST {forcing}
#define GS_FORCED_COST {forced}

static casadi_int gs_max(casadi_int a, casadi_int b) {{ return a > b ? a : b; }}

static void gs_grow(gs_work_fn f, casadi_int* sz) {{
  casadi_int a, r, i, w;
  if (!f) return;
  f(&a, &r, &i, &w);
  sz[0] = gs_max(sz[0], a); sz[1] = gs_max(sz[1], r); sz[2] = gs_max(sz[2], i); sz[3] = gs_max(sz[3], w);
}}

/* whether group g's time values are needed with the parameters pk, the parameters asked[j] != 0 asked for */
static int gs_group_on(casadi_int g, const casadi_real* pk, const char* asked) {{
  casadi_int s, i;
  for (s = gs_gate_start[g]; s < gs_gate_start[g + 1]; ++s) {{
    int off = 1;
    for (i = gs_set_start[s]; i < gs_set_start[s + 1] && off; ++i)
      if (pk[gs_set_params[i]] != 0 || asked[gs_set_params[i]]) off = 0;
    if (off) return 0;
  }}
  return 1;
}}

/* the time values of the groups on[g] and their derivatives at one time (the others' stay as they are; a group's
   derivatives come with its values, one function a group: a few operations more where a run needs no derivatives,
   half the functions to compile) */
static int gs_times(casadi_real at, const casadi_real* pk, const char* on, casadi_real* W, casadi_real* D,
                    const casadi_real** arg, casadi_real** res, casadi_int* iw, casadi_real* work) {{
  casadi_real wg[GS_NW > 0 ? GS_NW : 1], dg[GS_ND > 0 ? GS_ND : 1];
  casadi_int g, i;
  for (g = 0; g < GS_G; ++g) {{
    if (!on[g]) continue;
    arg[0] = &at; arg[1] = pk; res[0] = wg; res[1] = dg;
    if (gs_group_times[g](arg, res, iw, work, 0)) return 1;
    for (i = gs_w_start[g]; i < gs_w_start[g + 1]; ++i) W[gs_w_index[i]] = wg[i - gs_w_start[g]];
    for (i = gs_d_start[g]; i < gs_d_start[g + 1]; ++i) D[gs_d_index[i]] = dg[i - gs_d_start[g]];
  }}
  return 0;
}}

CASADI_SYMBOL_EXPORT int gearsym_fit_windows(casadi_int count, const casadi_int* samples,
    const casadi_int* substeps, const casadi_real* t0, const casadi_real* dt, const casadi_real* start,
    const casadi_real* p, casadi_int tangent, casadi_int ncols, const casadi_int* cols, casadi_int nchans,
    const casadi_int* chans, casadi_real* states, casadi_real* outputs, casadi_real* derivatives) {{
  casadi_int sz[4] = {{0, 0, 0, 0}}, i, k, s, j, l, col = 0, width = GS_N + ncols, all = 0, one_by_one = 0;
  casadi_real y[GS_N], y1[GS_N], Y[4 * GS_N], J[4 * GS_N * GS_N], q1[GS_N], Fj[4 * GS_N], t, h, at;
  casadi_real W[3 * GS_NW > 0 ? 3 * GS_NW : 1], D[3 * GS_ND > 0 ? 3 * GS_ND : 1];
  casadi_real* F = 0;
  casadi_real out, Hy[GS_N], Hp[GS_P > 0 ? GS_P : 1];
  casadi_real* Q = 0;
  const casadi_real** arg;
  casadi_real** res;
  casadi_int* iw;
  casadi_real* work;
  char asked[GS_P > 0 ? GS_P : 1], on[GS_G > 0 ? GS_G : 1], every[GS_G > 0 ? GS_G : 1];
  gs_grow(fit_state_step_work, sz); gs_grow(fit_stages_work, sz); gs_grow(fit_column_work, sz);
  for (i = 0; i < GS_G; ++i) gs_grow(gs_group_times_work[i], sz);
  for (i = 0; i < nchans; ++i) {{
    if (chans[i] < 0 || chans[i] >= GS_C) return 1;
    gs_grow(gs_channel_work[chans[i]], sz);
  }}
  memset(asked, 0, sizeof(asked));
  memset(every, 1, sizeof(every));
  for (j = 0; j < ncols; ++j) {{
    if (cols[j] < 0 || cols[j] >= GS_P) return 1;
    one_by_one += gs_param_cost[cols[j]];
    if (tangent) asked[cols[j]] = 1;
  }}
  /* the parameters' columns from every forcing at once where that is fewer operations than one by one */
  all = tangent && ncols > 0 && GS_FORCING_COST + ncols * GS_FORCED_COST < one_by_one;
  if (all) {{
    gs_grow(fit_forcing_work, sz); gs_grow(fit_column_forced_work, sz);
    F = (casadi_real*)malloc(sizeof(casadi_real) * (size_t)(4 * GS_N * GS_P));
    if (!F) return 1;
  }} else {{
    for (j = 0; j < ncols; ++j) gs_grow(gs_param_work[cols[j]], sz);
    if (ncols > 0) gs_grow(fit_column_forced_work, sz);
  }}
  arg = (const casadi_real**)malloc(sizeof(casadi_real*) * (size_t)gs_max(sz[0], 1));
  res = (casadi_real**)malloc(sizeof(casadi_real*) * (size_t)gs_max(sz[1], 1));
  iw = (casadi_int*)malloc(sizeof(casadi_int) * (size_t)gs_max(sz[2], 1));
  work = (casadi_real*)malloc(sizeof(casadi_real) * (size_t)gs_max(sz[3], 1));
  Q = (casadi_real*)malloc(sizeof(casadi_real) * (size_t)(GS_N * width));
  if (!arg || !res || !iw || !work || !Q) goto fail;
  for (k = 0; k < count; ++k) {{
    const casadi_real* pk = p + k * GS_P;
    GS_CLEAN_UPPER();
    memcpy(y, start + k * GS_N, sizeof(y));
    /* every group's values at the window's start, at all three times: a group skipped in this window keeps them
       (finite where it enters multiplied by 0: not 0, which could meet a division) */
    if (gs_times(t0[k], pk, every, W, D, arg, res, iw, work)) goto fail;
    for (i = 1; i < 3; ++i) {{
      memcpy(W + i * GS_NW, W, sizeof(casadi_real) * GS_NW);
      memcpy(D + i * GS_ND, D, sizeof(casadi_real) * GS_ND);
    }}
    for (i = 0; i < GS_G; ++i) on[i] = (char)gs_group_on(i, pk, asked);
    memset(Q, 0, sizeof(casadi_real) * (size_t)(GS_N * width));
    for (j = 0; j < GS_N; ++j) Q[j * GS_N + j] = 1;
    h = dt[k] / (casadi_real)substeps[k];
    for (s = 0; s < samples[k]; ++s, ++col) {{
      if (s > 0) {{
        for (l = 0; l < substeps[k]; ++l) {{
          GS_CLEAN_UPPER();
          t = t0[k] + dt[k] * (casadi_real)(s - 1) + h * (casadi_real)l;
          /* the time values at the stages' times, once each for every function of the step: at t (the step before
             computed them, or the window's start, which computed every group at t0), t + h/2 and t + h, which is the
             next step's t as it computes it (the last bit may differ from t + h) */
          if (gs_times(t + h / 2, pk, on, W + GS_NW, D + GS_ND, arg, res, iw, work)) goto fail;
          at = l + 1 < substeps[k] ? t0[k] + dt[k] * (casadi_real)(s - 1) + h * (casadi_real)(l + 1)
                                   : t0[k] + dt[k] * (casadi_real)s;
          if (gs_times(at, pk, on, W + 2 * GS_NW, D + 2 * GS_ND, arg, res, iw, work)) goto fail;
          if (tangent) {{
            arg[0] = y; arg[1] = W; arg[2] = &h; arg[3] = pk; res[0] = y1; res[1] = Y; res[2] = J;
            if (fit_stages(arg, res, iw, work, 0)) goto fail;
            if (all) {{
              arg[0] = Y; arg[1] = W; arg[2] = D; arg[3] = &h; arg[4] = pk; res[0] = F;
              if (fit_forcing(arg, res, iw, work, 0)) goto fail;
            }}
            for (j = 0; j < width; ++j) {{
              casadi_real* qj = Q + j * GS_N;
              if (j < GS_N) {{
                arg[0] = qj; arg[1] = J; arg[2] = &h; res[0] = q1;
                if (fit_column(arg, res, iw, work, 0)) goto fail;
              }} else if (all) {{
                casadi_int stage, r;
                for (stage = 0; stage < 4; ++stage)  /* (F: n x 4 P, stage i's df/dp in its columns i P ...) */
                  for (r = 0; r < GS_N; ++r) Fj[stage * GS_N + r] = F[(stage * GS_P + cols[j - GS_N]) * GS_N + r];
                arg[0] = qj; arg[1] = J; arg[2] = Fj; arg[3] = &h; res[0] = q1;
                if (fit_column_forced(arg, res, iw, work, 0)) goto fail;
              }} else {{  /* (parameter j's forcing alone, then its column as above) */
                arg[0] = Y; arg[1] = W; arg[2] = D; arg[3] = pk; res[0] = Fj;
                if (gs_param[cols[j - GS_N]](arg, res, iw, work, 0)) goto fail;
                arg[0] = qj; arg[1] = J; arg[2] = Fj; arg[3] = &h; res[0] = q1;
                if (fit_column_forced(arg, res, iw, work, 0)) goto fail;
              }}
              memcpy(qj, q1, sizeof(q1));
            }}
          }} else {{
            arg[0] = y; arg[1] = W; arg[2] = &h; arg[3] = pk; res[0] = y1;
            if (fit_state_step(arg, res, iw, work, 0)) goto fail;
          }}
          memcpy(y, y1, sizeof(y));
          memcpy(W, W + 2 * GS_NW, sizeof(casadi_real) * GS_NW);  /* (the next step's t) */
          memcpy(D, D + 2 * GS_ND, sizeof(casadi_real) * GS_ND);
        }}
      }}
      t = t0[k] + dt[k] * (casadi_real)s;
      memcpy(states + col * GS_N, y, sizeof(y));
      GS_CLEAN_UPPER();
      for (i = 0; i < nchans; ++i) {{  /* (the channels asked for, in their order) */
        arg[0] = y; arg[1] = &t; arg[2] = pk; res[0] = &out; res[1] = Hy; res[2] = Hp;
        if (gs_channel[chans[i]](arg, res, iw, work, 0)) goto fail;
        outputs[col * nchans + i] = out;
        if (tangent) {{
          casadi_real* d = derivatives + col * nchans * width;
          for (j = 0; j < width; ++j) {{
            casadi_real sum = j < GS_N ? 0 : Hp[cols[j - GS_N]];
            casadi_int r;
            for (r = 0; r < GS_N; ++r) sum += Hy[r] * Q[j * GS_N + r];
            d[j * nchans + i] = sum;
          }}
        }}
      }}
    }}
  }}
  free(arg); free(res); free(iw); free(work); free(Q); free(F);
  return 0;
fail:
  free(arg); free(res); free(iw); free(work); free(Q); free(F);
  return 1;
}}
"""
