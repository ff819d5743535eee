"""Start-up: ``gearsym lyap MODEL`` end to end, in a fresh process, when the model's library is cached.

Each shipped model is run once to fill the cache (its compiled library and the summary that spares the
reduction, ``gearsym/cached.py``), then ``REPEATS`` times, timed from outside (the interpreter's start and
every import included), with the shortest run the command accepts (10 measured periods). The median is the
result; the machine may be shared, so every time is kept. Also the imports alone (``import numpy, casadi``),
the floor under any command. Python keeps its bytecode as it does for any user (in a temporary
``PYTHONPYCACHEPREFIX``, not in the repository), even where ``PYTHONDONTWRITEBYTECODE`` is set, which would
make every process compile gearsym's modules again (about 0.2 s); ``--as-set`` measures with the environment
as it is. Alone: ``python -m bench.speed.startup [--repeats N] [--as-set]``.
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

from bench.machine import REPO

MODELS = ("one_stage", "one_stage_resonant", "flexible_shaft", "two_stage", "spur_pair", "duffing", "planetary",
          "planetary_differential", "planetary_two_stage")
COMMAND = ("lyap", "{model}", "--periods", "10", "--discard", "0")
REPEATS = 7
TARGET_SECONDS = 0.6


def _seconds(argv: list[str], env: dict) -> float:
    t = time.perf_counter()
    proc = subprocess.run(argv, capture_output=True, text=True, env=env, cwd=REPO)
    seconds = time.perf_counter() - t
    if proc.returncode:
        raise RuntimeError(f"{' '.join(argv)} failed: {proc.stderr.strip()[-500:]}")
    return seconds


def measure(models=MODELS, repeats: int = REPEATS, bytecode: bool = True,
            log=lambda s: print(s, file=sys.stderr, flush=True)) -> dict:
    with tempfile.TemporaryDirectory() as pycache:
        env = {**os.environ, "PYTHONPATH": str(REPO)}
        if bytecode:
            env.pop("PYTHONDONTWRITEBYTECODE", None)
            env["PYTHONPYCACHEPREFIX"] = pycache
        return _measure(models, repeats, env, bytecode, log)


def _measure(models, repeats: int, env: dict, bytecode: bool, log) -> dict:
    available = [m for m in models if (REPO / "models" / f"{m}.py").is_file()]
    imports = [_seconds([sys.executable, "-c", "import numpy, casadi"], env) for _ in range(repeats)]
    out = {"command": "gearsym " + " ".join(COMMAND), "repeats": repeats, "target_seconds": TARGET_SECONDS,
           "bytecode_cache": bytecode, "load_at_start": os.getloadavg()[0],
           "imports_numpy_casadi": {"seconds": imports, "median": statistics.median(imports)}, "models": {}}
    for model in available:
        argv = [sys.executable, "-m", "gearsym.cli", *(a.format(model=model) for a in COMMAND)]
        first = _seconds(argv, env)  # fills the cache (compiles or reduces if it has to)
        times = [_seconds(argv, env) for _ in range(repeats)]
        out["models"][model] = {"first": first, "seconds": times, "median": statistics.median(times)}
        log(f"  start-up {model}: median {statistics.median(times):.3f} s of {repeats} (first run {first:.2f} s)")
    return out


def lines(result: dict) -> list[str]:
    rows = [f"{m}: {r['median']:.3f} s" for m, r in result["models"].items()]
    cache = "bytecode cached" if result["bytecode_cache"] else "as the environment is set"
    return [f"start-up ({result['command']}, median of {result['repeats']}, {cache}, load "
            f"{result['load_at_start']:.1f}; target <= {result['target_seconds']} s): " + ", ".join(rows),
            f"  import numpy, casadi alone: {result['imports_numpy_casadi']['median']:.3f} s"]


def main() -> None:
    parser = argparse.ArgumentParser(prog="python -m bench.speed.startup", description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=REPEATS)
    parser.add_argument("--as-set", action="store_true", help="keep PYTHONDONTWRITEBYTECODE if it is set")
    parser.add_argument("--json", action="store_true", help="print the measurements as JSON")
    args = parser.parse_args()
    result = measure(repeats=args.repeats, bytecode=not args.as_set)
    print(json.dumps(result, indent=2) if args.json else "\n".join(lines(result)))


if __name__ == "__main__":
    main()
