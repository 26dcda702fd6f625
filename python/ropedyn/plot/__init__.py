"""Drawing helpers for pictures of a run (matplotlib axes in the picture frame: y to the
right, x downward) and the command-line modules that draw: `ropedyn.plot.overview`
(scripts/plot; also `python -m ropedyn.plot`) and `ropedyn.plot.energy`
(scripts/plot_energy.py).
"""
import argparse
import contextlib
import os
import pathlib
import re
import sys

import numpy as np

from ropedyn import io
from ropedyn.fields import ground_plane, supports, water_surface

SUPPORT_PATH_COLOR = "#2ca02c"
GROUND_COLOR = "#8c564b"
WATER_COLOR = "#1f77b4"


def draw_supports(ax, run, size=None, color="0.25", moving=True):
    """Draw the anchors of pinned and clamped ends (hatched ceiling / wall) on ax,
    which shows (y, x) with x downward, where they are at the first record (`moving`
    False: only the supports that do not move)."""
    size = size or 0.06 * float(run.group("rope").get("length", run.element_length.sum()))
    for sup, sign in zip(supports(run), (-1.0, 1.0)):
        if sup.kind not in ("pinned", "clamped") or (sup.moving and not moving):
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


def draw_support_paths(ax, run, color=SUPPORT_PATH_COLOR):
    """Draw the path of each moving support (its anchor at every record, as the model
    stored it in /supports/*/position); returns the supports drawn."""
    drawn = []
    for end, sup in zip(("top", "bottom"), supports(run)):
        if sup.kind == "free" or not sup.moving:
            continue
        ax.plot(sup.path[:, 1], sup.path[:, 0], ":", color=color, lw=1.2,
                label=f"{end} support path")
        drawn.append(sup)
    return drawn


def draw_ground(ax, run, color=GROUND_COLOR):
    """Draw the scene's ground line (&ground point and normal) when it has ground contact
    (&effects ground = .true.), with short hatches on the solid side; True if drawn."""
    plane = ground_plane(run)
    if plane is None:
        return False
    point, normal = plane
    along = np.array([-normal[1], normal[0]])
    ax.axline((point[1], point[0]), (point[1] + along[1], point[0] + along[0]), color=color,
              lw=1.5, label="ground")
    (ymin, ymax), (xmin, xmax) = ax.get_xlim(), sorted(ax.get_ylim())
    size = 0.03 * max(ymax - ymin, xmax - xmin)
    span = 2.0 * max(ymax - ymin, xmax - xmin)
    for k in np.linspace(-span, span, 121):
        p = point + k * along
        q = p - size * normal + size * along
        ax.plot([p[1], q[1]], [p[0], q[0]], color=color, lw=0.6, alpha=0.6)
    ax.set_xlim(ymin, ymax)
    ax.set_ylim(xmax, xmin)
    return True


def draw_water(ax, run, color=WATER_COLOR):
    """Draw the water's free surface (&fluid surface, a horizontal line: x is down) and
    shade the water below it when the scene has water (&effects water = .true.); True if
    drawn."""
    surface = water_surface(run)
    if surface is None:
        return False
    ax.axhline(surface, color=color, lw=1.2, ls="--", label="water surface")
    (ymin, ymax), (xmin, xmax) = ax.get_xlim(), sorted(ax.get_ylim())
    if xmax > surface:
        ax.axhspan(max(surface, xmin), xmax, color=color, alpha=0.08, lw=0)
    ax.set_xlim(ymin, ymax)
    ax.set_ylim(xmax, xmin)
    return True


def point_marker(run):
    """Line keywords for curves over a run's records: a marker when the run has one record
    only (a line through one point draws nothing), none otherwise."""
    return {"marker": "o", "ms": 5} if run.time.size == 1 else {}


#: The label of the work curve: the work done on the rope by moving supports, point loads
#: and a current (/energy/support_work), which T + V - E0 follows together with the
#: dissipated energy.
WORK_LABEL = "work W (supports, loads, current)"

#: What the energy curves add up to (the energy balance, docs/theory/energy-balance.md).
BALANCE_NOTE = "T + V - E0 = W - dissipated"


def work(run):
    """The work done on the rope so far, J (/energy/support_work), or None when the run
    has none (no moving support, point load or current: zero throughout)."""
    w = run.energy.get("support_work")
    if w is None or not np.any(w != 0.0):
        return None
    return w


def say_one_record(ax, run):
    """With one record only: say so in the corner of a panel of curves over time (which
    show single points); True if said."""
    if run.time.size != 1:
        return False
    ax.text(0.5, 0.9, f"one record (t = {run.time[0]:.6g} s)", ha="center", va="top",
            fontsize=9, color="0.3", transform=ax.transAxes)
    return True


def balance_curves(ax, run, total_width):
    """The curves of an energy panel after its energy parts: the dissipated energy, the
    work done on the rope (when there is any), T + V - E0 (their difference W -
    dissipated), the one-record note and the axes' labels."""
    t, e = run.time, run.energy
    one = point_marker(run)
    if "dissipated" in e:
        ax.plot(t, e["dissipated"], lw=1, ls="--", label="dissipated", **one)
    w = work(run)
    if w is not None:
        ax.plot(t, w, lw=1, ls="-.", color="C5", label=WORK_LABEL, **one)
    ax.plot(t, e["total"] - run.e0, "k", lw=total_width, label="total - E0", **one)
    say_one_record(ax, run)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("energy (J)")


def load_records(tool, path):
    """The run file `path` for the command-line tool `tool` (its name in messages), with at
    least one record: (run, 0); else (None, exit code) after one line on stderr: 2 when it
    is not a run file or cannot be read, 1 when it holds no output record."""
    try:
        run = io.load_run(path)
    except (OSError, ValueError) as exc:
        print(f"{tool}: {exc}", file=sys.stderr)
        return None, 2
    if run.time.size == 0:
        print(f"{tool}: {path}: no output records", file=sys.stderr)
        return None, 1
    return run, 0


def picture_limits(run, margin=0.08):
    """((ymin, ymax), (xmin, xmax)) covering every record, the anchors (over the whole run
    for moving ones) and, with ground contact, the ground below the rope's first point
    (its foot on the plane), with a margin."""
    pts = run.points.reshape(-1, 2)
    anchors = [s.path if s.path is not None else s.anchor for s in supports(run)
               if s.kind != "free"]
    plane = ground_plane(run)
    if plane is not None:
        point, normal = plane
        start = run.points[0, 0]
        anchors.append(start - np.dot(start - point, normal) * normal)
    anchors = np.vstack(anchors).reshape(-1, 2) if anchors else np.zeros((0, 2))
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
    """'WxH' -> (W, H) pixels, each at least 1."""
    match = re.fullmatch(r"\s*(\d+)\s*[xX]\s*(\d+)\s*", value)
    if not match or min(int(match.group(1)), int(match.group(2))) < 1:
        raise ValueError(f"size '{value}': expected WIDTHxHEIGHT in pixels, e.g. 640x480")
    return int(match.group(1)), int(match.group(2))


def parse_dpi(value):
    """--dpi: dots per inch, an integer >= 1 (argparse type)."""
    try:
        dpi = int(value)
    except ValueError:
        dpi = 0
    if dpi < 1:
        raise argparse.ArgumentTypeError(f"'{value}': expected dots per inch, an integer >= 1")
    return dpi


def check_directory(out):
    """ValueError unless the directory `out` goes into exists."""
    folder = pathlib.Path(out).parent
    if not folder.is_dir():
        raise ValueError(f"{out}: no such directory: {folder}")


def check_picture_name(out, run_path):
    """ValueError unless `out` can take a picture: a suffix matplotlib writes (.png, .pdf,
    .svg, ...), in a directory that exists, and not the run file it is drawn from."""
    from matplotlib.backend_bases import FigureCanvasBase
    formats = FigureCanvasBase.get_supported_filetypes()
    fmt = pathlib.Path(out).suffix.lstrip(".").lower()
    if fmt not in formats:
        raise ValueError(f"{out}: a picture's name ends in one of "
                         f".{', .'.join(sorted(formats))} (not '.{fmt}')")
    if pathlib.Path(out).resolve() == pathlib.Path(run_path).resolve():
        raise ValueError(f"{out}: is the run file itself: give the picture another name")
    check_directory(out)


def made_by(run, tool):
    """What a picture of `run` says made it: the tool, the run file, the code version that
    wrote the run, its model, method and status."""
    return (f"{tool} from {pathlib.Path(run.path).name}: ropedyn "
            f"{run.attrs.get('version', 'unknown')}, {io.title(run)}")


def png_text(run, tool):
    """The text chunks of a PNG of `run`: Software, Source (the run file), Description
    (made_by) and the run's effective scene."""
    return {"Software": f"ropedyn {run.attrs.get('version', 'unknown')}",
            "Source": str(run.path), "Description": made_by(run, tool),
            "Scene": run.attrs.get("scene", "")}


@contextlib.contextmanager
def written_whole(out):
    """Yield OUT.part to write; rename it to `out` when the block ends without an error,
    remove it otherwise: a picture (or the XDMF sidecar) is never left half-written under
    its name."""
    out = pathlib.Path(out)
    part = out.with_name(out.name + ".part")
    try:
        yield part
        os.replace(part, out)
    finally:
        if part.exists():
            part.unlink()


def save_figure(fig, out, run, tool, **kwargs):
    """fig saved whole to `out` (format from its suffix); a PNG says what made it
    (png_text)."""
    fmt = pathlib.Path(out).suffix.lstrip(".").lower() or "png"
    if fmt == "png":
        kwargs["metadata"] = png_text(run, tool)
    with written_whole(out) as part:
        fig.savefig(part, format=fmt, **kwargs)
