"""Figures (PNG, matplotlib's Agg backend: no display needed)."""
from .point import plot_point

__all__ = ["plot_point"]
