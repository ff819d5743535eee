"""``gearsym modes MODEL``: natural frequencies and mode shapes of the linear, time-averaged drivetrain."""
from __future__ import annotations

import argparse
import json

from ..loading import natural_modes
from .settings import add_set_argument, model_settings

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
    print(f"{'frequency':>14}  {'kind':<8}" + "".join(f"{b:>10}" for b in bodies) + "  |"
          + "".join(f"{c:>10}" for c in coordinates))
    for m in result.modes:
        kind = m.kind + (f" x{m.multiplicity}" if m.multiplicity > 1 else "")
        print(f"{m.frequency:>14.6g}  {kind:<8}" + "".join(f"{m.angles[b]:>10.4g}" for b in bodies) + "  |"
              + "".join(f"{m.coordinates[c]:>10.4g}" for c in coordinates))
    print("shapes: body angles (largest 1) | relative coordinates x = T psi")
    return 0
