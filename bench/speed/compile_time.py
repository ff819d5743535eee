"""Compile time per model, from an empty cache, and proof that an unchanged model is not compiled again.

Each model is loaded and compiled with the paper's plain RK4 twice, in fresh
Python processes sharing one empty temporary cache (``GEARSYM_CACHE``): the
first process compiles the C (the committed ``generated/`` source when its hash
matches, so the C is not even regenerated), the second must find the library
and compile nothing. The times are gearsym's own: ``symbolic`` (``gearsym.load``,
which reduces the model, and the code hash), then ``CompiledModel.timings``:
``build``/``generate`` (CasADi functions and C, only if no committed C
matched) and ``compile`` (the C compiler). A third process compiles the model
with the crossings located (the other scheme, its own C).
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time

from bench.machine import REPO

_PROBE = """
import json, sys, time
import gearsym
SCHEMES = {"paper": gearsym.Integration.paper(backend="compiled"),
           "located": gearsym.Integration(locate_crossings=True, backend="compiled")}
t = time.perf_counter()
system = gearsym.load(sys.argv[1])
loaded = time.perf_counter() - t
cm = gearsym.compile_model(system, SCHEMES[sys.argv[2]])
print(json.dumps({"timings": {**cm.timings, "symbolic": loaded + cm.timings["symbolic"]}, "library": str(cm.library)}))
"""


def _load(model: str, cache: str, scheme: str = "paper") -> dict:
    env = {**os.environ, "GEARSYM_CACHE": cache}
    t = time.perf_counter()
    proc = subprocess.run([sys.executable, "-c", _PROBE, model, scheme], capture_output=True, text=True, env=env,
                          cwd=REPO)
    wall = time.perf_counter() - t
    if proc.returncode != 0:
        raise RuntimeError(f"loading {model} failed:\n{proc.stderr[-2000:]}")
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    out["process_seconds"] = wall
    return out


def measure(models: list[str]) -> dict:
    out = {}
    with tempfile.TemporaryDirectory(prefix="gearsym-cache-") as cache:
        for model in models:
            first, second = _load(model, cache), _load(model, cache)
            out[model] = {
                "first": first["timings"], "first_process_seconds": first["process_seconds"],
                "second": second["timings"], "second_process_seconds": second["process_seconds"],
                "recompiled": "compile" in second["timings"],
                "same_library": first["library"] == second["library"],
                "crossings": _load(model, cache, "located")["timings"],
            }
    return out
