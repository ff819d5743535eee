"""What a sweep visits: axes of parameter values, and the order of the points.

``omega=0.1:2.0:0.01`` is a range (stop included), ``kS=0,0.1,1.0`` a list,
``D=2`` a single value. Values may carry a unit (``speed=500rpm:6000rpm:25rpm``,
``cZ=200,500 N*s/m``): the axis keeps it, in the unit of its first value, for a model with
physical values to turn into the engine's nondimensional values (:mod:`gearsym.physical.sweeps`). Ranges are counted in decimal arithmetic, so
0.1:2.0:0.01 gives exactly 0.1, 0.11, ... 2.0 as written (not 0.30000000000000004),
and the same command always visits the same floats.

The first axis is the one a continuation follows; every combination of the
other axes is a separate continuation line, started afresh from the initial
state. ``up`` follows the first axis in ascending order, ``down`` descending,
``both`` up and then back down from where the up run ended (the down run
shows hysteresis).
"""
from __future__ import annotations

import itertools
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, fields
from decimal import Decimal, InvalidOperation

from ..errors import GearsymError
from ..units import QUANTITY, check_quantity, parse_quantity

MODES = ("continuation", "independent")
DIRECTIONS = ("up", "down", "both")
INDEPENDENT = "independent"  # the direction column of independent points
#: the most points of one sweep (an axis, or all axes together): a million runs is days of work, more is a step mistyped
MAX_POINTS = 1_000_000


@dataclass(frozen=True)
class Axis:
    """One swept parameter and its values (distinct; ascending for ranges and lists alike)."""

    name: str
    values: tuple[float, ...]
    spec: str  # as written, for the record
    unit: str = ""  # a physical unit of the values ("rpm"), or "" for the model's own numbers
    option: str = "--param"  # the option it was given with, for the messages (basins' --grid)

    def __post_init__(self):
        if not self.values:
            raise GearsymError(f"{self.option} {self.spec!r}: no values")
        if len(set(self.values)) != len(self.values):
            raise GearsymError(f"{self.option} {self.spec!r}: values repeat")


def axis_fields(axis: Axis) -> dict:
    """``axis``'s fields as an :class:`Axis` has them (a subclass's own left out): what makes it again as given."""
    return {f.name: getattr(axis, f.name) for f in fields(Axis)}


def parse_axis(text: str, option: str = "--param") -> Axis:
    """``NAME=START:STOP:STEP``, ``NAME=V1,V2,...`` or ``NAME=VALUE``; ``option``: how the caller gave it (for
    the messages)."""
    example = "x=-5:5:0.1" if option == "--grid" else "omega=0.1:2.0:0.01"
    usage = (f"{option} {text!r}: expected NAME=START:STOP:STEP (e.g. {example}), "
             f"NAME=V1,V2,... (e.g. {'x=-1,0,1' if option == '--grid' else 'kS=0,0.1,1.0'}) or NAME=VALUE")
    name, sep, body = (part.strip() for part in text.partition("="))
    if not sep or not name or not body:
        raise GearsymError(usage)
    ranged = ":" in body
    texts, unit = _numbers_and_unit(text, body.split(":" if ranged else ","), option)
    try:
        if ranged:
            parts = [Decimal(p) for p in texts]
            if len(parts) != 3:
                raise GearsymError(usage)
            values = _range(text, *parts, option=option)
        else:
            values = [Decimal(p) for p in texts]
    except InvalidOperation:
        raise GearsymError(usage) from None
    if not all(v.is_finite() for v in values):
        raise GearsymError(f"{option} {text!r}: values must be finite numbers")
    return Axis(name, tuple(sorted(float(v) for v in values)), text, unit, option)


def _numbers_and_unit(text: str, parts: list[str], option: str = "--param") -> tuple[list[str], str]:
    """The numbers of ``parts`` as written, in the unit of the first part that has one (converted by pint if
    another part has another unit), and that unit ("" if none has one). The units are checked by the safe
    quantity parser."""
    units = [(m["unit"] or "").strip() if (m := QUANTITY.fullmatch(p)) else "" for p in parts]
    if not any(units):
        return [p.strip() for p in parts], ""
    unit = next(u for u in units if u)
    numbers = []
    for part, own in zip(parts, units):
        quantity, where = part if own else f"{part} {unit}", f"{option} {text!r}"
        if own in ("", unit):  # (already in the unit: only checked, without pint when the unit's meaning is kept)
            check_quantity(quantity, where)
            number = QUANTITY.fullmatch(part)["number"]
            numbers.append(number if own else repr(float(number)))  # (what pint's conversion to the unit gave)
            continue
        q = parse_quantity(quantity, where)
        try:
            numbers.append(repr(q.to(unit).magnitude))
        except Exception:
            raise GearsymError(f"{option} {text!r}: {part.strip()} cannot be converted to {unit}") from None
    return numbers, unit


def _range(text: str, start: Decimal, stop: Decimal, step: Decimal, option: str = "--param") -> list[Decimal]:
    if not (start.is_finite() and stop.is_finite() and step.is_finite()):
        raise GearsymError(f"{option} {text!r}: start, stop and step must be finite")
    if step == 0 or (stop - start) * step < 0:
        raise GearsymError(f"{option} {text!r}: the step must be nonzero and lead from start to stop")
    count = int((stop - start) / step) + 1  # stop included when the steps land on it
    if count > MAX_POINTS:
        raise GearsymError(f"{option} {text!r}: {count} values, more than the {MAX_POINTS} one {option} may have; "
                           "give a larger step")
    return [start + i * step for i in range(count)]


def check_points(axes: Sequence[Axis], runs: int = 1) -> None:
    """Refuse a grid of ``axes`` (each point run ``runs`` times: up and down) of more than MAX_POINTS, saying its
    size and the limit, before any point list is made."""
    count = runs
    for a in axes:
        count *= len(a.values)
    if count > MAX_POINTS:
        sizes = " x ".join(str(len(a.values)) for a in axes) + (f" x {runs} directions" if runs > 1 else "")
        raise GearsymError(f"the sweep has {count} points ({sizes}), more than the {MAX_POINTS} one sweep may have; "
                           "give larger steps or fewer values")


def axes_from(spec: Mapping[str, Sequence[float]] | Sequence[Axis | str]) -> tuple[Axis, ...]:
    """Axes from a mapping {name: values}, from Axis objects or from --param strings."""
    if isinstance(spec, Mapping):
        axes = tuple(Axis(n, tuple(sorted(_number(n, v) for v in vals)), f"{n}={','.join(map(repr, vals))}")
                     for n, vals in spec.items())
    else:
        axes = tuple(a if isinstance(a, Axis) else parse_axis(a) for a in spec)
    if not axes:
        raise GearsymError("a sweep needs at least one --param NAME=VALUES")
    names = [a.name for a in axes]
    if len(set(names)) != len(names):
        raise GearsymError(f"a parameter is swept twice: {', '.join(names)}")
    check_points(axes)
    return axes


def _number(name: str, value) -> float:
    """A value of a swept parameter given in Python: a number (a value with a unit is a model's scaling's)."""
    try:
        return float(value)
    except (TypeError, ValueError):
        pass
    hint = (f"; a value with a unit is swept on the model's scaling, gearsym.run_sweep(gearsym.scaling(MODEL), "
            f"{{{name!r}: [{value!r}, ...]}}), which gives the engine its numbers and the result in these units"
            if isinstance(value, str) or type(value).__module__.startswith("pint") else "")
    raise GearsymError(f"run_sweep: {name}={value!r} is not a number{hint}")


@dataclass(frozen=True)
class Point:
    """One point of the plan: the run direction and the values of the swept parameters (axis order)."""

    direction: str
    values: tuple[float, ...]

    @property
    def key(self) -> tuple:
        return (self.direction, self.values)


def plan(axes: Sequence[Axis], mode: str, direction: str) -> list[list[Point]]:
    """The tasks of a sweep, each a list of points run in order (state handed on in a continuation).

    Independent mode: one task per point. Continuation: one task per line (a
    combination of the other axes), up and/or down along the first axis.
    """
    if mode not in MODES:
        raise GearsymError(f"unknown mode {mode!r}; choose {' or '.join(MODES)}")
    if direction not in DIRECTIONS:
        raise GearsymError(f"unknown direction {direction!r}; choose one of {', '.join(DIRECTIONS)}")
    check_points(axes, 2 if mode != INDEPENDENT and direction == "both" else 1)
    first, others = axes[0], [a.values for a in axes[1:]]
    tasks = []
    for rest in itertools.product(*others):
        if mode == INDEPENDENT:
            tasks.extend([Point(INDEPENDENT, (v, *rest))] for v in first.values)
            continue
        up = [Point("up", (v, *rest)) for v in first.values]
        down = [Point("down", (v, *rest)) for v in reversed(first.values)]
        tasks.append({"up": up, "down": down, "both": up + down}[direction])
    return tasks


def points(tasks: Sequence[Sequence[Point]]) -> Iterator[Point]:
    return itertools.chain.from_iterable(tasks)
