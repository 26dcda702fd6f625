"""Drawing helpers for pictures of a run (matplotlib axes in the picture frame: y to the
right, x downward) and the command-line modules that draw: `ropedyn.plot.overview`
(scripts/plot; also `python -m ropedyn.plot`) and `ropedyn.plot.energy`
(scripts/plot_energy.py).
"""
import re

import numpy as np

from ropedyn.fields import supports


def draw_supports(ax, run, size=None, color="0.25"):
    """Draw the anchors of pinned and clamped ends (hatched ceiling / wall) on ax,
    which shows (y, x) with x downward."""
    size = size or 0.06 * float(run.group("rope").get("length", run.element_length.sum()))
    for sup, sign in zip(supports(run), (-1.0, 1.0)):
        if sup.kind not in ("pinned", "clamped"):
            continue
        x0, y0 = sup.anchor
        if sup.kind == "pinned":
            # a ceiling (or floor) segment with hatching, and the pin
            ax.plot([y0 - size, y0 + size], [x0 + sign * 0.3 * size] * 2, color=color, lw=1.5)
            for k in np.linspace(-size, size, 6):
                ax.plot([y0 + k, y0 + k + 0.3 * size],
                        [x0 + sign * 0.3 * size, x0 + sign * 0.6 * size], color=color, lw=0.8)
            ax.plot([y0], [x0], "o", ms=5, mfc="white", mec=color, mew=1.5, zorder=5)
        else:
            # a wall perpendicular to the clamp direction
            direction = np.array([np.cos(sup.angle), np.sin(sup.angle)]) * -sign
            normal = np.array([-direction[1], direction[0]])
            ends = [sup.anchor - size * normal, sup.anchor + size * normal]
            ax.plot([ends[0][1], ends[1][1]], [ends[0][0], ends[1][0]], color=color, lw=2.5)
            for k in np.linspace(-size, size, 6):
                p = sup.anchor + k * normal
                q = p - 0.3 * size * direction + 0.3 * size * normal
                ax.plot([p[1], q[1]], [p[0], q[0]], color=color, lw=0.8)


def picture_limits(run, margin=0.08):
    """((ymin, ymax), (xmin, xmax)) covering every record and the anchors, with a margin."""
    pts = run.points.reshape(-1, 2)
    anchors = np.array([s.anchor for s in supports(run) if s.kind != "free"]).reshape(-1, 2)
    allp = np.vstack([pts, anchors]) if anchors.size else pts
    lo, hi = allp.min(axis=0), allp.max(axis=0)
    pad = margin * max(hi - lo) + 1e-9
    return (lo[1] - pad, hi[1] + pad), (lo[0] - pad, hi[0] + pad)


def setup_picture_axes(ax, run):
    """Axes showing y to the right and x downward, limits covering the whole run (call
    fit_equal after the layout is final to make the scales equal)."""
    (ymin, ymax), (xmin, xmax) = picture_limits(run)
    ax.set_xlim(ymin, ymax)
    ax.set_ylim(xmax, xmin)  # x points down
    ax.set_xlabel("y (m)")
    ax.set_ylabel("x (m, down)")
    ax.grid(alpha=0.25)


def fit_equal(ax):
    """Widen the x or y limits so that one metre is as long across as down (the axes box
    stays as laid out, so the picture fills it)."""
    box = ax.get_window_extent()
    (y0, y1), (x1, x0) = ax.get_xlim(), ax.get_ylim()
    want = box.width / max(box.height, 1.0)
    across, down = y1 - y0, x1 - x0
    if across / down < want:
        pad = (want * down - across) / 2.0
        ax.set_xlim(y0 - pad, y1 + pad)
    else:
        pad = (across / want - down) / 2.0
        ax.set_ylim(x1 + pad, x0 - pad)
    ax.set_aspect("equal", adjustable="box")


def parse_size(value):
    """'WxH' -> (W, H) pixels."""
    match = re.fullmatch(r"\s*(\d+)\s*[xX]\s*(\d+)\s*", value)
    if not match:
        raise ValueError(f"size '{value}': expected WIDTHxHEIGHT in pixels, e.g. 640x480")
    return int(match.group(1)), int(match.group(2))
