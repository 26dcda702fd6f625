"""A line that carries tension only (&rope compression = .false.): a chain hanging from a top
shaken up and down faster than gravity can follow goes slack, and its axial springs then carry
no compression, while with the linear law (the default) they push. The energy balance holds
with both laws: the tension-only spring stores k max(stretch, 0)^2 / 2. A line that came apart
(two neighbours slid past each other where nothing holds them, at a fold) is warned of, with
the cause, and a run that then spends its step budget is offered no resume. Both models."""
import re
import subprocess

import h5py
import numpy as np
import pytest

BALANCE = re.compile(r"balance error\s+\S+ J \(\s*(\S+) m g L\)")

SCENE = """&rope
    length = 1.0, mass_per_length = 0.1, axial_stiffness = 2.0e3, bending_stiffness = 0.0,
    axial_damping = 0.0, diameter = 0.005
/
&model elements = 10 /
&supports
    top = 'pinned', bottom = 'free', top_motion = 'harmonic',
    top_amplitude = 0.03, 0.0, top_frequency = 5.0
/
&initial shape = 'equilibrium', angle_deg = 0.0 /
&solver t_end = 0.6, output_interval = 0.002, rtol = 1.0e-9, atol = 1.0e-11 /
"""


def shaken(exe, tmp_path, model, compression):
    scene = tmp_path / "chain.nml"
    scene.write_text(SCENE)
    out = tmp_path / f"{model}_{compression}.h5"
    sets = [f"model.kind={model}", f"rope.compression={compression}", f"output.file={out}"]
    result = subprocess.run([str(exe), "run", str(scene),
                             *[a for s in sets for a in ("--set", s)]],
                            capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    with h5py.File(out, "r") as f:
        axial = f["forces/axial"][:, :-1]        # the top and the joints (the end: free)
    return axial, float(BALANCE.search(result.stdout).group(1))


@pytest.mark.parametrize("model", ["rfem", "mpp"])
def test_a_slack_chain_carries_no_compression(ropedyn_exe, tmp_path, model):
    """The top's acceleration reaches 0.03 (10 pi)^2 = 30 m/s^2: the chain below falls behind
    and goes slack. With the linear law its springs push (a negative axial force at some
    joint); carrying tension only, no joint's axial force is negative, and the chain still
    pulls when taut. The pinned top carries tension only too: its spring (the RFEM's) stands
    for the rope's end section. The balance T + V + dissipated - work - E0 stays at the
    integrator's error."""
    linear, balance_linear = shaken(ropedyn_exe, tmp_path, model, ".true.")
    slack, balance_slack = shaken(ropedyn_exe, tmp_path, model, ".false.")
    weight = 0.1 * 1.0 * 9.81
    assert linear[:, 1:].min() < -0.05 * weight, linear.min()
    if model == "rfem":
        assert linear[:, 0].min() < -0.05 * weight, linear[:, 0].min()  # the linear pin pushes
    assert slack.min() >= -1e-9 * weight, slack.min()     # rounding of the projections
    assert slack.max() > weight
    assert abs(balance_linear) < 1e-5 and abs(balance_slack) < 1e-5, (balance_linear,
                                                                     balance_slack)


# A fall-arrest drop: 80 kg at the end of a 20 m cord (EA = 2e4 N), held folded beside the
# top anchor and let go. Carrying tension only, a joint at the fold has no axial spring, and
# two neighbours can slide past each other: the mass then falls through its cord.
DROP = """&rope
    length = 20.0, mass_per_length = 0.2, axial_stiffness = 2.0e4, bending_stiffness = 0.0,
    compression = .false.
/
&model elements = 41 /
&supports top = 'pinned', bottom = 'pinned', bottom_release_time = 0.0 /
&initial shape = 'folded' /
&attachments mass_positions = 20.0, masses = 80.0 /
&effects bending = .false. /
&solver output_interval = 0.005 /
"""

# two drops whose line came apart: the RFEM with a bending spring at the fold, whipped open
# within 0.14 s; the MPP, whose last member turns inside out at 2 s (run on to 10 s, it let
# the mass fall 490 m, a "complete" run with a balance error of 5e-3 J)
CAME_APART = {
    "rfem": (["effects.bending=.true.", "rope.bending_stiffness=10.0", "solver.t_end=0.3"],
             "element 22 slid past element 21"),
    "mpp": (["model.kind=mpp", "solver.t_end=2.2"], "member 41 turned inside out"),
}


def drop(exe, tmp_path, sets):
    scene = tmp_path / "drop.nml"
    scene.write_text(DROP)
    out = tmp_path / "drop.h5"
    result = subprocess.run([str(exe), "run", str(scene), "--force",
                             *[a for s in [*sets, f"output.file={out}"] for a in ("--set", s)]],
                            capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    with h5py.File(out, "r") as f:
        warnings = [w.decode() for w in f["solver/warnings"][:]] \
            if "solver/warnings" in f else []
        points, phi = f["rope/points"][:], f["state/q"][:, :, 2]
    # e_k . (A_{k+1} - A_k) of every body at every record (A_{n+1} = B_n), over its length
    starts = points[:, 0::2, :]
    step = np.concatenate([starts[:, 1:], points[:, -1:, :]], axis=1) - starts
    lengths = np.full(phi.shape[1], 20.0/(phi.shape[1] - 1))
    if "model.kind=mpp" in sets:
        lengths[:] = 20.0/phi.shape[1]
    else:
        lengths[[0, -1]] /= 2
    along = (np.cos(phi)*step[..., 0] + np.sin(phi)*step[..., 1])/lengths
    return result.stderr, warnings, along.min()


@pytest.mark.parametrize("model", ["rfem", "mpp"])
def test_a_line_that_came_apart_is_warned_of(ropedyn_exe, tmp_path, model):
    """Where a body's successor starts more than twice the body's length behind it (the
    records' geometry, measured here), the run warns on stderr and in /solver/warnings,
    naming the body, how far, the cause and the remedies; the same drop with axial damping
    holds together and is not warned of."""
    sets, named = CAME_APART[model]
    stderr, warnings, along = drop(ropedyn_exe, tmp_path, sets)
    assert along < -2.0, along
    said = [w for w in warnings if "the line passed through itself" in w]
    assert len(said) == 1 and said[0] in stderr, (warnings, stderr)
    assert named in said[0], said[0]
    assert "axial_damping" in said[0] and "compression = .true." in said[0], said[0]
    stderr, warnings, along = drop(ropedyn_exe, tmp_path, [*sets, "rope.axial_damping=100.0"])
    assert along > 0.0, along
    assert not any("passed through itself" in w for w in warnings), warnings


def test_a_slack_chain_overlapping_a_little_is_not_warned_of(ropedyn_exe, tmp_path):
    """The shaken chain above overlaps a joint by up to 1.3 body lengths while slack and
    pulls taut again: no warning."""
    scene = tmp_path / "chain.nml"
    scene.write_text(SCENE)
    result = subprocess.run([str(ropedyn_exe), "run", str(scene), "--set", "model.kind=mpp",
                             "--set", "rope.compression=.false.", "--set",
                             f"output.file={tmp_path / 'c.h5'}"],
                            capture_output=True, text=True, timeout=120)
    assert result.returncode == 0 and "passed through itself" not in result.stderr, \
        result.stderr


def test_a_torn_line_out_of_steps_is_not_offered_a_resume(ropedyn_exe, tmp_path):
    """A line torn open (the RFEM drop with a bending spring, from 0.14 s on) whips its loose
    end, which holds the step; a run that then spends its step budget was offered a resume
    with a larger budget, which only goes on with a line no longer physical. The error now
    names the tear and its time, and the remedies, and offers no resume."""
    scene = tmp_path / "drop.nml"
    scene.write_text(DROP)
    sets = [*CAME_APART["rfem"][0], "solver.t_end=2.0", "solver.max_steps=5000",
            f"output.file={tmp_path / 'torn.h5'}"]
    result = subprocess.run([str(ropedyn_exe), "run", str(scene), "--force",
                             *[a for s in sets for a in ("--set", s)]],
                            capture_output=True, text=True, timeout=120)
    assert result.returncode != 0
    error = [line for line in result.stderr.splitlines() if line.startswith("ropedyn: error:")]
    assert len(error) == 1, result.stderr
    assert "max_steps exceeded" in error[0], error[0]
    assert "the line passed through itself from t = 0.140 s on" in error[0], error[0]
    assert "axial_damping" in error[0] and "--resume" not in error[0], error[0]
