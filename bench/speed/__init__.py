"""One run, every tool, one task: gearsym against its peers (issue 6).

    python -m bench.speed            # the full benchmark (~10 min), writes bench/results/speed.json
    python -m bench.speed --quick    # a smoke test of every stage (~1 min), writes nothing by default
    python -m bench.speed.report     # docs/performance.md and its figure, from bench/results/speed.json

Stages, one module each: ``reference`` (step-halved converged exponents),
``points`` (full spectra at four omegas in every tool), ``sweep`` (the
191-point continuation in every tool), ``scaling`` (all cores, Dask),
``compile_time`` (C per model, and no recompilation), ``summary`` (errors,
equal-accuracy ratios, verdicts: pure functions of the raw measurements) and
``report`` (JSON -> markdown + figure, byte-deterministic).
"""
