"""``python -m bench.fit``: ``gearsym explain`` before and after the fit ran through compiled windows, in one run.

Two cases, the issue's: the one-stage model (x measured) and the flexible shaft (4 states, x1 measured),
each with data of a cubic stiffness at omega = 1.2 and 1.6 (1 % noise, 16 periods each). Each tree runs
``load_measurements`` + ``explain`` on the same CSV in a fresh process with an empty compile cache, so
compiling is part of the time; the reference tree is the commit ``--reference`` (default: where this
branch left main), extracted with ``git archive``. Two candidate lists: the whole library of each tree
(what a user gets), and one list both trees know (the same search). Writes bench/results/fit.json.
"""
from __future__ import annotations

import argparse
import datetime as _dt
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import gearsym
from gearsym.fit import augment

REPO = Path(__file__).resolve().parents[2]
DEFAULT_OUT = REPO / "bench" / "results" / "fit.json"
CASES = {"one_stage": "x", "flexible_shaft": "x1"}
COMMON = ["cubic_stiffness", "coulomb_friction", "coast_side_stiffness"]

#: what each process runs: the same calls in either tree
_CHILD = r"""
import json, sys, time
args = json.loads(sys.argv[1])
import gearsym
from gearsym import explain, load_measurements
system = gearsym.load(args["model"])
start = time.perf_counter()
data = load_measurements([args["data"]], system)
ex = explain(system, data, ["zeta", "B1"], candidates=args["candidates"])
seconds = time.perf_counter() - start
print(json.dumps({"seconds": seconds, "effects": ex.effects, "error_before": ex.base.error,
                  "error_after": ex.final.error, "candidates_tried": len(ex.tried),
                  "k3": ex.final.fit.estimates.get("k3")}))
"""


def log(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


def simulate(model: str, coordinate: str, path: Path) -> None:
    """The measured data, from the current tree (a CSV both trees read)."""
    truth = augment(gearsym.load(model), ["cubic_stiffness"], values={"k3": 0.02})
    table = gearsym.simulate_measurements(truth, options=gearsym.Integration(periods=116, discard=100),
                                          samples_per_period=40, noise=0.01, seed=1,
                                          records=[{"omega": 1.2}, {"omega": 1.6}])
    columns = ["tau", "record", "omega", coordinate]
    rows = [",".join(columns)] + [",".join(repr(float(table[c][i])) if c != "record" else str(int(table[c][i]))
                                           for c in columns) for i in range(table.rows)]
    path.write_text("\n".join(rows) + "\n")


def run(tree: Path, model: str, data: Path, candidates) -> dict:
    with tempfile.TemporaryDirectory(prefix="gearsym-bench-cache-") as cache:
        env = {**os.environ, "PYTHONPATH": str(tree), "GEARSYM_CACHE": cache}
        args = json.dumps({"model": model, "data": str(data), "candidates": candidates})
        out = subprocess.run([sys.executable, "-c", _CHILD, args], env=env, cwd=tree, capture_output=True, text=True)
    if out.returncode:
        raise RuntimeError(f"{tree}: {out.stderr[-2000:]}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench.fit", description=__doc__.splitlines()[0])
    parser.add_argument("--reference", default=None, help="the commit to compare with (default: merge-base with main)")
    parser.add_argument("--out", type=Path, default=DEFAULT_OUT)
    args = parser.parse_args(argv)
    reference = args.reference or subprocess.run(["git", "merge-base", "HEAD", "main"], cwd=REPO, capture_output=True,
                                                 text=True, check=True).stdout.strip()
    command = " ".join(["python -m bench.fit", *(sys.argv[1:] if argv is None else argv)])
    results = {"command": command, "date": _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
               "reference": reference, "now": subprocess.run(["git", "rev-parse", "HEAD"], cwd=REPO,
                                                             capture_output=True, text=True).stdout.strip(),
               "loadavg_at_start": list(os.getloadavg()), "cases": {}}
    with tempfile.TemporaryDirectory(prefix="gearsym-bench-fit-") as tmp:
        tmp = Path(tmp)
        before = tmp / "before"
        before.mkdir()
        archive = subprocess.run(["git", "archive", reference, "gearsym", "models"], cwd=REPO, capture_output=True, check=True)
        subprocess.run(["tar", "-x", "-C", str(before)], input=archive.stdout, check=True)
        for model, coordinate in CASES.items():
            data = tmp / f"{model}.csv"
            simulate(model, coordinate, data)
            case = {}
            for label, candidates in (("whole library", None), ("same candidates", COMMON)):
                rows = {}
                for tree_name, tree in (("before", before), ("now", REPO)):
                    log(f"{model}, {label}, {tree_name} ...")
                    rows[tree_name] = run(tree, model, data, candidates)
                    log(f"  {rows[tree_name]['seconds']:.1f} s, effects {rows[tree_name]['effects']}")
                rows["ratio"] = rows["before"]["seconds"] / rows["now"]["seconds"]
                case[label] = rows
            results["cases"][model] = case
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(results, indent=1) + "\n")
    for model, case in results["cases"].items():
        for label, rows in case.items():
            print(f"{model:15s} {label:16s} before {rows['before']['seconds']:6.1f} s  now {rows['now']['seconds']:6.1f} s"
                  f"  ratio {rows['ratio']:.1f}x")
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
