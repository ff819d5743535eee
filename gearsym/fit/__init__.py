"""The data loop: fit a model to measured windows, find the effect its residual says is missing,
add it to the symbolic model, and report the held-out error before and after.

:mod:`.shooting` (multiple-shooting fit) -> :mod:`.prediction` (held-out error) ->
:mod:`.explain` (forward selection over :mod:`.effects`) -> :mod:`.report`.
"""
from ..checks import json_safe
from ..data import load_measurements
from ..files.outputs import check_folder
from .effects import EFFECTS, FAMILIES, Effect, augment, effect, effect_terms, term_effect
from .selection import Explanation, explain
from .prediction import Prediction, predict_ahead
from .report import write_report
from .result import Fit
from .segment import Segment
from .shooting import fit_windows

__all__ = ["EFFECTS", "Effect", "Explanation", "FAMILIES", "Fit", "Prediction", "Segment", "augment", "effect",
           "effect_terms", "explain", "explain_files", "fit_windows", "predict_ahead", "term_effect"]


def explain_files(paths, system, fit, *, out=None, time_scale=None, held_out: float = 0.25, candidates=None,
                  progress=None, options=None, channels=None, bias=None, terms=(), harmonics=None, **values):
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
    ex = explain(system, measurements, fit, held_out=held_out, candidates=candidates, progress=progress,
                 bias=bias, terms=terms, **extra)
    if out is not None:
        return write_report(ex, system, out, measurements.sources)

    return json_safe(ex.as_dict())
