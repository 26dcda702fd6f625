"""Animate a ropedyn run: the rope's polyline over time, the tip's trail, the supports (a
moving one on its path), the ground, the water surface, a time stamp and optionally an energy panel. Works
from the HDF5 file alone (any model).

usage: scripts/animate RUN.h5 [-o RUN.gif|RUN.mp4] [--max-frames 300] [--fps F] [--energy]
       (python -m ropedyn.animate)

GIF is written with Pillow (comes with matplotlib); MP4 needs the ffmpeg program.
Frames are subsampled evenly from the records (--max-frames); by default the animation
plays in real time (fps = frames / simulated time, kept within 5 .. 30).
"""
import argparse
import pathlib
import shutil
import subprocess
import sys
import time as wallclock

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from ropedyn import fields, io, plot  # noqa: E402
from ropedyn.docstrings import summary  # noqa: E402

ROPE_COLOR = "#1f4e9c"
#: the slowest playback --fps takes
MIN_FPS = 0.01
TIP_COLOR = "#d62728"


def frame_indices(times, max_frames, t_start=None, t_stop=None):
    """Record indices of the frames: evenly spaced in [t_start, t_stop], at most max_frames."""
    lo = 0 if t_start is None else int(np.searchsorted(times, t_start, side="left"))
    hi = times.size - 1 if t_stop is None else int(np.searchsorted(times, t_stop, "right")) - 1
    if hi < lo:
        raise ValueError(f"no output record in the time window [{t_start}, {t_stop}] s")
    count = min(max_frames, hi - lo + 1)
    return np.unique(np.round(np.linspace(lo, hi, count)).astype(int))


def default_fps(times, frames):
    """Real-time playback, clipped to 5 .. 30 frames per second."""
    span = times[frames[-1]] - times[frames[0]]
    if frames.size < 2 or span <= 0:
        return 10.0
    return float(np.clip((frames.size - 1) / span, 5.0, 30.0))


#: the shortest GIF frame, hundredths of a second: the format counts frame times in
#: hundredths, and browsers play a shorter frame (0 or 0.01 s) at 0.1 s
GIF_MIN_CENTISECONDS = 2


def gif_centiseconds(fps):
    """A GIF frame's time for `fps`, in whole hundredths of a second (the format's unit),
    at least GIF_MIN_CENTISECONDS: at most 50 frames per second."""
    return max(GIF_MIN_CENTISECONDS, int(round(100.0 / fps)))


def written_fps(path, fps):
    """(the frame rate the animation at `path` plays at, a note saying why it is not `fps`
    or ''): a GIF's frame time is whole hundredths of a second, at least 0.02 s; an MP4
    takes `fps` as it is."""
    if pathlib.Path(path).suffix.lower() != ".gif":
        return fps, ""
    centiseconds = gif_centiseconds(fps)
    written = 100.0 / centiseconds
    if abs(written - fps) <= 1e-9 * fps:
        return written, ""
    return written, (f"; {fps:g} fps rounded to a GIF frame of {centiseconds / 100:g} s: "
                     "whole hundredths of a second, at least 0.02 s, so at most 50 fps")


def energy_panel(ax, run):
    """Energies over the whole run; returns the moving time cursor (a vertical line)."""
    t, e = run.time, run.energy
    one = plot.point_marker(run)        # with one record: points, and the panel says so
    ax.plot(t, e["kinetic"], lw=1, label="kinetic", **one)
    potential = e["gravity"] - e["gravity"][0] + e["elastic"]
    ax.plot(t, potential, lw=1, label="potential - V(0)", **one)
    plot.balance_curves(ax, run, 1.2)
    ax.legend(fontsize=7, loc="best", title=plot.BALANCE_NOTE, title_fontsize=7)
    ax.grid(alpha=0.3)
    return ax.axvline(t[0], color="0.3", lw=1, animated=True)


def build_figure(run, size, dpi, energy):
    """Figure, picture axes and the energy axes (or None)."""
    fig = plt.figure(figsize=(size[0] / dpi, size[1] / dpi), dpi=dpi)
    if energy:
        grid = fig.add_gridspec(1, 2, width_ratios=[1.1, 1.0])
        ax, ex = fig.add_subplot(grid[0]), fig.add_subplot(grid[1])
    else:
        ax, ex = fig.add_subplot(), None
    plot.setup_picture_axes(ax, run)
    plot.draw_ground(ax, run)
    plot.draw_water(ax, run)
    plot.draw_supports(ax, run, moving=False)
    plot.draw_support_paths(ax, run)
    ax.set_title(io.title(run), fontsize=9)
    return fig, ax, ex


class RopeFrames:
    """Draws the frames of one run by blitting: the static parts (axes, supports, energy
    curves) are drawn once, each frame restores them and draws only the moving artists."""

    def __init__(self, run, size, dpi, energy, trail):
        self.run, self.trail = run, trail
        self.fig, ax, ex = build_figure(run, size, dpi, energy)
        self.rope, = ax.plot([], [], "-", color=ROPE_COLOR, lw=2, animated=True)
        self.trail_line, = ax.plot([], [], "-", color=TIP_COLOR, lw=1, alpha=0.6,
                                   animated=True)
        self.tip, = ax.plot([], [], "o", color=TIP_COLOR, ms=4, animated=True)
        # moving supports: their anchor, moved along the stored path frame by frame
        self.moving = [s for s in fields.supports(run) if s.kind != "free" and s.moving]
        self.anchors = [ax.plot([], [], "s", ms=6, mfc="white", mec=plot.SUPPORT_PATH_COLOR,
                                mew=1.8, animated=True)[0] for _ in self.moving]
        self.stamp = ax.text(0.03, 0.04, "", transform=ax.transAxes, fontsize=10,
                             family="monospace", animated=True,
                             bbox={"fc": "white", "ec": "0.7", "alpha": 0.8})
        self.cursor = energy_panel(ex, run) if ex is not None else None
        self.fig.tight_layout()
        plot.fit_equal(ax)
        self.fig.tight_layout()  # the tick labels may have changed width
        self.axes = [(ax, [self.trail_line, self.rope, self.tip, *self.anchors, self.stamp])]
        if ex is not None:
            self.axes.append((ex, [self.cursor]))
        canvas = self.fig.canvas
        canvas.draw()
        self.background = canvas.copy_from_bbox(self.fig.bbox)

    def rgb(self, k):
        """Frame of record k as an (H, W, 3) uint8 array."""
        run, canvas = self.run, self.fig.canvas
        t, pts, tip = run.time, run.points, run.points[:, -1, :]
        first = np.searchsorted(t, t[k] - self.trail, side="left")
        self.rope.set_data(pts[k, :, 1], pts[k, :, 0])
        self.trail_line.set_data(tip[first:k + 1, 1], tip[first:k + 1, 0])
        self.tip.set_data([tip[k, 1]], [tip[k, 0]])
        for sup, marker in zip(self.moving, self.anchors):
            marker.set_data([sup.path[k, 1]], [sup.path[k, 0]])
        self.stamp.set_text(f"t = {t[k]:7.3f} s")
        if self.cursor is not None:
            self.cursor.set_xdata([t[k], t[k]])
        canvas.restore_region(self.background)
        for ax, artists in self.axes:
            for artist in artists:
                ax.draw_artist(artist)
        return np.asarray(canvas.buffer_rgba())[..., :3].copy()

    def close(self):
        plt.close(self.fig)


def _swatches(width):
    """Blocks of the moving artists' colours, so that the shared palette keeps them."""
    colors = [ROPE_COLOR, TIP_COLOR, plot.SUPPORT_PATH_COLOR]
    rgb = [np.array(matplotlib.colors.to_rgb(c)) for c in colors]
    rgb.append(0.6 * rgb[1] + 0.4)  # the trail (alpha 0.6) over white
    return np.concatenate([np.broadcast_to((255 * c).astype(np.uint8), (40, width, 3))
                           for c in rgb], axis=0)


def save_gif(path, frames, fps, comment=""):
    """GIF with one palette for all frames (from the first, middle and last frame and the
    artists' colours): no flicker, small frame deltas, fast; `comment` says what made it."""
    from PIL import Image

    frames = list(frames)
    probe = np.concatenate([frames[0], frames[len(frames) // 2], frames[-1],
                            _swatches(frames[0].shape[1])], axis=0)
    palette = Image.fromarray(probe).quantize(colors=255, method=Image.Quantize.MEDIANCUT)
    images = [Image.fromarray(f).quantize(palette=palette, dither=Image.Dither.NONE)
              for f in frames]
    images[0].save(path, format="GIF", save_all=True, append_images=images[1:],
                   duration=10 * gif_centiseconds(fps), loop=0,
                   comment=comment.encode("utf-8")[:255])


def save_mp4(path, frames, fps, comment=""):
    """MP4 (H.264) by piping raw RGB frames to ffmpeg; `comment` says what made it."""
    frames = iter(frames)
    first = next(frames)
    height, width = first.shape[:2]
    command = ["ffmpeg", "-y", "-loglevel", "error", "-f", "rawvideo", "-pix_fmt", "rgb24",
               "-s", f"{width}x{height}", "-r", f"{fps:.6g}", "-i", "-",
               "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-c:v", "libx264",
               "-pix_fmt", "yuv420p", "-metadata", f"comment={comment}", "-f", "mp4",
               str(path)]
    with subprocess.Popen(command, stdin=subprocess.PIPE) as proc:
        proc.stdin.write(first.tobytes())
        for frame in frames:
            proc.stdin.write(frame.tobytes())
        proc.stdin.close()
        if proc.wait() != 0:
            raise RuntimeError(f"{path}: ffmpeg failed (exit code {proc.returncode})")


def check_format(path, run_path):
    """ValueError if the animation cannot be written in the format of path's suffix or in
    its directory (none), or if path is the run file it is drawn from."""
    if path.resolve() == pathlib.Path(run_path).resolve():
        raise ValueError(f"{path}: is the run file itself: give the animation another name")
    suffix = path.suffix.lower()
    if suffix == ".mp4" and shutil.which("ffmpeg") is None:
        raise ValueError(f"{path}: MP4 needs the ffmpeg program, which is not installed "
                         "(Debian: apt-get install ffmpeg); write a .gif instead")
    if suffix not in (".gif", ".mp4"):
        raise ValueError(f"{path}: unknown animation format '{suffix}' (use .gif or .mp4)")
    plot.check_directory(path)


def parse_args(argv):
    parser = argparse.ArgumentParser(description=summary(__doc__))
    parser.add_argument("run", help="HDF5 output of ropedyn run")
    parser.add_argument("-o", "--output", help="animation file, .gif or .mp4 "
                                               "(default: RUN.gif next to the run)")
    parser.add_argument("--max-frames", type=int, default=300,
                        help="at most this many frames, evenly spaced (default 300)")
    parser.add_argument("--fps", type=float, help="frames per second "
                        "(default: real time, within 5 .. 30); a GIF plays at most 50, "
                        "its frame time in whole hundredths of a second")
    parser.add_argument("--start", type=float, help="first time shown (s)")
    parser.add_argument("--end", type=float, help="last time shown (s)")
    parser.add_argument("--trail", type=float, default=1.0,
                        help="length of the tip's trail in simulated seconds (default 1)")
    parser.add_argument("--energy", action="store_true", help="add an energy panel")
    parser.add_argument("--size", default=None,
                        help="WIDTHxHEIGHT in pixels (default 640x520, 1000x480 with --energy)")
    parser.add_argument("--dpi", type=plot.parse_dpi, default=100,
                        help="dots per inch (default 100)")
    args = parser.parse_args(argv)
    if args.max_frames < 1:
        parser.error("--max-frames must be >= 1")
    if args.fps is not None and not args.fps >= MIN_FPS:
        # (a GIF frame lasts at most 655.35 s; Pillow ended in an OverflowError)
        parser.error(f"--fps must be >= {MIN_FPS:g} (a frame of at most 100 s)")
    try:
        args.size = plot.parse_size(args.size or ("1000x480" if args.energy else "640x520"))
    except ValueError as exc:
        parser.error(str(exc))
    return args


def main(argv=None):
    args = parse_args(argv)
    out = pathlib.Path(args.output or str(pathlib.Path(args.run).with_suffix(".gif")))
    run, code = plot.load_records("animate", args.run)
    if run is None:
        return code
    try:
        check_format(out, args.run)
        frames = frame_indices(run.time, args.max_frames, args.start, args.end)
    except ValueError as exc:
        print(f"animate: {exc}", file=sys.stderr)
        return 2
    fps = args.fps or default_fps(run.time, frames)
    started = wallclock.perf_counter()
    drawer = RopeFrames(run, args.size, args.dpi, args.energy, args.trail)
    comment = plot.made_by(run, "ropedyn.animate (scripts/animate)")
    try:
        images = (drawer.rgb(k) for k in frames)
        with plot.written_whole(out) as part:
            if out.suffix.lower() == ".mp4":
                save_mp4(part, images, fps, comment)
            else:
                save_gif(part, images, fps, comment)
    finally:
        drawer.close()
    played, note = written_fps(out, fps)
    print(f"animate: {out} ({frames.size} frames at {played:.3g} fps, "
          f"{frames.size / played:.1f} s long{note}; written in "
          f"{wallclock.perf_counter() - started:.1f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
