"""``gearsym compile MODEL``: write generated/<model>/ (C and manifest) and compile it into the cache."""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..codegen.generated import generate_model
from ..files.outputs import check_folder
from ..loading import load
from ..registry import pregenerated_models, output_root
from .arguments.integration import add_integration_arguments, integration_from
from .arguments.settings import add_set_argument, model_settings

NAME = "compile"
HELP = "generate the model's C code into generated/<model>/ and compile it (cached)"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("models", nargs="*", metavar="MODEL", help="model names or model file paths")
    parser.add_argument("--all", action="store_true",
                        help="every model of `gearsym list` whose C and page are committed (not one whose file "
                             "says PREGENERATED = False)")
    add_set_argument(parser)
    add_integration_arguments(parser, periods=None)
    parser.add_argument("--out", type=Path, default=None, metavar="DIR",
                        help="where <model>/ is written (default: generated/ of the current directory)")
    parser.add_argument("--no-compile", action="store_true", help="write the C only")
    parser.add_argument("--check", action="store_true",
                        help="write nothing; exit 1 and name the files that differ from what would be written")


def run(args: argparse.Namespace) -> int:
    if bool(args.all) == bool(args.models):
        print("gearsym compile: error: give model names or --all (not both)", file=sys.stderr)
        return 2
    refs = pregenerated_models() if args.all else args.models
    settings = model_settings(args)
    options = integration_from(args)
    outs = [args.out or output_root(ref) / "generated" for ref in refs]
    for out in set(outs) if not args.check else ():
        check_folder(out)
    stale = []
    for ref, out in zip(refs, outs):
        report = generate_model(load(ref, **settings), out, options, check=args.check,
                                compile=not (args.no_compile or args.check))
        if args.check:
            stale += report.stale
            continue
        line = f"{report.name}: {report.source} ({report.size / 1024:.0f} KiB, hash {report.hash[:12]})"
        if report.library:
            how = f"compiled in {report.compile_seconds:.1f} s" if report.compile_seconds else "cached"
            line += f"; library {report.library} ({how})"
        print(line)
    if args.check:
        for path in stale:
            print(f"out of date: {path}", file=sys.stderr)
        if stale:
            print("run `gearsym compile --all` and commit generated/", file=sys.stderr)
            return 1
        print(f"generated code up to date ({len(refs)} models)")
    return 0
