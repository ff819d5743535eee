"""Parsing ``--set NAME=VALUE``, ``--teeth Z1,Z2`` and ``--y0 x=-2,v=-0.5`` (shared by the subcommands).

``--set`` and ``--teeth`` are read as they are given, once, into typed values (a quantity into a
:class:`~gearsym.units.Measure` in SI, a number into a float, tooth counts into
:class:`~gearsym.model.tooth_counts.ToothCounts`): ``args.set`` is a dict of them, ``args.teeth`` counts or None."""
from __future__ import annotations

import argparse
import math
import sys

from ...errors import GearsymError
from ...model.grammar import canonical_formula
from ...model.length_scale import check_length_scale
from ...model.tooth_counts import ToothCounts
from ...opening import checked_formulas as formulas_checked
from ...units import looks_like_quantity, measure


def add_set_argument(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--set", action=_Setting, default={}, metavar="NAME=VALUE",
        help="a parameter value (omega=1.5), a physical value with its unit (kZ=\"2e8 N/m\", speed=\"3000 rpm\"; "
             "length_scale=static|backlash|\"1 um\") or a new mesh stiffness formula in tau "
             "(\"k=1+0.2*cos(tau)\"); repeat for several",
    )
    add_teeth_argument(parser)


def add_teeth_argument(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--teeth", action=_Teeth, default=None, metavar="Z1,Z2",
        help="tooth counts of the first mesh's pinion (its driving gear) and wheel, for a model that declares none: "
             "shaft orders, tooth faults and eccentricity need them (one pinion revolution is Z1 mesh periods)",
    )


class _Setting(argparse.Action):
    """One ``--set NAME=VALUE``, read into its typed value as it is given, kept in the dict ``args.set``."""

    def __call__(self, parser, namespace, pair, option_string=None):
        setattr(namespace, self.dest, parse_settings([pair], getattr(namespace, self.dest) or {}))


class _Teeth(argparse.Action):
    """``--teeth Z1,Z2``, read into :class:`~gearsym.model.tooth_counts.ToothCounts` as it is given."""

    def __call__(self, parser, namespace, value, option_string=None):
        setattr(namespace, self.dest, ToothCounts.of(value))


def model_settings(args: argparse.Namespace, *, cached: bool = False) -> dict:
    """--set's values and, with --teeth, ``teeth`` = (Z1, Z2): what the face's ``gearsym.load`` takes. A formula's
    numbers are checked here too (:func:`checked_formulas`), unless the caller may find the model in the start-up
    cache (``cached``): it checks them when it builds the model, and a cached model's run never loads SymPy."""
    teeth = getattr(args, "teeth", None)
    settings = {**args.set, **({"teeth": teeth} if teeth is not None else {})}
    return settings if cached else checked_formulas(settings)


def checked_formulas(settings: dict) -> dict:
    """``settings``, after each formula among them is built (SymPy) to check its numbers: 1/0, log(0) or
    exp(1000) are refused with the option that gave them, before the model is loaded. (A model in the start-up
    cache was built with its formula once: the cache has it only if the formula passed.)"""
    return formulas_checked(settings, "--set")


def parse_settings(pairs: list[str], settings: dict | None = None) -> dict[str, object]:
    """``NAME=VALUE`` pairs added to ``settings`` (a new dict), each value read once into what it is (before any
    work starts; nothing is ever run as Python): a quantity (a number and a unit) becomes a
    :class:`~gearsym.units.Measure` in SI, a number a float, a length scale's name stays text, and a formula's
    grammar is checked without SymPy and kept in one spelling (:func:`~gearsym.model.grammar.canonical_formula`:
    the start-up cache's key); its numbers are checked when it is built (:func:`checked_formulas`)."""
    settings = dict(settings or {})
    for pair in pairs:
        name, sep, value = pair.partition("=")
        name, value = name.strip(), value.strip()
        if not sep or not name or not value:
            raise GearsymError(f"--set {pair!r}: expected NAME=VALUE, e.g. --set omega=1.5 or --set \"k=1+0.2*cos(tau)\"")
        if name in settings:
            raise GearsymError(f"--set gives {name} twice")
        if name == "teeth":
            raise GearsymError("--set teeth=...: tooth counts are given with --teeth Z1,Z2")
        if name == "length_scale":
            settings[name] = check_length_scale(value, "--set length_scale")
        elif looks_like_quantity(value):
            settings[name] = measure(value, f"--set {name}")
        elif _is_number(value):  # (a number needs no parser, and so no SymPy)
            if not math.isfinite(float(value)):
                raise GearsymError(f"--set {name}={value}: not a finite number (a double holds at most "
                                   f"{sys.float_info.max:.3g}); give a finite value")
            settings[name] = float(value)
        else:  # (its grammar, on Python's syntax tree alone; its numbers when it is built: checked_formulas)
            settings[name] = canonical_formula(value, f"--set {name}")
    return settings


def refuse_swept_and_set(swept: list[tuple[str, str]], settings: dict[str, str]) -> None:
    """A parameter both swept (``swept``: its name and the --param that moves it) and given with --set: the swept
    values would win and the --set value be ignored without a word, so say so before any work."""
    for name, spec in swept:
        if name in settings:
            raise GearsymError(f"{name} is both swept (--param {spec}) and set (--set {name}={settings[name]}); the "
                               f"swept values would be used and --set {name} ignored: drop one of the two")


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def parse_state(text: str | None) -> dict[str, float] | None:
    """``x=-2,v=-0.5`` -> {'x': -2.0, 'v': -0.5}; states not named start at 0."""
    return parse_numbers(text, "--y0", "x=-2,v=-0.5") if text else None


def parse_numbers(text: str, option: str, example: str) -> dict[str, float]:
    """``NAME=NUMBER,NAME=NUMBER`` -> a dict, with an error that shows ``option`` and an ``example``."""
    usage = f"{option} {text!r}: expected NAME=NUMBER pairs separated by commas, e.g. {option} {example}"
    numbers = {}
    for item in text.split(","):
        name, sep, value = (part.strip() for part in item.partition("="))
        if not sep or not name:
            raise GearsymError(usage)
        if name in numbers:
            raise GearsymError(f"{option} {text!r} gives {name} twice")
        try:
            numbers[name] = float(value)
        except ValueError:
            raise GearsymError(f"{usage} ({name}={value!r} is not a number)") from None
    return numbers
