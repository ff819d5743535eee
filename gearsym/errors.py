"""Errors that tell the user what is wrong with a declaration and how to fix it, and how the caller spells an
option in them: ``--time-scale 2.5`` on the command line, ``time_scale=2.5`` in Python.

A message that tells the user what to pass says it as they would write it. The command line runs each command
inside :func:`command_line`; everywhere else (a script, a notebook, the tests) the Python spelling is used.
"""
from __future__ import annotations

import difflib
import warnings
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar


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


_ON_COMMAND_LINE: ContextVar[bool] = ContextVar("gearsym_on_command_line", default=False)
#: what ``option(keyword)`` shows for the value when none is given
_ANY = object()


@contextmanager
def command_line() -> Iterator[None]:
    """While inside, messages spell options as the ``gearsym`` command takes them."""
    token = _ON_COMMAND_LINE.set(True)
    try:
        yield
    finally:
        _ON_COMMAND_LINE.reset(token)


def on_command_line() -> bool:
    return _ON_COMMAND_LINE.get()


def option_name(keyword: str, *, flag: str | None = None) -> str:
    """The option's name as the caller writes it: ``--out`` on the command line, ``out`` in Python."""
    return (flag or "--" + keyword.replace("_", "-")) if on_command_line() else keyword


def option(keyword: str, value: object = _ANY, *, flag: str | None = None) -> str:
    """``keyword`` (a Python keyword, e.g. ``time_scale``) with ``value`` as the caller writes it.

    On the command line: ``--time-scale VALUE`` (``flag`` if the command's option is named otherwise; ``True``
    is the flag alone, ``--overwrite``); in Python: ``time_scale=VALUE`` (``overwrite=True``). Without a value:
    ``--time-scale ...`` and ``time_scale=...``.
    """
    shown = "..." if value is _ANY else f"{value:g}" if isinstance(value, float) else value
    if on_command_line():
        name = option_name(keyword, flag=flag)
        return name if value is True else f"{name} {shown}"
    return f"{keyword}={shown!r}" if isinstance(value, str) else f"{keyword}={shown}"
