"""Seeing the results (docs/guide/visualization.md): animations, the overview plot, the XDMF
sidecar read by ParaView, the README figures, and the derived fields they show.

Small runs (5 elements, 0.2 s) are made once per module; each script runs as a user would
run it, and its picture is checked for size and for not being blank."""
import hashlib
import json
import os
import pathlib
import re
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET

import h5py
import numpy as np
import pytest
from PIL import Image

from ropedyn import fields, io
from ropedyn.namelist import parse_namelist

ROOT = pathlib.Path(__file__).resolve().parents[2]
G = np.array([9.81, 0.0])


def ropedyn(exe, workdir, scene_text, name, *overrides):
    """Run a scene (text) in workdir; returns the path of its HDF5 output."""
    scene = workdir / f"{name}.nml"
    scene.write_text(scene_text)
    out = workdir / f"{name}.h5"
    args = [str(exe), "run", str(scene), "--set", f"output.file={out}"]
    for item in overrides:
        args += ["--set", item]
    result = subprocess.run(args, capture_output=True, text=True, timeout=300, cwd=workdir)
    assert result.returncode == 0, result.stdout + result.stderr
    return out


def script(module, *args, package="ropedyn"):
    """Run `python -m PACKAGE.MODULE ARGS` (the code of scripts/animate, scripts/plot, ...)
    with this Python, tools/ on its path as the scripts/ commands put it (for the package
    ropedyn_tools, not installed) and python/ before it (the package ropedyn of this tree,
    also with a venv made for another worktree); returns the CompletedProcess."""
    path = os.pathsep.join([str(ROOT / "python"), str(ROOT / "tools")])
    return subprocess.run([sys.executable, "-m", f"{package}.{module}", *map(str, args)],
                          capture_output=True, text=True, timeout=120,
                          env=dict(os.environ, PYTHONPATH=path))


def assert_picture(image, size):
    """image has the pixel size (width, height) and is not blank."""
    assert image.size == size
    pixels = np.asarray(image.convert("RGB"), dtype=float)
    assert pixels.std() > 5.0, "picture is blank"


TINY = ("&model kind = 'rfem', elements = 5 /\n"
        "&solver t_end = 0.2, output_interval = 0.01 /\n")
TINY_MPP = ("&model kind = 'mpp', elements = 5 /\n"
            "&supports top = 'clamped', top_angle_deg = 10.0 /\n"
            "&solver t_end = 0.2, output_interval = 0.01 /\n")
RECORDS = 21


@pytest.fixture(scope="module")
def workdir(tmp_path_factory):
    return tmp_path_factory.mktemp("vis")


@pytest.fixture(scope="module")
def tiny(ropedyn_exe, workdir):
    """An RFEM run: 5 elements, 0.2 s, 21 records."""
    return ropedyn(ropedyn_exe, workdir, TINY, "tiny")


@pytest.fixture(scope="module")
def tiny_mpp(ropedyn_exe, workdir):
    """An MPP run with a clamped top."""
    return ropedyn(ropedyn_exe, workdir, TINY_MPP, "tiny_mpp")


# --- animate -------------------------------------------------------------------------------

def test_animate_gif(tiny, tmp_path):
    gif = tmp_path / "rope.gif"
    result = script("animate", tiny, "-o", gif, "--size", "320x240", "--max-frames", "12")
    assert result.returncode == 0, result.stderr
    with Image.open(gif) as image:
        assert image.n_frames == 12
        assert_picture(image, (320, 240))
        first = np.asarray(image.convert("RGB")).copy()
        image.seek(image.n_frames - 1)
        last = np.asarray(image.convert("RGB"))
        assert_picture(image, (320, 240))
    assert np.any(first != last), "the rope does not move"


def test_animate_mpp_with_energy_panel(tiny_mpp, tmp_path):
    gif = tmp_path / "mpp.gif"
    result = script("animate", tiny_mpp, "-o", gif, "--energy", "--size", "500x240")
    assert result.returncode == 0, result.stderr
    with Image.open(gif) as image:
        assert image.n_frames == RECORDS  # fewer records than --max-frames: one frame each
        assert_picture(image, (500, 240))


def test_animate_default_output_next_to_run(tiny, workdir):
    result = script("animate", tiny, "--max-frames", "3")
    assert result.returncode == 0, result.stderr
    assert (workdir / "tiny.gif").stat().st_size > 1000


def test_animate_mp4_needs_ffmpeg(tiny, tmp_path):
    mp4 = tmp_path / "rope.mp4"
    result = script("animate", tiny, "-o", mp4, "--max-frames", "5", "--size", "320x240")
    if shutil.which("ffmpeg"):
        assert result.returncode == 0, result.stderr
        assert mp4.stat().st_size > 1000
    else:
        assert result.returncode == 2
        assert "needs the ffmpeg program" in result.stderr and ".gif" in result.stderr
        assert not mp4.exists()


def test_animate_rejects_unknown_format(tiny, tmp_path):
    result = script("animate", tiny, "-o", tmp_path / "rope.avi")
    assert result.returncode == 2 and "unknown animation format '.avi'" in result.stderr


def test_animate_refuses_to_replace_the_run_file(tiny, tmp_path):
    """A run file named RUN.gif (default output RUN.gif) or given as -o: a usage error,
    exit 2, and the run file untouched (the GIF replaced it)."""
    run_as_gif = tmp_path / "run.gif"
    shutil.copy(tiny, run_as_gif)
    for args in ([], ["-o", run_as_gif]):
        result = script("animate", run_as_gif, "--max-frames", "3", *args)
        assert result.returncode == 2, result.stderr
        assert "is the run file itself" in result.stderr
        assert run_as_gif.read_bytes() == pathlib.Path(tiny).read_bytes()


@pytest.mark.parametrize("fps", ["0", "-1", "nan", "1e-9"])
def test_animate_refuses_a_frame_rate_too_slow_to_write(fps, tiny, tmp_path):
    """--fps at or below 0, not a number, or so slow that a GIF frame cannot last that long
    (1e-9 ended in Pillow's OverflowError traceback): a usage error, exit 2."""
    gif = tmp_path / "a.gif"
    result = script("animate", tiny, "-o", gif, "--max-frames", "2", "--fps", fps)
    assert result.returncode == 2, result.stderr
    assert "--fps must be >= 0.01" in result.stderr and "Traceback" not in result.stderr
    assert not gif.exists()


@pytest.mark.parametrize("fps, played, frame", [("60", "50", 20), ("1000", "50", 20),
                                                ("30", "33.3", 30), ("25", "25", 40)])
def test_animate_says_the_frame_rate_a_gif_plays_at(fps, played, frame, tiny, tmp_path):
    """A GIF's frame time is whole hundredths of a second, at least 0.02 s: --fps 60 plays
    at 50 fps, 30 at 33.3 (0.03 s). The report gives the rate written and says why it is
    not the one asked for (it gave --fps as asked); an MP4 takes the rate as it is."""
    from ropedyn import animate

    gif = tmp_path / "a.gif"
    result = script("animate", tiny, "-o", gif, "--max-frames", "3", "--fps", fps)
    assert result.returncode == 0, result.stderr
    assert f"(3 frames at {played} fps, " in result.stdout, result.stdout
    rounded = f"{fps} fps rounded to a GIF frame of {frame / 1000:g} s"
    assert (rounded in result.stdout) == (fps != played), result.stdout
    with Image.open(gif) as image:
        assert image.info["duration"] == frame
    assert animate.written_fps(tmp_path / "a.mp4", 60.0) == (60.0, "")


# --- plot ----------------------------------------------------------------------------------

@pytest.mark.parametrize("module", ["plot.overview", "plot.energy"])
def test_plots_refuse_a_name_that_takes_no_picture(module, tiny, tmp_path):
    """A name whose suffix matplotlib cannot write (it ended in matplotlib's traceback), or
    the run file itself (the picture would replace the data it is drawn from): a usage
    error, exit 2, and the run file untouched."""
    result = script(module, tiny, "-o", tmp_path / "plot.h5")
    assert result.returncode == 2, result.stderr
    assert "a picture's name ends in one of" in result.stderr
    assert "Traceback" not in result.stderr and not (tmp_path / "plot.h5").exists()
    run_as_png = tmp_path / "run.png"
    shutil.copy(tiny, run_as_png)
    result = script(module, run_as_png, "-o", run_as_png)
    assert result.returncode == 2 and "is the run file itself" in result.stderr
    assert run_as_png.read_bytes() == pathlib.Path(tiny).read_bytes()


@pytest.mark.parametrize("module", ["plot.overview", "plot.energy", "animate", "xdmf"])
def test_scripts_say_that_a_file_is_no_run_file(module, ropedyn_exe, tmp_path):
    """A file that is not a run file (the result of `ropedyn statics`, a text file, no file)
    is a usage error: one line naming the file and what it is, exit 2 (it ended in h5py's
    KeyError or OSError traceback)."""
    scene = tmp_path / "s.nml"
    scene.write_text(TINY)
    made = subprocess.run([str(ropedyn_exe), "statics", str(scene), "-o",
                           str(tmp_path / "statics.h5")], capture_output=True, text=True,
                          timeout=300, cwd=tmp_path)
    assert made.returncode == 0, made.stderr
    (tmp_path / "notes.h5").write_text("not HDF5\n")
    says = {"statics.h5": "statics.h5: not a run file of ropedyn (no /time): the file of "
                          "`ropedyn statics`",
            "notes.h5": "notes.h5: not an HDF5 file",
            "missing.h5": "missing.h5: no such file"}
    for name, message in says.items():
        result = script(module, tmp_path / name)
        assert result.returncode == 2, result.stderr
        assert "Traceback" not in result.stderr and message in result.stderr, result.stderr


@pytest.mark.parametrize("module", ["plot.overview", "plot.energy", "animate", "xdmf"])
def test_scripts_say_that_a_run_holds_the_file_open(module, tiny, tmp_path):
    """A run file held open for writing (here by this test, as a running ropedyn holds its
    FILE.part): one line naming the file and the way to read it anyway, exit 2 (h5py's
    "[Errno 11] Unable to synchronously open file (unable to lock file ...)" before)."""
    live = tmp_path / "live.h5.part"
    shutil.copy(tiny, live)
    env = {k: v for k, v in os.environ.items() if k != "HDF5_USE_FILE_LOCKING"}
    with h5py.File(live, "r+"):
        result = subprocess.run([sys.executable, "-m", f"ropedyn.{module}", str(live)],
                                capture_output=True, text=True, timeout=120,
                                env=dict(env, PYTHONPATH=str(ROOT / "python")))
    assert result.returncode == 2, result.stderr
    assert result.stderr.endswith(f"{live}: held open for writing (a run is writing it; to "
                                  "read it as of its last flush, set "
                                  "HDF5_USE_FILE_LOCKING=FALSE)\n"), result.stderr


@pytest.mark.parametrize("module", ["plot.overview", "plot.energy", "animate", "xdmf"])
def test_scripts_say_that_a_file_has_no_records(module, tiny, tmp_path):
    """A run file without records (a run killed before its first flush): one line, exit 1
    and no picture (plot_energy ended in an IndexError traceback)."""
    empty = tmp_path / "empty.h5"
    shutil.copy(tiny, empty)
    with h5py.File(empty, "r+") as f:
        f["time"].resize(0, axis=0)
    result = script(module, empty)
    assert result.returncode == 1, result.stderr
    assert "Traceback" not in result.stderr
    assert f"{empty}: no output records" in result.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["empty.h5"]


@pytest.mark.parametrize("module, suffix", [("plot.overview", "_plot.png"),
                                            ("plot.energy", "_energy.png")])
def test_plot_of_a_killed_run_keeps_the_complete_runs_picture(module, suffix, tiny,
                                                              tmp_path):
    """The picture of RUN.h5.part (a killed run's file, beside the complete RUN.h5 of an
    earlier run) is RUN.h5_SUFFIX: RUN_SUFFIX, the complete run's picture, stays (the
    energy plot cut the name at '.h5' and replaced it)."""
    shutil.copy(tiny, tmp_path / "r.h5")
    shutil.copy(tiny, tmp_path / "r.h5.part")
    assert script(module, tmp_path / "r.h5").returncode == 0
    before = sha256(tmp_path / f"r{suffix}")
    result = script(module, tmp_path / "r.h5.part")
    assert result.returncode == 0, result.stderr
    assert sha256(tmp_path / f"r{suffix}") == before
    assert (tmp_path / f"r.h5{suffix}").stat().st_size > 1000


@pytest.mark.parametrize("module, name", [("plot.overview", "p.png"),
                                          ("plot.energy", "e.png"), ("animate", "a.gif")])
def test_pictures_refuse_a_directory_that_does_not_exist(module, name, tiny, tmp_path):
    """-o into a directory that does not exist: one line, exit 2 (it ended in a
    FileNotFoundError traceback after the drawing)."""
    result = script(module, tiny, "-o", tmp_path / "nowhere" / name)
    assert result.returncode == 2, result.stderr
    assert "Traceback" not in result.stderr
    assert f"no such directory: {tmp_path / 'nowhere'}" in result.stderr
    assert not (tmp_path / "nowhere").exists()


@pytest.mark.parametrize("module", ["plot.overview", "animate"])
@pytest.mark.parametrize("option, says", [
    (("--size", "0x480"), "size '0x480': expected WIDTHxHEIGHT in pixels"),
    (("--dpi", "0"), "argument --dpi: '0': expected dots per inch, an integer >= 1")])
def test_pictures_refuse_a_size_or_dpi_of_zero(module, option, says, tiny, tmp_path):
    """A picture of no pixels or no dots per inch: a usage error, exit 2 (they ended in
    numpy's LinAlgError or a ZeroDivisionError traceback)."""
    out = tmp_path / ("p.png" if module == "plot.overview" else "a.gif")
    result = script(module, tiny, "-o", out, *option)
    assert result.returncode == 2, result.stderr
    assert says in result.stderr and "Traceback" not in result.stderr
    assert not out.exists()


@pytest.mark.parametrize("which", ["tiny", "tiny_mpp"])
def test_plot(which, request, tmp_path):
    run_file = request.getfixturevalue(which)
    png = tmp_path / "plot.png"
    result = script("plot", run_file, "-o", png, "--size", "900x700", "--times",
                    "0.05,0.2")
    assert result.returncode == 0, result.stderr
    with Image.open(png) as image:
        assert_picture(image, (900, 700))


@pytest.mark.parametrize("times, says", [("0.1,5", "--times 5: outside the run"),
                                         ("-0.1", "--times -0.1: outside the run"),
                                         ("0.21", "--times 0.21: outside the run"),
                                         ("nan", "--times nan: not a finite time"),
                                         ("inf", "--times inf: not a finite time")])
def test_plot_refuses_times_outside_the_run(times, says, tiny, tmp_path):
    """A time of --times outside the run's records (0 to 0.2 s, output interval 0.01 s;
    half an interval beyond either end is taken) or not finite is a usage error naming the
    records' span: it was drawn at the nearest record (nan at t = 0) without a word."""
    png = tmp_path / "plot.png"
    result = script("plot.overview", tiny, "-o", png, f"--times={times}")
    assert result.returncode == 2, result.stderr
    assert f"error: {says}" in result.stderr and "Traceback" not in result.stderr
    assert "the run's records span t = 0 to 0.2 s" in result.stderr
    assert not png.exists()
    inside = script("plot.overview", tiny, "-o", png, "--times=-0.004,0.1,0.204")
    assert inside.returncode == 0, inside.stderr


def test_plot_of_a_file_without_forces(ropedyn_exe, tmp_path):
    """A file written before the internal forces were stored (here: with them removed):
    no axial force is derived; the panel and the XDMF writer say why."""
    run_file = ropedyn(ropedyn_exe, tmp_path, TINY, "old")
    with h5py.File(run_file, "a") as f:
        del f["forces"], f["supports"]
    force, message = fields.axial_force(io.load_run(run_file))
    assert force is None and "predates stored internal forces" in message
    result = script("plot", run_file)
    assert result.returncode == 0, result.stderr
    with Image.open(tmp_path / "old_plot.png") as image:
        assert_picture(image, (1200, 900))
    result = script("xdmf", run_file)
    assert result.returncode == 0 and "predates stored internal forces" in result.stderr
    with h5py.File(tmp_path / "old_fields.h5") as f:
        assert "cell/tension" not in f and "cell/curvature" in f


def one_record_copy(run_file, path):
    """A copy of a run file cut to its first record (the file of a run killed after its
    first flush)."""
    path.write_bytes(pathlib.Path(run_file).read_bytes())
    with h5py.File(path, "r+") as f:
        def cut(name, obj):
            if isinstance(obj, h5py.Dataset) and obj.maxshape and obj.maxshape[0] is None:
                obj.resize(1, axis=0)
        f.visititems(cut)
    return path


def test_plots_of_one_record_draw_points(tiny, tmp_path, monkeypatch):
    """With one record a line draws nothing: the energy curves (overview, energy plot,
    animation panel) and the balance error are drawn as points, and the panels say "one
    record"; the step-size panel says that there is no step before it."""
    import matplotlib.pyplot as plt
    from ropedyn import animate, plot
    from ropedyn.plot import energy, overview

    run = io.load_run(one_record_copy(tiny, tmp_path / "one.h5"))
    assert run.time.size == 1

    def texts(ax):
        return " ".join(text.get_text() for text in ax.texts)

    def assert_points(ax):
        assert ax.lines and all(line.get_marker() not in (None, "None", "", " ")
                                for line in ax.lines if len(line.get_xdata()) == 1)
        assert "one record (t = 0 s)" in texts(ax)

    fig, (left, middle, right) = plt.subplots(1, 3)
    overview.plot_energies(left, run)
    overview.plot_solver(middle, run)
    animate.energy_panel(right, run)
    assert_points(left)
    assert_points(right)
    assert "one record (t = 0 s):\nno step before it" in texts(middle)
    figures = []
    monkeypatch.setattr(plot, "save_figure", lambda fig, *args, **kw: figures.append(fig))
    assert energy.main([str(run.path), "-o", str(tmp_path / "energy.png")]) == 0
    for ax in figures[0].axes:
        assert_points(ax)
    plt.close("all")
    result = script("plot", run.path)
    assert result.returncode == 0, result.stderr
    with Image.open(tmp_path / "one_plot.png") as image:
        assert_picture(image, (1200, 900))


# a damped rope on a shaken top: energy dissipated and work done by the first second tenth
DAMPED_SHAKEN = ("&model kind = 'rfem', elements = 5 /\n&rope normal_damping = 2.0e4 /\n"
                 "&supports top_motion = 'harmonic', top_amplitude = 0.0, 0.2, "
                 "top_frequency = 2.0 /\n"
                 "&solver t_end = 0.2, output_interval = 0.01 /\n")


def test_plots_take_the_balances_e0(ropedyn_exe, tmp_path, monkeypatch):
    """A run started from a record of another (&initial shape = 'state') carries the energy
    dissipated and the work done before into its balance: E0 = T + V + dissipated - work at
    its first record, as `ropedyn run` prints it. The energy plot, the overview and the
    animation's panel draw against that E0 (T + V at the first record, which they took
    before, is off by what was dissipated and done before: the balance started off zero)."""
    import matplotlib.pyplot as plt
    from ropedyn import animate, plot
    from ropedyn.plot import energy, overview

    ropedyn(ropedyn_exe, tmp_path, DAMPED_SHAKEN, "whole")
    scene = tmp_path / "branch.nml"
    scene.write_text(DAMPED_SHAKEN + "&initial shape = 'state', state_file = 'whole.h5', "
                     "state_time = 0.1 /\n")
    result = subprocess.run([str(ropedyn_exe), "run", str(scene), "--set",
                             "output.file='branch.h5'"], capture_output=True, text=True,
                            timeout=300, cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    printed = float(re.search(r"^ +E0 +(\S+) J$", result.stdout, re.M).group(1))
    run = io.load_run(tmp_path / "branch.h5")
    e = run.energy
    e0 = e["total"][0] + e["dissipated"][0] - e["support_work"][0]
    assert e["dissipated"][0] > 1e-5 and abs(e["support_work"][0]) > 1e-5, e
    assert abs(e0 - printed) <= 5e-6 * abs(e0)          # printed to 6 digits

    def start_of(ax, label):
        """E0 as the curve `label` (total - E0) of `ax` has it."""
        (line,) = [line for line in ax.lines if line.get_label() == label]
        return e["total"][0] - line.get_ydata()[0]

    figures = []
    monkeypatch.setattr(plot, "save_figure", lambda fig, *args, **kw: figures.append(fig))
    assert energy.main([str(run.path), "-o", str(tmp_path / "energy.png")]) == 0
    ax, bx = figures[0].axes
    assert abs(start_of(ax, "total E - E0 = T + V - E0") - e0) <= 1e-12
    assert abs(bx.lines[0].get_ydata()[0]) <= 1e-12     # the balance error starts at 0
    fig, (left, right) = plt.subplots(1, 2)
    overview.plot_energies(left, run)
    animate.energy_panel(right, run)
    assert abs(start_of(left, "total - E0") - e0) <= 1e-12
    assert abs(start_of(right, "total - E0") - e0) <= 1e-12
    plt.close("all")


def test_energy_plots_draw_the_work_done_on_the_rope(ropedyn_exe, tiny, tmp_path,
                                                     monkeypatch):
    """A shaken support does work on the rope, so T + V - E0 grows although the balance
    holds: T + V - E0 = W - dissipated. The energy plot, the overview and the animation's
    panel draw the work W (/energy/support_work) beside the total, and say what balances;
    a run without work (no moving support, load or current) gets no work curve."""
    import matplotlib.pyplot as plt
    from ropedyn import animate, plot
    from ropedyn.plot import energy, overview

    run = io.load_run(ropedyn(ropedyn_exe, tmp_path, DAMPED_SHAKEN, "shaken"))
    e = run.energy
    assert e["support_work"][-1] > 0.01 and e["dissipated"][-1] > 0.01, e

    def curve(ax, label):
        found = [line for line in ax.lines if line.get_label() == label]
        return found[0].get_ydata() if found else None

    figures = []
    monkeypatch.setattr(plot, "save_figure", lambda fig, *args, **kw: figures.append(fig))
    assert energy.main([str(run.path), "-o", str(tmp_path / "energy.png")]) == 0
    fig, (left, right) = plt.subplots(1, 2)
    overview.plot_energies(left, run)
    animate.energy_panel(right, run)
    for ax, total in ((figures[0].axes[0], "total E - E0 = T + V - E0"), (left, "total - E0"),
                      (right, "total - E0")):
        work = curve(ax, "work W (supports, loads, current)")
        assert work is not None, [line.get_label() for line in ax.lines]
        assert np.array_equal(work, e["support_work"])
        # what the legend says: the total follows the work less the dissipated energy
        assert ax.get_legend().get_title().get_text() == "T + V - E0 = W - dissipated"
        gap = curve(ax, total) - (work - e["dissipated"])
        assert np.max(np.abs(gap)) < 1e-3 * np.max(np.abs(work))
    # the balance panel stays: T + V + dissipated - work - E0
    assert np.allclose(figures[0].axes[1].lines[0].get_ydata(), run.balance - run.e0)
    still = io.load_run(tiny)
    assert not np.any(still.energy["support_work"])
    fig, ax = plt.subplots()
    overview.plot_energies(ax, still)
    assert curve(ax, "work W (supports, loads, current)") is None
    plt.close("all")


SHAKEN_GROUND = ("&model kind = '{kind}', elements = 5 /\n"
                 "&supports top_motion = 'harmonic', top_amplitude = 0.0, 0.2, "
                 "top_frequency = 2.0 /\n"
                 "&effects ground = .true. /\n&ground point = 0.9, 0.0, normal = -1.0, 0.2 /\n"
                 "&solver t_end = 0.2, output_interval = 0.01 /\n")


@pytest.mark.parametrize("kind", ["rfem", "mpp"])
def test_pictures_show_the_moving_support_and_the_ground(ropedyn_exe, tmp_path, kind):
    """A top shaken sideways over a sloping ground: the overview's picture draws the
    support's stored path and the ground line through &ground point with its normal, and
    the animation moves the support's marker along the path."""
    from ropedyn import animate
    from ropedyn.plot import overview

    run_file = ropedyn(ropedyn_exe, tmp_path, SHAKEN_GROUND.format(kind=kind), kind)
    run = io.load_run(run_file)
    top, _ = fields.supports(run)
    assert top.moving and np.array_equal(top.path, run.anchors["top"])
    fig = overview.make_figure(run, [0.1], (900, 700), 100)
    ax = fig.axes[1]
    lines = {line.get_label(): line for line in ax.get_lines()}
    path = lines["top support path"]
    assert np.array_equal(path.get_xdata(), run.anchors["top"][:, 1])
    assert np.array_equal(path.get_ydata(), run.anchors["top"][:, 0])
    ground = lines["ground"]
    (y0, x0), (y1, x1) = ground._xy1, ground._xy2
    assert (x0, y0) == (0.9, 0.0)
    assert np.dot([x1 - x0, y1 - y0], [-1.0, 0.2]) == pytest.approx(0.0, abs=1e-12)
    frames = animate.RopeFrames(run, (320, 240), 100, False, 1.0)
    try:
        frames.rgb(7)
        marker, = frames.anchors
        assert marker.get_xdata()[0] == run.anchors["top"][7, 1]
        assert marker.get_ydata()[0] == run.anchors["top"][7, 0]
    finally:
        frames.close()
    result = script("animate", run_file, "-o", tmp_path / "a.gif", "--max-frames", "4",
                    "--size", "320x240")
    assert result.returncode == 0, result.stderr


WATER = ("&model kind = '{kind}', elements = 6 /\n"
         "&rope diameter = 0.01 /\n&initial shape = 'straight', angle_deg = 60.0 /\n"
         "&effects water = .true. /\n&fluid density = 1000.0, surface = 0.4 /\n"
         "&solver t_end = 0.1, output_interval = 0.01 /\n")


@pytest.mark.parametrize("kind", ["rfem", "mpp"])
def test_pictures_show_the_water_surface(ropedyn_exe, tmp_path, kind):
    """A rope swinging into water: the overview's picture and the animation draw the
    surface at &fluid surface (x down) and shade the water below it; a scene without water
    draws none."""
    from ropedyn import animate
    from ropedyn.plot import overview

    wet = io.load_run(ropedyn(ropedyn_exe, tmp_path, WATER.format(kind=kind), kind))
    dry = io.load_run(ropedyn(ropedyn_exe, tmp_path, WATER.format(kind=kind), kind + "_dry",
                              "effects.water=.false."))
    for run, drawn in ((wet, True), (dry, False)):
        ax = overview.make_figure(run, [0.05], (900, 700), 100).axes[1]
        lines = {line.get_label(): line for line in ax.get_lines()}
        assert ("water surface" in lines) == drawn
        if drawn:
            assert list(lines["water surface"].get_ydata()) == [0.4, 0.4]
            shade, = [p for p in ax.patches if p.get_alpha() == 0.08]
            assert shade.get_y() == pytest.approx(0.4) and shade.get_height() > 0
    frames = animate.RopeFrames(wet, (320, 240), 100, False, 1.0)
    try:
        labels = [line.get_label() for line in frames.fig.axes[0].get_lines()]
        assert "water surface" in labels
    finally:
        frames.close()


# --- XDMF ----------------------------------------------------------------------------------

def sha256(path):
    return hashlib.sha256(pathlib.Path(path).read_bytes()).hexdigest()


def hdf_items(root):
    """(file, dataset, dimensions) of every HDF DataItem."""
    for item in root.iter("DataItem"):
        if item.get("Format") == "HDF":
            file_name, dataset = item.text.strip().split(":", 1)
            yield file_name, dataset, tuple(int(d) for d in item.get("Dimensions").split())


@pytest.fixture(scope="module")
def tiny_xmf(tiny):
    before = sha256(tiny)
    result = script("xdmf", tiny)
    assert result.returncode == 0, result.stderr
    assert sha256(tiny) == before, "ropedyn.xdmf changed the run file"
    return tiny.with_suffix(".xmf")


def test_xdmf_references_existing_datasets(tiny_xmf):
    root = ET.parse(tiny_xmf).getroot()
    grids = root.findall("./Domain/Grid/Grid")
    assert len(grids) == RECORDS
    with h5py.File(tiny_xmf.with_suffix(".h5")) as f:
        times = f["time"][:]
    assert [float(g.find("Time").get("Value")) for g in grids] == times.tolist()
    seen = set()
    for file_name, dataset, dims in hdf_items(root):
        with h5py.File(tiny_xmf.parent / file_name, "r") as f:
            assert dataset in f, f"{file_name}:{dataset}"
            assert f[dataset].shape == dims, f"{file_name}:{dataset}"
        seen.add(dataset)
    assert {"/connectivity"} | {f"/records/record_000007/{name}" for name in (
        "cell/tension", "cell/curvature", "cell/speed", "cell/velocity",
        "point/joint_tension")} <= seen
    # the geometry: a plain dataset per record holding the run's points of that record
    with h5py.File(tiny_xmf.with_suffix(".h5")) as f, \
            h5py.File(tiny_xmf.with_name("tiny_fields.h5")) as g:
        for k in range(RECORDS):
            assert f"/geometry/record_{k:06d}" in seen
            assert np.array_equal(g[f"geometry/record_{k:06d}"][:], f["rope/points"][k])
            assert np.array_equal(g[f"records/record_{k:06d}/cell/tension"][:],
                                  g["cell/tension"][k])
    assert all(g.find("Geometry/DataItem").get("Format") == "HDF" for g in grids)
    first = grids[0]
    assert first.find("Topology").get("NumberOfElements") == "5"
    assert first.find("Geometry").get("GeometryType") == "XY"


@pytest.mark.parametrize("reader", ["open", "XDMFReader", "Xdmf3ReaderS", "Xdmf3ReaderT"])
def test_paraview_reads_the_time_series(tiny_xmf, tmp_path, reader):
    """The sidecar opens in pvpython with OpenDataFile (ParaView's choice: an Xdmf3 reader)
    and with each XDMF reader ParaView offers, and each sees the same geometry and fields
    at every checked time (the Xdmf3 readers crashed on a HyperSlab geometry)."""
    pvpython = shutil.which("pvpython")
    if pvpython is None:
        pytest.skip("pvpython not found (Debian package python3-paraview, installed by "
                    "scripts/setup)")
    with h5py.File(tiny_xmf.with_suffix(".h5")) as f, \
            h5py.File(tiny_xmf.with_name("tiny_fields.h5")) as g:
        times = f["time"][:]
        checks = [{"record": k, "tip": f["rope/points"][k, -1].tolist(),
                   "tension": g["cell/tension"][k].tolist()} for k in (0, 7, RECORDS - 1)]
    expected = tmp_path / "expected.json"
    expected.write_text(json.dumps({"times": times.tolist(), "elements": 5,
                                    "checks": checks}))
    result = subprocess.run([pvpython, "--force-offscreen-rendering",
                             str(ROOT / "tests" / "e2e" / "pv_check_xdmf.py"),
                             str(tiny_xmf.resolve()), str(expected), reader],
                            capture_output=True, text=True, timeout=120)
    assert result.returncode == 0 and "OK" in result.stdout, result.stdout + result.stderr
    assert f"timesteps {RECORDS}" in result.stdout


def test_xdmf_for_mpp(tiny_mpp):
    result = script("xdmf", tiny_mpp, "--every", "5")
    assert result.returncode == 0, result.stderr
    root = ET.parse(tiny_mpp.with_suffix(".xmf")).getroot()
    assert len(root.findall("./Domain/Grid/Grid")) == 5  # records 0, 5, 10, 15, 20
    with h5py.File(tiny_mpp.with_name("tiny_mpp_fields.h5")) as f, h5py.File(tiny_mpp) as g:
        assert f["cell/tension"].shape == (RECORDS, 5)
        assert "/forces/axial" in f["cell/tension"].attrs["definition"]
        axial, moment = g["forces/axial"][()], g["forces/moment"][()]
        assert np.array_equal(f["cell/tension"][()], 0.5 * (axial[:, :-1] + axial[:, 1:]))
        assert np.array_equal(f["point/joint_moment"][:, 0::2], moment[:, :-1])
        assert np.array_equal(f["point/joint_moment"][:, 1::2], moment[:, 1:])
        assert f["point/joint_moment"].attrs["units"] == "N m"


def test_xdmf_says_what_made_it_and_keeps_other_files(tiny, tmp_path):
    """The sidecar carries the run's code version, scene and convention; a file of the
    sidecar's name that scripts/xdmf did not write (here another run's file) is refused
    (exit 2) and kept unless --force; an earlier sidecar is replaced without it."""
    run = tmp_path / "r.h5"
    shutil.copy(tiny, run)
    other = tmp_path / "r_fields.h5"
    shutil.copy(tiny, other)
    before = sha256(other)
    refused = script("xdmf", run)
    assert refused.returncode == 2
    assert "r_fields.h5: exists and is not a file of scripts/xdmf" in refused.stderr
    assert sha256(other) == before and not (tmp_path / "r.xmf").exists()
    assert script("xdmf", run, "--force").returncode == 0
    assert script("xdmf", run).returncode == 0          # its own sidecar: replaced
    with h5py.File(other) as f, h5py.File(run) as g:
        for name in ("version", "scene", "units_convention"):
            assert f.attrs[name] == io.text(g.attrs[name])
        version = io.text(g.attrs["version"])
    assert f"r.h5: ropedyn {version}," in (tmp_path / "r.xmf").read_text()
    (tmp_path / "r.xmf").write_text("my notes\n")
    assert script("xdmf", run).returncode == 2
    assert (tmp_path / "r.xmf").read_text() == "my notes\n"


def test_xdmf_keeps_an_xdmf_file_of_another_program(tiny, tmp_path):
    """An RUN.xmf that another program wrote (ParaView's XDMF writer starts with the same
    DOCTYPE as the sidecar) is refused (exit 2) and kept unless --force (it was taken for
    an earlier sidecar and replaced)."""
    run = tmp_path / "r.h5"
    shutil.copy(tiny, run)
    theirs = ('<?xml version="1.0" ?>\n<!DOCTYPE Xdmf SYSTEM "Xdmf.dtd" []>\n'
              '<Xdmf Version="2.0"><Domain><Grid Name="mesh"><Topology TopologyType='
              '"Polyline"/></Grid></Domain></Xdmf>\n')
    (tmp_path / "r.xmf").write_text(theirs)
    refused = script("xdmf", run)
    assert refused.returncode == 2
    assert "r.xmf: exists and is not a file of scripts/xdmf" in refused.stderr
    assert (tmp_path / "r.xmf").read_text() == theirs
    assert script("xdmf", run, "--force").returncode == 0
    assert script("xdmf", run).returncode == 0          # now its own sidecar: replaced


def test_xdmf_that_fails_leaves_the_earlier_sidecar_whole(tiny, tmp_path):
    """Both files are written as .part and renamed at the end: a sidecar that fails halfway
    (a run file whose /rope/points is shorter than /time) leaves the earlier pair as it
    was, and no .part file."""
    run = tmp_path / "r.h5"
    shutil.copy(tiny, run)
    assert script("xdmf", run).returncode == 0
    pair = {p: sha256(tmp_path / p) for p in ("r.xmf", "r_fields.h5")}
    with h5py.File(run, "r+") as f:
        f["rope/points"].resize(RECORDS - 3, axis=0)
    failed = script("xdmf", run)
    assert failed.returncode != 0 and "IndexError" in failed.stderr
    assert {p: sha256(tmp_path / p) for p in pair} == pair
    assert not list(tmp_path.glob("*.part"))


def test_pictures_say_what_made_them(tiny, tmp_path):
    """The overview and energy PNGs carry text chunks naming the run file, the code version
    that wrote it and its effective scene; a GIF's comment names the run and the version.
    Each is written whole (no .part left)."""
    with h5py.File(tiny) as f:
        version, scene = io.text(f.attrs["version"]), io.text(f.attrs["scene"])
    made = {"overview": tmp_path / "o.png", "energy": tmp_path / "e.png"}
    for module, out in made.items():
        result = script(f"plot.{module}", tiny, "-o", out, package="ropedyn")
        assert result.returncode == 0, result.stderr
        text = Image.open(out).text
        assert text["Software"] == f"ropedyn {version}" and text["Scene"] == scene
        assert text["Source"] == str(tiny)
        assert f"tiny.h5: ropedyn {version}, RFEM, n = 5" in text["Description"]
    result = script("animate", tiny, "-o", tmp_path / "a.gif", "--max-frames", "3")
    assert result.returncode == 0, result.stderr
    comment = Image.open(tmp_path / "a.gif").info["comment"].decode()
    assert comment.startswith("ropedyn.animate (scripts/animate) from tiny.h5: ropedyn "
                              f"{version}, RFEM, n = 5")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.gif", "e.png", "o.png"]


# --- README figures -----------------------------------------------------------------------

def test_readme_figures(tiny, tmp_path):
    result = script("studies.readme_figures", tiny, "--outdir", tmp_path, "--strobe-end", "0.2",
                    package="ropedyn_tools")
    assert result.returncode == 0, result.stderr
    for name, size in (("rope_motion.png", (800, 520)), ("energy.png", (800, 450))):
        with Image.open(tmp_path / name) as image:
            assert_picture(image, size)


# --- the derived fields ---------------------------------------------------------------------

def central_difference(values, times):
    """d/dt along axis 0 by the 4th-order central difference (uniform times; the first and
    last two records are NaN)."""
    h = times[1] - times[0]
    out = np.full_like(values, np.nan)
    out[2:-2] = (-values[4:] + 8 * values[3:-1] - 8 * values[1:-3] + values[:-4]) / (12 * h)
    return out


FINE = "&solver t_end = 0.1, output_interval = 0.0005, rtol = 1e-9, atol = 1e-12 /\n"


@pytest.mark.parametrize("model,tension", [("rfem", ".true."), ("mpp", ".true."),
                                           ("mpp", ".false.")])
def test_axial_force_is_newtons_law(ropedyn_exe, tmp_path, model, tension):
    """The stored axial force at each element's upper joint equals the axial component of
    what the rope below needs to move as it does: e . sum m (g - a), a by 4th-order central
    differences of /state/qdot. RFEM: the SDE's spring + damper in the frame of the element
    above; MPP: the force the member carries, in its own frame (inextensible members: the
    constraint force). Leaving out the damper would be off by 1e-3 of the force, the
    check is 5e-5."""
    run_file = ropedyn(ropedyn_exe, tmp_path, f"&model kind = '{model}', elements = 5 /\n"
                       f"&effects tension = {tension} /\n" + FINE, model)
    run = io.load_run(run_file)
    force, _ = fields.axial_force(run)
    acc = central_difference(run.qdot[:, :, :2], run.time)[2:-2]
    need = np.cumsum((run.element_mass[:, None] * (G - acc))[:, ::-1], axis=1)[:, ::-1]
    phi = fields.element_angles(run)[2:-2]
    e = np.stack([np.cos(phi), np.sin(phi)], axis=-1)
    upper = force.values[:, :-1]  # the joint above element i
    if model == "rfem":  # in element i-1's frame (joint 0: element 1's)
        frame = np.concatenate([e[:, :1], e[:, :-1]], axis=1)
    else:  # in member i's
        frame = e
    newton = np.sum(frame * need, axis=-1)
    scale = np.abs(newton).max()
    assert scale > 0.5
    assert np.abs(upper[2:-2] - newton).max() < 5e-5 * scale


def test_curvature_and_speed_at_release(ropedyn_exe, tmp_path):
    """Straight rope at rest released at 75 deg, top clamped at 0 deg: no speed, no
    curvature at the inner joints, and (phi_1 - psi)/dl = 75 deg / dl at the clamp."""
    run_file = ropedyn(ropedyn_exe, tmp_path, "&model kind = 'rfem', elements = 5 /\n"
                       "&supports top = 'clamped' /\n&solver t_end = 0.01 /\n", "clamp")
    run = io.load_run(run_file)
    kappa = fields.joint_curvature(run)
    dl = 1.0 / 4
    assert np.allclose(kappa[0, 1:], 0.0, atol=1e-12)
    assert kappa[0, 0] == pytest.approx(np.radians(75.0) / dl)
    assert np.allclose(fields.joints_to_elements(kappa)[0], [kappa[0, 0] / 2, 0, 0, 0, 0])
    assert np.all(fields.speed(run)[0] == 0.0)


def test_scene_text_parser():
    text = ("! comment / with a slash\n&rope length = 2.0, diameter = 1d-3 /\n"
            "&supports\n    top = 'clamped'  ! the top\n    top_anchor = 0.5, -1.0\n"
            "    bottom_anchor = NaN, NaN\n    top_anchor(2) = 0.25\n/\n"
            "&output file = 'out/a/b.h5', progress = .true. /\n&effects damping = F /\n")
    groups = parse_namelist(text)
    assert groups["rope"] == {"length": 2.0, "diameter": 1e-3}
    assert groups["supports"]["top"] == "clamped"
    assert groups["supports"]["top_anchor"] == [0.5, 0.25]
    assert all(np.isnan(groups["supports"]["bottom_anchor"]))
    assert groups["output"] == {"file": "out/a/b.h5", "progress": True}
    assert groups["effects"] == {"damping": False}
