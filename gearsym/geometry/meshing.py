"""The time-varying mesh stiffness of a pair over one mesh period, from the stiffness of its pairs of teeth.

**Phase.** The mesh phase phi runs over [0, 2 pi) in one mesh period (the time a contact takes to move one
transverse base pitch p_bt along the line of action), as the symbolic model's mesh phase does; phi = 0 is the
instant a pair of teeth comes into contact at the start of the path of contact (the tip of gear 2 on the
line of action), gear 1 driving. At phase phi the pairs in contact sit at s_j = s_A + (phi / 2 pi + j) p_bt,
j = 0, 1, ..., while s_j < s_E: ceil(eps_alpha) pairs for phi / 2 pi < eps_alpha - floor(eps_alpha), one fewer
after. Pairs in contact act in parallel, so their stiffnesses add.

**Helical pairs** are cut into ``slices`` thin spur pairs of the transverse section, each of width b / slices,
whose contact lines lag one another along the line of action by their axial offset times tan(beta_b): the
slice at axial position xi (from the face's middle) is at phase phi + 2 pi xi tan(beta_b) / p_bt. The slices add
(no elastic coupling between them along the face). The stiffness is along the transverse line of action, the
direction a torsional model's r_b theta coordinate measures.

The curve is a piecewise-smooth function of phi with jumps where a pair (of a slice) enters or leaves contact;
its mean and Fourier coefficients are not taken from samples but integrated exactly along the path of contact,
which each pair of teeth sweeps once per period (:meth:`_Curve.spectrum`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..checks import whole_number
from ..errors import GearsymError, warn
from .foundation import body_ratio
from .iso6336 import Iso6336Stiffness, iso6336_stiffness
from .pair import GearPair
from .quadrature import gauss_legendre
from .tooth_pair import QUADRATURE_POINTS, TERMS, check_terms, pair_stiffness

#: phases sampled over one mesh period (the curve returned; the mean and Fourier terms do not come from it)
PHASE_POINTS = 720
#: slices of a helical pair's face width unless told
HELICAL_SLICES = 20
#: sizes refused before any work: more than this many phases, slices, nodes
MAX_PHASE_POINTS = 1_000_000
MAX_SLICES = 2000
MAX_QUADRATURE_POINTS = 200
#: at most this many phases x slices are computed (about a minute); refused before any work beyond it
MAX_EVALUATIONS = 4_000_000
#: numbers per quadrature array when a curve is evaluated (in chunks of phases): ~32 MB each
_CHUNK_ELEMENTS = 4_000_000
#: Gauss–Legendre nodes along the path of contact for the mean (k_pair(s) is smooth there: converged to rounding),
#: and four more per Fourier order and per pair in contact for the oscillating factor
_PIECE_POINTS = 48


@dataclass(frozen=True)
class StiffnessOptions:
    """How the mesh stiffness is computed.

    * ``phase_points``: samples of the curve over one mesh period (:data:`PHASE_POINTS`);
    * ``quadrature_points``: Gauss–Legendre nodes per piece of the tooth profile (:data:`QUADRATURE_POINTS`);
    * ``slices``: slices of the face width (None: 1 for spur pairs, :data:`HELICAL_SLICES` for helical ones);
    * ``terms``: the compliances included (all of :data:`TERMS` by default; e.g. ``("hertz",)`` for the
      contact alone, or without ``"foundation"`` for a rigid gear body).
    """

    phase_points: int = PHASE_POINTS
    quadrature_points: int = QUADRATURE_POINTS
    slices: int | None = None
    terms: tuple[str, ...] = TERMS

    def __post_init__(self):
        points = whole_number(self.phase_points, "stiffness: phase points", 8)
        if points > MAX_PHASE_POINTS:
            raise GearsymError(f"stiffness: {points} phase points is more than the {MAX_PHASE_POINTS} allowed")
        nodes = whole_number(self.quadrature_points, "stiffness: quadrature points", 2)
        if nodes > MAX_QUADRATURE_POINTS:
            raise GearsymError(f"stiffness: {nodes} quadrature points is more than the {MAX_QUADRATURE_POINTS} allowed "
                               f"(the default {QUADRATURE_POINTS} is converged)")
        if self.slices is not None:
            slices = whole_number(self.slices, "stiffness: slices (--slices)", 1)
            if slices > MAX_SLICES:
                raise GearsymError(f"stiffness: {slices} slices is more than the {MAX_SLICES} allowed")
            object.__setattr__(self, "slices", slices)
        object.__setattr__(self, "phase_points", points)
        object.__setattr__(self, "quadrature_points", nodes)
        object.__setattr__(self, "terms", check_terms(self.terms))

    def check_size(self, pair: GearPair) -> None:
        """Refuse, before any work, a curve of more phases x slices than :data:`MAX_EVALUATIONS`."""
        slices = self.slices_for(pair)
        if self.phase_points * slices > MAX_EVALUATIONS:
            raise GearsymError(f"stiffness: {self.phase_points} phase points x {slices} slices is more than the "
                               f"{MAX_EVALUATIONS:.0e} evaluations allowed; lower either")

    def slices_for(self, pair: GearPair) -> int:
        if pair.gear1.helix_angle == 0.0:
            return 1
        return HELICAL_SLICES if self.slices is None else self.slices


@dataclass(frozen=True)
class Zone:
    """A phase interval [start, end) (rad) with ``pairs`` pairs of teeth in contact (in the mid-face section)."""

    start: float
    end: float
    pairs: int


@dataclass(frozen=True)
class Fourier:
    """k(phi) = mean (1 + sum_n cos[n-1] cos(n phi) + sin[n-1] sin(n phi)), n = 1 ... order."""

    mean: float
    cos: tuple[float, ...]
    sin: tuple[float, ...]

    def __call__(self, phase):
        phase = np.asarray(phase, dtype=float)
        n = np.arange(1, len(self.cos) + 1)
        arg = phase[..., None] * n
        return self.mean * (1.0 + (np.cos(arg) * self.cos).sum(-1) + (np.sin(arg) * self.sin).sum(-1))


class _Curve:
    """k(phi) of one pair: the slices' pairs of teeth in contact at any phase, summed."""

    def __init__(self, pair: GearPair, options: StiffnessOptions):
        self.pair = pair
        self.options = options
        self.slices = options.slices_for(pair)
        b, pitch = pair.face_width, pair.base_pitch
        offsets = (np.arange(self.slices) + 0.5) / self.slices * b - 0.5 * b
        # each slice's lead, in mesh periods
        self.shifts = offsets * math.tan(pair.gear1.base_helix_angle) / pitch
        self.width = b / self.slices
        self.start, self.end = pair.path_of_contact
        self.ratio = pair.contact_ratio
        self.pairs = math.ceil(self.ratio) + 1

    def __call__(self, phase) -> np.ndarray:
        phase = np.asarray(phase, dtype=float)
        flat = phase.ravel()
        # in chunks, so that the involute's quadrature arrays stay near _CHUNK_ELEMENTS numbers each
        chunk = max(1, _CHUNK_ELEMENTS // (self.slices * self.pairs * self.options.quadrature_points))
        k = np.concatenate([self._evaluate(flat[i:i + chunk]) for i in range(0, flat.size, chunk)] or [flat])
        return k.reshape(phase.shape)

    def _evaluate(self, phase: np.ndarray) -> np.ndarray:
        fraction = np.mod(phase[:, None] / (2.0 * math.pi) + self.shifts, 1.0)  # (phases, slices)
        positions = self.start + (fraction[..., None] + np.arange(self.pairs)) * self.pair.base_pitch  # (.., pairs)
        inside = positions < self.end
        k = np.zeros(positions.shape)
        k[inside] = pair_stiffness(self.pair, positions[inside], width=self.width,
                                   points=self.options.quadrature_points, terms=self.options.terms)
        return k.sum(axis=(-1, -2))

    def jumps(self) -> np.ndarray:
        """The phases in [0, 2 pi] where a pair of some slice enters or leaves contact, sorted, with 0 and 2 pi."""
        frac = self.ratio - math.floor(self.ratio)
        points = np.concatenate([np.mod(-self.shifts, 1.0), np.mod(frac - self.shifts, 1.0), [0.0, 1.0]])
        return np.unique(np.round(points * 2.0 * math.pi, 15))

    def spectrum(self, order: int) -> np.ndarray:
        """C_n = (1/2 pi) integral of k(phi) exp(-i n phi) over one period, n = 0 ... ``order`` (C_0 is the mean).

        Exact, without the jumps: a pair of teeth sweeps the whole path of contact once, so
        C_n of one slice is (1/p_bt) integral over [s_A, s_E] of k_pair(s) exp(-2 pi i n (s - s_A) / p_bt) ds, a
        smooth integrand (Gauss–Legendre); a slice shifted by delta periods multiplies it by exp(2 pi i n delta).
        """
        n = np.arange(order + 1)
        points = _PIECE_POINTS + 4 * order + 4 * math.ceil(self.ratio)
        s, w = gauss_legendre(self.start, self.end, points)
        k = pair_stiffness(self.pair, s, width=self.width, points=self.options.quadrature_points,
                           terms=self.options.terms)
        u = (s - self.start) / self.pair.base_pitch
        one_slice = (k * w * np.exp(-2j * math.pi * n[:, None] * u)).sum(-1) / self.pair.base_pitch
        return one_slice * np.exp(2j * math.pi * n[:, None] * self.shifts).sum(-1)


@dataclass(frozen=True)
class MeshStiffness:
    """The mesh stiffness of a gear pair over one mesh period (N/m; phases in rad, see the module's docstring).

    ``phase``, ``stiffness``: the sampled curve; ``mean`` (integrated exactly, not from the samples), ``min``,
    ``max``; ``contact_ratio`` (transverse) and ``overlap_ratio``; ``zones`` of single/double (...) contact in
    the mid-face section; ``iso6336``: ISO 6336-1 method B for the same pair; ``notes``: what the computation
    assumed or extrapolated (also given as warnings). ``at(phase)`` evaluates the curve anywhere,
    ``fourier(order)`` gives its Fourier series.
    """

    pair: GearPair
    options: StiffnessOptions
    slices: int
    phase: np.ndarray
    stiffness: np.ndarray
    mean: float
    min: float
    max: float
    contact_ratio: float
    overlap_ratio: float
    zones: tuple[Zone, ...]
    iso6336: Iso6336Stiffness
    notes: tuple[str, ...]
    _curve: _Curve = field(repr=False, compare=False)

    def at(self, phase) -> np.ndarray:
        """k at any phases (rad), in N/m."""
        return self._curve(phase)

    def fourier(self, order: int) -> Fourier:
        """The mean and the first ``order`` cosine and sine coefficients of k / mean (exact integrals)."""
        order = whole_number(order, "Fourier order", 1)
        if order > 400:
            raise GearsymError(f"Fourier order {order} is more than the 400 allowed")
        C = self._curve.spectrum(order)[1:]
        return Fourier(self.mean, tuple(float(c) for c in 2.0 * C.real / self.mean),
                       tuple(float(s) for s in -2.0 * C.imag / self.mean))

    def as_dict(self) -> dict:
        """JSON-ready: ``contact_ratio``, ``overlap_ratio``, ``mean``, ``min``, ``max`` (N/m), ``phase`` (rad),
        ``stiffness`` (N/m), ``zones``, ``iso6336`` (N/(mm um)), ``notes``, ``units``."""
        return {
            "contact_ratio": self.contact_ratio,
            "overlap_ratio": self.overlap_ratio,
            "mean": self.mean,
            "min": self.min,
            "max": self.max,
            "slices": self.slices,
            "phase": [float(p) for p in self.phase],
            "stiffness": [float(k) for k in self.stiffness],
            "zones": [{"start": z.start, "end": z.end, "pairs": z.pairs} for z in self.zones],
            "iso6336": self.iso6336.as_dict(),
            "notes": list(self.notes),
            "units": {"mean": "N/m", "min": "N/m", "max": "N/m", "stiffness": "N/m", "phase": "rad (one mesh period)",
                      "iso6336": "N/(mm um)"},
        }


def _zones(ratio: float) -> tuple[Zone, ...]:
    whole = math.floor(ratio)
    split = 2.0 * math.pi * (ratio - whole)
    zones = [Zone(0.0, split, whole + 1)] if split > 0.0 else []
    return tuple(zones + [Zone(split, 2.0 * math.pi, whole)])


def _notes(pair: GearPair, options: StiffnessOptions, iso: Iso6336Stiffness) -> tuple[str, ...]:
    notes = []
    if "foundation" in options.terms:
        for gear in (pair.gear1, pair.gear2) if pair.gear2 != pair.gear1 else (pair.gear1,):
            notes += body_ratio(gear)[1]
    return tuple(notes) + iso.notes


def mesh_stiffness(pair: GearPair, options: StiffnessOptions | None = None, *, line_load: float | None = None) -> MeshStiffness:
    """The mesh stiffness of ``pair`` over one mesh period (see the module's docstring), with ISO 6336-1's
    numbers beside it (``line_load``: F_t K_A / b in N/mm for ISO's light-load factor, None for >= 100)."""
    if not isinstance(pair, GearPair):
        raise GearsymError(f"mesh stiffness: expected a GearPair, got {type(pair).__name__}")
    options = StiffnessOptions() if options is None else options
    if not isinstance(options, StiffnessOptions):
        raise GearsymError(f"mesh stiffness: options must be a StiffnessOptions, got {type(options).__name__}")
    options.check_size(pair)
    curve = _Curve(pair, options)
    phase = np.linspace(0.0, 2.0 * math.pi, options.phase_points, endpoint=False)
    stiffness = curve(phase)
    # the extremes sit in the samples or at a jump's either side
    jumps = curve.jumps()
    eps = 1e-9
    edges = curve(np.concatenate([jumps[:-1] + eps, jumps[1:] - eps]))
    mean = float(curve.spectrum(0)[0].real)
    iso = iso6336_stiffness(pair, line_load=line_load)
    notes = _notes(pair, options, iso)
    for note in notes:
        warn(note)
    return MeshStiffness(pair, options, curve.slices, phase, stiffness, mean,
                         float(min(stiffness.min(), edges.min())), float(max(stiffness.max(), edges.max())),
                         pair.contact_ratio, pair.overlap_ratio, _zones(pair.contact_ratio), iso, notes, curve)
