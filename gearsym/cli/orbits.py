"""``gearsym orbits MODEL --param omega=0.5:2.0``: periodic orbits by shooting, their Floquet multipliers, and
their branches over a parameter with the bifurcations located (the frequency-response curve)."""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from ..checks import chosen_coordinate, whole_number
from ..errors import GearsymError, UnknownParameterError
from ..figures.orbits import plot_orbits
from ..files.atomic import write_atomically
from ..files.outputs import check_figure, check_file
from ..opening import open_model
from ..options import Execution
from ..periodic import ContinuationInterrupted, continue_orbits, periodic_orbit
from ..periodic.files import write_orbits
from ..periodic.orbit import sweep_start
from ..periodic.shooting import check_segments, pieces_per_period
from ..physical.files import write_physical_rows
from ..physical.point import Measured
from ..physical.sweeps import nondimensional_axis
from ..physical.text import parameters_line
from ..sweep import read_sweep
from ..sweep.grid import _numbers_and_unit, Axis
from ..sweep.store import sidecar
from ..units import shown
from .arguments.integration import add_integration_arguments, integration_from, model_request, step_line
from .arguments.settings import add_set_argument, parse_state, refuse_swept_and_set

NAME = "orbits"
HELP = "periodic orbits, their Floquet multipliers and stability, and their branches over a parameter with folds, " \
       "period doublings, Neimark-Sacker and grazing bifurcations located"
TRANSIENT = 300
#: multipliers below this fraction of the largest are the monodromy matrix's rounding, not values
ROUNDED = 1e-12


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("model", help="a model name (see `gearsym list`) or the path of a model file")
    parser.add_argument("--param", metavar="NAME=START:STOP",
                        help="continue the orbits in NAME from START to STOP (through folds; a physical value "
                             "with its unit: speed=1000rpm:3000rpm); without it, the one orbit at the --set values")
    add_set_argument(parser)
    parser.add_argument("--period-multiple", type=int, default=1, metavar="N",
                        help="the orbit's period in forcing periods (default 1; --periods is the run length of "
                             "the other commands)")
    parser.add_argument("--segments", type=int, default=None, metavar="M",
                        help="shooting segments per period (multiple shooting for strongly unstable orbits; 1, 2 "
                             "or 4 per forcing period; default 1, or for a model whose period is a gear's "
                             "revolution one per mesh period)")
    parser.add_argument("--y0", metavar="x=-2,v=-0.5",
                        help="Newton's start at the section t = 0 (default: where --transient periods from the "
                             "model's initial state end, or the --sweep's point)")
    parser.add_argument("--transient", type=int, default=TRANSIENT, metavar="P",
                        help=f"forcing periods simulated before Newton starts (default {TRANSIENT})")
    parser.add_argument("--sweep", type=Path, metavar="S.csv",
                        help="a brute-force sweep (`gearsym sweep ... --out S.csv`) of the same model: Newton "
                             "starts from its final state nearest START, and --plot draws its points")
    parser.add_argument("--switch-depth", type=int, default=1, metavar="D",
                        help="follow the period-2n branch born at each period doubling, D doublings deep "
                             "(default 1; 0: none)")
    parser.add_argument("--max-points", type=int, default=2000, help="points per branch at most (default 2000)")
    parser.add_argument("--quiet", action="store_true", help="no progress lines while a branch is followed")
    add_integration_arguments(parser, periods=None)
    parser.add_argument("--out", type=Path, metavar="F.csv",
                        help="one row per branch point (parameter, amplitudes, |multipliers|, stable, contact "
                             "regime per mesh); F.json beside it: the record and the bifurcations. Without "
                             "--param: F.json, the one orbit")
    parser.add_argument("--plot", type=Path, metavar="F.png",
                        help="the frequency-response curve: stable solid, unstable dashed, bifurcations marked")
    parser.add_argument("--coordinate", metavar="NAME", help="the coordinate --plot shows (default the first)")


def parse_range(text: str) -> tuple[str, float, float, str]:
    """NAME, START, STOP and the unit of a physical value ("" for the model's own numbers)."""
    usage = f"--param {text!r}: expected NAME=START:STOP, e.g. --param omega=0.5:2.0 or speed=1000rpm:3000rpm"
    name, sep, body = (part.strip() for part in text.partition("="))
    parts = body.split(":")
    if not sep or not name or len(parts) != 2:
        raise GearsymError(usage)
    numbers, unit = _numbers_and_unit(text, parts)
    try:
        start, stop = (float(p) for p in numbers)
    except ValueError:
        raise GearsymError(usage) from None
    if start == stop:
        raise GearsymError(f"--param {text!r}: START and STOP must differ")
    return name, start, stop, unit


def engine_range(args: argparse.Namespace, parameter: tuple, scaling) -> tuple[str, float, float]:
    """The nondimensional parameter and range a physical range (speed=1000rpm:3000rpm) moves, as a sweep's
    axis does (gearsym.physical.sweeps); a nondimensional range as it is."""
    name, start, stop, unit = parameter
    if scaling is None:
        if unit:
            raise GearsymError(f"--param {args.param!r} has a unit, but the model has no physical values; declare "
                               "them (model.set_physical) or give them with --set NAME='VALUE UNIT'")
        return name, start, stop

    axis = nondimensional_axis(scaling.full, Axis(name, (start, stop), args.param, unit))
    if axis.name != name:
        print(f"{name} {start:g} -> {stop:g}{' ' + unit if unit else ''} is {axis.name} {axis.values[0]:.6g} -> "
              f"{axis.values[1]:.6g}: continued in {axis.name}")
    return axis.name, axis.values[0], axis.values[1]


def run(args: argparse.Namespace) -> int:
    parameter = parse_range(args.param) if args.param else None
    for option, value, least in (("--period-multiple", args.period_multiple, 1), ("--segments", args.segments or 1, 1),
                                 ("--transient", args.transient, 1), ("--switch-depth", args.switch_depth, 0),
                                 ("--max-points", args.max_points, 2)):
        whole_number(value, option, least)
    if args.out:
        check_file(args.out, (".csv",) if parameter else (".json",))
    if args.plot:
        if parameter is None:
            raise GearsymError("--plot draws the branches of a continuation: add --param NAME=START:STOP")
        check_figure(args.plot)
    if args.sweep and parameter is None:
        raise GearsymError("--sweep starts a continuation: add --param NAME=START:STOP")
    y0 = parse_state(args.y0)
    sweep = None
    if args.sweep:
        sweep = read_sweep(args.sweep)

    options = integration_from(args).run(periods=args.transient, discard=0)
    request = model_request(args, options)
    model = open_model(request)
    scaling = model.scaling
    physical = scaling  # (None without physical values; else the answers are also in its units)
    if parameter:
        given = parameter[0]
        parameter = engine_range(args, parameter, scaling)
        refuse_swept_and_set([(given, args.param), (parameter[0], args.param)], args.set)
    system = model.summary  # (a cached model's: no reduction for these checks)
    if args.segments is not None:  # (before the code is compiled: a period of cycles forcing periods has
        pieces = system.cycles * pieces_per_period(options.steps_per_period)  # pieces in each)
        check_segments(args.segments, pieces, f"--segments {args.segments}: ", options.steps_per_period * system.cycles)
    if parameter and parameter[0] not in system.parameters:
        raise UnknownParameterError(parameter[0], system.parameters, f"--param {args.param}")
    compiled = model.compiled(over={parameter[0]: (parameter[1], parameter[2])} if parameter else None)
    chosen_coordinate(args.coordinate, compiled.observed, args.plot)
    print(f"gearsym: {step_line(compiled, scaling)}", file=sys.stderr)
    if parameter is None:
        return _one_orbit(compiled, args, y0, physical)
    name, start, stop = parameter
    if sweep is not None and y0 is None:
        y0 = sweep_start(sweep, compiled, name, start)
    return _continuation(compiled, args, name, start, stop, y0, sweep, physical)


def _one_orbit(compiled, args, y0, physical) -> int:
    orbit = periodic_orbit(compiled, y0=y0, period_multiple=args.period_multiple, segments=args.segments)
    print(f"{orbit.model}: period-{orbit.period_multiple} orbit, Newton residual {orbit.residual:.2g} after "
          f"{orbit.iterations} iterations, {'stable' if orbit.stable else 'unstable'}")
    units = physical.point_units() if physical is not None else None  # (the text's and the record's)
    print("parameters: " + parameters_line(orbit.parameters, units))
    print("state at the section: " + ", ".join(f"{k}={v:.10g}" for k, v in zip(orbit.state_names, orbit.state)))
    largest = float(np.max(np.abs(orbit.multipliers)))
    held = [m for m in orbit.multipliers if abs(m) > ROUNDED * largest]  # (the rest is the product's rounding)
    rest = len(orbit.multipliers) - len(held)
    print("Floquet multipliers: " + ", ".join(_complex(m) for m in held)
          + "  (|mu|: " + ", ".join(f"{abs(m):.6g}" for m in held) + ")"
          + (f"; {rest} more below the monodromy matrix's rounding" if rest else ""))
    if orbit.log_moduli is not None and rest:  # (what the monodromy matrix rounds away, from the segments' maps)
        print("their moduli from the segments' maps: " + ", ".join(
            f"|mu_{i + 1}| = e^{v:.6g}" if ok else f"|mu_{i + 1}| <= e^{v:.4g} (lost in rounding: a bound)"
            for i, (v, ok) in enumerate(zip(orbit.log_moduli, orbit.resolved))))
    for name, a in orbit.amplitude.items():
        print(f"amplitude A_{name} = {a:.6g}")
    for mesh, regime in orbit.contact.items():
        print(f"contact of {mesh}: {regime}")
    record = orbit.as_dict()
    if physical is not None:  # the same in the model's units
        w = orbit.parameters["omega"]
        amplitude = {k: units.state(k, v, w) for k, v in orbit.amplitude.items()}
        state = {k: units.state(k, v, w) for k, v in zip(orbit.state_names, orbit.state)}
        speed = Measured(float(units.speed_of(w)), units.speed_unit) if units.speed else None
        print("in physical units: " + (f"{shown(speed)}; " if speed else "")
              + ", ".join(f"A_{k} = {shown(v)}" for k, v in amplitude.items())
              + "; state at the section: " + ", ".join(f"{k}={shown(v, 10)}" for k, v in state.items()))
        record["physical"] = {**({"speed": _json(speed)} if speed else {}), "amplitude": {k: _json(v) for k, v in amplitude.items()},
                              "state": {k: _json(v) for k, v in state.items()}, "parameters": dict(units.values)}
    if args.out:
        write_atomically(args.out, json.dumps(record, indent=1) + "\n")
        print(f"gearsym: wrote {args.out}", file=sys.stderr)
    return 0


def _json(value: Measured) -> dict:
    return {"value": float(value.magnitude), "unit": str(value.units)}


def _continuation(compiled, args, name, start, stop, y0, sweep, physical) -> int:
    try:
        result = continue_orbits(compiled, name, start, stop, y0=y0, period_multiple=args.period_multiple,
                                 segments=args.segments, switch_depth=args.switch_depth, max_points=args.max_points,
                                 execution=Execution(progress=not args.quiet))
    except ContinuationInterrupted as exc:  # keep what was traced: the files say it was interrupted
        if args.out:
            _write(exc.result, args.out, physical)
        print(f"gearsym: {exc}" + (f" in {args.out} (rerun the command to compute them all)" if args.out else ""),
              file=sys.stderr)
        return 130
    shown_result = physical.to_physical(result) if physical is not None else result  # rpm and um
    if physical is not None and sweep is not None and sweep.axes[0].name == "omega":
        sweep = physical.to_physical(sweep)
    for line in _summary(shown_result):
        print(line)
    if args.out:
        written = _write(result, args.out, physical, shown_result)
        print(f"gearsym: wrote {' and '.join(map(str, written))}", file=sys.stderr)
    if args.plot:
        plot_orbits(shown_result, args.plot, coordinate=args.coordinate, sweep=sweep)
        print(f"gearsym: wrote {args.plot}", file=sys.stderr)
    return 0


def _summary(result) -> list[str]:
    """What the command prints of a continuation, in its units (a physical model's: rpm, um)."""
    name = result.parameter
    unit = f" {result.units[name]}" if name in result.units else ""
    lines = []
    for b in result.branches:
        stable = int(b.stable.sum())
        lines.append(f"branch {b.index}: period {b.period_multiple}, {len(b)} points ({stable} stable), {name} "
                     f"{b.values[0]:.6g} -> {b.values[-1]:.6g}{unit}"
                     + (f", from branch {b.parent}" if b.parent is not None else "") + f"; {b.end}")
    for bif in result.bifurcations:
        lines.append(f"  {bif.kind} at {name}={bif.value:.6g}{unit} (branch {bif.branch}, period "
                     f"{bif.period_multiple}): mu = " + ", ".join(_complex(m) for m in bif.multipliers)
                     + (f"; {bif.detail}" if bif.detail else ""))
    return lines


def _write(result, out: Path, physical, shown_result=None) -> list[Path]:
    """The continuation's files: the engine's table and record and, for a physical model, the table in its units
    (``F.physical.csv``) and the record's ``physical`` part (the scaling, the units, the bifurcations there)."""
    if physical is None:
        return list(write_orbits(result, out))
    shown_result = shown_result or physical.to_physical(result)
    extra = {"physical": {**shown_result.settings["physical"], "parameter": shown_result.parameter,
                          "units": shown_result.units, "start": shown_result.start, "stop": shown_result.stop,
                          "bifurcations": [b.as_dict(shown_result.parameter, shown_result.state_names)
                                           for b in shown_result.bifurcations]}}
    written = list(write_orbits(result, out, extra))
    rows = shown_result.rows()
    names = list(rows[0]) if rows else [shown_result.parameter]
    written.append(write_physical_rows(names, rows, shown_result.units, sidecar(out, ".physical.csv")))
    return written


def _complex(m: complex) -> str:
    return f"{m.real:.6g}{m.imag:+.6g}i" if abs(m.imag) > 1e-12 else f"{m.real:.6g}"
