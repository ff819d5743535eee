"""The data loop: fit a model to measured windows, find the effect its residual says is missing,
add it to the symbolic model, and report the held-out error before and after.

:mod:`.shooting` (multiple-shooting fit) -> :mod:`.prediction` (held-out error) ->
:mod:`.selection` (forward selection over :mod:`.effects`) -> :mod:`.report` (its pages; the report folder
with its figures: :mod:`gearsym.figures.fit_report`).
"""
from .effects import EFFECTS, FAMILIES, Effect, augment, effect, effect_terms, term_effect
from .selection import Explanation, explain
from .prediction import Prediction, predict_ahead
from .result import Fit
from .segment import Segment
from .shooting import fit_windows

__all__ = ["EFFECTS", "Effect", "Explanation", "FAMILIES", "Fit", "Prediction", "Segment", "augment", "effect",
           "effect_terms", "explain", "fit_windows", "predict_ahead", "term_effect"]
