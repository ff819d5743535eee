"""Compile generated C into a shared library, once per source and machine.

Libraries live in a cache (``$GEARSYM_CACHE``, else ``$XDG_CACHE_HOME/gearsym``
or ``~/.cache/gearsym``) under a name that hashes the source, the compiler and
its flags, so an unchanged model is never compiled twice and a changed one
never picks up a stale library.

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

import hashlib
import os
import platform
import shlex
import shutil
import subprocess
import tempfile
import time
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

from ..errors import GearsymError

DEFAULT_FLAGS = ("-O3", "-march=native", "-mtune=generic", "-fno-tree-partial-pre")

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


def cache_dir() -> Path:
    root = os.environ.get("GEARSYM_CACHE")
    if root:
        return Path(root)
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "gearsym"


def compile_flags() -> tuple[str, ...]:
    flags = os.environ.get("GEARSYM_CFLAGS")
    return tuple(shlex.split(flags)) if flags is not None else DEFAULT_FLAGS


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


@dataclass(frozen=True)
class Library:
    path: Path
    compiled: bool  # False: found in the cache
    seconds: float


def compile_library(source: Path, name: str, cc: str | None = None, flags: tuple[str, ...] | None = None,
                    announce=None) -> Library:
    """The shared library of ``source`` for this machine: from the cache, or compiled into it.

    ``announce(message)`` is called before an actual compilation (a few seconds), not on a cache hit.
    """
    cc = cc or find_compiler()
    if cc is None:
        raise CompilerError(REQUIRED_NOTE.format(what=compilers_looked_for()))
    flags = compile_flags() if flags is None else tuple(flags)
    digest = hashlib.sha256(Path(source).read_bytes() + CALL_SOURCE.encode()).hexdigest()[:16]
    target = cache_dir() / "lib" / f"{name}-{digest}-{_machine_key(cc, flags)}.so"
    if target.is_file():
        return Library(target, False, 0.0)
    target.parent.mkdir(parents=True, exist_ok=True)
    if announce:
        announce(f"compiling {name} ({' '.join(flags)}; once: cached in {target.parent})")
    start = time.perf_counter()
    with tempfile.TemporaryDirectory(dir=target.parent) as tmp:
        out, call = Path(tmp) / target.name, Path(tmp) / "gearsym_call.c"
        call.write_text(CALL_SOURCE)
        cmd = [*shlex.split(cc), *flags, "-fPIC", "-shared", "-o", str(out), str(source), str(call), "-lm"]
        try:
            proc = subprocess.run(cmd, capture_output=True, text=True)
        except OSError as exc:
            raise CompilerError(f"could not run the C compiler {cc!r}: {exc}. Set $CC to a working compiler.") from exc
        if proc.returncode != 0:
            raise CompilerError(
                f"compiling {source} failed ({' '.join(cmd)}):\n{proc.stderr.strip()[-2000:]}\n"
                "Check $CC and $GEARSYM_CFLAGS, or report the model that caused it."
            )
        os.replace(out, target)  # atomic: concurrent compilers of the same model do not collide
    return Library(target, True, time.perf_counter() - start)
