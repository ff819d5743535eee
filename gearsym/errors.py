"""Errors that tell the user what is wrong with a declaration and how to fix it."""
from __future__ import annotations

import difflib
import warnings
from collections.abc import Iterable


class GearsymError(Exception):
    """Base class of every error gearsym raises on purpose."""


class GearsymWarning(UserWarning):
    """Something gearsym does that the user may not expect: the command line prints it as one line."""


def warn(message: str) -> None:
    """Say ``message`` as a :class:`GearsymWarning` (``gearsym: warning: ...`` on the command line)."""
    warnings.warn(message, GearsymWarning, stacklevel=2)


class ModelError(GearsymError, ValueError):
    """An inconsistent or invalid model declaration.

    ``component`` names the offending component (or parameter) so that the
    message can point at the line of the model file to change.
    """

    def __init__(self, message: str, component: str | None = None):
        self.component = component
        prefix = f"{component}: " if component else ""
        super().__init__(prefix + message)


class UnknownParameterError(ModelError, KeyError):
    """A parameter name that the model does not have (often a misspelling)."""

    def __init__(self, name: str, known: Iterable[str], where: str | None = None):
        known = sorted(known)
        close = difflib.get_close_matches(name, known, n=3, cutoff=0.5)
        hint = f" Did you mean {' or '.join(repr(c) for c in close)}?" if close else ""
        listing = ", ".join(known) if known else "(none)"
        super().__init__(
            f"unknown parameter {name!r}.{hint} Known parameters: {listing}.", where
        )
        self.name = name

    def __str__(self) -> str:  # KeyError would otherwise quote the message
        return self.args[0]


def suggest(name: str, known: Iterable[str]) -> str:
    """A short ' Did you mean ...?' hint, or '' if nothing is close."""
    close = difflib.get_close_matches(name, list(known), n=3, cutoff=0.5)
    return f" Did you mean {' or '.join(repr(c) for c in close)}?" if close else ""
