"""``gearsym lyap MODEL``: the Lyapunov spectrum, amplitudes and final state at one point."""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from ..analysis.lyapunov import lyapunov_spectrum
from ..analysis.poincare import phase_trajectory
from ..analysis.divergence import stiffness_notes
from ..analysis.regime import describe_regime, zero_band
from ..checks import chosen_coordinate
from ..errors import GearsymError
from ..files.atomic import write_atomically
from ..figures import plot_point
from ..files.outputs import check_figure
from ..opening import open_model
from ..physical.point import loads_trajectory
from ..physical.text import parameters_line
from .arguments.integration import add_integration_arguments, integration_from, model_request, step_line
from .arguments.settings import add_set_argument, parse_state

NAME = "lyap"
HELP = "Lyapunov spectrum (all exponents, per unit time) at one parameter point"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("model", help="a model name (see `gearsym list`) or the path of a model file")
    add_set_argument(parser)
    add_integration_arguments(parser)
    parser.add_argument("--y0", metavar="x=-2,v=-0.5", help="initial state (default: the model's)")
    parser.add_argument("--format", choices=("text", "json"), default="text")
    parser.add_argument("--plot", type=Path, metavar="FILE.png",
                        help="also draw the exponents' convergence and the phase portrait with the Poincare points")
    parser.add_argument("--coordinate", metavar="NAME",
                        help="the coordinate of the phase portrait (against the state after it; default the first)")


def run(args: argparse.Namespace) -> int:
    if args.plot:
        check_figure(args.plot)
    y0 = parse_state(args.y0)  # (before the model is compiled)
    request = model_request(args, integration_from(args))
    model = open_model(request)
    scaling = model.scaling
    compiled = model.compiled()
    coordinate = chosen_coordinate(args.coordinate, compiled.observed, args.plot)
    result = lyapunov_spectrum(compiled, y0=y0)
    if result.divergence is not None:
        raise GearsymError(diverged_message(compiled, result))
    units = scaling.point_units() if scaling is not None else None  # (the figure's, the JSON's and the text's)
    # (the mesh forces and shaft torques from a trajectory at the point, as in Python: physical/point.py; carried
    # back by the numbers the start-up cache keeps, so a first run shows what a cached one does, without pint)
    physical = units.point(result, loads_trajectory(compiled, result)) if units is not None else None
    if args.plot:
        shown = min(30, result.periods - result.discard)
        trajectory = phase_trajectory(compiled, options=compiled.integration.run(discard=result.periods - shown),
                                      y0=y0)
        if physical is not None:  # in the model's units: exponents per second, um, mm/s, rad
            spectrum, shown_trajectory, shown_units, title = units.figure(result, trajectory, request.settings)
            plot_point(spectrum, shown_trajectory, args.plot, x=coordinate, units=shown_units, title=title)
            caption = args.plot.with_suffix(".caption.txt")  # (the values the title leaves out)
            write_atomically(caption, f"{scaling.name}: the figure {args.plot.name}'s values\n" + units.caption())
        else:
            plot_point(result, trajectory, args.plot, x=coordinate)
        print(f"gearsym: wrote {args.plot}", file=sys.stderr)
    if args.format == "json":
        values = {"parameters": units.values} if physical else {}  # (as given, with their units)
        print(json.dumps({**result.as_dict(), **({"physical": {**physical.as_dict(), **values}} if physical else {})},
                         indent=2))
        return 0
    print(f"{result.model}: {result.periods} periods ({result.discard} discarded), "
          f"{result.steps_per_period} {compiled.integration.method_name} steps/period, "
          f"{'plain' if args.plain else 'crossings located'}, {result.backend}")
    print(step_line(compiled, scaling))
    print("parameters: " + parameters_line(result.parameters, units))
    print("Lyapunov exponents (per unit time, +- standard error):")
    paired = {j: i for i, j in result.pairs}
    known = result.resolution
    for i, (lam, err) in enumerate(zip(result.exponents, result.stderr), 1):
        if known is not None and not known.resolved[i - 1]:
            print(f"  lambda_{i}: {known.note(i - 1)}")
            continue
        same = (f"  (= lambda_{paired[i - 1] + 1}: one complex pair of Floquet multipliers, its common real part)"
                if i - 1 in paired else "")
        print(f"  lambda_{i} = {lam:+.6f} +- {err:.6f}{same}")
    print(f"  sum      = {result.sum:+.6f}")
    if result.at_rest:
        print(f"regime: equilibrium, {'stable' if max(result.exponents) < 0 else 'unstable'} (the run never left a "
              "fixed point: the exponents are the real parts of the Jacobian's eigenvalues there, "
              + ", ".join(f"{e.real:.6g}{e.imag:+.6g}i" if e.imag else f"{e.real:.6g}" for e in result.eigenvalues)
              + ")")
    else:
        print("regime: " + describe_regime(result.regime, result.exponents, result.stderr, result.measured_time,
                                           result.autonomous, result.settling))
        for line in _undecided(result):
            print(line)
    for name, a in result.amplitude.items():
        print(f"amplitude A_{name} = {a:.6g}")
    print("final state: " + ", ".join(f"{k}={v:.6g}" for k, v in result.final_state.items()))
    for line in physical.lines() if physical else ():
        print(line)
    return 0


def _undecided(result) -> list[str]:
    """What an undetermined run's Poincare points did, and how many periods would decide."""
    if result.settling is None or result.regime != "undetermined":
        return []
    band = float(zero_band(result.stderr, result.measured_time)[0])
    needed = result.periods_to_decide
    return [f"  {result.settling.describe()}",
            f"  lambda_1 = {result.exponents[0]:+.6g} lies within {band:.3g} of zero (the zero band: 3 standard errors "
            f"or 5/(measured time)) after {result.periods - result.discard} measured periods: "
            + (f"about {needed} measured periods would decide (--periods {needed + result.discard} --discard "
               f"{result.discard}, or a longer --discard to let the transient pass)" if needed else
               "no run length within reach would decide while the points move this way")]


def diverged_message(compiled, result) -> str:
    """One line: how the run diverged, and where a stiffness of the model goes negative (the likely cause)."""
    system = compiled.system
    time_name = system.time_name
    text = f"{result.model}: the motion diverged: {result.divergence.describe(result.period, time_name)}"
    try:
        notes = stiffness_notes(system, result.parameters)
    except Exception:  # noqa: BLE001 (an explanation that cannot be computed is left out, the verdict stands)
        notes = []
    if notes:
        text += "; " + "; ".join(notes)
    return text + ". A run that grows without bound has no regime (see docs/engine.md, 'Verdicts')"

