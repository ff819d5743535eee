"""The ``gearsym`` command line.

Each subcommand lives in its own module of this package, named as the command, which defines ``NAME``,
``HELP``, ``add_arguments(parser)`` and ``run(args) -> int`` (the exit status); what the commands share is in
:mod:`.arguments`. Adding a subcommand (``compile``, ``lyap``, ``sweep``, ...) means writing such a module:
:data:`MODULES` finds it, :func:`main` does the rest,
including turning every :class:`~gearsym.errors.GearsymError` into a one-line
message and exit status 2 (a user's mistake, not a crash: no traceback).
A plain ``kill`` (SIGTERM) is handled like Ctrl-C: a sweep keeps its finished
points and says so, forked workers are stopped; the exit status is 130 after
Ctrl-C, 143 after SIGTERM (128 + the signal, as a shell reports either).
"""
from __future__ import annotations

import argparse
import gc
import importlib
import os
import pkgutil
import re
import signal
import sys
import threading
import warnings
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from types import ModuleType

from ..errors import GearsymError, GearsymWarning, command_line
from ..version import __version__
from ..files.atomic import NO_ROOM

#: the commands whose module is named otherwise (a module named ``list`` would hide the builtin in this package)
_RENAMED = {"list_models": "list"}
#: every subcommand's name -> its module: the modules of this package but ``__main__``, found without importing
#: them (a run imports the module of its own command only: the others' imports would cost it start-up time), in
#: the order ``gearsym --help`` lists them
MODULES = dict(sorted((_RENAMED.get(m.name, m.name), m.name) for m in pkgutil.iter_modules(__path__)
                      if not (m.ispkg or m.name.startswith("_"))))

#: exit status of a GearsymError (argparse uses the same for bad arguments)
USAGE_ERROR = 2
#: exit status when the reader of stdout went away (`gearsym list | head -1`), as a shell reports SIGPIPE
CLOSED_PIPE = 141
#: exit status after Ctrl-C (commands return it); after SIGTERM :func:`main` makes it 128 + 15
INTERRUPTED = 128 + signal.SIGINT


def __getattr__(name: str):
    if name == "COMMANDS":  # the subcommand modules, in the order ``gearsym --help`` lists them
        return _modules(MODULES)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _modules(names) -> tuple[ModuleType, ...]:
    return tuple(importlib.import_module(f"{__name__}.{MODULES[name]}") for name in names)


class _Parser(argparse.ArgumentParser):
    """argparse's parser, but a value that starts with a minus and is a number or numbers separated by commas
    (``--profile-shift -0.3,0.3``, ``--teeth -3,5``) is an option's value, not an option: argparse knows only a
    lone negative number as one."""

    NEGATIVE = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?(,\s*[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?)*$")

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = self.NEGATIVE


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The parser of every subcommand, or of ``command`` alone (a name in :data:`MODULES`)."""
    parser = _Parser(
        prog="gearsym", description="Symbolic drivetrain models, reduced and nondimensionalised automatically."
    )
    parser.add_argument("--version", action="version", version=f"gearsym {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for module in _modules([command] if command in MODULES else MODULES):
        command = sub.add_parser(module.NAME, help=module.HELP, description=module.HELP)
        module.add_arguments(command)
        command.set_defaults(run=module.run)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``gearsym`` with ``argv`` (default: the process arguments); returns the exit status."""
    own_process = argv is None  # (the console script's, or python -m gearsym.cli's)
    if own_process:
        _one_blas_thread()
    argv = sys.argv[1:] if argv is None else list(argv)
    closed = _closed_standard_streams()
    with _collector_paused(freeze=own_process):
        parser = build_parser(argv[0] if argv else None)
    if closed:
        print(f"gearsym: error: {closed}", file=sys.stderr)
        return USAGE_ERROR
    with warnings.catch_warnings(), _sigterm_as_ctrl_c() as terminated, command_line(), _guarded_stdout():
        warnings.simplefilter("default", GearsymWarning)
        warnings.showwarning = _one_line
        try:
            args = parser.parse_args(argv)  # (--set's values are read as they are parsed: their errors are one line)
            status = args.run(args)
            sys.stdout.flush()  # a closed pipe shows here rather than at the interpreter's exit
        except BrokenPipeError:
            _discard_stdout()  # nobody reads the rest
            return CLOSED_PIPE
        except GearsymError as exc:
            if isinstance(exc, StdoutError):
                _discard_stdout()
            print(f"gearsym: error: {exc}", file=sys.stderr)
            return USAGE_ERROR
        except OSError as exc:
            if exc.errno not in NO_ROOM:
                raise
            where = f" (writing {exc.filename})" if exc.filename else ""
            print(f"gearsym: error: {exc.strerror}{where}: free some space there, or write elsewhere (--out, "
                  "$GEARSYM_CACHE)", file=sys.stderr)
            return USAGE_ERROR
        except KeyboardInterrupt:  # a command with nothing to keep, or to say about it
            print("gearsym: interrupted", file=sys.stderr)
            status = INTERRUPTED
    return 128 + signal.SIGTERM if status == INTERRUPTED and terminated else status


class StdoutError(GearsymError):
    """Standard output that cannot be written (``> /dev/full``, a full disk): said in one line on stderr."""


class _GuardedStream:
    """sys.stdout, but a failure to write it (other than a closed pipe, which :func:`main` ends quietly) is a
    :class:`StdoutError`, said in one line like any other error, not a traceback."""

    def __init__(self, stream):
        self._stream = stream

    def _guarded(self, call, *args):
        try:
            return call(*args)
        except BrokenPipeError:
            raise
        except OSError as exc:
            raise StdoutError(f"cannot write to standard output: {exc.strerror or exc}; its output is lost (redirect "
                              "it to a file on a disk with room, or to /dev/null)") from None

    def write(self, text):
        return self._guarded(self._stream.write, text)

    def writelines(self, lines):
        return self._guarded(self._stream.writelines, lines)

    def flush(self):
        return self._guarded(self._stream.flush)

    def __getattr__(self, name):
        return getattr(self._stream, name)


@contextmanager
def _guarded_stdout() -> Iterator[None]:
    """sys.stdout guarded (:class:`_GuardedStream`) while a command runs."""
    stream = sys.stdout
    sys.stdout = _GuardedStream(stream)
    try:
        yield
    finally:
        if sys.stdout is not None and getattr(sys.stdout, "_stream", None) is stream:
            sys.stdout = stream


def _discard_stdout() -> None:
    """What is left to print goes nowhere (a closed pipe, a full disk): the interpreter's last flush cannot fail."""
    try:
        fd = sys.__stdout__.fileno() if sys.__stdout__ is not None else 1
        os.dup2(os.open(os.devnull, os.O_WRONLY), fd)
    except (OSError, ValueError):
        pass


def _closed_standard_streams() -> str | None:
    """What is wrong if gearsym was started with stdout closed (``>&-``), else None. A closed descriptor 0, 1
    or 2 is given /dev/null first, so that no file gearsym opens later takes its number (and gets its output,
    or a compiler's)."""
    closed = []
    for fd in (0, 1, 2):
        try:
            os.fstat(fd)
        except OSError:
            closed.append(fd)
            opened = os.open(os.devnull, os.O_RDWR)
            if opened != fd:
                os.dup2(opened, fd)
                os.close(opened)
    if 2 in closed and sys.stderr is None:
        sys.stderr = open(os.devnull, "w")
    if 1 in closed or sys.stdout is None:
        if sys.stdout is None:
            sys.stdout = open(os.devnull, "w")
        return ("standard output is closed (>&-): gearsym prints its results there; redirect it instead (> FILE, "
                "or > /dev/null to drop them)")
    return None


def _one_line(message, category, filename, lineno, file=None, line=None):
    """Warnings of gearsym as one line on stderr, like its errors; others as Python prints them."""
    if issubclass(category, GearsymWarning):
        print(f"gearsym: warning: {message}", file=sys.stderr, flush=True)
    else:
        sys.stderr.write(warnings.formatwarning(message, category, filename, lineno, line))


#: what sets the threads of OpenBLAS (NumPy's), in the order it reads them
BLAS_THREADS = ("OPENBLAS_NUM_THREADS", "GOTO_NUM_THREADS", "OMP_NUM_THREADS")


def _one_blas_thread() -> None:
    """NumPy's BLAS on one thread unless the user said otherwise, set before NumPy is imported: its pool of
    threads started with NumPy and spun for its work (a tenth of a cached model's start-up, 0.42 -> 0.30 s of CPU),
    while the engine's linear algebra is on matrices of a few hundred rows at most, and the runs are in C."""
    if not any(name in os.environ for name in BLAS_THREADS):
        os.environ["OPENBLAS_NUM_THREADS"] = "1"


@contextmanager
def _collector_paused(freeze: bool) -> Iterator[None]:
    """Python's cyclic garbage collector off while the command's modules (and NumPy) are imported: what an import
    makes lives as long as the process, so the collections that ran among it (about forty, 7 % of a cached model's
    start-up) had nothing to free. ``freeze``: the process is the command's own (not a caller's, whose garbage
    would be kept), so what exists then is set aside for good (``gc.freeze``), and the collections of the run do
    not walk the modules again (their time 18 -> 5 ms)."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if freeze:
            gc.freeze()
        if enabled:
            gc.enable()


@contextmanager
def _sigterm_as_ctrl_c() -> Iterator[list]:
    """While running a command, SIGTERM raises KeyboardInterrupt in the main thread, so every cleanup written
    for Ctrl-C runs (a sweep keeps its points, stops its workers, removes its lock). A second SIGTERM ends
    the process at once (its forked workers end with it). Yields a list that is non-empty once it came."""
    received: list = []
    if threading.current_thread() is not threading.main_thread():  # (signal handlers live there only)
        yield received
        return

    def interrupt(signum, frame):
        received.append(signum)
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        raise KeyboardInterrupt

    previous = signal.signal(signal.SIGTERM, interrupt)
    try:
        yield received
    finally:
        signal.signal(signal.SIGTERM, previous)
