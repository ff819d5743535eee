"""Order spectra: a signal's amplitude against frequency in orders of the mesh, with the mesh harmonics and the
shaft-order sidebands of each gear labelled.

In a gear pair every shaft-order effect shows as sidebands: a gear of Z teeth turns at 1/Z of the mesh frequency,
so an eccentric gear or a faulty tooth modulates each mesh harmonic m at its shaft orders, m +- k/Z (k = 1, 2,
...), and a local fault spreads over many k (one short event per revolution). Here frequencies are in orders of
the mesh (the mesh frequency is order 1; ``mesh_order`` converts from the model's time: the mesh phase is
``mesh_order * tau``).

The continuous spectrum is the FFT of the signal (Hann window, mean removed, amplitude-corrected) where the
samples are evenly spaced; the labelled lines' amplitudes are least-squares fits of cos and sin at their exact
frequencies together (so a record that holds no whole number of revolutions, or samples with gaps, still gives
each line's amplitude without leakage between the labelled lines), weighted by a Hann window over the record:
what the fit does not label (a period-2 response's half orders, mesh harmonics beyond those labelled) would
otherwise leak into the sidebands of a record that is no whole number of revolutions (one_stage with 20/53
teeth, period 2 at omega = 1.5, over 212 mesh periods: a sideband energy of 0.034 at the pinion without the
window, 1e-7 with it, of a mesh line of 2.2). A gear's sidebands need a record of at least
``MIN_REVOLUTIONS`` of its revolutions (:func:`check_length`), and sideband k of a gear of Z teeth is labelled
only for k < Z/2 (beyond, m + k/Z is the next harmonic's lower sideband m + 1 - (Z - k)/Z).
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from ..checks import json_safe
from ..errors import GearsymError

#: mesh harmonics labelled, and shaft-order sidebands on each side of each
MESH_HARMONICS = 3
SIDEBANDS = 3
#: the revolutions of a gear a record must hold for its sidebands (the windowed fit resolves lines 1/Z apart
#: with two; one cycle of the shaft order is not enough to tell it from the mesh harmonic beside it)
MIN_REVOLUTIONS = 2


def most_sidebands(teeth: int) -> int:
    """The sidebands k = 1 ... of a gear of ``teeth`` teeth that are its own: k < Z/2."""
    return (int(teeth) - 1) // 2


def check_length(length: float, gears: Mapping[str, int], what: str, fix: str) -> None:
    """A record of ``length`` mesh periods (``what``, e.g. 'record 1 of m.csv') holds at least MIN_REVOLUTIONS
    revolutions of every gear of ``gears``; otherwise a one-line error that ends with ``fix``."""
    short = [(g, z) for g, z in gears.items() if length < MIN_REVOLUTIONS * z]
    if short:
        g, z = max(short, key=lambda gz: gz[1])
        raise GearsymError(f"{what} holds {length:.4g} mesh periods, less than the {MIN_REVOLUTIONS} revolutions of "
                           f"{g} ({z} teeth: {MIN_REVOLUTIONS * z} mesh periods) its sidebands need; {fix}")


@dataclass(frozen=True)
class OrderLine:
    """One labelled line: the mesh harmonic ``mesh`` (0 for a shaft order alone) plus ``shaft`` orders of ``gear``
    (negative: a lower sideband), at ``order`` mesh orders, and its amplitude."""

    label: str
    order: float
    mesh: int
    gear: str | None
    shaft: int
    amplitude: float = 0.0

    def as_dict(self) -> dict:
        return {"label": self.label, "order": self.order, "mesh_harmonic": self.mesh, "gear": self.gear,
                "shaft_order": self.shaft, "amplitude": self.amplitude}


@dataclass(frozen=True)
class OrderSpectrum:
    """An order spectrum of one channel: ``orders`` and ``amplitude`` (the FFT; empty when the samples are not
    evenly spaced), the labelled ``lines``, the gears (name -> teeth) and the signal's length in mesh periods."""

    channel: str
    orders: np.ndarray
    amplitude: np.ndarray
    lines: tuple[OrderLine, ...]
    gears: Mapping[str, int]
    length: float
    noise: float = 0.0  # the amplitude one line of white noise of the residual's size would reach
    title: str = ""
    info: dict = field(default_factory=dict)
    unit: str = ""  # the amplitudes' unit ("" in the model's own; µm, rad for a model with physical values)
    #: the other meshes of the train: name -> (its frequency in orders of this mesh, its gears' names and teeth)
    meshes: Mapping[str, tuple[float, Mapping[str, int]]] = field(default_factory=dict)

    def line(self, label: str) -> OrderLine:
        for ln in self.lines:
            if ln.label == label:
                return ln
        raise GearsymError(f"no line {label!r} in the order spectrum ({', '.join(ln.label for ln in self.lines)})")

    def sideband_energy(self, gear: str) -> float:
        """The root sum of squares of the gear's sidebands and shaft orders: how much of the signal is modulated
        at that gear's revolution."""
        return float(np.sqrt(sum(ln.amplitude**2 for ln in self.lines if ln.gear == gear)))

    def as_dict(self) -> dict:
        return json_safe({"channel": self.channel, "gears": dict(self.gears), "length_mesh_periods": self.length,
                          "unit": self.unit, "other_meshes": {k: {"order": o, "gears": dict(g)}
                                                              for k, (o, g) in self.meshes.items()},
                          "noise": self.noise, "title": self.title,
                          "lines": [ln.as_dict() for ln in self.lines],
                          "sideband_energy": {g: self.sideband_energy(g) for g in self.gears},
                          "orders": self.orders, "amplitude": self.amplitude, **self.info})


def order_lines(gears: Mapping[str, int], mesh_harmonics: int = MESH_HARMONICS,
                sidebands: int = SIDEBANDS, meshes: Mapping[str, tuple[float, Mapping[str, int]]] | None = None,
                ) -> list[OrderLine]:
    """The lines an order spectrum labels: the mesh harmonics 1 ... ``mesh_harmonics``; for each gear its shaft
    orders 1 ... ``sidebands`` and the sidebands m +- k/Z of every mesh harmonic; the same for every other mesh
    of ``meshes`` (name -> its frequency r in orders of this mesh and its gears: its harmonics m r, labelled
    '<name> x<m>', and its gears' sidebands m r +- k r/Z). Lines of two gears at the same order (a 1:1 pair, a
    gear in two meshes) are labelled once, with the first name."""
    out: list[OrderLine] = []
    for mesh, (rate, mesh_gears) in {"mesh": (1.0, gears), **(meshes or {})}.items():
        out += [OrderLine(f"{mesh} x{m}", m * rate, m, None if mesh == "mesh" else mesh, 0)
                for m in range(1, mesh_harmonics + 1)]
        for gear, teeth in mesh_gears.items():
            for k in range(1, min(sidebands, most_sidebands(teeth)) + 1):
                if k < teeth:
                    out.append(OrderLine(f"{gear} x{k}", k * rate / teeth, 0, gear, k))
                for m in range(1, mesh_harmonics + 1):
                    for sign in (-1, 1):
                        out.append(OrderLine(f"{mesh} x{m} {'+' if sign > 0 else '-'} {gear} x{k}",
                                             (m + sign * k / teeth) * rate, m, gear, sign * k))
    seen: dict[float, OrderLine] = {}
    kept = []
    for ln in out:
        key = round(ln.order, 12)
        if key in seen:
            continue
        seen[key] = ln
        kept.append(ln)
    return kept


def order_spectrum(tau: np.ndarray, signal: np.ndarray, gears: Mapping[str, int], *, mesh_order: float = 1.0,
                   channel: str = "x", mesh_harmonics: int = MESH_HARMONICS, sidebands: int = SIDEBANDS,
                   title: str = "", meshes: Mapping[str, tuple[float, Mapping[str, int]]] | None = None,
                   unit: str = "") -> OrderSpectrum:
    """The order spectrum of ``signal`` sampled at ``tau`` (the model's time) for a pair with ``gears`` (name ->
    teeth), the lines of the train's other ``meshes`` labelled too (:func:`order_lines`), amplitudes in ``unit``
    (the signal's); see the module docstring."""
    tau, x = np.asarray(tau, dtype=float).reshape(-1), np.asarray(signal, dtype=float).reshape(-1)
    if tau.size != x.size or tau.size < 8:
        raise GearsymError(f"an order spectrum needs at least 8 samples of {channel} with their times")
    if not (np.all(np.isfinite(tau)) and np.all(np.isfinite(x))):
        raise GearsymError(f"the samples of {channel} must be finite for an order spectrum")
    phase = mesh_order * tau / (2 * np.pi)  # in mesh periods
    length = float(phase[-1] - phase[0] + np.median(np.diff(phase)))
    lines = order_lines(gears, mesh_harmonics, sidebands, meshes)
    x0 = x - x.mean()
    # (gears turning less than MIN_REVOLUTIONS times in the record: their lines not resolved, NaN; a gear of
    # another mesh of relative frequency r turns once in z / r periods of this one)
    short = {g for rate, mesh_gears in [(1.0, gears), *(meshes or {}).values()] for g, z in mesh_gears.items()
             if length * rate < MIN_REVOLUTIONS * z}
    resolvable = [ln for ln in lines if ln.order * length >= 1.0 and ln.gear not in short]
    columns = [np.ones_like(phase)]
    for ln in resolvable:
        columns += [np.cos(2 * np.pi * ln.order * phase), np.sin(2 * np.pi * ln.order * phase)]
    A = np.column_stack(columns)
    weight = _hann(phase)
    Aw = A * weight[:, None]
    # the normal equations, formed without threaded BLAS (on a busy machine it made such products 10x slower)
    coef = np.linalg.lstsq(np.einsum("ri,rj->ij", Aw, Aw), np.einsum("ri,r->i", Aw, x0 * weight), rcond=None)[0]
    amplitudes = {ln.label: float(np.hypot(coef[1 + 2 * i], coef[2 + 2 * i])) for i, ln in enumerate(resolvable)}
    rest = x0 - A @ coef
    noise = float(np.std(rest) * np.sqrt(2.0 / x.size))
    kept = tuple(OrderLine(ln.label, ln.order, ln.mesh, ln.gear, ln.shaft, amplitudes.get(ln.label, float("nan")))
                 for ln in lines)
    orders, amplitude = _fft(phase, x0)
    return OrderSpectrum(channel, orders, amplitude, kept, dict(gears), length, noise, title,
                         {"unresolved": [ln.label for ln in lines if ln not in resolvable]}, unit, dict(meshes or {}))


def _hann(phase: np.ndarray) -> np.ndarray:
    """The Hann window over the record, at each sample's phase (samples with gaps: by their time, not their
    count); zero only at the record's ends, so every sample counts."""
    span = phase[-1] - phase[0]
    step = float(np.median(np.diff(phase))) if phase.size > 1 else 1.0
    u = (phase - phase[0] + step / 2) / (span + step)
    return 0.5 - 0.5 * np.cos(2 * np.pi * u)


def _fft(phase: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The Hann-windowed amplitude spectrum against mesh orders, if the samples are evenly spaced."""
    steps = np.diff(phase)
    if steps.size == 0 or np.ptp(steps) > 1e-6 * np.median(steps):
        return np.zeros(0), np.zeros(0)
    w = np.hanning(x.size)
    spectrum = np.fft.rfft(x * w)
    amplitude = 2 * np.abs(spectrum) / w.sum()
    orders = np.fft.rfftfreq(x.size, d=float(np.median(steps)))
    return orders, amplitude


def gaps_joined(pieces: Sequence[tuple[np.ndarray, np.ndarray]]) -> tuple[np.ndarray, np.ndarray]:
    """Samples of several windows (tau, values) as one series, in time order (the lines' fit takes gaps)."""
    if not pieces:
        return np.zeros(0), np.zeros(0)
    tau = np.concatenate([np.asarray(t, float) for t, _ in pieces])
    x = np.concatenate([np.asarray(v, float) for _, v in pieces])
    order = np.argsort(tau, kind="stable")
    return tau[order], x[order]
