"""The residual's sidebands: the evidence for a shaft-order effect, before and after it is added.

A model that lacks a gear's eccentricity or one of its tooth faults leaves, in its residual, the modulation the
effect makes: lines at the gear's shaft orders and at the mesh harmonics plus and minus them
(:mod:`gearsym.analysis.orders`). For each record the training residual (measurement minus the fitted windows,
one contiguous stretch per record) is analysed channel by channel, relative to the channel's spread; the report
shows each line averaged over the records and channels, and each gear's sideband energy, as declared and after.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from ..analysis.orders import gaps_joined, order_spectrum
from ..system import FirstOrderSystem
from .result import Fit
from .segment import Segment


def geared_pairs(system: FirstOrderSystem) -> list[tuple[dict[str, int], float]]:
    """(gear -> teeth, mesh order) of every mesh whose gears both have tooth counts."""
    out = []
    for c in system.couplings:
        if c.kind == "mesh" and c.gears and all(g.teeth for g in c.gears):
            out.append(({g.gear: g.teeth for g in c.gears}, float(c.order or 1)))
    return out


def residual_sidebands(system: FirstOrderSystem, fit: Fit, segments: Sequence[Segment]) -> dict | None:
    """Per line label: its amplitude in the training residual (relative to each channel's spread, averaged over the
    records and channels), with each gear's sideband energy under ``"energy"``; None without gears with teeth."""
    pairs = geared_pairs(system)
    if not pairs:
        return None
    gears, mesh_order = pairs[0]
    by_record: dict = {}
    for seg, residual in zip(segments, fit.residuals):
        key = seg.key[0] if seg.key else id(seg)
        for name, r in residual.items():
            by_record.setdefault((key, name), []).append((seg.tau, r))
    spread = {}
    for seg in segments:
        for name, v in seg.observed.items():
            spread.setdefault(name, []).append(v)
    spread = {k: float(np.std(np.concatenate(v))) or 1.0 for k, v in spread.items()}
    amplitudes: dict[str, list[float]] = {}
    energy: dict[str, list[float]] = {g: [] for g in gears}
    noise = []
    for (key, name), pieces in by_record.items():
        tau, r = gaps_joined(pieces)
        if tau.size < 8:
            continue
        spectrum = order_spectrum(tau, r / spread[name], gears, mesh_order=mesh_order, channel=name)
        for ln in spectrum.lines:
            if np.isfinite(ln.amplitude):
                amplitudes.setdefault(ln.label, []).append(ln.amplitude)
        for g in gears:
            if np.isfinite(spectrum.sideband_energy(g)):  # (a record shorter than two of its revolutions: none)
                energy[g].append(spectrum.sideband_energy(g))
        noise.append(spectrum.noise)
    if not amplitudes:
        return None
    return {"gears": gears, "lines": {k: float(np.mean(v)) for k, v in amplitudes.items()},
            "energy": {g: float(np.mean(v)) if v else 0.0 for g, v in energy.items()},
            "noise": float(np.mean(noise)) if noise else 0.0}


def strongest(evidence: Mapping, gear: str, count: int = 4) -> list[tuple[str, float]]:
    """The ``count`` strongest lines of ``gear`` (shaft orders and sidebands) in ``evidence``."""
    lines = [(k, v) for k, v in evidence["lines"].items() if gear in k.split()]
    return sorted(lines, key=lambda kv: -kv[1])[:count]
