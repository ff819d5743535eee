"""The derivation of a model, collected once and rendered as text, LaTeX, JSON or Markdown.

``derive(model)`` walks the pipeline and returns a
:class:`~gearsym.derivation.records.Derivation`; ``render(derivation, fmt)``
prints it. ``gearsym derive`` and ``gearsym docs`` are thin wrappers.
"""
from .collect import derive
from .formats import FORMATS, render
from .records import Derivation

__all__ = ["FORMATS", "Derivation", "derive", "render"]
