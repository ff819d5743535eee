"""How the caller spells an option: ``--time-scale 2.5`` on the command line, ``time_scale=2.5`` in Python.

A message that tells the user what to pass says it as they would write it. The command line runs each command
inside :func:`command_line`; everywhere else (a script, a notebook, the tests) the Python spelling is used.
"""
from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar

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


def name(keyword: str, *, flag: str | None = None) -> str:
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
        name = flag or "--" + keyword.replace("_", "-")
        return name if value is True else f"{name} {shown}"
    return f"{keyword}={shown!r}" if isinstance(value, str) else f"{keyword}={shown}"
