"""The lanes (gearsym/codegen/lanes.py): L trajectories at once give, lane by lane, the scalar loop's numbers.

Without fused multiply-adds every lane does the scalar loop's operations in its order, so the records must be the
same bits; a chaotic model (Lorenz) turns any difference into an O(1) one within a few periods, so it is the
sharpest check. The libraries are built with -O3 -ffp-contract=off: no -march, so the lanes' entry points are the portable
build's (cloned for AVX2 and the baseline, the CPU choosing at load time), which is also what must run on a CPU
without AVX2.
"""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

import gearsym
from gearsym import FirstOrderSystem, GearsymError, Integration, find_attractors, lyapunov_spectrum
from gearsym.analysis.lane_spectra import lyapunov_spectra
from gearsym.analysis.regime import DIVERGED
from gearsym.codegen.compiled import CompiledModel
from gearsym.codegen.compiler import compile_library, find_compiler
from gearsym.codegen.functions import LoopOptions, build_functions
from gearsym.codegen.generate import code_hash, write_code
from gearsym.codegen.lane_runs import LaneLibrary, LaneRunner
from gearsym.codegen.library import library_functions
from gearsym.codegen.native import load_native

import conftest

needs_cc = pytest.mark.skipif(find_compiler() is None, reason="needs a C compiler")

#: no fused multiply-adds, no -march: the portable build (with no contraction at all: also where the baseline has
#: FMA); test_printed_loops.py's flags, so that the scalar loops' libraries it compiles are the session cache's
PORTABLE = ("-O3", "-ffp-contract=off")


def loop_options(located: bool) -> LoopOptions:
    """45 steps a period in blocks of 3 (plain: blocks of several steps, an odd number of them), chunks of 3
    periods: test_printed_loops.py's options, whose C (and library) it makes too."""
    return LoopOptions(steps_per_period=45, chunk_periods=3, block_steps=3, locate_crossings=located)


_BUILT: dict = {}


def _built(name: str, options: LoopOptions, tmp_path: Path, flags=PORTABLE) -> tuple[CompiledModel, LaneLibrary]:
    """The model's scalar loops and its lanes, both compiled with ``flags`` from freshly generated C (once per
    session for the same model and options)."""
    key = (name, options, flags)
    if key not in _BUILT:
        _BUILT[key] = _build(name, options, tmp_path, flags)
    return _BUILT[key][:2]


def _build(name: str, options: LoopOptions, tmp_path: Path, flags) -> tuple[CompiledModel, LaneLibrary]:
    system = conftest.system(name)
    mf = build_functions(system, options)
    digest = code_hash(system, options)
    code = write_code(mf, tmp_path / name, digest)
    main = compile_library(code.source, name, flags=flags).path
    lanes = compile_library(code.lanes, f"{name}_lanes", flags=flags, includes=(code.source,)).path
    functions = library_functions(main)
    integration = Integration(steps_per_period=options.steps_per_period, locate_crossings=options.locate_crossings)
    model = CompiledModel(system, options, digest, functions, "compiled", main, {}, load_native(main, functions),
                          integration)
    return model, LaneLibrary(lanes), code.lanes


def _records_equal(a, b) -> list[str]:
    return [f for f in a.__dataclass_fields__ if not np.array_equal(getattr(a, f), getattr(b, f), equal_nan=True)]


@needs_cc
@pytest.mark.parametrize("name, located, omega", [("one_stage", True, 1.5), ("one_stage", False, 1.0),
                                                  ("lorenz", True, None)])
@pytest.mark.slow
def test_every_lane_gives_the_bits_of_the_scalar_loop_from_its_start(name, located, omega, tmp_path):
    """one_stage with its backlash split and in plain blocks of steps; Lorenz (no switching surface: single steps,
    as located) chaotic, where a differing bit grows. (Lorenz's scalar library is test_printed_loops.py's: the same
    C and flags; its lanes' C of single steps compiles in 60 % of the time of the blocks' C.)"""
    model, lanes = _built(name, loop_options(located), tmp_path)
    assert lanes.width >= 2, "the portable build has lanes (cloned for AVX2 and the baseline on x86-64)"
    values = {"omega": omega} if omega else {}
    inputs = model.prepare(model.parameter_vector(values))
    n = model.dimension
    starts = np.random.default_rng(5).uniform(-5, 5, size=(2 * lanes.width + 1, n))  # a last block not full
    if name == "lorenz":
        starts += [0, 0, 25]
    for tangent in (False, True):
        wide = LaneRunner(model, 7, 30, lanes=lanes).orbits(starts, inputs, tangent=tangent)
        one = LaneRunner(model, 7, 30, lanes=False).orbits(starts, inputs, tangent=tangent)
        assert np.isfinite(one.strobe).all()
        assert _records_equal(wide, one) == [], (name, located, tangent)
    if located and name == "one_stage":  # the lanes' split ran: some trajectory crossed the backlash surface x = 0
        x = one.strobe[:, :, 0]
        assert ((x.min(axis=1) < 0) & (x.max(axis=1) > 0)).any()


@pytest.mark.slow
@needs_cc
def test_constants_may_differ_from_lane_to_lane(tmp_path):
    """Points of a sweep that share their tables (omega in tau) run in one call, each lane with its constants."""
    model, lanes = _built("one_stage", loop_options(True), tmp_path)
    omegas = np.linspace(0.9, 1.6, lanes.width + 2)
    inputs = [model.prepare(model.parameter_vector(omega=w)) for w in omegas]
    constants = np.array([i.constants for i in inputs])
    start = np.tile([-2.0, -0.5], (len(omegas), 1))
    wide = LaneRunner(model, 5, 20, lanes=lanes).orbits(start, inputs[0], constants=constants, tangent=True)
    for i, point in enumerate(inputs):
        one = LaneRunner(model, 5, 20, lanes=False).orbits(start[i:i + 1], point, tangent=True)
        assert np.array_equal(wide.strobe[i], one.strobe[0]) and np.array_equal(wide.log_stretch[i], one.log_stretch[0])


def _cpu_flags() -> set[str]:
    try:
        text = Path("/proc/cpuinfo").read_text()
    except OSError:
        return set()
    line = next((l for l in text.splitlines() if l.startswith("flags")), "")
    return set(line.split(":", 1)[-1].split())


@needs_cc
def test_the_lanes_are_as_wide_as_the_target_says():
    """With the default flags (-march=native) the width comes from the target's macros: one AVX-512 register of
    doubles, or two AVX registers: 8 either way."""
    model = conftest.compiled("one_stage")
    width = LaneRunner(model, 1, 1).width
    cpu = _cpu_flags()
    if not cpu:
        pytest.skip("no /proc/cpuinfo to read the CPU's flags from")
    if not {"avx", "avx512f"} & cpu:
        pytest.skip("a CPU without AVX: the width is the portable build's")
    assert width == 8


@needs_cc
def test_under_the_default_flags_the_lanes_agree_with_the_scalar_loop_to_rounding():
    """With fused multiply-adds gcc may fuse other multiply-adds in the scalar loop (where its basic-block
    vectoriser packs operations) than in the lanes: the same numbers to rounding (on a periodic attractor,
    where rounding does not grow)."""
    model = conftest.compiled("one_stage")
    inputs = model.prepare(model.parameter_vector(omega=1.5))
    starts = np.array([[-2.0, -0.5], [-1.5, -0.4], [-2.5, -0.7], [-1.8, -0.6], [-2.2, -0.3]])
    wide = LaneRunner(model, 50, 50).orbits(starts, inputs)
    one = LaneRunner(model, 50, 50, lanes=False).orbits(starts, inputs)
    assert np.allclose(wide.strobe, one.strobe, rtol=0, atol=1e-10)


@needs_cc
def test_every_per_step_piece_is_the_models_own_called_in_a_loop_over_the_lanes(tmp_path):
    """The lanes' C (as the generator writes it) includes the model's up to its step pieces and holds no copy
    of them: each per-step piece is the model's, its entries a stride apart, called in a loop over the lanes on
    lane l's entries (the tables of time too); the split and Gram-Schmidt are the scalar loops' own functions."""
    options = loop_options(True)
    _built("one_stage", options, tmp_path)
    lanes = _BUILT[("one_stage", options, PORTABLE)][2]
    source, model = lanes.read_text(), (lanes.parent / "one_stage.c").read_text()
    assert '#define GEARSYM_STEP_PIECES_ONLY\n#include "one_stage.c"' in source
    assert not re.search(r"^\s*a\d+=", source, re.M), "no line of CasADi's step bodies in the lanes' C"
    for piece in ("tangent_state", "tangent_vector", "state_try", "state_keep"):
        body = re.search(rf"static GEARSYM_INLINE void gsl_{piece}\(.*?\n}}\n", source, re.S).group(0)
        assert re.search(rf"GS_LANES gs_{piece}_strided\(A0 \+ l, .*, GS_L\);", body), piece
        strided = re.search(rf"void gs_{piece}_strided\(.*?\n}}\n", model, re.S).group(0)
        assert "[S*" in strided and not re.search(r"\b[AR]\d\[[1-9]\d*\]", strided), piece
    assert model.index("gs_state_try_strided") < model.index("#ifndef GEARSYM_STEP_PIECES_ONLY") \
        < model.index("gs_state_span")
    assert "gs_state_split(ys, los, his, yts, Ts, cs, y1s, lo1s, hi1s);" in source
    assert "gs_gram_schmidt(Qc, Qn, lg);" in source
    assert 'target_clones("avx2", "default")' in source


@needs_cc
@pytest.mark.parametrize("name, axes", [("one_stage", ["omega=1.5,1.6,1.7,1.8,1.9"]),
                                        ("flexible_shaft", ["omega=1.5,1.8", "kS=0.5,1.0,2.0"])])
@pytest.mark.slow
def test_an_independent_sweep_in_the_lanes_gives_the_scalar_sweeps_rows(name, axes):
    """Points that only move constants share a lanes call, each lane with its constants: the rows are those of
    the scalar sweep (periodic points, where a rounding difference would not grow: the lanes may fuse other
    multiply-adds than the scalar loop)."""
    model = conftest.compiled(name)
    kw = dict(mode="independent", options=Integration(periods=60, discard=20))
    wide = gearsym.run_sweep(model, axes, execution=gearsym.Execution(jobs=1, lanes=True), **kw)
    one = gearsym.run_sweep(model, axes, execution=gearsym.Execution(jobs=1), **kw)
    assert len(wide) == len(one) == (5 if name == "one_stage" else 6)
    for column in one.columns:
        a, b = wide[column], one[column]
        if a.dtype.kind in "fc":
            assert np.allclose(a, b, rtol=1e-9, atol=1e-12), column
        else:
            assert list(a) == list(b), column
    assert list(wide.record.items()) == list(one.record.items())


@pytest.mark.slow
def test_the_lanes_spectra_carry_each_start_s_verdict_as_lyapunov_spectrum_gives_it():
    """lyapunov_spectra (find_attractors' runs, in the lanes) gives each start what lyapunov_spectrum gives it from
    there: the regime (where the exponents cannot decide, decided by the Poincare points: periodic, or
    undetermined), the complex pairs, no divergence, and what the Poincare points did."""
    model = conftest.compiled("one_stage_resonant", Integration(periods=500, discard=300))
    starts = np.random.default_rng(0).uniform(-5, 5, size=(6, model.dimension))
    wide = lyapunov_spectra(model, starts, model.run_options(None), model.parameter_vector(omega=1.5))
    for y0, w in zip(starts, wide):
        one = lyapunov_spectrum(model, y0=y0, omega=1.5)
        assert (w.regime, w.pairs, w.divergence) == (one.regime, one.pairs, one.divergence), y0
        assert (w.settling is None) == (one.settling is None) and (w.settling is None or (
            w.settling.state, w.settling.lag) == (one.settling.state, one.settling.lag)), y0
        assert np.allclose(w.exponents, one.exponents, rtol=0, atol=1e-9)
    assert any(w.settling is not None for w in wide)  # (at omega = 1.5 the exponents cannot decide alone)


def escape_oscillator() -> FirstOrderSystem:
    """x'' + d x' + x - x^2 = F cos(w t): bounded in the well around 0, escaping in finite time beyond x = 1."""
    return FirstOrderSystem.from_equations("escape", ["x", "v"], ["v", "-d*v - x + x**2 + F*cos(w*t)"],
                                           {"d": 0.1, "F": 0.02, "w": 0.8}, time="t", period="2*pi/w")


@pytest.mark.slow
def test_a_start_that_diverges_in_the_lanes_is_diverged_and_find_attractors_names_it():
    """A run that grows without bound is 'diverged' in the lanes as in lyapunov_spectrum (not an error, not a
    regime); find_attractors, which has no attractor to group it with, says which start and what to do."""
    model = gearsym.compile_model(escape_oscillator(), Integration(periods=80, discard=40))
    starts = np.array([[0.1, 0.0], [3.0, 0.0]])
    wide = lyapunov_spectra(model, starts, model.run_options(None), model.parameter_vector())
    one = lyapunov_spectrum(model, y0=starts[1])
    assert wide[0].divergence is None and wide[0].regime == "periodic"
    assert wide[1].regime == one.regime == DIVERGED and wide[1].divergence == one.divergence is not None
    with pytest.raises(GearsymError, match=r"initial state #1 \(x=3, v=0\): the motion diverged: .*smaller box"):
        find_attractors(model, initial_states=[{"x": 0.1, "v": 0.0}, {"x": 3.0, "v": 0.0}])
