"""JiTCODE's ``jitcode_lyap`` (all n exponents) on the symbolic right-hand side.

JiTCODE derives the tangent equations from the symbolic f (symengine),
generates C for the n + n^2 system, compiles it as a Python extension and
integrates it with an adaptive integrator: "dopri5" by default (Dormand-Prince
5(4) via scipy.integrate.ode, what JiTCODE's docs suggest trying first; the C
right-hand side is called back once per stage). k(tau) and the forcing are
evaluated in the generated code at every RHS call, from JiTCODE's time ``t``.

Backlash: ``symengine.Piecewise((x, x >= 0), (x + eta, x <= -eta), (0, True))``.
symengine differentiates it branch by branch to Piecewise((1, ..), (1, ..),
(0, True)), i.e. the exact g' in {0, 1} the other tools use, and JiTCODE prints
both as C ternaries. (``jitcxde_common.conditional`` would be a tanh-smoothed
step, not the exact g'; symengine cannot differentiate Max/Min.)

omega is a control parameter (``control_pars``), so one compiled module serves
every point of a sweep; the other parameters are baked into the code. The
module is compiled once per (model, parameters) in a process and, unless
``cache=False``, kept in $TMPDIR/gearsym-peers-jitcode for later processes.
Setup is mostly code generation: with JiTCODE's defaults (simplify for n <= 10)
symengine passes the tangent expressions to SymPy's simplify (trigsimp,
piecewise_simplify), several seconds; ``simplify=False`` skips that.

``integrate`` is called at every period end: jitcode_lyap then
orthonormalises the tangent vectors (QR, which gives the Gram-Schmidt norms in
column order) and returns the local exponents log(norm_j)/T of that period;
their mean over the measured periods is the spectrum. The tangent vectors are
set to the identity at every point (``jitcode.set_initial_value`` on the full
state: jitcode_lyap's own ``set_initial_value`` would draw random vectors).
"""
from __future__ import annotations

import contextlib
import hashlib
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import symengine as se

from bench.peers.common import (DIM, K_HARMONICS, T, ContinuationSweep, PointResult, Stopwatch,
                                check_periods, initial_state, model_params, shaft_constants)

DEFAULT_ACCURACY = {"rtol": 1e-10, "atol": 1e-12}
CACHE_DIR = Path(tempfile.gettempdir()) / "gearsym-peers-jitcode"
OMEGA = se.Symbol("omega")

_COMPILED: dict[str, Path] = {}  # key -> module file compiled in this process


def f_sym(model: str, p: dict[str, float]) -> list:
    """The model's right-hand side in JiTCODE's symbols y(i), t and the control parameter omega."""
    from jitcode import t, y

    k = 1 + p["k_a"] * sum(c * se.cos(m * t) for m, c in K_HARMONICS)
    forcing = p["B0"] + p["B1"] * se.cos(t + p["Theta"])
    x = y(0)
    g = se.Piecewise((x, x >= 0), (x + p["eta"], x <= -p["eta"]), (0, True))
    c1 = 2 * p["zeta"] / OMEGA
    if model == "one_stage":
        return [y(1), -c1 * y(1) + forcing / OMEGA**2 - k * g / OMEGA**2]
    b1, b2, b3 = shaft_constants(p)
    return [
        y(1),
        -c1 * y(1) + forcing / OMEGA**2 - k * g / OMEGA**2 - p["kS"] * b1 * y(2) / OMEGA**2,
        y(3),
        -p["kS"] * b2 * y(2) / OMEGA**2 - c1 * b3 * y(1) - b3 * k * g / OMEGA**2,
    ]


def _key(model: str, f: list, simplify: bool | None) -> str:
    import jitcode
    import jitcxde_common

    text = "\0".join([model, *map(str, f), f"simplify={simplify}", jitcode.__version__,
                      jitcxde_common.__version__, se.__version__, sys.version])
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _compile(model: str, f: list, path_stem: Path, simplify: bool | None) -> Path:
    """Generate and compile the jitcode_lyap module; return the module file."""
    from jitcode import jitcode_lyap

    n = DIM[model]
    ode = jitcode_lyap(f, n_lyap=n, control_pars=[OMEGA], simplify=simplify, verbose=False)
    ode.generate_f_C(simplify=simplify)
    # Compile into a private directory under the final file name (the module
    # name comes from it), then move it into place: concurrent builds are safe.
    # The build runs from that directory: setuptools would otherwise read the
    # pyproject.toml of whatever directory the benchmark was started from.
    tmpdir = Path(tempfile.mkdtemp(prefix="build-", dir=path_stem.parent))
    try:
        with contextlib.chdir(tmpdir):
            built = Path(ode.save_compiled(str(tmpdir / path_stem.name), overwrite=True))
        final = path_stem.parent / built.name
        os.replace(built, final)
    finally:
        shutil.rmtree(tmpdir, ignore_errors=True)
    return final


class JiTCODELyap(ContinuationSweep):
    def __init__(self, model: str, accuracy: dict | None, integrator: str, cache: bool,
                 simplify: bool | None, params: dict[str, float]):
        from jitcode import jitcode_lyap

        t0 = time.perf_counter()
        acc = {**DEFAULT_ACCURACY, **(accuracy or {})}
        if set(acc) - {"rtol", "atol"}:
            raise ValueError(f"JiTCODE's integrators are adaptive: accuracy takes 'rtol' and 'atol', got {accuracy}")
        self.model, self.integrator = model, integrator
        self.name = "JiTCODE" if integrator == "dopri5" else f"JiTCODE {integrator}"
        self.p = model_params(model, **params)
        self.accuracy = {k: float(v) for k, v in acc.items()}
        n = DIM[model]

        f = f_sym(model, self.p)
        key = _key(model, f, simplify)
        CACHE_DIR.mkdir(parents=True, exist_ok=True)
        stem = CACHE_DIR / f"jitcode_{model}_{key}"
        found = sorted(CACHE_DIR.glob(stem.name + ".*"))  # the extension suffix is platform-specific
        if key in _COMPILED:
            module, self.setup_note = _COMPILED[key], "compiled earlier in this process"
        elif cache and found:
            module, self.setup_note = found[0], "cached module file (no compile)"
        else:
            module, self.setup_note = _compile(model, f, stem, simplify), "code generation + compile"
            _COMPILED[key] = module

        self._ode = jitcode_lyap(n=n, n_lyap=n, control_pars=[OMEGA], module_location=str(module),
                                 verbose=False)
        self._ode.set_integrator(integrator, **self.accuracy)
        self.setup_seconds = time.perf_counter() - t0

    def spectrum(self, omega: float, y0=None, periods: int = 400, discard: int = 100) -> PointResult:
        from jitcode import jitcode

        check_periods(periods, discard)
        n = DIM[self.model]
        s0 = np.concatenate([initial_state(self.model, y0), np.eye(n).ravel()])
        ode = self._ode
        sum_local = np.zeros(n)
        with Stopwatch() as sw:
            ode.set_parameters(float(omega))
            jitcode.set_initial_value(ode, s0, 0.0)  # Q = I (bypasses jitcode_lyap's random vectors)
            for k in range(1, periods + 1):
                state, local, _ = ode.integrate(k * T)
                if k > discard:
                    sum_local += local
        return PointResult(sum_local / (periods - discard), np.array(state, dtype=float), sw.seconds)


def make(model: str, accuracy: dict | None = None, integrator: str = "dopri5", cache: bool = True,
         simplify: bool | None = None, **params: float) -> JiTCODELyap:
    """``simplify``: None keeps JiTCODE's defaults (simplify when n <= 10, where
    symengine hands cos/Piecewise expressions to SymPy's simplify: most of the
    setup time); False skips it."""
    return JiTCODELyap(model, accuracy, integrator, cache, simplify, params)
