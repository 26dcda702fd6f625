"""Overview plot of a ropedyn run: energies (with the work done on the rope) over time, the
tip's trajectory (with a moving support's path, the ground and the water surface), the
solver's step size and order over time, and the axial force along the rope at chosen times.

usage: scripts/plot RUN.h5 [-o RUN_plot.png] [--times 0.5,1,2] [--size 1200x900]
       (python -m ropedyn.plot, or python -m ropedyn.plot.overview)

Works from the HDF5 file alone (any model): the axial force is the one the model stored
with each record (a file written before that has none: the panel says so; see
docs/guide/visualization.md).
"""
import argparse
import pathlib
import sys
import textwrap

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from ropedyn import fields, io, plot  # noqa: E402
from ropedyn.docstrings import summary  # noqa: E402


def plot_energies(ax, run):
    """Energy parts relative to their start, the dissipated energy, the work done on the
    rope (when there is any) and T + V - E0, which is their difference W - dissipated (with
    one record: points, and the panel says so)."""
    t, e = run.time, run.energy
    one = plot.point_marker(run)
    ax.plot(t, e["kinetic"], lw=1, label="kinetic T", **one)
    ax.plot(t, e["gravity"] - e["gravity"][0], lw=1, label="gravity - gravity(0)", **one)
    ax.plot(t, e["elastic"], lw=1, label="elastic", **one)
    plot.balance_curves(ax, run, 1.4)
    ax.set_title("energies", fontsize=10)
    ax.legend(fontsize=7, loc="best", title=plot.BALANCE_NOTE, title_fontsize=7)
    ax.grid(alpha=0.3)


def plot_tip(ax, run):
    """The free end's path, coloured by time, with the first and last rope shapes."""
    tip = run.points[:, -1, :]
    plot.setup_picture_axes(ax, run)
    plot.draw_ground(ax, run)
    plot.draw_water(ax, run)
    plot.draw_supports(ax, run)
    plot.draw_support_paths(ax, run)
    ax.plot(run.points[0, :, 1], run.points[0, :, 0], color="0.6", lw=1.2, label="rope, start")
    ax.plot(run.points[-1, :, 1], run.points[-1, :, 0], color="#1f4e9c", lw=1.6,
            label="rope, end")
    art = ax.scatter(tip[:, 1], tip[:, 0], c=run.time, s=2, cmap="viridis", lw=0)
    ax.figure.colorbar(art, ax=ax, label="t (s)", fraction=0.046, pad=0.02)
    ax.set_title("tip trajectory", fontsize=10)
    ax.legend(fontsize=7, loc="lower right")


def plot_solver(ax, run):
    """Step size (log scale) and method order over time."""
    if run.step_size is None:
        ax.text(0.5, 0.5, "no solver data", ha="center", transform=ax.transAxes)
        return
    if run.time.size == 1:
        # the first record is the initial state: no step before it, nothing to draw
        ax.text(0.5, 0.5, f"one record (t = {run.time[0]:.6g} s):\nno step before it",
                ha="center", va="center", fontsize=9, transform=ax.transAxes)
        ax.set_title("solver: last step size and order before each output", fontsize=10)
        ax.set_axis_off()
        return
    ax.semilogy(run.time, np.where(run.step_size > 0, run.step_size, np.nan), lw=1,
                color="C0")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("step size (s)", color="C0")
    ax.grid(alpha=0.3)
    if run.order is not None:
        bx = ax.twinx()
        bx.step(run.time, run.order, where="post", color="C3", lw=0.8, alpha=0.8)
        bx.set_ylabel("order", color="C3")
        top = max(int(np.max(run.order)) if run.order.size else 1, 1)
        bx.set_ylim(0, top + 1)
        bx.set_yticks(range(0, top + 2))
    ax.set_title("solver: last step size and order before each output", fontsize=10)


def record_indices(times, wanted):
    """Indices of the records nearest to the wanted times (sorted, unique)."""
    wanted = np.asarray(wanted, dtype=float)
    return np.unique(np.abs(times[None, :] - wanted[:, None]).argmin(axis=1))


def output_interval(run):
    """The run's output interval, s: &solver output_interval, else the median spacing of
    its records (0 for one record)."""
    interval = run.group("solver").get("output_interval")
    if isinstance(interval, (int, float)) and interval > 0:
        return float(interval)
    return float(np.median(np.diff(run.time))) if run.time.size > 1 else 0.0


def check_times(run, wanted):
    """ValueError unless every wanted time is finite and within the run's records (from
    the first to the last, with half an output interval of tolerance beyond either end)."""
    first, last = float(run.time[0]), float(run.time[-1])
    slack = 0.5 * output_interval(run)
    span = f"the run's records span t = {first:g} to {last:g} s"
    for t in wanted:
        if not np.isfinite(t):
            raise ValueError(f"--times {t:g}: not a finite time; {span}")
        if not first - slack <= t <= last + slack:
            raise ValueError(f"--times {t:g}: outside the run; {span} (half an output "
                             f"interval, {slack:g} s, beyond either end is taken)")


def default_times(times, count=5):
    """count times evenly spread over the run, leaving out the start."""
    return np.linspace(times[0], times[-1], count + 1)[1:]


def plot_axial_force(ax, run, wanted):
    """N along the rope (arc length from the top) at the records nearest to wanted."""
    force, message = fields.axial_force(run)
    ax.set_title("axial force along the rope", fontsize=10)
    if force is None:
        # (wrapped to the panel: matplotlib's wrap=True wraps at the figure's edge, and
        # the text ran over the panel beside it)
        ax.text(0.5, 0.5, "\n".join(textwrap.wrap(message, 48)), ha="center", va="center",
                fontsize=9, transform=ax.transAxes)
        ax.set_axis_off()
        return
    for k in record_indices(run.time, wanted):
        ax.plot(force.s, force.values[k], "-o", ms=2.5, lw=1, label=f"t = {run.time[k]:.3g} s")
    ax.axhline(0.0, color="0.5", lw=0.8)
    ax.set_xlabel("s (m), joints along the unstretched rope from the top")
    ax.set_ylabel("N (N), tension > 0")
    ax.legend(fontsize=7, loc="best")
    ax.grid(alpha=0.3)
    ax.text(0.01, 0.01, force.definition, transform=ax.transAxes, fontsize=6, color="0.4",
            va="bottom")


def make_figure(run, wanted, size, dpi):
    """The 2 x 2 overview figure."""
    fig, axes = plt.subplots(2, 2, figsize=(size[0] / dpi, size[1] / dpi), dpi=dpi)
    plot_energies(axes[0, 0], run)
    plot_tip(axes[0, 1], run)
    plot_solver(axes[1, 0], run)
    plot_axial_force(axes[1, 1], run, wanted)
    fig.suptitle(f"{pathlib.Path(run.path).name}: {io.title(run)}", fontsize=11)
    fig.tight_layout()
    plot.fit_equal(axes[0, 1])
    return fig


def parse_times(value):
    """'0.5, 1, 2' -> [0.5, 1.0, 2.0]."""
    try:
        return [float(v) for v in value.split(",") if v.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{value}': expected times in s, e.g. 0.5,1,2")


def main(argv=None):
    parser = argparse.ArgumentParser(description=summary(__doc__))
    parser.add_argument("run", help="HDF5 output of ropedyn run")
    parser.add_argument("-o", "--output", help="PNG file (default: RUN_plot.png)")
    parser.add_argument("--times", type=parse_times,
                        help="times (s) of the axial-force curves, e.g. 0.5,1,2, each "
                             "drawn at the nearest record; within the run's records "
                             "(default: 5 times spread over the run)")
    parser.add_argument("--size", default="1200x900", help="WIDTHxHEIGHT in pixels")
    parser.add_argument("--dpi", type=plot.parse_dpi, default=100)
    args = parser.parse_args(argv)
    try:
        size = plot.parse_size(args.size)
    except ValueError as exc:
        parser.error(str(exc))
    out = args.output or str(pathlib.Path(args.run).with_suffix("")) + "_plot.png"
    try:
        plot.check_picture_name(out, args.run)
    except ValueError as exc:
        parser.error(str(exc))
    run, code = plot.load_records("plot", args.run)
    if run is None:
        return code
    if args.times:
        try:
            check_times(run, args.times)
        except ValueError as exc:
            parser.error(str(exc))
    fig = make_figure(run, args.times or default_times(run.time), size, args.dpi)
    plot.save_figure(fig, out, run, "ropedyn.plot.overview (scripts/plot)", dpi=args.dpi)
    plt.close(fig)
    print(f"plot: {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
