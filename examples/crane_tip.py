"""A crane's tip carries a load on a rope: a Python loop moves the tip, ropedyn answers with
the rope's motion and the tension at the tip, and the tension is plotted.

    python examples/crane_tip.py [--t-end 6] [--out crane_tension.png]

The rope is the paper's (1 m, 5 mm steel-like rod; input/paper.nml) with a 0.5 kg load at
its lower end, hanging at rest (the static equilibrium) under the crane's tip. The tip
travels 0.5 m sideways in 2 s (a smooth start and stop), then holds: the load lags,
swings, and the tension at the tip swings with it. The tip is the rope's top support,
driven every millisecond through set_support (&supports top_motion = 'coupled').
"""
import argparse
import pathlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import ropedyn  # noqa: E402

PAPER = pathlib.Path(__file__).resolve().parents[1] / "input" / "paper.nml"
TRAVEL, TRAVEL_TIME, DT = 0.5, 2.0, 1e-3    # m, s, s


def crane_tip(t):
    """The tip's position (x down, y sideways) and velocity at time t: smoothstep travel."""
    u = min(t / TRAVEL_TIME, 1.0)
    y = TRAVEL * u ** 3 * (10 - 15 * u + 6 * u * u)
    v = TRAVEL * 30 * u * u * (1 - u) ** 2 / TRAVEL_TIME
    return (0.0, y), (0.0, v)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--t-end", type=float, default=6.0)
    parser.add_argument("--out", default="crane_tension.png")
    args = parser.parse_args(argv)

    scene = ropedyn.Scene.from_file(PAPER).set({
        "model.elements": 20, "initial.angle_deg": 0.0,
        "supports.top_motion": "coupled",
        "attachments.mass_positions": 1.0, "attachments.masses": 0.5})
    times, tension, load = [], [], []
    with ropedyn.Simulation(scene, statics=True) as sim:   # hanging at rest
        for k in range(1, int(round(args.t_end / DT)) + 1):
            t = k * DT
            position, velocity = crane_tip(t)
            sim.set_support("top", position=position, velocity=velocity)
            sim.advance(t)
            times.append(t)
            tension.append(np.linalg.norm(sim.reaction("top")))
            load.append(sim.points[-1, 1])

    fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(7, 5))
    ax1.plot(times, tension)
    ax1.set_ylabel("tension at the tip (N)")
    ax2.plot(times, [crane_tip(t)[0][1] for t in times], label="crane tip")
    ax2.plot(times, load, label="load")
    ax2.set_ylabel("sideways position (m)")
    ax2.set_xlabel("time (s)")
    ax2.legend()
    fig.tight_layout()
    fig.savefig(args.out, dpi=100)
    print(f"tension at the tip: {tension[0]:.3f} N at rest, {max(tension):.3f} N at most, "
          f"{min(tension):.3f} N at least; plot {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
