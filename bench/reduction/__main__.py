"""``python -m bench.reduction``: how long a model takes from its declaration to its C, by stage (issues 35, 39).

Each model in a fresh process with an empty cache: the reduction (``gearsym.reduce``: Lagrange's equations, the
coordinates, the frame's weights, the self-check, the nondimensional form), the engine's system with its physical
values (``gearsym.load``), then its C and manifest generated (``generate_model`` into a temporary folder, not
compiled: gcc is not SymPy's). CPU seconds of the process (``time.process_time``: a loaded machine inflates wall
time most) and wall seconds. ``--against DIR`` runs the same in the gearsym of another checkout (``git archive
main | tar -x -C DIR``), interleaved model by model, and records the ratios: only ratios within one run compare.

    python -m bench.reduction                      # writes bench/results/reduction.json
    python -m bench.reduction --against /tmp/main  # ... with the former code's times and the ratios
    python -m bench.reduction --models planetary_translational --out /tmp/r.json
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

from bench.machine import REPO, machine_info, user_environment

MODELS = ("planetary_translational", "planetary_translational:planets=4", "spur_pair_bearings",
          "planetary_two_stage", "two_stage_gearbox", "planetary", "one_stage")

#: the child: one model, its stages timed, a line of JSON (self-contained: it runs in either checkout's gearsym)
CHILD = r"""
import json, sys, tempfile, time, warnings
from pathlib import Path
warnings.simplefilter("ignore")
start = time.process_time(), time.perf_counter()
import gearsym
from gearsym.codegen.generated import generate_model
from gearsym.registry import load_model
name, _, given = sys.argv[1].partition(":")
options = {k: int(v) for k, v in (kv.split("=") for kv in given.split(","))} if given else {}
out = {}
def stage(key, f):
    c, w = time.process_time(), time.perf_counter()
    value = f()
    out[key] = {"cpu": round(time.process_time() - c, 3), "wall": round(time.perf_counter() - w, 3)}
    return value
out["import"] = {"cpu": round(time.process_time() - start[0], 3), "wall": round(time.perf_counter() - start[1], 3)}
model = stage("declare", lambda: load_model(name, options or None))
stage("reduce", lambda: gearsym.reduce(model))
system = stage("system", lambda: gearsym.load(name, **options))
stage("generate", lambda: generate_model(system, Path(tempfile.mkdtemp()), compile=False))
out["total"] = {"cpu": round(time.process_time() - start[0], 3), "wall": round(time.perf_counter() - start[1], 3)}
print(json.dumps(out))
"""


def run_one(model: str, source: Path, environment: dict) -> dict:
    with tempfile.TemporaryDirectory(prefix="bench-reduction-cache-") as cache:
        env = {**environment, "GEARSYM_CACHE": cache, "PYTHONPATH": str(source)}
        done = subprocess.run([sys.executable, "-c", CHILD, model], capture_output=True, text=True, env=env,
                              cwd=source, timeout=3600)
    if done.returncode != 0:
        return {"error": (done.stderr.strip().splitlines() or ["failed"])[-1]}
    return json.loads(done.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench.reduction", description=__doc__.splitlines()[0])
    parser.add_argument("--models", nargs="+", default=list(MODELS), metavar="MODEL[:option=value]")
    parser.add_argument("--against", type=Path, default=None, metavar="DIR",
                        help="another checkout whose gearsym runs the same, model by model (the former code)")
    parser.add_argument("--out", type=Path, default=REPO / "bench" / "results" / "reduction.json")
    args = parser.parse_args(argv)
    results = {"machine": machine_info(), "command": "python -m bench.reduction " + " ".join(argv or sys.argv[1:]),
               "models": {}}
    environment = user_environment("reduction")  # (one bytecode folder: the first run of each checkout fills it)
    sources = [REPO] + ([args.against.resolve()] if args.against is not None else [])
    for source in sources:  # (that first run, not timed: Python compiling SymPy's bytecode is not the reduction)
        run_one("one_stage", source, environment)
    for model in args.models:
        entry = {"this": run_one(model, REPO, environment)}
        if args.against is not None:
            entry["against"] = run_one(model, args.against.resolve(), environment)
            ok = all("error" not in entry[k] for k in ("this", "against"))
            entry["ratio_cpu"] = {s: round(entry["against"][s]["cpu"] / max(entry["this"][s]["cpu"], 1e-3), 2)
                                  for s in ("reduce", "system", "generate", "total")} if ok else None
        results["models"][model] = entry
        this = entry["this"]
        line = "error: " + this["error"] if "error" in this else (
            f"reduce {this['reduce']['cpu']:.1f} s, system {this['system']['cpu']:.1f} s, "
            f"generate {this['generate']['cpu']:.1f} s, total {this['total']['cpu']:.1f} s CPU "
            f"({this['total']['wall']:.1f} s wall)")
        if entry.get("ratio_cpu"):
            line += f"; former total {entry['against']['total']['cpu']:.1f} s CPU ({entry['ratio_cpu']['total']}x)"
        print(f"{model}: {line}", file=sys.stderr, flush=True)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(results, indent=2, sort_keys=True) + "\n")
    print(f"wrote {args.out}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
