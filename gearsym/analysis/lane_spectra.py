"""Lyapunov spectra of one model at one parameter point from many starts, many at once in the lanes
(:mod:`gearsym.codegen.lane_runs`): each start's spectrum is what :func:`~.lyapunov.lyapunov_spectrum` gives it
(the lanes compute the scalar loop's numbers), summarised together (:func:`~.lyapunov.summarise_runs`). The runs
of :func:`~.attractors.find_attractors`; a single spectrum (``gearsym lyap``) does not load the lanes."""
from __future__ import annotations

import numpy as np

from ..codegen import CompiledModel, TangentRuns
from ..codegen.lane_runs import LaneRunner
from ..errors import GearsymError
from ..options import Integration
from .divergence import run_failure
from .lyapunov import LyapunovSpectrum, spectrum_resolution, summarise_runs


def lyapunov_spectra(model: CompiledModel, starts: np.ndarray, options: Integration, p: np.ndarray, *,
                     lanes: bool = True) -> list[LyapunovSpectrum]:
    """:func:`lyapunov_spectrum` of ``model`` at the parameter vector ``p`` from each of ``starts`` (runs x n),
    many at once in the lanes (:mod:`gearsym.codegen.lane_runs`: each lane the scalar loop's numbers); a run that
    failed (rather than diverged) raises the error :func:`lyapunov_spectrum` raises, naming its start; a run that
    diverged is ``diverged`` (its ``divergence`` says how), as in :func:`lyapunov_spectrum`."""
    inputs = model.prepare(p)
    records = LaneRunner(model, 0, options.periods, lanes=lanes).orbits(starts, inputs, tangent=True)
    count, n, o = len(starts), model.dimension, len(model.observed)
    runs = TangentRuns(n, o, options.periods, max(count, 1))
    runs.strobe[:count], runs.log_stretch[:count] = records.strobe, records.log_stretch
    runs.low[:count], runs.high[:count] = records.low, records.high
    summary = summarise_runs(model, runs, np.tile(p, (count, 1)), np.full(count, inputs.period), options.discard)
    for i in range(count):
        failure = run_failure(model, p, inputs.period, starts[i], runs.strobe[i], runs.log_stretch[i],
                              summary.divergences[i])
        if failure is not None:
            start = ", ".join(f"{name}={v:g}" for name, v in zip(model.state_names, starts[i]))
            raise GearsymError(f"initial state #{i} ({start}): {failure}") from None
    out = []
    for i in range(count):
        measured = runs.log_stretch[i, options.discard:] / inputs.period
        history = np.cumsum(measured, axis=0) / np.arange(1, measured.shape[0] + 1)[:, None]
        history = history[:, summary.order[i]]
        for a, b in summary.pairs[i]:  # a pair's running estimate: its common real part's
            history[:, [a, b]] = history[:, [a, b]].mean(axis=1, keepdims=True)
        out.append(LyapunovSpectrum(
            model=model.name, parameters=dict(zip(model.parameter_names, map(float, p))),
            exponents=summary.exponents[i], stderr=summary.stderr[i], history=history,
            amplitude=dict(zip(model.observed, map(float, summary.amplitude[i]))),
            final_state=dict(zip(model.state_names, map(float, records.final[i]))),
            strobe=runs.strobe[i].T[:, options.discard:], periods=options.periods, discard=options.discard,
            steps_per_period=model.steps_per_period, period=inputs.period, backend=model.backend,
            autonomous=model.system.autonomous,
            info={"Q": records.Q[i], "locate_crossings": model.options.locate_crossings,
                  "integration": model.integration},
            eigenvalues=summary.eigenvalues[i], regime=summary.regimes[i], pairs=tuple(summary.pairs[i]),
            divergence=summary.divergences[i], settling=summary.settlings[i],
            resolution=spectrum_resolution(model, summary.exponents[i], p, records.final[i], inputs.period,
                                   summary.divergences[i])))
    return out
