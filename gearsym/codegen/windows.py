"""The fit's windows as compiled code: every window's outputs and their exact derivatives in one call.

The multiple-shooting fit (:mod:`gearsym.fit.shooting`) asks, at every Levenberg-Marquardt step,
for each window's model outputs at its sample times and their derivatives by the window's start
state and by the parameters. Here that is one C call for all windows:

* ``fit_step`` (SX): one RK4 step (:func:`~gearsym.codegen.rk4.rk4_step`, the one RK4) of the
  state y and of its tangent Q = [dy/dy0 | dy/dp], as RK4 of the augmented system z = (y, p),
  z' = (f(tau, y, p), 0): the tangent is the exact derivative of the discrete flow;
* ``fit_state_step``: the same step without the tangent;
* ``fit_output``: the observation channels h(tau, y, p) (a state, a derivative dv/dtau = f_v, a
  combination) and dh/d(y0, p) = dh/dy Q + [0 | dh/dp];
* ``gearsym_fit_windows`` (hand-written C around them): every window from its start state, its
  samples ``substeps`` RK4 steps apart, the outputs written into the caller's arrays.

Derivatives are taken by every parameter: a fit picks the columns it estimates, so the library
of candidate effects (all parameters at 0 but the tried ones) is compiled once for all candidates.
The C is cached like the engine's (:mod:`.compiler`); without a compiler the same functions run in
CasADi's virtual machine, mapped over the windows.
"""
from __future__ import annotations

import ctypes
import hashlib
import json
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import casadi as ca
import numpy as np
import sympy as sp

from ..errors import GearsymError
from ..private_files import write_private
from ..system import FirstOrderSystem
from .compiler import cache_dir, compile_library, find_compiler
from .casadi_symbols import SystemSymbols
from .rk4 import rk4_step
from .generate import generator_digest
from .translate import to_casadi
from .trust import record, trusted

#: bump when the generated window code changes for the same system and channels
WINDOWS_VERSION = 1
_OPTS = {"cse": True}


@dataclass(frozen=True)
class WindowRun:
    """What :meth:`Windows.run` returns: per sample (column), the states, outputs and their derivatives."""

    states: np.ndarray  # (n, samples of all windows)
    outputs: np.ndarray  # (channels, samples)
    derivatives: np.ndarray | None  # (channels, n + parameters, samples): by [start state, parameters]


def _harmonics_of_time(exprs: Sequence[sp.Expr], time: sp.Symbol, t: ca.SX) -> tuple[list[sp.Expr], dict]:
    """``exprs`` with every cos(n time) and sin(n time) (n a whole number) replaced by a symbol, and the SX of
    those symbols from cos(t), sin(t) by the angle-addition recurrence: two trigonometric calls per
    evaluation instead of one per harmonic (a library of candidate harmonics has dozens; they dominated)."""
    found: dict[tuple[str, int], sp.Symbol] = {}

    def order(arg: sp.Expr) -> int | None:
        n = sp.simplify(arg / time)
        return int(n) if n.is_Integer and n > 0 else None

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


def window_functions(system: FirstOrderSystem, channels: Sequence[sp.Expr]) -> dict[str, ca.Function]:
    """``fit_step``, ``fit_state_step`` and ``fit_output`` of ``system`` (see the module docstring)."""
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
    state_step = ca.Function("fit_state_step", [y, t, h, p], [y1], _OPTS)
    out = ca.vertcat(*to_casadi(list(channels), mapping, f"{system.name}: observation channels"))
    dout = ca.mtimes(ca.jacobian(out, y), Q) + ca.horzcat(ca.SX(out.numel(), n), ca.jacobian(out, p))
    output = ca.Function("fit_output", [y, Q, t, p], [out, ca.densify(dout)], _OPTS)
    return {"fit_step": step, "fit_state_step": state_step, "fit_output": output}


class Windows:
    """The window integrator of one system and set of channels, compiled or in-process."""

    def __init__(self, system: FirstOrderSystem, channels: Sequence[sp.Expr], backend: str = "auto"):
        self.system, self.channels = system, tuple(channels)
        self.n, self.parameters = system.dimension, len(system.parameters)
        self.digest = windows_hash(system, self.channels)
        compiled = backend == "compiled" or (backend == "auto" and find_compiler() is not None)
        self.backend = "compiled" if compiled else "in-process"
        self._functions: dict[str, ca.Function] | None = None
        self._library = self._compile() if compiled else None

    @property
    def functions(self) -> dict[str, ca.Function]:
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
        library = compile_library(source, f"{self.system.name}_windows", describes=describes)
        lib = ctypes.CDLL(str(library.path))
        call = lib.gearsym_fit_windows
        call.restype = ctypes.c_int
        call.argtypes = [ctypes.c_longlong] + [ctypes.c_void_p] * 6 + [ctypes.c_longlong] + [ctypes.c_void_p] * 3
        return call

    def _source(self) -> str:
        gen = ca.CodeGenerator("windows.c", {"with_header": False, "verbose": False, "prefix": ""})
        for f in self.functions.values():
            gen.add(f)
        return gen.dump() + _DRIVER.format(n=self.n, p=self.parameters, c=len(self.channels))

    def run(self, starts: np.ndarray, t0: Sequence[float], dt: Sequence[float], samples: Sequence[int],
            substeps: Sequence[int], parameters: np.ndarray, tangent: bool = True) -> WindowRun:
        """Every window k from ``starts[:, k]`` at time ``t0[k]``: ``samples[k]`` samples ``dt[k]`` apart,
        ``substeps[k]`` RK4 steps between samples, parameter vector ``parameters[:, k]``."""
        starts = np.asfortranarray(starts, dtype=float)
        parameters = np.asfortranarray(parameters, dtype=float)
        count = starts.shape[1]
        samples = np.ascontiguousarray(samples, dtype=np.int64)
        substeps = np.ascontiguousarray(substeps, dtype=np.int64)
        t0, dt = np.ascontiguousarray(t0, dtype=float), np.ascontiguousarray(dt, dtype=float)
        total, c, width = int(samples.sum()), len(self.channels), self.n + self.parameters
        states = np.zeros((self.n, total), order="F")
        outputs = np.zeros((c, total), order="F")
        derivatives = np.zeros((c, width, total), order="F") if tangent else None
        if self._library is not None:
            status = self._library(count, samples.ctypes.data, substeps.ctypes.data, t0.ctypes.data,
                                   dt.ctypes.data, starts.ctypes.data, parameters.ctypes.data, int(tangent),
                                   states.ctypes.data, outputs.ctypes.data,
                                   derivatives.ctypes.data if tangent else None)
            if status:
                raise GearsymError("the compiled window integrator reported an error")
        else:
            self._run_in_process(starts, t0, dt, samples, substeps, parameters, tangent, states, outputs,
                                 derivatives)
        return WindowRun(states, outputs, derivatives)

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
            step = f["fit_step"].map(K) if tangent else f["fit_state_step"].map(K)
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


def windows_hash(system: FirstOrderSystem, channels: Sequence[sp.Expr]) -> str:
    """What determines the window code: the equations, names, channels, this module and the versions."""
    description = {
        "version": WINDOWS_VERSION,
        # this module and the step's own generator (translate, functions, ...): an edit to either changes the C
        "generator": hashlib.sha256(Path(__file__).read_bytes()).hexdigest() + generator_digest(),
        "casadi": ca.__version__,
        "name": system.name,
        "time": system.time.name,
        "states": [s.name for s in system.states],
        "rhs": [sp.srepr(f) for f in system.rhs],
        "parameters": list(system.parameters),
        "channels": [sp.srepr(c) for c in channels],
    }
    return hashlib.sha256(json.dumps(description, sort_keys=True).encode()).hexdigest()


_LOADED: dict[tuple, Windows] = {}


def compile_windows(system: FirstOrderSystem, channels: Sequence[sp.Expr], backend: str = "auto") -> Windows:
    """The window integrator of ``system`` observed through ``channels``: built once per process (found again by
    the equations themselves, whose hashes SymPy keeps), compiled once per machine (the C is cached by its hash)."""
    key = (system.name, system.time, system.states, system.rhs, tuple(system.parameters), tuple(channels), backend)
    if key not in _LOADED:
        _LOADED[key] = Windows(system, channels, backend)
    return _LOADED[key]


#: the loop over windows, samples and RK4 steps around the generated functions (no per-step Python)
_DRIVER = r"""
/* gearsym: the fit's window loop (gearsym/codegen/windows.py) */
#include <stdlib.h>
#include <string.h>
#define GS_N {n}
#define GS_P {p}
#define GS_C {c}
#define GS_W (GS_N + GS_P)

static casadi_int gs_max(casadi_int a, casadi_int b) {{ return a > b ? a : b; }}

CASADI_SYMBOL_EXPORT int gearsym_fit_windows(casadi_int count, const casadi_int* samples,
    const casadi_int* substeps, const casadi_real* t0, const casadi_real* dt, const casadi_real* start,
    const casadi_real* p, casadi_int tangent, casadi_real* states, casadi_real* outputs,
    casadi_real* derivatives) {{
  casadi_int sz_arg = 0, sz_res = 0, sz_iw = 0, sz_w = 0, a, r, i, w, k, s, j, col = 0;
  casadi_real y[GS_N], y1[GS_N], Q[GS_N * GS_W], Q1[GS_N * GS_W], t, h;
  const casadi_real** arg;
  casadi_real** res;
  casadi_int* iw;
  casadi_real* work;
  fit_step_work(&a, &r, &i, &w);
  sz_arg = gs_max(sz_arg, a); sz_res = gs_max(sz_res, r); sz_iw = gs_max(sz_iw, i); sz_w = gs_max(sz_w, w);
  fit_state_step_work(&a, &r, &i, &w);
  sz_arg = gs_max(sz_arg, a); sz_res = gs_max(sz_res, r); sz_iw = gs_max(sz_iw, i); sz_w = gs_max(sz_w, w);
  fit_output_work(&a, &r, &i, &w);
  sz_arg = gs_max(sz_arg, a); sz_res = gs_max(sz_res, r); sz_iw = gs_max(sz_iw, i); sz_w = gs_max(sz_w, w);
  arg = (const casadi_real**)malloc(sizeof(casadi_real*) * (size_t)gs_max(sz_arg, 1));
  res = (casadi_real**)malloc(sizeof(casadi_real*) * (size_t)gs_max(sz_res, 1));
  iw = (casadi_int*)malloc(sizeof(casadi_int) * (size_t)gs_max(sz_iw, 1));
  work = (casadi_real*)malloc(sizeof(casadi_real) * (size_t)gs_max(sz_w, 1));
  if (!arg || !res || !iw || !work) {{ free(arg); free(res); free(iw); free(work); return 1; }}
  for (k = 0; k < count; ++k) {{
    const casadi_real* pk = p + k * GS_P;
    memcpy(y, start + k * GS_N, sizeof(y));
    memset(Q, 0, sizeof(Q));
    for (j = 0; j < GS_N; ++j) Q[j * GS_N + j] = 1;
    h = dt[k] / (casadi_real)substeps[k];
    for (s = 0; s < samples[k]; ++s, ++col) {{
      if (s > 0) {{
        for (j = 0; j < substeps[k]; ++j) {{
          t = t0[k] + dt[k] * (casadi_real)(s - 1) + h * (casadi_real)j;
          if (tangent) {{
            arg[0] = y; arg[1] = Q; arg[2] = &t; arg[3] = &h; arg[4] = pk; res[0] = y1; res[1] = Q1;
            if (fit_step(arg, res, iw, work, 0)) goto fail;
            memcpy(Q, Q1, sizeof(Q));
          }} else {{
            arg[0] = y; arg[1] = &t; arg[2] = &h; arg[3] = pk; res[0] = y1;
            if (fit_state_step(arg, res, iw, work, 0)) goto fail;
          }}
          memcpy(y, y1, sizeof(y));
        }}
      }}
      t = t0[k] + dt[k] * (casadi_real)s;
      memcpy(states + col * GS_N, y, sizeof(y));
      arg[0] = y; arg[1] = Q; arg[2] = &t; arg[3] = pk;
      res[0] = outputs + col * GS_C; res[1] = tangent ? derivatives + col * GS_C * GS_W : 0;
      if (fit_output(arg, res, iw, work, 0)) goto fail;
    }}
  }}
  free(arg); free(res); free(iw); free(work);
  return 0;
fail:
  free(arg); free(res); free(iw); free(work);
  return 1;
}}
"""
