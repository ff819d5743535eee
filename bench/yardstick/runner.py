"""Build and run the hand-written C yardstick (``flexible_shaft.c``).

The C program is the reference a competent researcher would write by hand for
the Lyapunov-spectrum sweep of the flexible-shaft gear model; the benchmark
times it and compares its numbers with gearsym's. Only numpy is needed here.

    binary = build()
    res = run(binary, variant="table")
    res["exponents"]    # (points, 4), Gram-Schmidt column order
"""
from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np

SOURCE = Path(__file__).with_name("flexible_shaft.c")

# Physical parameters the C program accepts as ``--name value``.
PARAMS = ("zeta", "B0", "B1", "Theta", "eta", "kS", "k_a", "I1", "I2", "I3", "r1", "r2")


def build(cc: str = "gcc", flags=("-O3",), out_dir=None) -> Path:
    """Compile flexible_shaft.c and return the path of the executable.

    The binary is cached under ``out_dir`` (default: a directory in the system
    temp dir) with a name derived from the source, compiler and flags, so
    repeated calls do not recompile.
    """
    compiler = shutil.which(cc)
    if compiler is None:
        raise RuntimeError(
            f"C compiler {cc!r} not found on PATH; the C yardstick needs one "
            "(install gcc or pass cc=... to build())"
        )
    flags = tuple(flags)
    source = SOURCE.read_bytes()
    key = hashlib.sha256(
        source + b"\0" + compiler.encode() + b"\0" + "\0".join(flags).encode()
    ).hexdigest()[:16]
    out = Path(out_dir) if out_dir is not None else Path(tempfile.gettempdir()) / "gearsym-yardstick"
    out.mkdir(parents=True, exist_ok=True)
    binary = out / f"flexible_shaft-{key}"
    if binary.exists():
        return binary

    # Compile to a temporary name and rename, so a concurrent build never
    # sees a half-written executable.
    tmp = out / f".flexible_shaft-{key}.{os.getpid()}.tmp"
    std = [] if any(f.startswith("-std=") for f in flags) else ["-std=gnu99"]  # GNU mode: FMA contraction allowed
    cmd = [compiler, *flags, *std, "-o", str(tmp), str(SOURCE), "-lm"]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        tmp.unlink(missing_ok=True)
        raise RuntimeError(
            "compiling the C yardstick failed:\n  " + " ".join(cmd) + "\n" + proc.stderr
        )
    tmp.replace(binary)
    return binary


def command(binary, variant="table", steps=200, periods=400, discard=100,
            omega_start=0.1, omega_stop=2.0, omega_step=0.01, y0=None, **params):
    """The argument list ``run`` executes (handy for reporting)."""
    if variant not in ("table", "direct"):
        raise ValueError(f"variant must be 'table' or 'direct', not {variant!r}")
    unknown = set(params) - set(PARAMS)
    if unknown:
        raise TypeError(f"unknown model parameter(s) {sorted(unknown)}; known: {PARAMS}")
    cmd = [str(binary), f"--{variant}",
           "--steps", str(int(steps)), "--periods", str(int(periods)),
           "--discard", str(int(discard)),
           "--omega-start", repr(float(omega_start)),
           "--omega-stop", repr(float(omega_stop)),
           "--omega-step", repr(float(omega_step))]
    if y0 is not None:
        cmd += ["--y0", ",".join(repr(float(v)) for v in y0)]
    for name, value in params.items():
        cmd += [f"--{name}", repr(float(value))]
    return cmd


def run(binary, variant="table", steps=200, periods=400, discard=100,
        omega_start=0.1, omega_stop=2.0, omega_step=0.01, **params) -> dict:
    """Run the sweep and parse its output.

    ``params`` are model parameters (zeta, B0, B1, Theta, eta, kS, k_a, I1,
    I2, I3, r1, r2) or ``y0=(x1, v1, x2, v2)`` for the first point's state.
    Returns omega (points,), exponents (points, 4), amplitude (points, 2) of
    x1 and x2, point_seconds (points,) and total_seconds (the C program's own
    CLOCK_MONOTONIC time of the whole sweep, output excluded).
    """
    cmd = command(binary, variant, steps, periods, discard,
                  omega_start, omega_stop, omega_step, **params)
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed ({proc.returncode}):\n{proc.stderr}")

    rows, total = [], None
    lines = proc.stdout.splitlines()
    if not lines or not lines[0].startswith("omega,"):
        raise RuntimeError(f"unexpected output from {cmd[0]}:\n{proc.stdout[:500]}")
    for line in lines[1:]:
        if line.startswith("# total_seconds="):
            total = float(line.split("=", 1)[1])
        elif line and not line.startswith("#"):
            rows.append([float(v) for v in line.split(",")])
    if total is None:
        raise RuntimeError(f"no total_seconds line in output of {cmd[0]}")
    data = np.array(rows, dtype=float).reshape(-1, 8)
    return {
        "omega": data[:, 0].copy(),
        "exponents": data[:, 1:5].copy(),
        "amplitude": data[:, 5:7].copy(),
        "point_seconds": data[:, 7].copy(),
        "total_seconds": total,
    }
