"""The README's figures from one run of the paper scene: a strobe picture of the rope in
motion (docs/figures/rope_motion.png) and its energies (docs/figures/energy.png).

usage: scripts/readme_figures [RUN.h5] [--t-end 5] [--outdir docs/figures] [--strobe-end 1.4]
                              [--snapshots 15] [--exe PATH]

The code of scripts/readme_figures (python -m ropedyn_tools.studies.readme_figures). Without
RUN.h5 it runs the paper scene for --t-end seconds (default 5) with the Release build.
"""
import argparse
import pathlib
import subprocess
import sys
import tempfile

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402

from ropedyn import io, plot  # noqa: E402
from ropedyn_tools.repo import PAPER, add_exe_argument, exe_or_build, set_args  # noqa: E402
from ropedyn.docstrings import summary

DPI = 100


def strobe_figure(run, t_end, snapshots, size=(800, 520)):
    """Polylines at evenly spaced times in [0, t_end], older ones fainter, with the tip's
    path over the same window."""
    fig, ax = plt.subplots(figsize=(size[0] / DPI, size[1] / DPI), dpi=DPI)
    window = run.time <= t_end + 1e-12
    shown = io.Run(**{**run.__dict__, "points": run.points[window],
                            "time": run.time[window]})
    plot.setup_picture_axes(ax, shown)
    plot.draw_supports(ax, run)
    tip = shown.points[:, -1, :]
    ax.plot(tip[:, 1], tip[:, 0], color="#d62728", lw=1, alpha=0.7, label="tip path")
    picks = np.unique(np.abs(shown.time[None, :] - np.linspace(0.0, t_end, snapshots)[:, None])
                      .argmin(axis=1))
    colors = plt.get_cmap("Blues")(np.linspace(0.3, 1.0, picks.size))
    segments = [np.column_stack([shown.points[k, :, 1], shown.points[k, :, 0]]) for k in picks]
    ax.add_collection(LineCollection(segments, colors=colors, linewidths=1.8))
    for k, offset, align in ((picks[0], (-8, 8), "right"), (picks[-1], (8, -4), "left")):
        ax.annotate(f"t = {shown.time[k]:.1f} s", xy=(tip[k, 1], tip[k, 0]), fontsize=8,
                    xytext=offset, textcoords="offset points", ha=align, color="0.2")
    ax.set_title(f"The paper's rope released at 75\u00b0 ({run.model.upper()}, n = {run.n}): "
                 f"{picks.size} snapshots from 0 to {shown.time[picks[-1]]:.1f} s, "
                 "later ones darker", fontsize=9)
    ax.legend(fontsize=8, loc="lower left")
    fig.tight_layout()
    plot.fit_equal(ax)
    return fig


def energy_figure(run, size=(800, 450)):
    """Energies over the run and the balance error."""
    t, e = run.time, run.energy
    fig, (ax, bx) = plt.subplots(2, 1, figsize=(size[0] / DPI, size[1] / DPI), dpi=DPI,
                                 sharex=True, gridspec_kw={"height_ratios": [3, 1]})
    ax.plot(t, e["kinetic"], lw=1, label="kinetic")
    ax.plot(t, e["gravity"] - e["gravity"][0], lw=1, label="gravity - gravity(0)")
    ax.plot(t, e["elastic"], lw=1, label="elastic")
    ax.plot(t, e["dissipated"], lw=1, ls="--", label="dissipated")
    ax.plot(t, e["total"] - run.e0, "k", lw=1.4, label="total - E0")
    ax.set_ylabel("energy (J)")
    ax.legend(fontsize=7, ncol=5, loc="lower center", bbox_to_anchor=(0.5, 1.0),
              frameon=False)
    ax.grid(alpha=0.3)
    fig.suptitle(f"Energies of the paper's rope ({run.model.upper()}, n = {run.n}, "
                 f"{run.method})", fontsize=9)
    bx.plot(t, run.balance - run.e0, "r", lw=1)
    bx.set_ylabel("balance\nerror (J)", fontsize=8)
    bx.set_xlabel("t (s)")
    bx.grid(alpha=0.3)
    fig.tight_layout()
    return fig


def draw(run_file, outdir, strobe_end, snapshots):
    """Both figures of the run file into outdir."""
    run = io.load_run(run_file)
    outdir = pathlib.Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    for name, fig in (("rope_motion.png", strobe_figure(run, strobe_end, snapshots)),
                      ("energy.png", energy_figure(run))):
        fig.savefig(outdir / name, dpi=DPI)
        plt.close(fig)
        print(f"readme_figures: {outdir / name}")


def main(argv=None):
    parser = argparse.ArgumentParser(description=summary(__doc__))
    parser.add_argument("run", nargs="?", help="HDF5 output of the paper scene (default: "
                        "run input/paper.nml for --t-end seconds)")
    parser.add_argument("--outdir", default="docs/figures", help="where the PNGs go")
    parser.add_argument("--strobe-end", type=float, default=1.4,
                        help="last time (s) of the strobe picture (default 1.4)")
    parser.add_argument("--snapshots", type=int, default=15,
                        help="polylines in the strobe picture (default 15)")
    parser.add_argument("--t-end", default="5",
                        help="without RUN.h5: seconds of the paper scene to run (default 5)")
    add_exe_argument(parser, "without RUN.h5: the ropedyn executable")
    args = parser.parse_args(argv)
    if args.run is not None:
        draw(args.run, args.outdir, args.strobe_end, args.snapshots)
        return 0
    exe = exe_or_build(args.exe)
    with tempfile.TemporaryDirectory() as work:
        run_file = pathlib.Path(work) / "paper.h5"
        result = subprocess.run([exe, "run", str(PAPER), *set_args(
            [f"solver.t_end={args.t_end}", f"output.file={run_file}"])],
            stdout=subprocess.DEVNULL)
        if result.returncode != 0:
            return result.returncode
        draw(run_file, args.outdir, args.strobe_end, args.snapshots)
    return 0


if __name__ == "__main__":
    sys.exit(main())
