"""The data loop's report: its figures (where the held-out residual lives, the one-period-ahead prediction, a
tooth-by-tooth form's values tooth by tooth), and
the folder of page, data and figures written together (:func:`write_report`, the pages from
:mod:`gearsym.fit.report`); :func:`explain_files`, the whole loop from measurement files to that folder."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..checks import json_safe
from ..data import load_measurements
from ..files.atomic import write_atomically
from ..files.outputs import check_folder
from ..files.sets import written_together
from ..fit.effects import augment
from ..fit.report import PARTIAL_MARKER, REPORT_FILES, TEETH_FIGURE, derived_model_page, report_page
from ..fit.selection import Candidate, Explanation, explain, record_label
from ..fit.tooth_forms import standing_out, tooth_values
from ..fit.tooth_scan import from_record_start
from ..system import FirstOrderSystem
from .save import finish, pyplot, save_figure


def explain_files(paths, system, fit, *, out=None, time_scale=None, held_out: float = 0.25, candidates=None,
                  execution=None, options=None, channels=None, bias=None, terms=(), harmonics=None, **values):
    """The whole loop from files: load ``paths`` for ``system`` (``values`` fix parameter values; ``channels``
    declares combinations measured as one column), explain (``bias``: channels with an unknown offset, by default
    the acceleration channels; ``terms``: hand-written terms tried as effects), and with ``out`` write the report
    there. Returns the report's dict (the keys of report.json)."""
    if out is not None:
        check_folder(out)
    measurements = load_measurements(paths, system, time_scale=time_scale, channels=channels, **values)
    system = system.with_values(**values)
    extra = {"options": options} if options else {}
    if harmonics is not None:
        extra["harmonics"] = harmonics
    ex = explain(system, measurements, fit, held_out=held_out, candidates=candidates, execution=execution,
                 bias=bias, terms=terms, **extra)
    if out is not None:
        return write_report(ex, system, out, measurements.sources)

    return json_safe(ex.as_dict())


def write_report(ex: Explanation, system: FirstOrderSystem, out: str | Path, sources=()) -> dict:
    """Write DIR/report.md, DIR/report.json, DIR/residuals.png, DIR/prediction.png and DIR/derived_model.md (and
    DIR/teeth.png when a tooth-by-tooth form was tried), all or none: a failure or a kill while they are made
    leaves the previous report as it was (never a new report.json beside an old report.md)."""
    teeth = _tooth_candidate(ex)
    names = REPORT_FILES + ((TEETH_FIGURE,) if teeth is not None else ())
    with written_together(out, names, PARTIAL_MARKER, "the report") as stage:
        data = json_safe(ex.as_dict())
        write_atomically(stage / "report.json", json.dumps(data, indent=1, allow_nan=False) + "\n")
        residual_figure(ex, system, stage / "residuals.png")  # (fitted once, as they are written)
        prediction_figure(ex, system.name, stage / "prediction.png")
        if teeth is not None:
            save_figure(tooth_figure(ex, teeth, system.name, sources), stage / TEETH_FIGURE, dpi=100)
        effects = [ex.library[e] for e in ex.effects]
        derived = augment(system, effects) if effects else system
        write_atomically(stage / "derived_model.md", derived_model_page(system, derived, effects))
        write_atomically(stage / "report.md", report_page(ex, system, derived, data, sources))
    stale = Path(out) / TEETH_FIGURE
    if teeth is None and stale.is_file() and not stale.is_symlink():  # (a previous run's, not this report's)
        stale.unlink()
    return data


def _views(c: Candidate, system: FirstOrderSystem):
    """Mesh phase, the mesh coordinate and its rate along the prediction, and the first channel's residual."""
    p = c.prediction
    names = system.state_names
    mesh = next((cp for cp in system.couplings if cp.kind == "mesh"), None)
    x = names.index(mesh.coordinate) if mesh else 0
    v = names.index(mesh.velocity) if mesh else min(1, len(names) - 1)
    channel = next(iter(p.residual))
    return np.mod(p.tau, 2 * np.pi), p.states[x], p.states[v], p.residual[channel], channel, names[x], names[v]


def _tooth_candidate(ex: Explanation) -> Candidate | None:
    """The tooth-by-tooth candidate a report draws: the chosen one, else the best tried."""
    tried = [c for c in ex.tried if c.regularised is not None or any(ex.library[e].gears for e in c.effects)]
    chosen = [c for c in tried if c is ex.final]
    return (chosen or sorted(tried, key=lambda c: c.error))[0] if tried else None


def tooth_figure(ex: Explanation, c: Candidate, system_name: str = "", sources=()):
    """Every tooth's value of a tooth-by-tooth form (its regularised fit, ± one standard error), gear by gear,
    counted from the first record's start; the teeth that stand out in red, each gear's median dashed (a level
    shared by every tooth of one gear and taken back by every tooth of the other is one no record can tell from
    nothing: compare a tooth with its gear's median)."""
    plt = pyplot()
    e = next(ex.library[name] for name in c.effects if ex.library[name].gears)
    every = c.regularised or c.fit
    values = tooth_values(e, every.estimates, every.stderr)
    out = standing_out(values)
    stiffness = e.name.startswith("tooth_stiffness")
    starts = ex.info.get("records", {})
    first_key = next(iter(starts), None)
    start = starts.get(first_key, 0.0)
    order = next((float(cp.order or 1) for cp in (ex.system.couplings if ex.system else ())
                  if cp.coordinate == e.coordinate), 1.0)
    fig, axs = plt.subplots(1, len(values), figsize=(5 + 0.12 * sum(len(v) for v in values.values()), 4.0),
                            constrained_layout=True, squeeze=False, sharey=True,
                            gridspec_kw={"width_ratios": [len(v) for v in values.values()]})
    scale = 100 if stiffness else 1
    for ax, (gear, vs) in zip(axs[0], values.items()):
        Z = len(vs)
        counted = np.array([from_record_start(n, Z, start, order) for n in range(1, Z + 1)])
        shown = np.array([-v * scale if stiffness else v for v, _ in vs])
        errs = np.array([(err or 0.0) * scale for _, err in vs])
        colours = ["C3" if n in out[gear] else "0.55" for n in range(1, Z + 1)]
        ax.bar(counted, shown, color=colours, yerr=errs, capsize=2, error_kw={"lw": 0.8})
        ax.axhline(0, color="k", lw=0.6)
        ax.axhline(np.median(shown), color="0.3", lw=0.8, ls="--")
        ax.set_xticks(np.arange(1, Z + 1)[:: max(1, Z // 20)])
        ax.set_xlabel(f"tooth of {gear} ({Z} teeth)")
        named = sorted(from_record_start(n, Z, start, order) for n in out[gear])
        ax.set_title(f"{gear}: standing out (red): {', '.join(map(str, named)) or 'none'}", fontsize=9)
    axs[0][0].set_ylabel("mesh stiffness change while in mesh [%]" if stiffness else
                         "profile error while carrying the load\n[length unit of the mesh coordinate]")
    state = "chosen" if c is ex.final else f"tried, not chosen (held-out error {c.error:.3g})"
    data = f"; data {', '.join(Path(str(s)).name for s in sources)}" if sources else ""
    record = f" ({record_label(first_key)})" if first_key is not None else ""
    fig.suptitle(f"{system_name}: {e.name}, every tooth of both gears fitted together (regularised; bars ± one "
                 f"standard error, dashed: the gear's median) — {state}{data}; teeth counted from the first "
                 f"record's start{record}", fontsize=8.5)
    return fig


def residual_figure(ex: Explanation, system: FirstOrderSystem, path: str | Path | None = None):
    """Where the held-out residual lives (against the mesh phase, the coordinate and its rate) and its spectrum:
    the model as declared always, and after when effects were added; written to ``path`` if given."""
    plt = pyplot()
    fig, axs = plt.subplots(1, 4, figsize=(17, 3.8), constrained_layout=True)
    shown = [(ex.base, "0.6", "as declared")]
    if ex.effects:
        shown.append((ex.final, "k", "+" + "+".join(ex.effects)))
    for c, color, label in shown:
        phase, x, v, r, channel, xname, vname = _views(c, system)
        for ax, what in zip(axs[:3], (phase, x, v)):
            ax.plot(what, r, ".", ms=2, color=color, label=label)
    titles = ("residual against the mesh phase", f"against {xname}", f"against {vname}")
    for ax, xlabel, title in zip(axs, ("τ mod 2π", f"{xname} (predicted)", f"{vname} (predicted)"), titles):
        ax.set_xlabel(xlabel)
        ax.set_title(title, fontsize=10)
    axs[0].set_ylabel(f"held-out residual of {channel}")
    axs[0].legend(fontsize=8, markerscale=4)
    spectra = [(ex.spectrum, "0.6", "as declared")] + ([(ex.final_spectrum, "k", "after")] if ex.effects else [])
    width = 0.8 / len(spectra)
    for i, (s, color, label) in enumerate(spectra):
        if s is None:
            continue
        orders = np.array(s.orders)
        axs[3].bar(orders + (i - (len(spectra) - 1) / 2) * width, s.amplitude, width, color=color, label=label)
        for o in s.standout:
            axs[3].annotate(str(o), (o + (i - (len(spectra) - 1) / 2) * width, s.amplitude[o - 1]), ha="center",
                            va="bottom", fontsize=8)
    if ex.spectrum is not None:
        axs[3].axhline(ex.spectrum.noise, color="C3", lw=0.8, ls="--", label="white noise (1 s.e.)")
        axs[3].set_xticks(list(ex.spectrum.orders))
    axs[3].set_xlabel("harmonic of the forcing")
    axs[3].set_ylabel("amplitude / channel spread")
    axs[3].set_title("held-out residual's spectrum (numbers: orders tried)", fontsize=10)
    axs[3].legend(fontsize=8)
    fig.suptitle(f"{system.name}: the held-out residual of {channel}, {_which(ex.base.prediction)}", fontsize=10)
    return finish(fig, path, dpi=100)


def _which(prediction) -> str:
    """'every held-out window (12) of measured.csv record 1 (omega=1.2), measured.csv record 2 (omega=1.6)'."""
    records = prediction.records()
    return (f"every held-out window ({prediction.pairs}) of " + "; ".join(records) if records
            else f"every held-out window ({prediction.pairs})")


def prediction_figure(ex: Explanation, system_name: str = "", path: str | Path | None = None):
    """The measurement and the predictions of the first three held-out windows of the first record (the
    title says which); written to ``path`` if given."""
    plt = pyplot()
    p0, p1 = ex.base.prediction, ex.final.prediction
    channel = next(iter(p0.measured))
    count, shown = p0.shown(3)
    idx = np.arange(count)
    fig, ax = plt.subplots(figsize=(11, 3.6), constrained_layout=True)
    ax.plot(idx, p0.measured[channel][:count], ".", ms=3, color="C0", label="measured (held out)")
    ax.plot(idx, p0.predicted[channel][:count], "-", color="0.6", lw=1.2,
            label=f"as declared: error {ex.base.error:.3g}")
    if ex.effects:
        ax.plot(idx, p1.predicted[channel][:count], "-", color="k", lw=1,
                label=f"+{'+'.join(ex.effects)}: error {ex.final.error:.3g}")
    ax.set_xlabel("held-out sample (one period ahead of each estimated start)")
    ax.set_ylabel(channel)
    ax.set_title(f"{system_name + ': ' if system_name else ''}one-period-ahead prediction of {channel} on the "
                 f"held-out data: {shown}", fontsize=10)
    ax.legend(fontsize=8)
    return finish(fig, path, dpi=100)


__all__ = ["explain_files", "prediction_figure", "residual_figure", "tooth_figure", "write_report"]
