"""What ``gearsym reproduce`` computes: the paper's runs, and the parameter study beyond them.

Every run is declared here as data, so the figures, the claims and the report
all read from one list, and a quick variant (coarser grids, for the tests)
is the same list with other numbers.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace

from ..options import Integration

#: the paper's frequency grid: omega = 0.1 .. 2.0 in steps of 0.01, by continuation
PAPER_OMEGA = "omega=0.1:2.0:0.01"
#: the paper's regions of chaos for D = 0 (Section 3): near omega = 1.0, and [1.24, 1.62]
NEAR_ONE = (0.95, 1.05)
CHAOS_BAND = (1.24, 1.62)
#: parameters the paper does not give; their values are listed in the report and on every figure
NOT_IN_PAPER = ("k_a", "I1", "I2", "I3", "r1", "r2")
#: the paper's amplitude jumps for D = 2 (Fig. 3a), and how close a found jump must be
PAPER_JUMPS = (1.36, 1.70)
JUMP_TOLERANCE = 0.04


@dataclass(frozen=True)
class SweepJob:
    """One sweep, as ``gearsym sweep`` would run it."""

    name: str
    model: str
    params: tuple[str, ...]
    settings: dict = field(default_factory=dict)
    direction: str = "up"
    poincare: int = 0
    title: str = ""


@dataclass(frozen=True)
class AttractorJob:
    """Poincare maps from random initial states (the paper's Fig. 4)."""

    model: str
    omega: float
    ics: int = 10
    seed: int = 0


@dataclass(frozen=True)
class BasinJob:
    """A basin map over the box Fig. 4's random starts are drawn from ([-5, 5] in x and v): Fig. 4 seen as
    basins, every start of a grid instead of ten."""

    model: str
    omega: float
    points: int = 51  # starts per state


@dataclass(frozen=True)
class FractionJob:
    """Basin fractions along omega across the paper's jumps of Fig. 3 (D = 2), on a grid over the same box."""

    model: str
    omegas: str  # an --param range of omega
    points: int = 17


@dataclass(frozen=True)
class OrbitJob:
    """Periodic orbits continued over omega from ``start`` to ``stop`` for the model and values of the sweep
    ``sweep``, Newton starting from its final state at ``start`` (Fig. 3a's branches, and what the jumps are)."""

    sweep: str
    start: float = 0.1
    stop: float = 2.0
    switch_depth: int = 1


@dataclass(frozen=True)
class PortraitJob:
    """A phase portrait with its Poincare points from the paper's initial state (Fig. 7)."""

    letter: str
    settings: dict
    x: str
    y: str


@dataclass(frozen=True)
class Scenario:
    """Values for what the paper leaves open, applied to every run of a plan."""

    name: str
    label: str
    one_stage: dict  # for one_stage and one_stage_resonant
    flexible_shaft: dict

    def settings(self, model: str) -> dict:
        return dict(self.flexible_shaft if model == "flexible_shaft" else self.one_stage)


#: The values under which the paper's claims hold best (found with the parameter study, see
#: docs/reproduction.md): a weak mesh stiffness variation, and inertias twice the unit.
CALIBRATED = Scenario("calibrated", "calibrated to the paper", {"k_a": 0.05},
                      {"k_a": 0.05, "I1": 2.0, "I2": 2.0, "I3": 2.0})
#: The models' own declared defaults (k_a = 0.2, unit inertias): a typical spur-gear variation.
MODEL_DEFAULTS = Scenario("defaults", "the models' defaults", {}, {})
SCENARIOS = (CALIBRATED, MODEL_DEFAULTS)


@dataclass(frozen=True)
class Plan:
    scenario: Scenario
    sweeps: tuple[SweepJob, ...]
    attractors: tuple[AttractorJob, ...]
    portraits: tuple[PortraitJob, ...]
    portrait_model: str = "flexible_shaft"
    portrait_omega: float = 1.5
    portrait_window: int = 100  # the last periods of each portrait's run drawn, with their Poincare points
    periods: int = 400
    discard: int = 100
    attractor_periods: int = 200
    attractor_discard: int = 300
    orbits: tuple[OrbitJob, ...] = ()
    basins: tuple[BasinJob, ...] = ()
    fractions: tuple[FractionJob, ...] = ()

    def sweep(self, name: str) -> SweepJob:
        return next(s for s in self.sweeps if s.name == name)


def paper_plan(quick: bool = False, scenario: Scenario = CALIBRATED, study: bool = True) -> Plan:
    """The full plan (the paper's grids) under ``scenario``; ``quick``: the same runs on coarse grids,
    in seconds; ``study``: include the parameter study."""
    omega = "omega=0.1:2.0:0.05" if quick else PAPER_OMEGA
    study_omega = "omega=0.1:2.0:0.1" if quick else "omega=0.1:2.0:0.02"
    sweeps = (
        SweepJob("fig3_D0", "one_stage", (omega,), direction="both", poincare=30,
                 title="Eq. 2 (D = 0): curve '1'"),
        SweepJob("fig3_D2", "one_stage_resonant", (omega,), direction="both", poincare=30,
                 title="Eq. 6 (D = 2): curve '2'"),
        SweepJob("fig6", "flexible_shaft", (omega, "kS=0,0.1,1.0"), poincare=30,
                 title="Eq. 9: curves '1', '2', '3' for kS = 0, 0.1, 1.0"),
    )
    studies = (
        SweepJob("study_kS", "flexible_shaft", (study_omega, "kS=0:1.0:0.25" if quick else "kS=0:1.0:0.05"),
                 title="the shaft stiffness kS"),
        SweepJob("study_ka", "one_stage", (study_omega, "k_a=0:0.5:0.25" if quick else "k_a=0:0.4:0.025"),
                 title="the mesh stiffness variation k_a (D = 0)"),
        SweepJob("study_inertia", "flexible_shaft",
                 (study_omega, "I2=0.5,2,8" if quick else "I2=0.5,1,2,4,8"), settings={"kS": 0.1},
                 title="the inertia I2 of gear 2 (sets beta_1 = 1/I2, beta_2, beta_3), kS = 0.1"),
        SweepJob("study_inertia_kS0", "flexible_shaft",  # the baseline of "kS = 0.1 keeps the chaos of kS = 0"
                 (study_omega, "I2=0.5,2,8" if quick else "I2=0.5,1,2,4,8"), settings={"kS": 0.0},
                 title="the same at kS = 0"),
    )
    sweeps = tuple(replace(job, settings={**_unswept(scenario.settings(job.model), job.params), **job.settings})
                   for job in sweeps + (studies if study else ()))
    attractors = tuple(AttractorJob(m, w, ics=4 if quick else 10)
                       for w in (1.5, 1.6) for m in ("one_stage", "one_stage_resonant"))
    portraits = (
        PortraitJob("a", {"kS": 0.0}, "x1", "v1"),
        PortraitJob("b", {"kS": 1.0}, "x1", "v1"),
        PortraitJob("c", {"kS": 0.1}, "x1", "v1"),
        PortraitJob("d", {"kS": 0.1}, "x2", "v2"),
    )
    # quick: from omega = 2 down to 1 (the orbit at the start must be periodic: at 1.0 it may be chaotic)
    orbits = tuple(OrbitJob(name, *((2.0, 1.0) if quick else (0.1, 2.0))) for name in ("fig3_D0", "fig3_D2"))
    basins = tuple(BasinJob(m, w, 9 if quick else 51) for w in (1.5, 1.6) for m in ("one_stage", "one_stage_resonant"))
    fractions = (FractionJob("one_stage_resonant", "omega=1.3:1.8:0.1" if quick else "omega=1.3:1.8:0.02",
                             7 if quick else 17),)
    if quick:
        return Plan(scenario, sweeps, attractors, portraits, periods=120, discard=40, attractor_periods=60,
                    attractor_discard=60, orbits=orbits, basins=basins, fractions=fractions)
    return Plan(scenario, sweeps, attractors, portraits, orbits=orbits, basins=basins, fractions=fractions)


def _unswept(settings: dict, params: tuple[str, ...]) -> dict:
    swept = {p.partition("=")[0].strip() for p in params}
    return {k: v for k, v in settings.items() if k not in swept}

#: the orbits' scheme: crossings located (their Jacobian, the monodromy matrix, is exact only so: plain RK4 is
#: first order in it across the backlash's kink), where the sweeps keep the paper's plain scheme, like for like
ORBITS = Integration()
