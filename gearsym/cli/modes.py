"""``gearsym modes MODEL``: natural frequencies and mode shapes of the linear, time-averaged drivetrain."""
from __future__ import annotations

import argparse
import json

from ..loading import natural_modes
from .arguments.settings import add_set_argument, model_settings

NAME = "modes"
HELP = "natural frequencies and mode shapes (mean mesh stiffness, no backlash); in Hz with physical values"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("model", help="a model name (see `gearsym list`) or the path of a model file")
    add_set_argument(parser)
    parser.add_argument("--format", choices=("text", "json"), default="text")


def run(args: argparse.Namespace) -> int:
    result = natural_modes(args.model, **model_settings(args))
    if args.format == "json":
        print(json.dumps(result.as_dict(), indent=2))
        return 0
    unit = "Hz" if result.unit == "Hz" else "rad per time unit 1/omega_n"
    print(f"{result.model}: {len(result.modes)} modes, frequencies in {unit} (mean mesh stiffness, backlash closed)")
    if result.assumed:
        print(f"not given, taken as 1: {', '.join(result.assumed)}")
    bodies = list(result.modes[0].angles)
    coordinates = list(result.modes[0].coordinates)
    kinds = [m.kind + (f" x{m.multiplicity}" if m.multiplicity > 1 else "") for m in result.modes]
    kind_width = max(len("kind"), *map(len, kinds))
    print(table_row(f"{'frequency':>14}  {'kind':<{kind_width}}", bodies, coordinates))
    for m, kind in zip(result.modes, kinds):
        print(table_row(f"{m.frequency:>14.6g}  {kind:<{kind_width}}", [shown(m.angles[b]) for b in bodies],
                        [shown(m.coordinates[c]) for c in coordinates]))
    print(f"shapes: body angles (largest 1) | relative coordinates x = T psi; components below {TINY:g} printed as 0")
    return 0


#: a mode-shape component below this is rounding (the shapes are scaled to a largest angle of 1): printed as 0
TINY = 1e-12


def table_row(first: str, angles, coordinates) -> str:
    """One line of the table: at least one space before every cell, however wide its number."""
    return first + "".join(f" {a:>10}" for a in angles) + "  |" + "".join(f" {c:>10}" for c in coordinates)


def shown(value: float) -> str:
    """A mode-shape component as the table prints it: 4 significant digits, rounding noise as 0."""
    return "0" if abs(value) < TINY else f"{value:.4g}"
