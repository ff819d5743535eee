"""The data loop's report: its figures (where the held-out residual lives, the one-period-ahead prediction), and
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
from ..fit.report import PARTIAL_MARKER, REPORT_FILES, derived_model_page, report_page
from ..fit.selection import Candidate, Explanation, explain
from ..system import FirstOrderSystem
from .layout import fit_texts
from .save import pyplot, save_figure


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
    """Write DIR/report.md, DIR/report.json, DIR/residuals.png, DIR/prediction.png and DIR/derived_model.md, all
    or none: a failure or a kill while they are made leaves the previous report as it was (never a new
    report.json beside an old report.md)."""
    with written_together(out, REPORT_FILES, PARTIAL_MARKER, "the report") as stage:
        data = json_safe(ex.as_dict())
        write_atomically(stage / "report.json", json.dumps(data, indent=1, allow_nan=False) + "\n")
        save_figure(residual_figure(ex, system), stage / "residuals.png", dpi=100)
        save_figure(prediction_figure(ex, system.name), stage / "prediction.png", dpi=100)
        effects = [ex.library[e] for e in ex.effects]
        derived = augment(system, effects) if effects else system
        write_atomically(stage / "derived_model.md", derived_model_page(system, derived, effects))
        write_atomically(stage / "report.md", report_page(ex, system, derived, data, sources))
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


def residual_figure(ex: Explanation, system: FirstOrderSystem):
    """Where the held-out residual lives (against the mesh phase, the coordinate and its rate) and its spectrum:
    the model as declared always, and after when effects were added."""
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
    fit_texts(fig)
    return fig


def _which(prediction) -> str:
    """'every held-out window (12) of measured.csv record 1 (omega=1.2), measured.csv record 2 (omega=1.6)'."""
    records = prediction.records()
    return (f"every held-out window ({prediction.pairs}) of " + "; ".join(records) if records
            else f"every held-out window ({prediction.pairs})")


def prediction_figure(ex: Explanation, system_name: str = ""):
    """The measurement and the predictions of the first three held-out windows of the first record (the
    title says which)."""
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
    fit_texts(fig)
    return fig


__all__ = ["explain_files", "prediction_figure", "residual_figure", "write_report"]
