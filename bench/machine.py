"""What the benchmark ran on: CPU, load, versions, commit (the ratios are only comparable within one run)."""
from __future__ import annotations

import os
import platform
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]


def user_environment(name: str) -> dict[str, str]:
    """The environment of a timed command: Python keeps its bytecode as for any user (an installed package has
    it), in a temporary PYTHONPYCACHEPREFIX (not in the repository) that lives as long as this process, even where
    PYTHONDONTWRITEBYTECODE is set, which would add compiling gearsym's sources (about 0.3 s) to every start-up."""
    folder = tempfile.TemporaryDirectory(prefix=f"bench-{name}-pycache-")
    _KEPT.append(folder)
    return {**{k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}, "PYTHONPYCACHEPREFIX": folder.name}


_KEPT: list[tempfile.TemporaryDirectory] = []  # (the folders, removed when the benchmark's process ends)


def _run_text(cmd: list[str]) -> str:
    try:
        return subprocess.run(cmd, capture_output=True, text=True, timeout=30).stdout
    except (OSError, subprocess.SubprocessError):
        return ""


def _version(module: str) -> str | None:
    try:
        from importlib.metadata import version

        return version(module)
    except Exception:  # not installed: the tool is reported as missing elsewhere
        return None


def machine_info(cc: str = "gcc") -> dict:
    cpu = platform.processor()
    flags = ""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name") and cpu in ("", platform.machine()):
                cpu = line.split(":", 1)[1].strip()
            elif line.startswith("flags") and not flags:
                flags = line.split(":", 1)[1]
    except OSError:
        pass
    simd = [f for f in ("sse4_2", "avx", "avx2", "fma", "avx512f") if f in flags.split()]
    commit = _run_text(["git", "-C", str(REPO), "rev-parse", "HEAD"]).strip() or None
    dirty = bool(_run_text(["git", "-C", str(REPO), "status", "--porcelain", "--", "gearsym", "models"]).strip())
    try:
        load = [round(x, 2) for x in os.getloadavg()]
    except OSError:
        load = None
    cc_version = _run_text([cc, "--version"]).splitlines()
    return {
        "platform": platform.platform(),
        "cpu_model": cpu,
        "cpu_simd": simd,
        "nproc": os.cpu_count(),
        "loadavg_at_start": load,
        "python": sys.version.split()[0],
        "versions": {name: _version(name) for name in
                     ("numpy", "casadi", "sympy", "numba", "jitcode", "symengine", "scipy", "dask", "distributed")},
        "numpy": np.__version__,
        "casadi": _version("casadi"),
        "cc": cc,
        "cc_version": cc_version[0] if cc_version else None,
        "gearsym_cflags": os.environ.get("GEARSYM_CFLAGS"),
        "git_commit": commit,
        "git_dirty_gearsym_or_models": dirty,
    }
