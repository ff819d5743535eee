"""The Campbell diagram: natural frequencies against speed, with the excitation orders as lines through the
origin and their crossings, the speeds at which an order excites a mode."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..scales.map import Scaling
from ..units import from_si, to_si


@dataclass(frozen=True)
class Order:
    """An excitation whose frequency is ``per_speed`` times the operating speed (both in rad/s, or both in rev/s:
    cycles per revolution of the body whose speed is the operating speed, a rotating machine's "order")."""

    label: str
    kind: str  # "mesh" | "torque"
    per_speed: float

    def frequency(self, speed_rad_s) -> np.ndarray:
        """In Hz."""
        return self.per_speed * np.asarray(speed_rad_s, dtype=float) / (2 * math.pi)


@dataclass(frozen=True)
class Crossing:
    order: str
    natural_frequency: float  # Hz
    speed: float  # in the diagram's speed unit


@dataclass(frozen=True)
class Campbell:
    model: str
    speed_unit: str
    speeds: np.ndarray  # the axis, in speed_unit
    natural_frequencies: tuple[float, ...]  # Hz, elastic modes (a repeated one once)
    orders: tuple[Order, ...]
    crossings: tuple[Crossing, ...]
    speed_body: str = ""  # the body whose speed the axis is (an order counts cycles per its revolution)

    def speeds_rad_s(self, speeds=None) -> np.ndarray:
        values = self.speeds if speeds is None else speeds
        return to_si(np.asarray(values, dtype=float), self.speed_unit)

    def as_dict(self) -> dict:
        return {"model": self.model, "speed_unit": self.speed_unit,
                "natural_frequencies_Hz": list(self.natural_frequencies),
                "orders": [{"label": o.label, "kind": o.kind, "cycles_per_revolution": _rounded(o.per_speed)}
                           for o in self.orders],
                "crossings": [{"order": c.order, "natural_frequency_Hz": c.natural_frequency,
                               f"speed_{self.speed_unit}": c.speed} for c in self.crossings],
                "speed": f"the speed of {self.speed_body!r}" if self.speed_body else None}


def campbell(scaling: Scaling, speeds, speed_unit: str, modes, mesh_orders: int = 3) -> Campbell:
    """The diagram over ``speeds`` (numbers in ``speed_unit``): the elastic frequencies of ``modes`` (in Hz),
    the first ``mesh_orders`` harmonics of every mesh's frequency and the torque harmonics' orders."""
    orders = []
    single = len(scaling.model.functions) == 1
    for f in scaling.model.functions:
        rc = scaling.model._mesh(f)
        base = scaling.mesh_frequency_ratio(rc)
        name = "mesh" if single else f"mesh {rc.name}"
        orders += [Order(f"{k}x {name}", "mesh", k * base) for k in range(1, mesh_orders + 1)]
    harmonics = sorted({ft.order for ft in scaling.model.reduction.resolved.forcing if ft.order})
    orders += [Order(f"torque {h}x", "torque", h * scaling.forcing_ratio) for h in harmonics]
    naturals = tuple(sorted({round(m.frequency, 9) for m in modes.elastic}))
    low, high = to_si(float(np.min(speeds)), speed_unit), to_si(float(np.max(speeds)), speed_unit)
    crossings = []
    for order in orders:
        for fn in naturals:
            at = 2 * math.pi * fn / order.per_speed  # rad/s
            if low <= at <= high:
                crossings.append(Crossing(order.label, fn, float(from_si(at, speed_unit))))
    crossings.sort(key=lambda c: c.speed)
    return Campbell(scaling.name, speed_unit, np.asarray(speeds, dtype=float), naturals, tuple(orders),
                    tuple(crossings), scaling.speed.body if scaling.speed else "")


def _rounded(x: float) -> float:
    """A ratio of tooth counts as the number it is (28.0, not 27.999999999999996)."""
    return float(f"{x:.12g}")
