"""Figures (PNG, matplotlib's Agg backend: no display needed).

``point``: one parameter point; ``sweep``: curves and maps over a sweep;
``poincare``: attractors from many starts and phase portraits (Figs. 4, 7).
"""
from .point import plot_point

__all__ = ["plot_point"]
