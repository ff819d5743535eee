"""``gearsym list``: the models in ``models/`` with their titles."""
from __future__ import annotations

import argparse

from ..errors import GearsymError
from ..registry import available_models, load_model

NAME = "list"
HELP = "list the available models"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    pass


def title_of(name: str) -> str:
    """A model's title; a model that fails to load is listed with its error, not fatal to the listing."""
    try:
        model = load_model(name)
    except GearsymError as exc:
        return f"(cannot be loaded: {exc})"
    if model.is_drivetrain:
        return model.title
    return model.title or f"first-order system, {model.dimension} states"


def run(args: argparse.Namespace) -> int:
    names = available_models()
    width = max((len(n) for n in names), default=0)
    for name in names:
        print(f"{name.ljust(width)}  {title_of(name)}")
    return 0
