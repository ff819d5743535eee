"""Checking where a command's output goes before any work starts.

A figure that matplotlib cannot write, or a folder nobody may write to, would
otherwise be found out only at the end of a run of minutes: every command
checks its outputs first, and says which option to change.
"""
from __future__ import annotations

import os
import tempfile
from functools import cache
from pathlib import Path

from ..errors import GearsymError


@cache
def figure_formats() -> tuple[str, ...]:
    """The suffixes matplotlib can write (``.png``, ``.pdf``, ``.svg``, ...)."""
    from matplotlib.backend_bases import FigureCanvasBase

    return tuple(sorted(f".{ext}" for ext in FigureCanvasBase.get_supported_filetypes()))


def check_figure(path: str | Path, what: str = "--plot") -> Path:
    """``path`` as a figure file matplotlib can write, in a folder that can be written."""
    return check_file(path, figure_formats(), what)


def check_file(path: str | Path, suffixes: tuple[str, ...], what: str = "--out") -> Path:
    """``path`` as a file with one of ``suffixes``, not a folder, in a folder that exists or can be made and
    can be written; otherwise a one-line error naming ``what`` (the option)."""
    path = Path(path)
    if path.suffix.lower() not in suffixes:
        shown = ", ".join(suffixes)
        got = f"{path.suffix!r} is not one of them" if path.suffix else "it has none"
        raise GearsymError(f"{what} {path}: the file name must end in {shown} ({got})")
    if path.is_dir():
        raise GearsymError(f"{what} {path} is a folder; give a file name ending in {suffixes[0]}")
    if path.is_symlink():  # (writing through it would change the file it points at, whoever's it is)
        raise GearsymError(f"{what} {path} is a symlink (to {os.readlink(path)}); gearsym never writes through one: "
                           "give the file's own path, or remove the link")
    _check_writable(path.parent, f"{what} {path}")
    return path


def check_folder(path: str | Path, what: str = "--out") -> Path:
    """``path`` as a folder that exists or can be made, and can be written (not an existing file)."""
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise GearsymError(f"{what} {path} is a file, not a folder; give a folder (it is made if missing)")
    _check_writable(path, f"{what} {path}")
    return path


def _check_writable(folder: Path, where: str) -> None:
    """A file can be made in ``folder``: tried in it, or in the nearest existing folder above it
    (which must then let the missing ones be made); nothing is left behind."""
    existing = folder.absolute()
    while not existing.exists():
        existing = existing.parent
    if not existing.is_dir():
        raise GearsymError(f"{where}: {existing} is a file, so no folder can be made below it")
    try:
        fd, probe = tempfile.mkstemp(dir=existing, prefix=".gearsym-probe-")
    except OSError as exc:
        reason = exc.strerror or type(exc).__name__
        raise GearsymError(f"{where}: no file can be made in {existing} ({reason}); choose another place") from None
    os.close(fd)
    os.unlink(probe)
