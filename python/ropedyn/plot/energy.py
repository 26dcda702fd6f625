"""Plot the energies of a ropedyn run: E - E0 by part, the dissipated energy and the work
done on the rope, and the balance error.

usage: scripts/plot_energy.py RUN.h5 [-o RUN_energy.png]   (python -m ropedyn.plot.energy)
"""
import argparse
import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from ropedyn import io, plot  # noqa: E402
from ropedyn.docstrings import summary  # noqa: E402


def main(argv=None):
    parser = argparse.ArgumentParser(description=summary(__doc__))
    parser.add_argument("run", help="HDF5 output of ropedyn run")
    parser.add_argument("-o", "--output", help="PNG file (default: RUN_energy.png)")
    args = parser.parse_args(argv)
    # RUN.h5 -> RUN_energy.png and RUN.h5.part (a killed run's) -> RUN.h5_energy.png, as the
    # overview names its picture: not the picture of the complete RUN.h5 beside it
    out = args.output or str(pathlib.Path(args.run).with_suffix("")) + "_energy.png"
    try:
        plot.check_picture_name(out, args.run)
    except ValueError as exc:
        parser.error(str(exc))

    run, code = plot.load_records("plot_energy", args.run)
    if run is None:
        return code
    t, e = run.time, run.energy
    e0 = run.e0
    balance = run.balance - e0

    fig, (ax, bx) = plt.subplots(2, 1, figsize=(8, 6.5), sharex=True,
                                 gridspec_kw={"height_ratios": [3, 1]})
    one = plot.point_marker(run)        # with one record: points, and the panels say so
    ax.plot(t, e["total"] - e0, "k", lw=1.6, label="total E - E0 = T + V - E0", **one)
    ax.plot(t, e["kinetic"], lw=1, label="kinetic T", **one)
    ax.plot(t, e["gravity"] - e["gravity"][0], lw=1, label="gravity - gravity(0)", **one)
    ax.plot(t, e["elastic"], lw=1, label="elastic", **one)
    ax.plot(t, -e["dissipated"], "--", lw=1, label="- dissipated", **one)
    # the work of moving supports, loads and a current: T + V - E0 = W - dissipated, so
    # without it a shaken rope's total would seem to drift
    work = plot.work(run)
    if work is not None:
        ax.plot(t, work, "-.", lw=1, color="C5", label=plot.WORK_LABEL, **one)
    plot.say_one_record(ax, run)
    ax.set_ylabel("energy (J)")
    ax.set_title(io.title(run))
    ax.legend(fontsize=8, loc="lower left", title=plot.BALANCE_NOTE, title_fontsize=8)
    ax.grid(alpha=0.3)
    bx.plot(t, balance, "r", lw=1, **one)
    plot.say_one_record(bx, run)
    bx.set_ylabel("balance error (J)")
    bx.set_xlabel("time (s)")
    bx.grid(alpha=0.3)
    bx.set_title("T + V + dissipated - support work - E0", fontsize=9)
    fig.tight_layout()
    plot.save_figure(fig, out, run, "ropedyn.plot.energy (scripts/plot_energy.py)", dpi=110)
    print(f"plot: {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
