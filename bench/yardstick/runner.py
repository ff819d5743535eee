"""Build and run the hand-written C yardsticks (``one_stage.c``, ``flexible_shaft.c``).

Each C program is the reference a competent researcher would write by hand for
the Lyapunov-spectrum sweep of its gear model; the benchmarks time it and
compare its numbers with the other tools'. Only numpy is needed here.

    binary = build()                           # flexible_shaft (the default)
    res = run(binary, variant="table")
    res["exponents"]    # (points, 4), Gram-Schmidt column order

    binary = build(model="one_stage", flags=("-O3", "-march=native"))
    res = run(binary, omega_start=1.5, omega_stop=1.5, y0=(-2, -0.5))
    res["exponents"]    # (1, 2)

The binary's file name starts with its model, so ``command``/``run`` know which
parameters and ``y0`` length it takes (or pass ``model=`` explicitly).
"""
from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np


@dataclass(frozen=True)
class ModelSpec:
    source: Path
    params: tuple[str, ...]   # physical parameters the program accepts as --name value
    state: tuple[str, ...]    # state variables, the order of --y0


_HERE = Path(__file__).parent
MODELS: dict[str, ModelSpec] = {
    "flexible_shaft": ModelSpec(
        _HERE / "flexible_shaft.c",
        ("zeta", "B0", "B1", "Theta", "eta", "kS", "k_a", "I1", "I2", "I3", "r1", "r2"),
        ("x1", "v1", "x2", "v2")),
    "one_stage": ModelSpec(
        _HERE / "one_stage.c",
        ("zeta", "B0", "B1", "Theta", "eta", "k_a"),
        ("x", "v")),
}
DEFAULT_MODEL = "flexible_shaft"


def _spec(model: str) -> ModelSpec:
    try:
        return MODELS[model]
    except KeyError:
        raise ValueError(f"unknown model {model!r}; known: {sorted(MODELS)}") from None


def _compiler(cc: str) -> str:
    compiler = shutil.which(cc)
    if compiler is None:
        raise RuntimeError(
            f"C compiler {cc!r} not found on PATH; the C yardstick needs one "
            "(install gcc or pass cc=... to build())"
        )
    return compiler


def _effective_flags(flags) -> tuple[str, ...]:
    """The flags as compiled: GNU C mode unless a -std= is given (FMA contraction allowed)."""
    flags = tuple(flags)
    return flags if any(f.startswith("-std=") for f in flags) else (*flags, "-std=gnu99")


def binary_path(cc: str = "gcc", flags=("-O3",), out_dir=None, model: str = DEFAULT_MODEL) -> Path:
    """Where ``build`` puts (or has put) the executable; it need not exist yet.

    The name is derived from the model, the source, the compiler and every flag
    actually passed (including the implied -std=gnu99), so a binary built in
    another C mode is never picked up by mistake.
    """
    spec = _spec(model)
    compiler = _compiler(cc)
    key = hashlib.sha256(
        spec.source.read_bytes() + b"\0" + compiler.encode() + b"\0"
        + "\0".join(_effective_flags(flags)).encode()
    ).hexdigest()[:16]
    out = Path(out_dir) if out_dir is not None else Path(tempfile.gettempdir()) / "gearsym-yardstick"
    return out / f"{model}-{key}"


def build(cc: str = "gcc", flags=("-O3",), out_dir=None, model: str = DEFAULT_MODEL) -> Path:
    """Compile the model's C program and return the path of the executable.

    The binary is cached under ``out_dir`` (default: a directory in the system
    temp dir) with a name derived from the model, source, compiler and flags,
    so repeated calls do not recompile.
    """
    flags = tuple(flags)
    binary = binary_path(cc, flags, out_dir, model)
    if binary.exists():
        return binary
    binary.parent.mkdir(parents=True, exist_ok=True)

    # Compile to a temporary name and rename, so a concurrent build never
    # sees a half-written executable.
    tmp = binary.with_name(f".{binary.name}.{os.getpid()}.tmp")
    cmd = [_compiler(cc), *_effective_flags(flags), "-o", str(tmp), str(_spec(model).source), "-lm"]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        tmp.unlink(missing_ok=True)
        raise RuntimeError(
            "compiling the C yardstick failed:\n  " + " ".join(cmd) + "\n" + proc.stderr
        )
    tmp.replace(binary)
    return binary


def model_of(binary) -> str:
    """The model a binary built by ``build`` belongs to (from its file name)."""
    name = Path(binary).name
    for model in MODELS:
        if name.startswith(model + "-"):
            return model
    return DEFAULT_MODEL  # a binary built elsewhere: assume the original program


def command(binary, variant="table", steps=200, periods=400, discard=100,
            omega_start=0.1, omega_stop=2.0, omega_step=0.01, y0=None, model=None, **params):
    """The argument list ``run`` executes (handy for reporting)."""
    model = model or model_of(binary)
    spec = _spec(model)
    if variant not in ("table", "direct"):
        raise ValueError(f"variant must be 'table' or 'direct', not {variant!r}")
    unknown = set(params) - set(spec.params)
    if unknown:
        raise TypeError(f"model {model!r} has no parameter(s) {sorted(unknown)}; known: {spec.params}")
    cmd = [str(binary), f"--{variant}",
           "--steps", str(int(steps)), "--periods", str(int(periods)),
           "--discard", str(int(discard)),
           "--omega-start", repr(float(omega_start)),
           "--omega-stop", repr(float(omega_stop)),
           "--omega-step", repr(float(omega_step))]
    if y0 is not None:
        if len(y0) != len(spec.state):
            raise ValueError(f"y0 for {model!r} needs {len(spec.state)} values {spec.state}, got {len(y0)}")
        cmd += ["--y0", ",".join(repr(float(v)) for v in y0)]
    for name, value in params.items():
        cmd += [f"--{name}", repr(float(value))]
    return cmd


def run(binary, variant="table", steps=200, periods=400, discard=100,
        omega_start=0.1, omega_stop=2.0, omega_step=0.01, **params) -> dict:
    """Run the sweep and parse its output.

    ``params`` are the model's parameters (see ``MODELS[model].params``),
    ``y0=`` the first point's state and optionally ``model=`` (by default taken
    from the binary's name). Returns omega (points,), exponents (points, n),
    amplitude (points, m) (x for one_stage; x1 and x2 for flexible_shaft),
    point_seconds (points,), total_seconds (the C program's own
    CLOCK_MONOTONIC time of the whole sweep, output excluded), columns (the CSV
    header) and final_state (points, n), or None if the program does not print
    its ``# y_end=`` lines.
    """
    cmd = command(binary, variant, steps, periods, discard,
                  omega_start, omega_stop, omega_step, **params)
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed ({proc.returncode}):\n{proc.stderr}")

    lines = proc.stdout.splitlines()
    if not lines or not lines[0].startswith("omega,"):
        raise RuntimeError(f"unexpected output from {cmd[0]}:\n{proc.stdout[:500]}")
    columns = lines[0].split(",")
    lam = [i for i, c in enumerate(columns) if c.startswith("lambda_")]
    amp = [i for i, c in enumerate(columns) if c.startswith("A_")]
    if not lam or columns[-1] != "seconds":
        raise RuntimeError(f"unexpected header from {cmd[0]}: {lines[0]}")

    rows, y_end, total = [], [], None
    for line in lines[1:]:
        if line.startswith("# total_seconds="):
            total = float(line.split("=", 1)[1])
        elif line.startswith("# y_end="):
            y_end.append([float(v) for v in line.split("=", 1)[1].split(",")])
        elif line and not line.startswith("#"):
            rows.append([float(v) for v in line.split(",")])
    if total is None:
        raise RuntimeError(f"no total_seconds line in output of {cmd[0]}")
    data = np.array(rows, dtype=float).reshape(-1, len(columns))
    return {
        "omega": data[:, 0].copy(),
        "exponents": data[:, lam].copy(),
        "amplitude": data[:, amp].copy(),
        "point_seconds": data[:, -1].copy(),
        "total_seconds": total,
        "columns": columns,
        "final_state": np.array(y_end, dtype=float) if y_end else None,
    }
