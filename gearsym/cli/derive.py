"""``gearsym derive MODEL``: print a model's reduced equations and coefficient groups."""
from __future__ import annotations

import argparse

from ..derivation import derive, render
from ..loading import declared
from .arguments.settings import add_teeth_argument


NAME = "derive"
HELP = "print the reduced, nondimensional equations and coefficient groups of a model"
FORMATS = ("text", "latex", "json")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("model", help="a model name (see `gearsym list`) or the path of a model file")
    parser.add_argument("--format", choices=FORMATS, default="text", help="output format (default: text)")
    parser.add_argument("--full", action="store_true",
                        help="text/latex: show every step, from the components to the first-order system "
                             "(json always has them)")
    add_teeth_argument(parser)


def run(args: argparse.Namespace) -> int:
    print(render(derive(declared(args.model, args.teeth)), args.format, full=args.full), end="")
    return 0
