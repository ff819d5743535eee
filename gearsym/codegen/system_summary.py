"""The part of a first-order system a run reads, without SymPy: what the start-up cache keeps of a reduced model
(:mod:`gearsym.cached`) and a compiled model of it runs on (:class:`SystemSummary`); its symbolic part comes from
the full system, loaded (and reduced) only if something asks for it."""
from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import field

from ..records import record_class
from ..parameters import Constraint, ParameterChecks


@record_class(eq=False)
class SystemSummary(ParameterChecks):
    """The part of a :class:`~gearsym.system.FirstOrderSystem` a run reads, without SymPy; its symbolic part
    (equations, couplings, the period as an expression) comes from the full system (:attr:`full`), loaded on
    first use."""

    name: str
    title: str
    time_name: str
    state_names: tuple[str, ...]
    parameters: Mapping[str, float]
    initial: Mapping[str, float]
    coordinates: tuple[str, ...]
    descriptions: Mapping[str, str]
    constraints: Mapping[str, Constraint]
    autonomous: bool
    physical: bool  # the model has physical values (its results are also given in its units)
    load: Callable[[], object] = field(repr=False, default=None)  # the full system
    cycles: int = 1  # forcing periods in one period (a gear's revolution with shaft-order terms)
    fastest: float = 0.0  # the fastest linearised mode's rate and the forcing period at these values: the step's
    cycle: float = 0.0  # choice (codegen/step_choice.py) without the model
    #: the full system's contact_watches when each is numbers and parameters' names (what an orbit's contact is
    #: read from, without the reduction); None: from the full system
    watches: tuple[tuple[str, str, float | str, float | str], ...] | None = None

    @property
    def dimension(self) -> int:
        return len(self.state_names)

    @property
    def observed(self) -> tuple[str, ...]:
        return self.coordinates or self.state_names

    @property
    def initial_vector(self) -> tuple[float, ...]:
        return tuple(float(self.initial.get(s, 0.0)) for s in self.state_names)

    @property
    def full(self):
        """The full system (the model loaded and reduced: seconds, once)."""
        if "_full" not in self.__dict__:
            object.__setattr__(self, "_full", self.load())
        return self.__dict__["_full"]

    @property
    def time(self):
        """The time symbol (from the full system)."""
        return self.full.time

    @property
    def states(self):
        return self.full.states

    @property
    def rhs(self):
        return self.full.rhs

    @property
    def period(self):
        """The period as an expression (from the full system)."""
        return self.full.period

    @property
    def contact_watches(self) -> tuple:
        """The meshes an orbit's contact regime is read on (see the full system's ``contact_watches``)."""
        return self.full.contact_watches if self.watches is None else self.watches

    @property
    def couplings(self):
        """The meshes and shafts the reduction handed on (from the full system)."""
        return self.full.couplings

    def as_dict(self) -> dict:
        return {"name": self.name, "title": self.title, "time_name": self.time_name,
                "state_names": list(self.state_names), "parameters": dict(self.parameters),
                "initial": dict(self.initial), "coordinates": list(self.coordinates),
                "descriptions": dict(self.descriptions),
                "constraints": {k: c.as_list() for k, c in self.constraints.items()},
                "autonomous": self.autonomous, "physical": self.physical, "cycles": self.cycles,
                "fastest": self.fastest, "cycle": self.cycle,
                "watches": None if self.watches is None else [list(w) for w in self.watches]}

    @classmethod
    def from_dict(cls, d: dict, load: Callable[[], object]) -> "SystemSummary":
        return cls(str(d["name"]), str(d["title"]), str(d["time_name"]), tuple(map(str, d["state_names"])),
                   {str(k): float(v) for k, v in d["parameters"].items()},
                   {str(k): float(v) for k, v in d["initial"].items()}, tuple(map(str, d["coordinates"])),
                   {str(k): str(v) for k, v in d["descriptions"].items()},
                   {str(k): Constraint.from_list(c) for k, c in d["constraints"].items()},
                   bool(d["autonomous"]), bool(d["physical"]), load, int(d["cycles"]), float(d["fastest"]),
                   float(d["cycle"]), _watches(d["watches"]))

    @classmethod
    def of(cls, system, physical: bool, fastest: float = 0.0) -> "SystemSummary":
        """The summary of ``system`` (``fastest``: its fastest linearised mode's rate, for the step's choice)."""
        return cls(system.name, system.title, system.time.name, system.state_names, dict(system.parameters),
                   dict(system.initial), tuple(system.coordinates), dict(system.descriptions),
                   dict(system.constraints), system.autonomous, physical, lambda: system, system.cycles,
                   fastest, system.cycle_at(),
                   system.watches if isinstance(system, SystemSummary) else _plain_watches(system.contact_watches))


def _plain_watches(watches) -> tuple | None:
    """``watches`` if each backlash and offset is a number or a parameter's name (what a summary can hold), else
    None."""
    plain = all(isinstance(v, (float, str)) for w in watches for v in w[2:])
    return tuple(tuple(w) for w in watches) if plain else None


def _watches(stored) -> tuple | None:
    if stored is None:
        return None
    return tuple((str(n), str(c), *(v if isinstance(v, str) else float(v) for v in (b, o))) for n, c, b, o in stored)


def read_summary(system: Mapping | None, full: Callable[[], object]) -> SystemSummary | None:
    """The :class:`SystemSummary` of a system's summary as read from the cache (``full``: the full system, loaded
    only if a caller asks for its symbolic part), or None: no summary, or none that reads as one."""
    try:
        return SystemSummary.from_dict(system, full)
    except (KeyError, TypeError, ValueError, AttributeError):
        return None
