"""Errors that tell the user what is wrong with a declaration and how to fix it."""
from __future__ import annotations

import difflib
import warnings
from collections.abc import Iterable


class GearsymError(Exception):
    """Base class of every error gearsym raises on purpose."""

    def for_command_line(self) -> str:
        """The message as the ``gearsym`` command prints it (options spelled as flags: :class:`AdviceError`)."""
        return str(self)


#: an option named in an error's advice, as each caller spells it: (in Python, on the command line)
SPELLINGS = {"overwrite": ("overwrite=True", "--overwrite"), "out": ("out=", "--out"),
             "threads": ('workers=Workers(parallel="threads")', "--parallel threads"),
             "same_run": ("the call", "the command")}


class AdviceError(GearsymError):
    """An error whose advice names options of the caller: the message is a template with ``{overwrite}``,
    ``{out}``, ... (:data:`SPELLINGS`), written as Python spells them (``overwrite=True``), and as the command
    line does (``--overwrite``) by :meth:`for_command_line`, so that each caller reads its own spelling."""

    def __init__(self, template: str):
        self.template = template
        super().__init__(template.format(**{k: python for k, (python, _) in SPELLINGS.items()}))

    def for_command_line(self) -> str:
        return self.template.format(**{k: flag for k, (_, flag) in SPELLINGS.items()})


def literal(value) -> str:
    """``value`` as text inside an :class:`AdviceError` template (its braces kept as they are)."""
    return str(value).replace("{", "{{").replace("}", "}}")


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
