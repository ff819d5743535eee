"""How a run integrates and how it is executed: two small options objects for every verb.

Like diffrax's ``SaveAt`` or step-size controllers, :class:`Integration` is passed to the verbs
(``lyapunov_spectrum(model, options=Integration(periods=800))``) instead of each verb restating the
same keywords with its own defaults. The default steps per period lives here and nowhere else.
:class:`Execution` says how a verb that runs many things runs them (threads or workers, the lanes, progress),
which never changes its numbers: ``run_sweep``, ``basin_map``, ``continue_basins``, ``explain`` and
``reproduce`` take it as ``execution=``.
"""
from __future__ import annotations

import sys
from collections.abc import Callable
from dataclasses import field, replace

from .records import record_class
from .errors import GearsymError, option
from .checks import MAX_STEPS_PER_PERIOD, RUN_BYTES_PER_PERIOD, TABLE_BYTES_PER_STEP, check_fits, whole_number

#: RK4 steps per forcing period (the paper's 200): the one definition of the default
STEPS_PER_PERIOD = 200
#: where the engine runs: compiled C, CasADi's interpreter, or compiled when a C compiler exists
BACKENDS = ("auto", "compiled", "in-process")
#: ways to use more than one core of this machine for a sweep's points (``Execution(parallel=...)``)
PARALLEL = ("auto", "processes", "threads")


@record_class
class Execution:
    """How a verb runs what it runs; the numbers are the same whatever this says.

    * ``jobs``: threads or worker processes (0: one per core of this machine);
    * ``parallel``: how a sweep's points use them: ``"processes"`` (this one and ``jobs - 1`` forked from it),
      ``"threads"``, or ``"auto"`` (processes where the OS can fork);
    * ``scheduler``: a sweep's points on a Dask cluster (the ``distributed`` extra): ``"local"`` (a cluster of
      ``jobs`` processes on this machine), ``"tcp://HOST:PORT"``, or a ``distributed.Client``;
    * ``lanes``: many starts per native call, L at a time in the SIMD lanes (None: the verb's default, on for
      basins, off for sweeps, whose files then stay those of the scalar loops wherever they run);
    * ``progress``: what has been done said on stderr as the run goes (a bar, a line per value), or a callable
      given each line instead; off by default (the command line turns it on; ``--quiet`` off).
    """

    jobs: int = 0
    parallel: str = "auto"
    scheduler: object = None
    lanes: bool | None = None
    progress: bool | Callable[[str], None] = False

    def __post_init__(self):
        object.__setattr__(self, "jobs", whole_number(self.jobs, "jobs"))
        if self.parallel not in PARALLEL:
            raise GearsymError(f"parallel={self.parallel!r}: choose one of {', '.join(PARALLEL)}")
        if self.lanes not in (None, True, False):
            raise GearsymError(f"lanes must be True, False or None (the verb's default), got {self.lanes!r}")
        if not (isinstance(self.progress, bool) or callable(self.progress)):
            raise GearsymError(f"progress must be True, False or a function of one line, got {self.progress!r}")

    @property
    def verbose(self) -> bool:
        """Whether the run says what it does (its progress, and the compiling it does first)."""
        return bool(self.progress)

    def with_lanes(self, default: bool) -> bool:
        """Whether to run in the lanes: as asked, else the verb's ``default``."""
        return default if self.lanes is None else self.lanes

    @property
    def say(self) -> Callable[[str], None]:
        """A line of progress: to stderr, to the caller's function, or nowhere."""
        if callable(self.progress):
            return self.progress
        if self.progress:
            return lambda line: print(f"gearsym: {line}", file=sys.stderr, flush=True)
        return lambda line: None
#: the steps the loops take: explicit RK4, or the stiff RODAS4 with the exact Jacobian (codegen/rosenbrock.py)
METHODS = ("rk4", "stiff")
#: what a run asks for: one of METHODS, or "auto": chosen from the model's fastest linearised mode
INTEGRATORS = ("auto", *METHODS)


@record_class
class Integration:
    """Fixed-step RK4 over whole forcing periods.

    * ``periods``: periods in all, the transient included; ``discard``: the transient periods
      left out of every average, amplitude and sample. A period is the system's: one forcing period, or for
      a system whose period holds several (``FirstOrderSystem.cycles``: 61 for a 23/61, 19/47 box) all of them.
    * ``steps_per_period``: RK4 steps per forcing period.
    * ``locate_crossings``: split every step that crosses a backlash switching surface at the crossing,
      so that RK4 stays 4th order across the kink of g (exponents on periodic orbits ~1e-8 accurate at 200
      steps instead of ~1e-3, for ~1.3x the time per step; see docs/engine.md). On by default;
      :meth:`paper` is the paper's plain scheme.
    * ``backend``: ``"compiled"`` (fail without a C compiler), ``"in-process"`` (CasADi's virtual
      machine) or ``"auto"`` (compiled where a C compiler exists).
    * ``integrator``: ``"rk4"`` (explicit, 4th order), ``"stiff"`` (RODAS4: linearly implicit, L-stable, 4th
      order, its W-matrix from the exact Jacobian) or ``"auto"`` (the default): chosen, with the steps, from the
      model's fastest linearised mode when the model is compiled (``step_choice.py``): RK4 with at least
      ``steps_per_period`` steps, as many as resolve that mode, or the stiff step where RK4 would need many
      times more. ``choice`` says what was chosen and why (set by the choice; not part of the comparison).

    ``steps_per_period``, ``locate_crossings`` and ``backend`` shape the compiled code; ``periods`` and
    ``discard`` only the run, so a compiled model runs with any of them.
    """

    periods: int = 400
    discard: int = 100
    steps_per_period: int = STEPS_PER_PERIOD
    locate_crossings: bool = True
    backend: str = "auto"
    integrator: str = "auto"
    choice: str = field(default="", compare=False)

    def __post_init__(self):
        periods = whole_number(self.periods, "periods", 1)
        discard = whole_number(self.discard, "discard")
        if discard >= periods:
            raise GearsymError(f"the transient (discard={discard}) must be shorter than the run (periods={periods}): "
                               "periods counts every forcing period, the discarded ones included; give "
                               f"{option('discard', 0)} or more periods")
        steps = whole_number(self.steps_per_period, "steps per period", 1)
        if steps > MAX_STEPS_PER_PERIOD:
            raise GearsymError(f"{option('steps_per_period', steps)}: at most {MAX_STEPS_PER_PERIOD} RK4 steps per "
                               "forcing period (200 for each natural period 5000 times shorter than the forcing's; "
                               "the compiled tables hold every step)")
        check_fits(steps, TABLE_BYTES_PER_STEP, asked=option("steps_per_period", steps), item="step",
                   what="the compiled tables of time, at least")
        check_fits(periods, RUN_BYTES_PER_PERIOD, asked=option("periods", periods), item="period",
                   what="each period's state, stretch and extremes, at least")
        if not isinstance(self.locate_crossings, bool):
            raise GearsymError(f"locate_crossings must be True or False, got {self.locate_crossings!r}")
        if self.integrator not in INTEGRATORS:
            raise GearsymError(f"unknown integrator {self.integrator!r}; choose one of {', '.join(INTEGRATORS)}")
        if self.backend not in BACKENDS:
            raise GearsymError(f"unknown backend {self.backend!r}; choose one of {', '.join(BACKENDS)}")
        object.__setattr__(self, "periods", periods)
        object.__setattr__(self, "discard", discard)
        object.__setattr__(self, "steps_per_period", steps)

    @classmethod
    def paper(cls, **changes) -> "Integration":
        """The paper's scheme: plain RK4 at 200 steps per period, 400 periods with 100 discarded
        (what ``gearsym reproduce`` and the comparisons with hand-written C use, like for like)."""
        return cls(**{"locate_crossings": False, "integrator": "rk4", **changes})

    @property
    def measured(self) -> int:
        """Periods after the transient: what averages, amplitudes and samples are taken over."""
        return self.periods - self.discard

    def run(self, periods: int | None = None, discard: int | None = None) -> "Integration":
        """The same scheme over another run length."""
        return replace(self, periods=self.periods if periods is None else periods,
                       discard=self.discard if discard is None else discard)

    @property
    def method_name(self) -> str:
        """The step's name in reports: RK4, RODAS4 (stiff), or 'auto' before the choice."""
        return {"rk4": "RK4", "stiff": "RODAS4 (stiff)"}.get(self.integrator, "auto")

    def describe(self) -> str:
        """One line for reports: '400 periods (100 discarded), 200 RK4 steps/period, crossings located'."""
        scheme = ("crossings located" if self.locate_crossings else
                  "plain RK4 (the paper's scheme)" if self.integrator == "rk4" else "crossings not located")
        return (f"{self.periods} periods ({self.discard} discarded), {self.steps_per_period} {self.method_name} "
                f"steps/period, {scheme}")
