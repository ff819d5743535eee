"""``docs/performance.md`` and ``docs/figures/performance.png``, rendered from the benchmark's JSON.

    python -m bench.speed.report [bench/results/speed.json]

The page is a pure function of the JSON (measurements and their summary) plus
the prose in ``bench/speed/notes.md`` (why a number is what it is: written by a
person after reading a run, with no numbers of its own), so the tests render it
again from the committed record and compare it byte for byte.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

from bench.orbits.report import section
from gearsym.figures.save import save_figure
from bench.basins import report as basins_report
from bench.orbits import report as orbits_report
from bench.machine import REPO
from .summary import summarise, TARGETS

PAGE = REPO / "docs" / "performance.md"
FIGURE = REPO / "docs" / "figures" / "performance.png"
NOTES = Path(__file__).with_name("notes.md")
DEFAULT_JSON = REPO / "bench" / "results" / "speed.json"


def _ms(seconds: float) -> str:
    ms = seconds * 1e3
    return f"{ms:.3g}" if ms < 100 else f"{ms:,.0f}"


def _x(ratio: float | None) -> str:
    if ratio is None:
        return "–"
    return f"{ratio:.2f}×" if ratio < 10 else f"{ratio:,.0f}×"


def _e(err: float | None) -> str:
    return "–" if err is None else f"{err:.1e}"


def _accuracy(acc: dict) -> str:
    if "steps" in acc:
        return f"RK4, {acc['steps']} steps/period"
    return f"rtol = atol = {acc['rtol']:g}"


def _verdicts(summary: dict) -> list[str]:
    lines = ["| target | measured | goal | met |", "|---|---|---|---|"]
    for v in summary["verdicts"]:
        value = v["value"]
        shown = f"{value:d}" if isinstance(value, int) and not isinstance(value, bool) else \
            _e(value) if value < 1e-2 else (f"{value:.2f}" if value < 10 else f"{value:,.0f}")
        lines.append(f"| {v['what']} | {shown} | {v['target']} | {'yes' if v['met'] else '**no**'} |")
    return lines


def _points_table(s: dict) -> list[str]:
    lines = ["| tool | ms per point | × C | × gearsym | error, periodic points | error, chaotic points "
             "| Σλ + 2ζ/ω | − C, periodic points | setup (s) |", "|---|---|---|---|---|---|---|---|---|"]
    for label, r in s["tools"].items():
        name = f"{label}{' (C reference)' if label == s['c_reference'] else ''}"
        lines.append(f"| {name} | {_ms(r['per_point'])} | {_x(r['vs_c'])} | {_x(r['vs_gearsym'])} | "
                     f"{_e(r['errors']['periodic'])} | {_e(r['errors']['chaotic'])} | {_e(r['sum_rule'])} | "
                     f"{_e(r['same_as_c'])} | {r['setup_seconds']:.2f} ({r['setup_note']}) |")
    return lines


def _precision_table(s: dict) -> list[str]:
    lines = ["| tool | setting | ms per point | × gearsym (200 steps) | error, periodic points | "
             "error, chaotic points | setup (s) |", "|---|---|---|---|---|---|---|"]
    for tool, rows in s["precision"].items():
        picks = {base: eq[tool]["setting"] for base, eq in s["equal_accuracy"].items() if tool in eq}
        for r in rows:
            mark = "".join(f" ← as accurate as {base}" for base, setting in picks.items() if setting == r["setting"])
            lines.append(f"| {tool} | {_accuracy(r['accuracy'])}{mark} | {_ms(r['per_point'])} | "
                         f"{_x(r['vs_gearsym'])} | {_e(r['errors']['periodic'])} | {_e(r['errors']['chaotic'])} | "
                         f"{r['setup_seconds']:.2f} ({r['setup_note']}) |")
    return lines


def _reference_table(raw_model: dict) -> list[str]:
    ref = raw_model["reference"]
    first = next(iter(ref.values()))
    steps, tols = first["steps"], first["tolerances"]
    lines = ["| ω | reference λ | C, change per step halving " + f"({steps[0]} → {steps[-1]})"
             + " | C finest − ref | JiTCODE, change per tightening " + f"({tols[0]:g} → {tols[-1]:g})"
             + " | SciPy − ref | converged |", "|---|---|---|---|---|---|---|"]
    for r in ref.values():
        lams = ", ".join(f"{x:+.8f}" for x in r["reference"])
        lines.append(f"| {r['omega']:g} | {lams} | {' '.join(_e(c) for c in r['step_changes'])} | "
                     f"{_e(r['step_finest_difference'])} | {' '.join(_e(c) for c in r['tolerance_changes'])} | "
                     f"{_e(r['scipy_difference'])} | {'yes' if r['converged'] else 'no (chaotic)'} |")
    return lines


def _sweep_table(s: dict) -> list[str]:
    sw = s["sweep"]
    if not sw:
        return ["(not run)"]
    lines = ["| tool | accuracy | points | ms per point | × C | × gearsym | same exponents as C (≤ 1e-9 / ≤ 1e-2) |",
             "|---|---|---|---|---|---|---|"]
    for label, t in sw["tools"].items():
        agree = t["agree_with_c"]
        agreed = f"{agree['1e-9']} / {agree['1e-2']} of {agree['points']}" if agree else \
            f"(every {t['every']}th ω: own continuation)"
        name = f"{label}{' (C reference)' if label == sw['c_reference'] else ''}"
        lines.append(f"| {name} | {_accuracy(t['accuracy'])} | {t['points']} | {_ms(t['per_point'])} | "
                     f"{_x(t['vs_c'])} | {_x(t['vs_gearsym'])} | {agreed} |")
    return lines


def _scaling_table(raw: dict, summary: dict) -> list[str]:
    sc = summary["scaling"]
    if not sc:
        return ["(not run)"]
    work = raw["scaling"]["workloads"]
    lines = ["| workload | configuration | median (s) | min (s) | speed-up | CPU (s) | CPU / 1 thread | cores busy "
             "| stolen (s) | rows bit-identical to 1 thread |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for name, configs in sc.items():
        w = work[name]
        what = f"{name}: {w['points']} points, {w['mode']}, " + " × ".join(f"{k} {v}" for k, v in w["axes"].items())
        for label, c in configs.items():
            cpu = (f"{c['cpu']:.3f} | {c['work']:.3f} | {c['busy']:.2f}" if "cpu" in c else "– | – | –")
            steal = f"{c['steal']:.2f}" if "steal" in c else "–"
            lines.append(f"| {what} | {label} | {c['median']:.3f} | {c['min']:.3f} | {c['speedup']:.2f}× | {cpu} | "
                         f"{steal} | {'yes' if c['identical'] else '**no**'} |")
            what = ""
    return lines


def _compile_table(raw: dict) -> list[str]:
    comp = raw.get("compile")
    if not comp:
        return ["(not run)"]
    lines = ["| model | symbolic (s) | C generated (s) | C compiled (s) | second load (s) | compiled again "
             "| with crossings located: generated + compiled (s) |", "|---|---|---|---|---|---|---|"]
    for model, c in comp.items():
        f, x = c["first"], c.get("crossings", {})
        gen = f.get("build", 0.0) + f.get("generate", 0.0)
        lines.append(f"| {model} | {f.get('symbolic', 0.0):.2f} | {gen:.2f} | {f.get('compile', 0.0):.2f} | "
                     f"{c['second_process_seconds']:.2f} | {'**yes**' if c['recompiled'] else 'no'} | "
                     f"{x.get('build', 0.0) + x.get('generate', 0.0):.2f} + {x.get('compile', 0.0):.2f} |")
    return lines


def _profile_table(raw: dict) -> list[str]:
    prof = raw.get("profile")
    if not prof:
        return ["(not run)"]
    lines = [f"At ω = {prof['omega']:g}, {prof['steps_per_period']} RK4 steps per period, medians of interleaved "
             "runs of 1 and of " f"{prof['periods']} periods:", "",
             "| model | gearsym ns per step | C ns per step | gearsym / C per step | gearsym fixed µs per point "
             "| C fixed µs per point |", "|---|---|---|---|---|---|"]
    for model, e in prof["models"].items():
        g, c = e["gearsym"], e["C"]
        lines.append(f"| {model} | {g['ns_per_step']:.1f} | {c['ns_per_step']:.1f} | {e['step_ratio']:.2f} | "
                     f"{g['fixed_us_per_point']:.0f} | {c['fixed_us_per_point']:.0f} |")
    sel = prof.get("backlash_select")
    if sel:
        lines += ["", f"The one-stage C yardstick with the backlash written as gearsym's generated code writes it "
                      f"(branch-free selects, `-DBACKLASH_SELECT`): {sel['select_ms']:.2f} ms per point against "
                      f"{sel['branch_ms']:.2f} ms with if/else, **{sel['ratio']:.2f}×** (same flags: "
                      f"`{' '.join(sel['flags'])}`)."]
    return lines


def _startup_lines(raw: dict) -> list[str]:
    """Start-up and sweep overhead (bench/speed/startup.py, overhead.py), if this run measured them."""
    start, over = raw.get("startup"), raw.get("sweep_overhead")
    if not (start or over):
        return []
    out = ["## Start-up and the Python around each sweep point", ""]
    if start:
        cached = ", Python's bytecode cached as for any user" if start.get("bytecode_cache") else ""
        out += [f"`{start['command']}` end to end in a fresh process, the model's library and summary cached{cached} "
                f"(median of {start['repeats']}; target ≤ {start['target_seconds']:g} s); `import numpy, casadi` "
                f"alone: {start['imports_numpy_casadi']['median']:.2f} s.", "",
                "| model | start-up (s) | first run (s) |", "|---|---|---|"]
        out += [f"| {m} | {r['median']:.2f} | {r['first']:.2f} |" for m, r in start["models"].items()]
        out.append("")
    if over:
        out += [f"{over['model']}, {over['points']}-point continuation, {over['periods']} periods, "
                f"{over['steps_per_period']} steps per period, one worker, files written: "
                f"{over['median_ms_per_point']:.2f} ms per point, {over['median_compiled_ms_per_point']:.2f} ms of "
                f"it in the compiled loops: **{over['median_overhead']:+.1%}** around them (target ≤ "
                f"{over['target']:.0%}; median of {len(over['runs'])}).", ""]
    return out


def render(raw: dict, notes: str | None = None, orbits: dict | None = None, basins: dict | None = None) -> str:
    """The page; ``orbits``, ``basins``: the records of ``python -m bench.orbits`` and ``python -m bench.basins``,
    whose sections it adds."""
    summary = raw["summary"]
    m = raw["machine"]
    st = raw["settings"]
    out = [
        "# Performance: gearsym against its peers",
        "",
        "<!-- Generated by `python -m bench.speed.report` from `bench/results/speed.json`; do not edit. -->",
        "",
        f"Measured {raw['date']} in one run of `{raw['command']}` ({raw['seconds'] / 60:.0f} min) on "
        f"{m['cpu_model']} ({m['nproc']} cores, {', '.join(m['cpu_simd'])}; load at start "
        f"{', '.join(map(str, m['loadavg_at_start'] or []))}), {m['cc_version']}, Python {m['python']}, "
        f"commit `{(m['git_commit'] or '?')[:10]}`. The machine is shared and noisy, so only **ratios measured in "
        "this one run** are reported as results; absolute times are there to read the ratios by.",
        "",
        "**The task**: the full Lyapunov spectrum of the one-stage model (Eq. 2, 2 exponents) and the "
        f"flexible-shaft model (Eq. 9, 4 exponents) at the models' default parameters, {st['periods']} forcing "
        f"periods of which {st['discard']} are discarded, tangent vectors re-orthonormalised (modified "
        "Gram–Schmidt) every period; at ω ∈ {" + ", ".join(f"{w:g}" for w in next(iter(raw["models"].values()))["omegas"])
        + "} from the models' initial state, and along the 191-point continuation ω = 0.1, 0.11, …, 2.0. "
        f"Fixed-step tools use RK4 with {st['steps_per_period']} steps per period (the paper's setting); the "
        "rows named *gearsym* run the paper's plain RK4 (`Integration.paper()`), the C programs' scheme, and "
        "*gearsym (crossings located)* gearsym's default, which splits the steps that cross a backlash kink. The "
        "adaptive ones (JiTCODE, SciPy) are timed at several tolerances and compared **at equal accuracy**: at "
        "the loosest tolerance whose error is no larger than gearsym's.",
        "",
        "## Targets",
        "",
        *_verdicts(summary),
        "",
        "![work against precision, time per point relative to the hand-written C, and scaling]"
        "(figures/performance.png)",
        "",
    ]
    for model, s in summary["models"].items():
        rm = raw["models"][model]
        out += [
            f"## {model}: one point at a time",
            "",
            f"All at {st['steps_per_period']} RK4 steps per period; {st['repeats']} interleaved repetitions "
            f"(median per point, summed over the ω). Periodic points (converged reference): "
            f"{', '.join(f'{w:g}' for w in s['periodic_omegas']) or 'none'}; chaotic: "
            f"{', '.join(f'{w:g}' for w in s['chaotic_omegas']) or 'none'}. gearsym's error on the periodic "
            f"points: {_e(s['gearsym_error'])}. Every tool starts from the same state; *− C* is the largest "
            "exponent difference from the C reference on the periodic points: rounding for the rows that run the "
            "C's scheme (like for like), the scheme's own error for the others.",
            "",
            *_points_table(s),
            "",
            f"### {model}: work against precision",
            "",
            "Each tool once per setting, the same points (the 200-step rows are the medians above):",
            "",
            *_precision_table(s),
            "",
            f"### {model}: the reference",
            "",
            *_reference_table(rm),
            "",
            f"### {model}: the 191-point continuation sweep",
            "",
            *_sweep_table(s),
            "",
        ]
    out += ["## Every core, and beyond one machine", ""]
    if raw.get("scaling"):
        sc = raw["scaling"]
        dask = f"; the Dask LocalCluster took {sc['dask_startup_seconds']:.1f} s to start (not in the times)" \
            if "dask_startup_seconds" in sc else f"; Dask: {sc.get('dask', 'not run')}"
        out += [f"flexible_shaft through `gearsym.sweep.run_sweep` on a prebuilt model, {sc['periods']} periods "
                f"({sc['discard']} discarded), {st['repeats']} interleaved repetitions after a warm-up, "
                f"{sc['cores']} cores{dask}.", ""]
    out += [*_scaling_table(raw, summary), "", "## Where the time goes", "", *_profile_table(raw), "",
            "## Compile time", "",
            "Each model loaded in a fresh process with an empty cache, then again in another fresh process:", "",
            *_compile_table(raw), "", f"Target: at most {TARGETS['compile_seconds']:g} s of C compilation per "
            "model, and nothing compiled again for an unchanged model.", "", *_startup_lines(raw)]
    if orbits:
        out += section(orbits)
    if basins:
        out += basins_report.section(basins)
    if notes:
        out += [notes.rstrip(), ""]
    return "\n".join(out)


def figure(raw: dict, path: Path) -> Path:
    import matplotlib.pyplot as plt


    summary = raw["summary"]
    models = list(summary["models"])
    fig, axes = plt.subplots(2, 2, figsize=(11, 8))
    markers = dict(zip(["gearsym", "C", "Numba RK4", "JiTCODE", "SciPy RK45"], "os^Dv"))
    for ax, model in zip(axes[0], models):  # work-precision: one line per tool
        s = summary["models"][model]
        for tool, rows in s["precision"].items():
            pts = sorted((r["per_point"] * 1e3, r["errors"]["periodic"]) for r in rows
                         if r["errors"]["periodic"] is not None)
            if pts:
                ax.plot(*zip(*pts), marker=markers.get(tool, "o"), label=tool)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("time per point (ms)")
        ax.set_ylabel("largest exponent error, periodic points")
        ax.set_title(f"{model}: work against precision", fontsize=9)
        ax.grid(True, which="major", alpha=0.3)
        if ax.get_lines():
            ax.legend(fontsize=7)
        else:
            ax.text(0.5, 0.5, "no periodic point: no converged reference", ha="center", transform=ax.transAxes)
    ax = axes[1][0]
    c_label = "C (fastest build)"
    labels: list[str] = []
    for s in summary["models"].values():
        for label in [*s["tools"], *s["equal_accuracy"]["gearsym"]]:
            label = c_label if label == s["c_reference"] else label
            if label not in labels and not label.startswith("C "):
                labels.append(label)
    width = 0.8 / len(models)
    for i, (model, s) in enumerate(summary["models"].items()):
        values = []
        for label in labels:
            key = s["c_reference"] if label == c_label else label
            values.append(s["tools"][key]["vs_c"] if key in s["tools"] else
                          s["equal_accuracy"]["gearsym"].get(key, {}).get("vs_c", float("nan")))
        xs = [j + (i - (len(models) - 1) / 2) * width for j in range(len(labels))]
        ax.bar(xs, values, width, label=model)
    ax.set_yscale("log")
    ax.axhline(1.0, color="k", lw=0.8)
    ax.set_xticks(range(len(labels)))
    ax.set_xticklabels([label.replace(" (", "\n(") for label in labels], fontsize=7)
    ax.set_ylabel("time per point / hand-written C")
    ax.set_title("one point, full spectrum (adaptive tools at gearsym's accuracy)", fontsize=9)
    ax.legend(fontsize=8)
    ax = axes[1][1]
    sc = summary["scaling"]
    if sc:
        names = list(sc)
        configs = list(next(iter(sc.values())))
        width = 0.8 / len(configs)
        for i, c in enumerate(configs):
            xs = [j + (i - (len(configs) - 1) / 2) * width for j in range(len(names))]
            ax.bar(xs, [sc[n][c]["speedup"] for n in names], width, label=c)
        ax.axhline(raw["scaling"]["cores"], color="k", lw=0.8, ls="--")
        ax.set_xticks(range(len(names)))
        ax.set_xticklabels(names)
        ax.set_ylabel("speed-up over 1 thread")
        ax.set_title("flexible_shaft sweeps on every core", fontsize=9)
        ax.set_ylim(0, raw["scaling"]["cores"] * 1.25)
        ax.legend(fontsize=7, loc="upper center", ncol=2)
    fig.tight_layout()
    return save_figure(fig, path, dpi=100)


def write_report(json_path: Path = DEFAULT_JSON, page: Path = PAGE, figure_path: Path = FIGURE,
                 orbits_path: Path | None = None, orbits_figure: Path | None = None) -> list[Path]:
    """The page and the figure from the benchmark's JSON, and (if its record exists) the orbits' section and
    figure from ``bench/results/orbits.json``."""
    raw = json.loads(Path(json_path).read_text())
    raw["summary"] = summarise(raw)  # recomputed: the page never shows a number the raw data does not give
    notes = NOTES.read_text() if NOTES.exists() else None
    orbits_path = orbits_path or orbits_report.RECORD
    orbits = json.loads(orbits_path.read_text()) if orbits_path.is_file() else None
    basins = json.loads(basins_report.RECORD.read_text()) if basins_report.RECORD.is_file() else None
    page.write_text(render(raw, notes, orbits, basins))
    written = [page, figure(raw, figure_path)]
    if orbits:
        written.append(orbits_report.figure(orbits, orbits_figure or figure_path.with_name(orbits_report.FIGURE.name)))
    return written


if __name__ == "__main__":
    for p in write_report(Path(sys.argv[1]) if len(sys.argv) > 1 else DEFAULT_JSON):
        print(f"wrote {p}")
