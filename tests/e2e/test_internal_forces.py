"""The internal forces and support reactions the model stores (docs/reference/file-format.md, /forces and
/supports; definitions in docs/theory/internal-forces.md): the datasets of a run and of the
statics, the stored reaction of a moving top against the rope's momentum balance from the
file for every model and integrator, the static reaction of a moving top, the run
summary's peak tension, resuming a file without them, and the shaken top's top force."""
import subprocess

import h5py
import numpy as np
import pytest

from ropedyn import io

from conftest import ROOT

G = np.array([9.81, 0.0])
FORCES = {"forces/axial": "N", "forces/shear": "N", "forces/moment": "N m"}
SUPPORTS = {f"supports/{end}/{what}": units for end in ("top", "bottom")
            for what, units in (("reaction", "N"), ("position", "m"))}

#: A 1 m rope (input/paper.nml's), 5 elements, top shaken (harmonic, 2 Hz, phase 90
#: degrees: it starts at rest with an acceleration), bottom pinned at the lower end of the
#: straight start at 10 degrees; the rope starts in its static equilibrium, so that the
#: motion is smooth enough for differences of the records.
SHAKEN = """&model kind = '{kind}', elements = 5 /
&supports top_motion = 'harmonic', top_amplitude = 0.02, 0.03, top_frequency = 2.0,
          top_phase_deg = 90.0, 90.0, bottom = 'pinned' /
&initial angle_deg = 10.0, shape = 'equilibrium' /
&solver method = '{method}', t_end = 0.05, output_interval = 0.00025, rtol = 1e-9,
        atol = 1e-12 /
"""


def ropedyn(exe, workdir, text, name, *args, command="run"):
    scene = workdir / f"{name}.nml"
    scene.write_text(text)
    out = workdir / f"{name}.h5"
    result = subprocess.run([str(exe), command, str(scene), "--set", f"output.file={out}",
                             *args], capture_output=True, text=True, timeout=600, cwd=workdir)
    assert result.returncode == 0, result.stdout + result.stderr
    return out, result.stdout


def text(value):
    return io.text(value)


@pytest.mark.parametrize("kind", ["rfem", "mpp"])
def test_run_file_datasets(ropedyn_exe, tmp_path, kind):
    """Every record holds the forces at the n + 1 joints and the supports (x, y), with units
    and a description saying the sign convention; a free end has no anchor: no position
    dataset (no record holds a NaN)."""
    out, _ = ropedyn(ropedyn_exe, tmp_path, SHAKEN.format(kind=kind, method="auto")
                     .replace("bottom = 'pinned'", "bottom = 'free'"), kind)
    with h5py.File(out) as f:
        records = f["time"].shape[0]
        for name, units in FORCES.items():
            assert f[name].shape == (records, 6), name
            assert text(f[name].attrs["units"]) == units
            assert f[name].maxshape[0] is None
        assert "tension (> 0: stretched)" in text(f["forces/axial"].attrs["description"])
        assert "from x towards y" in text(f["forces/moment"].attrs["description"])
        # whole: the frame of both models (the axial text was cut at 300 characters, before
        # the mpp's frame)
        for name in ("forces/axial", "forces/shear"):
            assert text(f[name].attrs["description"]).endswith(
                "; mpp, the member below the joint, at joint n member n)"), name
        for name, units in SUPPORTS.items():
            if name == "supports/bottom/position":
                assert name not in f
                continue
            assert f[name].shape == (records, 2), name
            assert text(f[name].attrs["units"]) == units
            assert text(f[name].attrs["columns"]) == "x, y"
            assert np.all(np.isfinite(f[name][()]))
        assert "force of the top support on the rope" in text(
            f["supports/top/reaction"].attrs["description"])
        assert np.all(f["supports/bottom/reaction"][()] == 0.0)
        top = f["supports/top/position"][()]
        t = f["time"][()]
        expected = np.stack([0.02 * np.cos(4 * np.pi * t), 0.03 * np.cos(4 * np.pi * t)],
                            axis=-1)
        assert np.abs(top - expected).max() < 1e-15


@pytest.mark.parametrize("kind", ["rfem", "mpp"])
@pytest.mark.parametrize("method", ["auto", "cvode", "mebdf", "erk", "adams"])
def test_top_reaction_is_the_momentum_balance(ropedyn_exe, tmp_path, kind, method):
    """The stored reaction of the shaken top equals what the rope's momentum needs:
    R_top = d/dt sum m v - W - R_bottom, d/dt by the fourth-order central difference of
    /state/qdot (the element or rod centres) over the records, within 1e-5 of the largest
    reaction (the integration's and the differencing's error). A force law re-derived with
    the anchor's rest position (as before the forces were stored) is off by its 2 - 3 cm
    times the support's stiffness, tens of N; the check holds to 1e-6 (auto, RFEM)."""
    out, _ = ropedyn(ropedyn_exe, tmp_path, SHAKEN.format(kind=kind, method=method),
                     f"{kind}_{method}")
    run = io.load_run(out)
    h = run.time[1] - run.time[0]
    p = np.einsum("tnc,n->tc", run.qdot[:, :, :2], run.element_mass)
    dpdt = (-p[4:] + 8 * p[3:-1] - 8 * p[1:-3] + p[:-4]) / (12 * h)
    weight = run.element_mass.sum() * G
    need = dpdt - weight - run.reactions["bottom"][2:-2]
    stored = run.reactions["top"][2:-2]
    scale = np.abs(run.reactions["top"]).max()
    assert scale > 0.1 and np.abs(run.reactions["bottom"]).max() > 1e-3
    assert np.abs(stored - need).max() < 1e-5 * scale


@pytest.mark.parametrize("kind", ["rfem", "mpp"])
def test_statics_datasets_and_moving_top(ropedyn_exe, tmp_path, kind):
    """`ropedyn statics` writes the same datasets for its one state; with a top moving
    sideways (velocity and acceleration at t = 0) the static rope hangs straight below the
    anchor and the top's reaction is (-W, 0): a static force never depends on the
    support's motion. /statics/support_force_top is the same number."""
    scene = ("&model kind = '{kind}', elements = 10 /\n&rope length = 10.0 /\n"
             "&supports top_motion = 'harmonic', top_amplitude = 0.0, 0.5, "
             "top_frequency = 0.2, top_phase_deg = 0.0, 30.0 /\n"
             "&initial shape = 'hanging' /\n").format(kind=kind)
    ropedyn(ropedyn_exe, tmp_path, scene, "moving", command="statics")
    with h5py.File(tmp_path / "moving_statics.h5") as f:
        for name, units in FORCES.items():
            assert f[name].shape == (1, 11), name
            assert text(f[name].attrs["units"]) == units
        for name, units in SUPPORTS.items():
            if name == "supports/bottom/position":  # a free end: no anchor
                assert name not in f
            else:
                assert f[name].shape == (1, 2) and np.all(np.isfinite(f[name][()])), name
        weight = f["statics/weight"][()]
        top = f["supports/top/reaction"][0]
        assert abs(top[1]) <= 1e-12 * weight
        assert top[0] == pytest.approx(-weight, rel=1e-9)
        assert np.array_equal(f["statics/support_force_top"][()], top)
        assert f["supports/top/position"][0][1] == pytest.approx(0.25, rel=1e-14)
        assert abs(f["rope/points"][0, -1, 1] - 0.25) < 1e-12
        axial = f["forces/axial"][0]
        assert axial[0] == pytest.approx(weight, rel=1e-9) and abs(axial[-1]) < 1e-9 * weight


def test_summary_reports_the_peak_tension(ropedyn_exe, tmp_path):
    """The run summary's peak tension is the largest stored axial force, with its joint,
    the joint's arc length and the record's time."""
    out, stdout = ropedyn(ropedyn_exe, tmp_path, SHAKEN.format(kind="rfem", method="auto"),
                          "peak")
    run = io.load_run(out)
    axial = run.forces["axial"]
    k, j = np.unravel_index(np.argmax(axial), axial.shape)
    line = next(s for s in stdout.splitlines() if s.strip().startswith("peak tension"))
    words = line.split()
    assert float(words[2]) == pytest.approx(axial[k, j], rel=1e-5)
    assert f"at joint {j} (" in line
    arc = np.concatenate([[0.0], np.cumsum(run.element_length)])[j]
    assert f"({arc:.4f} m from the top)" in line
    assert f"t = {run.time[k]:.4f} s" in line


def test_resume_refuses_a_file_without_forces(ropedyn_exe, tmp_path, run):
    """A file written before the forces were stored (here: with them removed) is not
    continued, and is left as it was."""
    out, _ = ropedyn(ropedyn_exe, tmp_path, SHAKEN.format(kind="rfem", method="auto"), "old")
    with h5py.File(out, "a") as f:
        del f["forces"]
        before = f["time"].shape[0]
    result = run("run", "--resume", out, "--set", "solver.t_end=0.06")
    assert result.returncode == 4, result.stdout + result.stderr
    assert "/forces/axial: missing" in result.stderr
    assert "did not store the internal forces" in result.stderr
    with h5py.File(out) as f:
        assert f["time"].shape[0] == before and text(f.attrs["status"]) == "complete"


@pytest.mark.parametrize("kind", ["rfem", "mpp"])
def test_shaken_top_force_is_physical(ropedyn_exe, tmp_path, kind):
    """input/shaken_top.nml (the top shaken 1 cm sideways): the stored force at the top is
    about the weight (its mean over the first second within 5 %), a tension after the
    start, and continuous with the joint below (within 5 % of the weight). Re-derived in
    Python from the rest position of the anchor it was -48 .. +27 N for a weight of
    1.16 N."""
    out = tmp_path / "shaken.h5"
    result = subprocess.run([str(ropedyn_exe), "run", str(ROOT / "input" / "shaken_top.nml"),
                             "--set", "solver.t_end=1.0", "--set", f"output.file={out}",
                             "--set", f"model.kind={kind}"], capture_output=True, text=True,
                            timeout=600)
    assert result.returncode == 0, result.stdout + result.stderr
    run = io.load_run(out)
    axial = run.forces["axial"]
    weight = run.element_mass.sum() * G[0]
    assert axial[:, 0].mean() == pytest.approx(weight, rel=0.05)
    assert np.all(axial[run.time > 0.05, 0] > 0.0)
    assert np.abs(axial[:, 0] - axial[:, 1]).max() < 0.05 * weight
