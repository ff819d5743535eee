"""``python -m bench.faults``: ``gearsym explain`` naming a tooth fault on 2 records x 16 pinion revolutions of a
20/53 pair (issue 28's target: under 60 s on 2 cores).

The data: gearsym's one-stage pair with tooth counts 20 and 53, a crack taking 30 % of the stiffness of the
wheel's tooth 7, at omega = 1.2 and 1.6, 25 samples per mesh period and 1 % noise, 320 mesh periods per record
(16 pinion revolutions, 6.04 of the wheel: 7 simulated, cut) after a transient of 2 wheel revolutions. ``load_measurements`` +
``explain`` (the whole library, fitting zeta and B1) run in a fresh process with an empty compile cache, so
compiling the model's windows is part of the time, as for a user's first run; and once more with the cache
warm. Writes bench/results/faults.json with the wall and CPU seconds, the load average and the verdict.
"""
from __future__ import annotations

import argparse
import datetime as _dt
import json
import math
import os
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
DEFAULT_OUT = REPO / "bench" / "results" / "faults.json"
TEETH = (20, 53)
TRUTH = {"q_gear2": 0.3, "tooth_gear2": 7}

_SIMULATE = ["gearsym", "simulate", "one_stage", "--teeth", "20,53", "--effect", "tooth_fault_gear2",
             "--set", "q_gear2=0.3", "--set", "tooth_gear2=7", "--record", "omega=1.2", "--record", "omega=1.6",
             "--periods", "9", "--discard", "2", "--samples-per-period", "25", "--noise", "0.01", "--seed", "1"]
#: mesh periods kept of each record (7 wheel revolutions simulated): 16 pinion revolutions
KEPT = 16 * TEETH[0]

#: what the timed process runs
_CHILD = r"""
import json, os, sys, time
args = json.loads(sys.argv[1])
start, cpu = time.perf_counter(), time.process_time()
import gearsym
from gearsym import explain, load_measurements
system = gearsym.load("one_stage", teeth=(20, 53))
data = load_measurements([args["data"]], system)
ex = explain(system, data, ["zeta", "B1"])
seconds = time.perf_counter() - start
children = os.times()
report = ex.as_dict()
print(json.dumps({"seconds": seconds, "cpu_seconds": time.process_time() - cpu + children.children_user
                  + children.children_system, "effects": ex.effects, "faults": report["faults"],
                  "error_before": ex.base.error, "error_after": ex.final.error, "candidates_tried": len(ex.tried)}))
"""


def log(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


def run(data: Path, cache: str) -> dict:
    env = {**os.environ, "PYTHONPATH": str(REPO), "GEARSYM_CACHE": cache}
    out = subprocess.run([sys.executable, "-c", _CHILD, json.dumps({"data": str(data)})], env=env, cwd=REPO,
                         capture_output=True, text=True)
    if out.returncode:
        raise RuntimeError(out.stderr[-2000:])
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench.faults", description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=DEFAULT_OUT)
    args = parser.parse_args(argv)
    results = {"command": "python -m bench.faults", "target_seconds": 60,
               "date": _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
               "now": subprocess.run(["git", "rev-parse", "HEAD"], cwd=REPO, capture_output=True, text=True).stdout.strip(),
               "cores": os.cpu_count(), "loadavg_at_start": list(os.getloadavg()), "simulate": " ".join(_SIMULATE)}
    with tempfile.TemporaryDirectory(prefix="gearsym-bench-faults-") as tmp:
        data = Path(tmp) / "measured.csv"
        simulated = Path(tmp) / "simulated.csv"
        subprocess.run([*_SIMULATE, "--out", str(simulated)], check=True, capture_output=True,
                       env={**os.environ, "GEARSYM_CACHE": str(Path(tmp) / "sim-cache")})
        lines = simulated.read_text().splitlines()
        kept = [lines[0]] + [row for row in lines[1:] if float(row.split(",")[0]) < KEPT * 2 * math.pi - 1e-9]
        data.write_text("\n".join(kept) + "\n")
        results["samples"] = len(kept) - 1
        with tempfile.TemporaryDirectory(prefix="gearsym-bench-cache-") as cache:
            log("explain, empty compile cache ...")
            results["cold"] = run(data, cache)
            log(f"  {results['cold']['seconds']:.1f} s ({results['cold']['cpu_seconds']:.1f} s CPU)")
            log("explain, cache warm ...")
            results["warm"] = run(data, cache)
            log(f"  {results['warm']['seconds']:.1f} s ({results['warm']['cpu_seconds']:.1f} s CPU)")
    results["loadavg_at_end"] = list(os.getloadavg())
    results["within_target"] = results["cold"]["seconds"] < 60
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(results, indent=1) + "\n")
    fault = (results["cold"]["faults"] or [{}])[0]
    print(f"explain, 2 records x 16 pinion revolutions of a 20/53 pair: {results['cold']['seconds']:.1f} s cold "
          f"({results['cold']['cpu_seconds']:.1f} s CPU), {results['warm']['seconds']:.1f} s warm; found "
          f"{results['cold']['effects']}: tooth {fault.get('tooth')} of {fault.get('gear')}, stiffness "
          f"{fault.get('stiffness_change_percent', float('nan')):.1f} %; load average at start "
          f"{results['loadavg_at_start'][0]:.1f}")
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
