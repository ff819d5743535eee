"""Compile generated C into a shared library, once per source and machine.

Libraries live in a cache (``$GEARSYM_CACHE``, else ``$XDG_CACHE_HOME/gearsym``
or ``~/.cache/gearsym``) under a name that hashes the source, the compiler and
its flags, so an unchanged model is never compiled twice and a changed one
never picks up a stale library. A library is code, so the cache is private
(:mod:`gearsym.files.private`: made 0700, used only while nobody else can write
it) and a library is loaded only if its bytes are those recorded when it was
compiled (:mod:`.trust`).

Default flags: ``-O3 -march=native -mtune=generic -fno-tree-partial-pre``.
``-march=native`` lets the compiler use the CPU's fused multiply-add (measured
1.3x on the tangent loop) and makes the library specific to this CPU (part of the
cache key). ``-mtune=generic`` keeps that instruction set but schedules for
current CPUs in general rather than for the one the compiler detected: on the
AMD EPYC virtual machine of the measurements GCC 12 detects znver1, and its
znver1 tuning made every loop ~10 % slower (same instructions, same results to
the bit). Partial redundancy elimination, on at -O3, lengthens live ranges in the
long straight-line RK4 step: switching it off measured 8 % faster (58 -> 54 ns
per flexible-shaft step). Measured with the placement of the work arrays fixed
(:mod:`.native`), 18-24 loads each, median ns per step (incl. the call) of
one_stage and flexible_shaft, paper's scheme / crossings located: these flags
48.5/73.0 and 127/170; without ``-mtune=generic`` 53.7/78.4 and 136/180; without
``-fno-tree-partial-pre`` 54.9/76.2 and 127/170; plain ``-O3`` (no FMA)
55.5/81.7 and 141/189; ``-mprefer-vector-width=128`` (what the hand-written C
needs on AVX-512 CPUs) changed nothing. Set ``GEARSYM_CFLAGS`` to change the
flags, e.g. ``-O3`` for results bit-identical to CasADi's in-process evaluation.
The flags are part of the library's cache key (:func:`_machine_key`), so a
change rebuilds.
"""
from __future__ import annotations

import atexit
import errno
import hashlib
import json
import os
import platform
import shlex
import shutil
import subprocess
import tempfile
import time
from collections.abc import Sequence
from functools import lru_cache
from pathlib import Path

from ..records import record_class
from ..errors import GearsymError, warn
from ..files.atomic import no_room, write_error
from ..files.cache import configured_cache
from ..files.private import CACHE_ADVICE, NotPrivate, private_folder
from .trust import record, trusted

DEFAULT_FLAGS = ("-O3", "-march=native", "-mtune=generic", "-fno-tree-partial-pre")
#: the fit's window libraries (:mod:`.windows`): a function of straight-line code per parameter column, up to 800 kB of
#: C for a shaft-order library, where -O3's passes and the points-to analysis cost 3x the compile time and gain nothing
#: (the 20/53 pair's library of docs/examples/explain-cracked-tooth: gcc 12, 15.8 s of CPU at DEFAULT_FLAGS, 5.3 s at
#: these; one evaluation of its 78 windows with the tangent 0.141 and 0.147 s, of a 9/13 pair's 0.063 and 0.063 s,
#: min of 12 each); FMA contraction stays (-march=native)
WINDOW_FLAGS = ("-O1", "-fno-tree-pta", "-march=native", "-mtune=generic")

#: compiled into every library beside the generated code: the entry points are called through it, with the
#: stack moved to a fixed place modulo 4 KiB relative to the caller's work arrays (see :mod:`.native`)
CALL_SOURCE = r"""
#include <stdint.h>
typedef int (*gearsym_entry)(const double**, double**, long long*, double*, int);
int gearsym_call(gearsym_entry f, const double** arg, double** res, long long* iw, double* w, const void* anchor) {
    char here;
    volatile char* gap = __builtin_alloca((((uintptr_t)&here - (uintptr_t)anchor) & 4095) + 1);
    gap[0] = 0;
    return f(arg, res, iw, w, 0);
}
"""


class CompilerError(GearsymError):
    """No usable C compiler, or the compiler failed."""


def cache_dir(*levels: str) -> Path:
    """The library cache (or its folder ``levels``, e.g. ``"lib"``), made private if missing and checked.

    A cache that someone else could write (not yours, writable by group or others, reached through their
    symlink) is not used: a one-line warning says why, and this process keeps its libraries in a private
    temporary folder instead (removed at exit). A cache path that cannot be a folder is an error."""
    configured = configured_cache()
    root = _BYPASSED.get(str(configured))
    if root is None:
        try:
            root = private_folder(configured)
            return private_folder(root.joinpath(*levels), cache=root) if levels else root
        except NotPrivate as exc:
            root = _bypass(configured, exc)
        except GearsymError as exc:
            raise GearsymError(f"the library cache {_named(configured)} cannot be used: {exc}; set GEARSYM_CACHE "
                               "to a folder of your own (made if missing)") from None
    return private_folder(root.joinpath(*levels), cache=root)


_BYPASSED: dict[str, Path] = {}  # refused caches -> the private temporary folder used instead


def _bypass(configured: Path, why: NotPrivate) -> Path:
    root = Path(tempfile.mkdtemp(prefix="gearsym-cache-"))
    atexit.register(shutil.rmtree, root, ignore_errors=True)
    _BYPASSED[str(configured)] = root
    warn(f"the library cache {_named(configured)} is not used, as someone else could put code in it: {why}. "
         f"This run compiles into a private temporary folder; give gearsym a cache only you can write "
         f"(chmod go-w, or set GEARSYM_CACHE to a folder of your own)")
    return root


def _named(configured: Path) -> str:
    return f"GEARSYM_CACHE={configured}" if os.environ.get("GEARSYM_CACHE") else str(configured)


def compile_flags(default: tuple[str, ...] = DEFAULT_FLAGS) -> tuple[str, ...]:
    """``$GEARSYM_CFLAGS`` if set, else ``default``."""
    flags = os.environ.get("GEARSYM_CFLAGS")
    return tuple(shlex.split(flags)) if flags is not None else default


@lru_cache(maxsize=None)
def find_compiler() -> str | None:
    """``$CC`` if set, else the first of cc, gcc, clang on PATH; None if there is none."""
    env = os.environ.get("CC")
    candidates = [env] if env else ["cc", "gcc", "clang"]
    for cand in candidates:
        path = shutil.which(shlex.split(cand)[0]) if cand else None
        if path:
            return cand
    return None


def compilers_looked_for() -> str:
    env = os.environ.get("CC")
    return f"$CC={env!r}" if env else "cc, gcc, clang on PATH"


#: what to do without a compiler; the first sentence depends on the backend asked for
INSTALL_HINT = ("To compile: install one (Debian/Ubuntu: `apt install gcc`; macOS: `xcode-select --install`) "
                "or point $CC at it.")
FALLBACK_NOTE = ("no C compiler found (looked for {what}). gearsym falls back to CasADi's in-process "
                 "evaluation, which gives the same results about 10x slower. " + INSTALL_HINT)
REQUIRED_NOTE = ("no C compiler found (looked for {what}), and the compiled backend was asked for. "
                 + INSTALL_HINT + " Or choose the in-process backend (same results, about 10x slower).")


@lru_cache(maxsize=None)
def _machine_key(cc: str, flags: tuple[str, ...]) -> str:
    try:
        version = subprocess.run([*shlex.split(cc), "--version"], capture_output=True, text=True, timeout=30).stdout
    except (OSError, subprocess.SubprocessError):
        version = ""
    return hashlib.sha256("\n".join([version, " ".join(flags), platform.machine(), _cpu(flags)]).encode()
                          ).hexdigest()[:12]


def _cpu(flags: tuple[str, ...]) -> str:
    """The CPU a library built with ``flags`` is specific to ('' unless the flags say native)."""
    if "-march=native" not in flags and "-mtune=native" not in flags:
        return ""
    try:
        info = Path("/proc/cpuinfo").read_text()
        cpu = next((line for line in info.splitlines() if line.startswith("flags")), "")
        return cpu + next((line for line in info.splitlines() if line.startswith("model name")), "")
    except OSError:
        return platform.processor()


def binary_key(flags: tuple[str, ...]) -> str:
    """Whether a library built here with ``flags`` runs on another machine with the same results to the bit:
    same system, architecture, C library (its libm evaluates sin, cos, exp) and, for native flags, CPU.
    Not the compiler: it made the bytes, which travel as they are."""
    parts = [platform.system(), platform.machine(), " ".join(platform.libc_ver()), " ".join(flags), _cpu(flags)]
    return hashlib.sha256("\n".join(parts).encode()).hexdigest()[:12]


@record_class
class Library:
    path: Path
    compiled: bool  # False: found in the cache
    seconds: float


def compile_library(source: Path, name: str, cc: str | None = None, flags: tuple[str, ...] | None = None,
                    announce=None, describes: dict | None = None, includes: Sequence[Path] = ()) -> Library:
    """The shared library of ``source`` for this machine: from the cache, or compiled into it.

    ``describes`` says what the library is (the model, its code hash, states, parameters: kept in its record,
    part of its name). A cached library is used only if its bytes are those recorded when it was compiled
    (:func:`.trust.trusted`); one that is not (cut short, damaged, changed) is compiled again, and a warning
    says so. ``announce(message)`` is called before an actual compilation (a few seconds), not on a cache hit.
    ``includes``: the files ``source`` includes (the lanes' C includes the model's), whose bytes name the library
    too.
    """
    cc = cc or find_compiler()
    if cc is None:
        raise CompilerError(REQUIRED_NOTE.format(what=compilers_looked_for()))
    flags = compile_flags() if flags is None else tuple(flags)
    described = json.dumps(describes or {}, sort_keys=True).encode()
    included = b"".join(Path(path).read_bytes() for path in includes)
    digest = hashlib.sha256(Path(source).read_bytes() + CALL_SOURCE.encode() + described + included).hexdigest()[:16]
    target = library_path(f"{name}-{digest}-{_machine_key(cc, flags)}.so")
    if trusted(target, describes) is not None:
        return Library(target, False, 0.0)
    if announce:
        kept = "for this run only" if str(configured_cache()) in _BYPASSED else f"once: cached in {target.parent}"
        announce(f"compiling {name} ({' '.join(flags)}; {kept})")
    start = time.perf_counter()
    try:
        _compile_into(cc, flags, source, target, describes)
    except OSError as exc:  # (the cache's disk full: not the compiler's fault)
        raise write_error(exc, target, CACHE_ADVICE) from None
    return Library(target, True, time.perf_counter() - start)


def _compile_into(cc: str, flags: tuple, source: Path, target: Path, describes) -> None:
    """Compile ``source`` into the library ``target`` through a temporary folder beside it and a rename."""
    with tempfile.TemporaryDirectory(dir=target.parent) as tmp:
        out, call = Path(tmp) / target.name, Path(tmp) / "gearsym_call.c"
        call.write_text(CALL_SOURCE)
        cmd = [*shlex.split(cc), *flags, "-fPIC", "-shared", "-o", str(out), str(source), str(call), "-lm"]
        try:
            proc = subprocess.run(cmd, capture_output=True, text=True)
        except OSError as exc:
            raise CompilerError(f"could not run the C compiler {cc!r}: {exc}. Set $CC to a working compiler.") from exc
        if proc.returncode != 0:
            if no_room(tmp):  # (the compiler could not write its output: the disk, not $CC)
                raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
            raise CompilerError(
                f"compiling {source} failed ({' '.join(cmd)}):\n{proc.stderr.strip()[-2000:]}\n"
                "Check $CC and $GEARSYM_CFLAGS, or report the model that caused it."
            )
        os.chmod(out, 0o700)  # (whatever the umask)
        record(target, out.read_bytes(), describes)  # (before the rename: the library in place always has one)
        os.replace(out, target)  # atomic: concurrent compilers of the same model do not collide


def library_path(file_name: str) -> Path:
    """Where the cache keeps the library ``file_name`` (its folder made private and checked)."""
    if Path(file_name).name != file_name or file_name.startswith("."):
        raise GearsymError(f"{file_name!r} is not a library's file name")
    return cache_dir("lib") / file_name
