"""Shared, cached helpers for the gearsym correctness tests (imported as `conftest`).

Reductions take seconds each, so every shipped model is reduced at most once
per test session. The model objects returned by ``gearsym.load_model`` are
module-level singletons shared by all tests: tests must never mutate them
(``set_defaults``, ``add``); build a fresh drivetrain instead (``fresh_one_stage``).
"""
from __future__ import annotations

import collections
from pathlib import Path
from types import SimpleNamespace

import functools
import os
import sys

import numpy as np
import sympy as sp

import gearsym
from gearsym.model.symbols import parameter_symbol, t

GEAR_MODELS = ("one_stage", "one_stage_resonant", "flexible_shaft", "two_stage")
#: pre-generated models whose byte-for-byte checks of generated/ and docs/derivations/ take many seconds (run with
#: -m slow): Lin & Parker's translational set (its reduction about 5 s of CPU, then 4 s to generate its C:
#: python -m bench.reduction)
SLOW_MODELS: tuple[str, ...] = ("planetary_translational",)
#: the xdist group of the tests that reduce a slow model (`slow_models_group`): in a parallel run (pytest -n auto
#: --dist loadgroup) they run on one worker, so that the model's reduction, cached on the model, is made once
SLOW_MODELS_GROUP = "reductions of the slow models"


def slow_models_group():
    """The mark of a test that reduces a slow model (see SLOW_MODELS_GROUP)."""
    import pytest

    return pytest.mark.xdist_group(SLOW_MODELS_GROUP)


#: the xdist group of the tests that read the one quick reproduction of the session (`quick_reproduction`): its
#: figures checked in test_figures.py, its files in test_reproduce.py, made once on one worker
QUICK_REPRODUCTION_GROUP = "the quick reproduction"


def quick_reproduction_group():
    """The mark of a test that reads the session's quick reproduction (see QUICK_REPRODUCTION_GROUP)."""
    import pytest

    return pytest.mark.xdist_group(QUICK_REPRODUCTION_GROUP)


def model_params(names):
    """Model names as test parameters, the slow ones marked slow and put in the slow models' group."""
    import pytest

    return [pytest.param(n, marks=(pytest.mark.slow, slow_models_group())) if n in SLOW_MODELS else n for n in names]


@functools.cache
def load(name: str):
    if name == "rich":
        return rich_model()
    if name == "idler":
        return idler_model()
    return gearsym.load_model(name)


def idler_model() -> gearsym.Drivetrain:
    """Three gears in a chain (1-2, 2-3) with two backlash meshes: no shaft, two mesh coordinates."""
    from gearsym import Drivetrain, Gear, Harmonic, Mesh, Torque

    m = Drivetrain("idler")
    a = m.add(Gear("g1", inertia="I1", base_radius="r1"))
    b = m.add(Gear("g2", inertia="I2", base_radius="r2"))
    c = m.add(Gear("g3", inertia="I3", base_radius="r3"))
    m.add(Mesh("m1", a, b, variation="1 + kv*cos(phi)", coordinate="x1"))
    m.add(Mesh("m2", b, c, stiffness="kZ2", damping="cZ2", backlash="eta2", variation="1 + kv*cos(phi)",
               phase="ph2", coordinate="x2"))
    m.add(Torque("T1", on=a, mean="M1", harmonics=(Harmonic("M1a"),)))
    m.add(Torque("T3", on=c, mean="M3", load=True))
    return m


def rich_model() -> gearsym.Drivetrain:
    """An inline drivetrain with what the shipped models lack: shaft damping, a forced shaft
    declared disk-first, a mesh phase and a custom variation, harmonics of two orders on
    several bodies, a load torque with harmonics."""
    from gearsym import Disk, Drivetrain, Gear, Harmonic, Mesh, Shaft, Torque

    m = Drivetrain("rich")
    a = m.add(Gear("gear1", inertia="I1", base_radius="r1"))
    b = m.add(Gear("gear2", inertia="I2", base_radius="r2"))
    d = m.add(Disk("disk3", inertia="I3"))
    m.add(Mesh("mesh", a, b, variation="1 + kv*cos(phi) + kw*sin(2*phi)", phase="ph", coordinate="x1"))
    m.add(Shaft("shaft", d, b, stiffness="kS", damping="cS", forced=True, coordinate="x2"))
    m.add(Torque("M1", on=a, mean="M1", harmonics=(Harmonic("M1a", phase="Theta", group="B1"),)))
    m.add(Torque("M2", on=b, mean="M2", load=True,
                 harmonics=(Harmonic("M2a", phase="Theta"), Harmonic("M2b", order=2))))
    m.add(Torque("M3", on=d, mean="M3", load=True, harmonics=(Harmonic("M3a", phase="Theta2"),)))
    m.set_defaults(omega=1.5, zeta=0.08, eta=1.0, kv=0.2, kw=0.05, ph=0.3, kS=0.5, cS=0.02,
                   I1=1.0, I2=2.0, I3=0.5, r1=1.0, r2=1.5, Theta=0.0, Theta2=0.4,
                   B0=1.0, B1=2.0, B2=0.5, B0_x2=0.1, B1_x2=0.2, B2_x2=0.3, B1_Theta2_x2=0.1)
    return m


@functools.cache
def reduced(name: str) -> gearsym.NondimensionalModel:
    return gearsym.reduce(load(name))


def system(name: str, **values) -> gearsym.FirstOrderSystem:
    """The engine's system of a shipped (or conftest) model, as ``gearsym.load(name, **values)`` gives it,
    from the session's one reduction of the model."""
    if not values:
        return _default_system(name)
    model = load(name)
    return gearsym.load(reduced(name) if isinstance(model, gearsym.Drivetrain) else model, **values)


@functools.cache
def _default_system(name: str) -> gearsym.FirstOrderSystem:
    model = load(name)
    return gearsym.load(reduced(name) if isinstance(model, gearsym.Drivetrain) else model)


@functools.cache
def compiled(name: str, options: gearsym.Integration = gearsym.Integration()):
    """The compiled model of ``name`` at its default values, with ``options`` (compiled once per session)."""
    return gearsym.compile_model(system(name), options)


def fresh_one_stage(name: str = "one_stage", resonant: bool = False) -> gearsym.Drivetrain:
    """A new, unshared one-stage drivetrain built by the shipped model's own builder."""
    load("one_stage")  # makes the ``models`` package importable and imports models.one_stage
    return sys.modules["models.one_stage"].build(name, resonant=resonant)


def P(name: str) -> sp.Symbol:
    """The canonical parameter symbol."""
    return parameter_symbol(name)


def psi(i: int) -> sp.Expr:
    """The paper's psi_i(t), typed independently of the library."""
    return sp.Function(f"psi_{i}", real=True)(t)


def coord(name: str, time: sp.Symbol) -> sp.Expr:
    return sp.Function(name, real=True)(time)


# --------------------------------------------------------------------------- an independent reference
def paper_rk4_spectrum(omega, periods, discard, steps, zeta=0.08, B0=1.0, B1=4.0, eta=10.0, a=0.2):
    """Eq. 2 with k(tau) = 1 + a cos(tau), typed from the paper: plain NumPy RK4 on the state and
    its 2x2 tangent matrix, Gram-Schmidt (QR) once per period (the paper's scheme), from the paper's start
    (x, v) = (-2, -0.5). Returns the exponents (in Gram-Schmidt order), the final state and the amplitude of x."""
    def g(x):
        return x if x >= 0 else (x + eta if x <= -eta else 0.0)

    def dg(x):
        return 1.0 if (x >= 0 or x <= -eta) else 0.0

    def f(tau, y, Q):
        x, v = y
        k = 1 + a * np.cos(tau)
        dy = np.array([v, -2 * zeta / omega * v - k * g(x) / omega**2 + (B0 + B1 * np.cos(tau)) / omega**2])
        J = np.array([[0.0, 1.0], [-k * dg(x) / omega**2, -2 * zeta / omega]])
        return dy, J @ Q

    h = 2 * np.pi / steps
    y, Q = np.array([-2.0, -0.5]), np.eye(2)
    logs, lo, hi = [], np.inf, -np.inf
    for period in range(periods):
        for i in range(steps):
            tau = i * h
            k1, K1 = f(tau, y, Q)
            k2, K2 = f(tau + h / 2, y + h / 2 * k1, Q + h / 2 * K1)
            k3, K3 = f(tau + h / 2, y + h / 2 * k2, Q + h / 2 * K2)
            k4, K4 = f(tau + h, y + h * k3, Q + h * K3)
            y = y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
            Q = Q + h / 6 * (K1 + 2 * K2 + 2 * K3 + K4)
            if period >= discard:
                lo, hi = min(lo, y[0]), max(hi, y[0])
        q, r = np.linalg.qr(Q)
        signs = np.sign(np.diag(r))
        Q = q * signs
        logs.append(np.log(np.abs(np.diag(r))))
    lam = np.array(logs[discard:]).sum(axis=0) / ((periods - discard) * 2 * np.pi)
    return lam, y, (hi - lo) / 2


# --------------------------------------------------------------------------- compiled engine
import pytest  # noqa: E402


@pytest.fixture(scope="session", autouse=True)
def _private_library_cache(tmp_path_factory, pytestconfig):
    """Compiled libraries go to a fresh cache per session: the tests compile for real and see cache hits
    they caused themselves, never a stale library from an earlier checkout. The workers of a parallel run
    (pytest -n) share it, as a user's processes share theirs: each model is compiled once, and two workers
    compiling the same one meanwhile is a case the cache handles (its libraries land whole, by rename)."""

    old = os.environ.get("GEARSYM_CACHE")
    if not hasattr(pytestconfig, "workerinput"):  # (what pytest-xdist gives its workers)
        os.environ["GEARSYM_CACHE"] = str(tmp_path_factory.mktemp("gearsym-cache"))
    else:  # the session's folder, beside the workers' own (pytest-N/popen-gw0, ...)
        os.environ["GEARSYM_CACHE"] = str(tmp_path_factory.getbasetemp().parent / "gearsym-cache")
    yield
    if old is None:
        os.environ.pop("GEARSYM_CACHE", None)
    else:
        os.environ["GEARSYM_CACHE"] = old


@pytest.fixture(scope="session", autouse=True)
def _cores_for_two_workers():
    """gearsym runs no more workers than the machine has cores; the tests ask for two to exercise the parallel
    paths, so they see at least two cores even on a machine of one (a test of the cap patches it itself)."""
    import gearsym.sweep.workers as workers

    cores = workers.cores
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(workers, "cores", lambda: max(2, cores()))
        yield


@pytest.fixture(scope="session")
def quick_reproduction(tmp_path_factory):
    """``gearsym reproduce --quick`` run once for the session, as the user runs it (into a folder of its own):
    its folder, its record, each scenario's computed plan (by scenario name) and every figure it wrote (by file
    name), as written: at the resolution it was written at, its artists where the file's drawing put them
    (figure_checks.as_saved), so that a check reads what the PNG shows."""
    import gearsym.figures.save as save
    import gearsym.reproduce as reproduction
    from figure_checks import as_saved

    computed, figures, resolution = {}, {}, {}
    written, drawn = save.save_figure, reproduction.draw_all

    def kept(fig, path, dpi, **kwargs):
        figures[Path(path).name], resolution[Path(path).name] = fig, dpi
        return written(fig, path, dpi, **kwargs)

    def recorded(c, out, suffix=""):
        computed[c.plan.scenario.name] = c
        return drawn(c, out, suffix)

    out = tmp_path_factory.mktemp("quick-reproduction")
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(reproduction, "draw_all", recorded)
        patch.setattr(sys.modules["gearsym.reproduce.figures"], "save_figure", kept)
        record = reproduction.reproduce(out / "figures", out / "reproduction.md", quick=True)
    for name, fig in figures.items():
        as_saved(fig, resolution[name])  # (read as the file's drawing left it: not laid out or drawn again)
    return SimpleNamespace(out=out, record=record, computed=computed, figures=figures)


@pytest.fixture
def report_without_its_two_plots(monkeypatch):
    """For a test that reads a report's pages and data but never looks at its residual and prediction figures: the
    report writes those two files empty instead of drawing them (about 3 s of matplotlib's layout a report; the teeth
    figure is still drawn). The figures are drawn and checked where a test looks at them:
    test_explain.py's residual figure and report command."""
    import gearsym.figures.fit_report as fit_report

    monkeypatch.setattr(fit_report, "residual_figure", lambda ex, system, path: path.write_bytes(b""))
    monkeypatch.setattr(fit_report, "prediction_figure", lambda ex, name, path: path.write_bytes(b""))


def interrupt_after(count):
    """An ``on_point`` for sweeps that presses Ctrl-C once ``count`` points are stored."""
    seen = []

    def on_point(row):
        seen.append(row)
        if len(seen) == count:
            raise KeyboardInterrupt

    return on_point


@pytest.hookimpl(tryfirst=True)  # (before xdist's own, which suffixes each node id with the groups it sees)
def pytest_collection_modifyitems(config, items):
    """For a parallel run (pytest -n auto --dist loadgroup): every test file is a group that runs on one worker, so
    that its module fixtures (a compiled model, simulated data) are made once, as in a serial run; the docs' pages
    are groups of their own (tests/test_doc_examples.py), so that the pages run in parallel."""
    for item in items:
        if item.get_closest_marker("xdist_group") is None:
            item.add_marker(pytest.mark.xdist_group(item.nodeid.split("::")[0]))
    # the heaviest groups first (a slow test counts as SLOW_WEIGHT quick ones), so that no worker is left with a
    # long group at the end while the other has finished: xdist takes the groups in this order (pytest_configure)
    if not hasattr(config, "workerinput"):  # (a serial run keeps the files' order)
        return
    weight, first = collections.Counter(), {}
    for n, item in enumerate(items):
        weight[_group(item)] += SLOW_WEIGHT if item.get_closest_marker("slow") else 1
        first.setdefault(_group(item), n)
    items.sort(key=lambda item: (-weight[_group(item)], first[_group(item)]))  # (stable: a group's tests in order)


#: about how many quick tests' time a test marked slow takes (~10 s against ~0.3 s)
SLOW_WEIGHT = 30


def _group(item) -> str:
    return item.get_closest_marker("xdist_group").args[0]


def pytest_configure(config):
    """xdist's --dist loadgroup hands out the groups largest first by their number of tests; the order
    pytest_collection_modifyitems gives (by their time) is the better one.

    The gearsym processes the tests start run as an installed gearsym does, with its bytecode kept: an environment
    that says PYTHONDONTWRITEBYTECODE (this machine's does) would have each of them compile gearsym's ~140 modules
    from source again (about a second of CPU each; ``pip install`` writes the bytecode of a user's gearsym once).
    Set here, before xdist starts its workers, so that they and every process they start inherit it."""
    if hasattr(config.option, "loadscopereorder"):
        config.option.loadscopereorder = False
    os.environ.pop("PYTHONDONTWRITEBYTECODE", None)
    sys.dont_write_bytecode = False
