"""What can be checked of a matplotlib Figure by machine: that nothing in it is clipped or hidden, and that
its legends name what is drawn. Read from the laid-out Figure (drawn once, as it is saved)."""
from __future__ import annotations

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import to_rgba
from matplotlib.text import Text


def laid_out(fig):
    """``fig`` drawn (laid out by its engine, as when it is saved) and the renderer it was drawn with: drawn
    again only if something changed since it was last drawn (the checks of one figure read one layout)."""
    if fig.stale or getattr(fig, "_checks_drawn", None) is not fig.canvas:
        fig.canvas.draw()
        fig._checks_drawn = fig.canvas
    return fig.canvas.get_renderer()


def as_saved(fig, dpi: float):
    """``fig`` as ``save_figure`` left it after drawing it into its file at ``dpi`` (closed, which puts it on a
    plain canvas at the screen's resolution): back on an Agg canvas at ``dpi``, its layout engine set aside, and
    taken as drawn. Its artists are where the file's drawing put them, so the checks read what the file shows
    without drawing it again (a figure changed since is drawn again by :func:`laid_out`)."""
    FigureCanvasAgg(fig)
    fig.set_dpi(dpi)
    fig.set_layout_engine("none")
    fig._checks_drawn = fig.canvas
    fig.stale = False  # (stale only from its closing and the steps above: nothing in it changed since it was drawn)
    return fig


def _undrawn_tick_labels(fig) -> set[int]:
    """Tick labels matplotlib keeps but does not draw (their ticks lie outside the axis' view). Read only: the
    ticks it asks for are those the draw made (a figure drawn before is left as not changed since)."""
    out, stale = set(), fig.stale
    for ax in fig.findobj(lambda a: hasattr(a, "xaxis") and hasattr(a, "yaxis")):
        for axis in (ax.xaxis, ax.yaxis):
            drawn = {id(t) for t in axis._update_ticks()}
            for tick in [*axis.get_major_ticks(), *axis.get_minor_ticks()]:
                if id(tick) not in drawn:
                    out |= {id(tick.label1), id(tick.label2)}
    fig.stale = stale
    return out


def clipped_texts(fig) -> list[str]:
    """Every visible, non-empty text that reaches beyond the figure's edges."""
    renderer = laid_out(fig)
    edge = fig.bbox
    undrawn = _undrawn_tick_labels(fig)
    out, stale = [], fig.stale
    for text in fig.findobj(Text):
        if not text.get_visible() or not text.get_text().strip() or id(text) in undrawn:
            continue
        axes = text.axes
        if axes is not None and not axes.get_visible():
            continue
        box = text.get_window_extent(renderer)
        if box.x0 < edge.x0 - 1 or box.x1 > edge.x1 + 1 or box.y0 < edge.y0 - 1 or box.y1 > edge.y1 + 1:
            out.append(text.get_text())
    fig.stale = stale  # (an annotation measured places its arrow as the draw did: nothing changed)
    return out


def data_points(ax) -> np.ndarray:
    """Every drawn data vertex of ``ax`` (lines and scatter points), in pixels."""
    pts = []
    for line in ax.lines:
        if line.get_visible() and len(line.get_xdata()):
            xy = np.column_stack([np.asarray(line.get_xdata(), float), np.asarray(line.get_ydata(), float)])
            pts.append(line.get_transform().transform(xy))
    for coll in ax.collections:
        offsets = coll.get_offsets()
        if coll.get_visible() and len(offsets) and hasattr(coll, "get_sizes") and len(coll.get_sizes()):
            pts.append(coll.get_offset_transform().transform(np.asarray(offsets, float)))
    return np.vstack(pts) if pts else np.zeros((0, 2))


def points_under_legend(ax) -> int:
    """How many data vertices of ``ax`` its legend covers."""
    legend = ax.get_legend()
    if legend is None or not legend.get_visible():
        return 0
    renderer = laid_out(ax.figure)
    box = legend.get_window_extent(renderer)
    p = data_points(ax)
    p = p[np.all(np.isfinite(p), axis=1)]
    return int(np.count_nonzero((p[:, 0] > box.x0) & (p[:, 0] < box.x1) & (p[:, 1] > box.y0) & (p[:, 1] < box.y1)))


def _style(artist) -> tuple:
    """(colour, line style, marker) of a Line2D or the face colour of a patch."""
    if hasattr(artist, "get_linestyle") and hasattr(artist, "get_marker"):
        ls = artist.get_linestyle()
        marker = artist.get_marker()
        color = artist.get_color() if marker in ("", "None", None) or ls not in ("None", "", " ") \
            else (artist.get_markeredgecolor() if artist.get_markerfacecolor() in ("none", "None")
                  else artist.get_markerfacecolor())
        return (tuple(np.round(to_rgba(color), 3)), ls if ls not in ("", " ") else "None",
                marker if marker not in ("", None) else "None")
    return (tuple(np.round(to_rgba(artist.get_facecolor()), 3)), None, None)


def unmatched_legend_entries(ax, legend=None) -> list[str]:
    """Legend entries of ``ax`` with no drawn artist of the same style (colour, line style, marker) in it."""
    legend = legend or ax.get_legend()
    if legend is None:
        return []
    drawn = {_style(a) for a in [*ax.lines, *ax.patches] if a.get_visible()}
    for coll in ax.collections:  # broken_barh and the like: their face colours
        for face in np.atleast_2d(coll.get_facecolor()):
            drawn.add((tuple(np.round(face, 3)), None, None))
    out = []
    for handle, text in zip(legend.legend_handles, legend.get_texts()):
        style = _style(handle)
        grey = style[0][0] == style[0][1] == style[0][2] and style[1] is not None
        if style not in drawn and not (grey and any(d[1:] == style[1:] for d in drawn)):  # a grey key: a style
            out.append(text.get_text())
    return out


def label_overlaps(boxes) -> list[tuple[int, int]]:
    """Pairs of boxes (Bbox) that overlap."""
    out = []
    for i in range(len(boxes)):
        for j in range(i + 1, len(boxes)):
            if boxes[i].overlaps(boxes[j]):
                out.append((i, j))
    return out
