"""``gearsym reproduce``: the paper's figures and claims, from one command."""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..files.outputs import check_file, check_folder
from ..options import Execution
from ..reproduce import reproduce

NAME = "reproduce"
HELP = "recompute the paper's Figs. 3, 4, 6, 7, check its claims and write docs/reproduction.md"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--out", type=Path, default=Path("docs/figures"),
                        help="where the PNGs and claims.json go (default docs/figures)")
    parser.add_argument("--doc", type=Path, default=None,
                        help="the report page (default: reproduction.md beside OUT, i.e. docs/reproduction.md)")
    parser.add_argument("--data", type=Path, default=None,
                        help="sweep tables, a cache and resume point (default OUT/data; not committed)")
    parser.add_argument("--quick", action="store_true", help="coarse grids and short runs: a smoke test in seconds")
    parser.add_argument("--jobs", type=int, default=0, help="threads per sweep (default 0: every core)")
    parser.add_argument("--quiet", action="store_true", help="no progress output")


def run(args: argparse.Namespace) -> int:
    doc = args.doc or args.out.parent / "reproduction.md"
    check_folder(args.out)
    check_file(doc, (".md",), "--doc")
    if args.data:
        check_folder(args.data, "--data")
    try:
        reproduce(args.out, doc, quick=args.quick, execution=Execution(args.jobs, progress=not args.quiet),
                  data=args.data)
    except KeyboardInterrupt as exc:
        print(f"gearsym: {exc}" if str(exc) else "gearsym: interrupted; run the same command again to resume",
              file=sys.stderr)
        return 130
    print(f"wrote {doc} and the figures in {args.out}")
    return 0
