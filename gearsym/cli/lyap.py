"""``gearsym lyap MODEL``: the Lyapunov spectrum, amplitudes and final state at one point."""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from ..analysis import lyapunov_spectrum, phase_trajectory
from ..analysis.regime import describe_regime
from ..checks import chosen_coordinate
from ..figures import plot_point
from ..outputs import check_figure
from .integration import add_integration_arguments, compiled_from, scaling_from
from .settings import add_set_argument, parse_state

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
    scaling = scaling_from(args)
    compiled = compiled_from(args)
    coordinate = chosen_coordinate(args.coordinate, compiled.observed, args.plot)
    result = lyapunov_spectrum(compiled, y0=parse_state(args.y0))
    # (the mesh forces and shaft torques from a trajectory at the point, as in Python: physical/point.py)
    physical = scaling.to_physical(result, model=compiled) if scaling is not None else None
    if args.plot:
        shown = min(30, result.periods - result.discard)
        trajectory = phase_trajectory(compiled, options=compiled.integration.run(discard=result.periods - shown),
                                      y0=parse_state(args.y0))
        if physical is not None:  # in the model's units: exponents per second, um, mm/s, rad
            spectrum, shown_trajectory, units, title = scaling.point_units().figure(result, trajectory)
            plot_point(spectrum, shown_trajectory, args.plot, x=coordinate, units=units, title=title)
        else:
            plot_point(result, trajectory, args.plot, x=coordinate)
        print(f"gearsym: wrote {args.plot}", file=sys.stderr)
    if args.format == "json":
        print(json.dumps({**result.as_dict(), **({"physical": physical.as_dict()} if physical else {})}, indent=2))
        return 0
    print(f"{result.model}: {result.periods} periods ({result.discard} discarded), "
          f"{result.steps_per_period} RK4 steps/period, {'plain RK4' if args.plain else 'crossings located'}, "
          f"{result.backend}")
    print("parameters: " + ", ".join(f"{k}={v:g}" for k, v in result.parameters.items()))
    print("Lyapunov exponents (per unit time, +- standard error):")
    for i, (lam, err) in enumerate(zip(result.exponents, result.stderr), 1):
        print(f"  lambda_{i} = {lam:+.6f} +- {err:.6f}")
    print(f"  sum      = {result.sum:+.6f}")
    if result.at_rest:
        print(f"regime: equilibrium, {'stable' if max(result.exponents) < 0 else 'unstable'} (the run never left a "
              "fixed point: the exponents are the real parts of the Jacobian's eigenvalues there, "
              + ", ".join(f"{e.real:.6g}{e.imag:+.6g}i" if e.imag else f"{e.real:.6g}" for e in result.eigenvalues)
              + ")")
    else:
        print("regime: " + describe_regime(result.regime, result.exponents, result.stderr, result.measured_time,
                                           result.autonomous))
    for name, a in result.amplitude.items():
        print(f"amplitude A_{name} = {a:.6g}")
    print("final state: " + ", ".join(f"{k}={v:.6g}" for k, v in result.final_state.items()))
    for line in physical.lines() if physical else ():
        print(line)
    return 0
