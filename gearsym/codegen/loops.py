"""The structure of the generated loops, without the code generator (SymPy, CasADi): a model whose library is
cached is loaded with it alone."""
from __future__ import annotations

from dataclasses import dataclass

from ..errors import ModelError
from ..options import METHODS, STEPS_PER_PERIOD, Integration


@dataclass(frozen=True)
class LoopOptions:
    """Structure of the generated loops (part of the model hash; values of parameters are not)."""

    steps_per_period: int = STEPS_PER_PERIOD
    chunk_periods: int = 50  # periods per compiled call
    block_steps: int = 0  # RK4 steps unrolled per SX block; 0 chooses
    locate_crossings: bool = False  # split steps at backlash switching surfaces (4th order exponents)
    method: str = "rk4"  # the step: "rk4" (explicit) or "stiff" (RODAS4, linearly implicit: rosenbrock.py)
    #: steps between two Gram-Schmidt re-orthonormalisations of the tangent vectors within a period (0: once per
    #: period, the paper's scheme and the hand-written C's). A vector that decays faster than the first by more
    #: than e^36 between two falls below the rounding of the others and its exponent is lost: over 25 steps
    #: that is a spread of 1.4 per step, beyond what RK4 resolves (h|lambda| <= 0.5) and near its stability
    #: limit; the analyses check the spread they measured (gearsym.analysis.resolution)
    reorthonormalise: int = 25  # (REORTHONORMALISE)

    @classmethod
    def of(cls, options: Integration, cycles: int = 1) -> "LoopOptions":
        """The part of an :class:`~gearsym.options.Integration` that shapes the generated code, for a system whose
        period is ``cycles`` forcing periods (a gear's revolution): the options' steps per forcing period are
        kept, so the loops take ``cycles`` times as many per period (a long period costs time, not accuracy)."""
        # (an integrator not chosen yet is RK4 at the steps asked: compile_model chooses it for a model first)
        method = options.integrator if options.integrator in METHODS else "rk4"
        paper = options.integrator == "rk4" and not options.locate_crossings
        return cls(steps_per_period=options.steps_per_period * cycles, locate_crossings=options.locate_crossings,
                   method=method, reorthonormalise=0 if paper else REORTHONORMALISE)

    def __post_init__(self):
        if self.steps_per_period < 1:
            raise ModelError(f"steps per period must be at least 1, not {self.steps_per_period}")
        if self.method not in METHODS:
            raise ModelError(f"unknown method {self.method!r}; the loops step with one of {', '.join(METHODS)}")
        if self.chunk_periods < 1:
            raise ModelError(f"periods per chunk must be at least 1, not {self.chunk_periods}")

    def orthonormalised(self, dimension: int) -> tuple[int, int]:
        """(blocks between two Gram-Schmidt steps, and in the period's last piece): (0, 0) once per period."""
        every = self.reorthonormalise // self.block(dimension)
        blocks = self.steps_per_period // self.block(dimension)
        if not every or every >= blocks:
            return 0, 0
        return every, blocks % every

    def by_column(self, dimension: int) -> bool:
        """Whether the functions that carry the whole tangent matrix (the located step's substep, Gram-Schmidt)
        are made of pieces by column (:mod:`.columns`): from :data:`BY_COLUMN_FROM` states on."""
        return dimension >= BY_COLUMN_FROM

    def block(self, dimension: int) -> int:
        """RK4 steps per SX function call.

        One, measured: the call costs little next to a tangent step, and longer
        straight-line blocks run slower (register pressure) and compile slower.
        """
        if self.locate_crossings or self.method != "rk4":  # the crossing test and its branch are per step; the
            return 1  # stiff step is long already
        target = self.block_steps or 1
        return max(d for d in range(1, target + 1) if self.steps_per_period % d == 0)


#: states from which the tangent matrix's functions are made of pieces by column (:mod:`.columns`): their C grows
#: with n^2 then, not n^3 (Lin & Parker's planetary set, 34 states: 4.8 MB of C unrolled); below it (every shipped
#: model up to planetary_two_stage's 12 states) the unrolled functions, whose C the tests compare byte for byte
BY_COLUMN_FROM = 16

#: steps between the Gram-Schmidt re-orthonormalisations within a period (LoopOptions.reorthonormalise), but for
#: the paper's plain scheme
REORTHONORMALISE = 25

#: a period is shot in up to this many pieces (multiple shooting of strongly unstable orbits)
SHOOTING_SEGMENTS = 4


def shooting_segments(N: int, K: int, cycles: int = 1) -> int:
    """The pieces of a period in ``monodromy_period``: ``SHOOTING_SEGMENTS``, or the largest number below
    that the period's N // K blocks divide into; a period of ``cycles`` forcing periods (a gear's revolution)
    is cut that way in each forcing period, so that multiple shooting has a piece in every mesh period."""
    blocks = N // K // cycles
    return cycles * max(d for d in range(1, SHOOTING_SEGMENTS + 1) if blocks % d == 0)
