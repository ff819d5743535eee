"""``gearsym docs``: write (or check) the Markdown derivation pages ``docs/derivations/<model>.md``.

The pages are committed; ``--check`` is what CI and the tests run to catch a
page that no longer matches its model.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..derivation import derive, render
from ..paths import DERIVATIONS_DIR
from ..registry import available_models, load_model

NAME = "docs"
HELP = "write the Markdown derivation of models to DIR/<model>.md"
DEFAULT_OUT = DERIVATIONS_DIR


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("models", nargs="*", metavar="MODEL", help="model names or model file paths")
    parser.add_argument("--all", action="store_true", help="every model of `gearsym list`")
    parser.add_argument("--out", type=Path, default=DEFAULT_OUT, metavar="DIR",
                        help="output folder (default: docs/derivations of the repository)")
    parser.add_argument("--check", action="store_true",
                        help="write nothing; exit 1 and name the pages that differ from what would be written")


def page(model: str) -> tuple[str, str]:
    """(model name, Markdown page) for a model reference."""
    derivation = derive(load_model(model))
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
    refs = available_models() if args.all else args.models
    pages = [page(ref) for ref in refs]
    if args.check:
        stale = []
        for name, text in pages:
            path = args.out / f"{name}.md"
            if not path.is_file() or path.read_bytes() != text.encode("utf-8"):
                stale.append(path)
        for path in stale:
            print(f"gearsym docs: {shown(path)} is out of date; run `gearsym docs {path.stem}`", file=sys.stderr)
        if not stale:
            print(f"{len(pages)} page(s) up to date in {shown(args.out)}")
        return 1 if stale else 0
    args.out.mkdir(parents=True, exist_ok=True)
    for name, text in pages:
        path = args.out / f"{name}.md"
        path.write_bytes(text.encode("utf-8"))
        print(shown(path))
    return 0
