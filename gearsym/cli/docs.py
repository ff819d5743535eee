"""``gearsym docs``: write (or check) the Markdown derivation pages ``docs/derivations/<model>.md``.

The pages are committed; ``--check`` is what CI and the tests run to catch a
page that no longer matches its model.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..derivation import derive, render
from ..files.atomic import write_atomically
from ..files.outputs import check_folder
from ..loading import declared
from ..registry import pregenerated_models, output_root
from .arguments.settings import add_teeth_argument

NAME = "docs"
HELP = "write the Markdown derivation of models to DIR/<model>.md"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("models", nargs="*", metavar="MODEL", help="model names or model file paths")
    parser.add_argument("--all", action="store_true",
                        help="every model of `gearsym list` whose C and page are committed (not one whose file "
                             "says PREGENERATED = False)")
    parser.add_argument("--out", type=Path, default=None, metavar="DIR",
                        help="output folder (default: docs/derivations/ of the current directory)")
    parser.add_argument("--check", action="store_true",
                        help="write nothing; exit 1 and name the pages that differ from what would be written")
    add_teeth_argument(parser)


def page(model: str, teeth=None) -> tuple[str, str]:
    """(model name, Markdown page) for a model reference (with ``teeth`` for one that declares none)."""
    derivation = derive(declared(model, teeth))
    return derivation.model, render(derivation, "markdown")


def shown(path: Path) -> str:
    """``path`` relative to the working directory when it lies below it (shorter messages)."""
    try:
        return str(path.resolve().relative_to(Path.cwd().resolve()))
    except ValueError:
        return str(path)


def run(args: argparse.Namespace) -> int:
    if bool(args.all) == bool(args.models):
        print("gearsym docs: error: give model names or --all (not both)", file=sys.stderr)
        return 2
    refs = pregenerated_models("page") if args.all else args.models
    outs = [args.out or output_root(ref) / "docs" / "derivations" for ref in refs]
    for out in set(outs) if not args.check else ():
        check_folder(out)
    pages = [page(ref, args.teeth) for ref in refs]
    if args.check:
        stale = []
        for (name, text), out in zip(pages, outs):
            path = out / f"{name}.md"
            if not path.is_file() or path.read_bytes() != text.encode("utf-8"):
                stale.append(path)
        for path in stale:
            print(f"gearsym docs: {shown(path)} is out of date; run `gearsym docs {path.stem}`", file=sys.stderr)
        if not stale:
            print(f"{len(pages)} page(s) up to date in {', '.join(sorted(map(shown, set(outs))))}")
        return 1 if stale else 0
    for (name, text), out in zip(pages, outs):
        path = out / f"{name}.md"
        write_atomically(path, text.encode("utf-8"))
        print(shown(path))
    return 0
