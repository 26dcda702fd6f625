"""A line that carries tension only (&rope compression = .false.): a chain hanging from a top
shaken up and down faster than gravity can follow goes slack, and its axial springs then carry
no compression, while with the linear law (the default) they push. The energy balance holds
with both laws: the tension-only spring stores k max(stretch, 0)^2 / 2. Both models."""
import re
import subprocess

import h5py
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
&solver t_end = 0.6, output_interval = 0.002, rtol = 1.0e-7, atol = 1.0e-9 /
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
        axial = f["forces/axial"][:, 1:-1]       # the joints; the ends are the supports'
    return axial, float(BALANCE.search(result.stdout).group(1))


@pytest.mark.parametrize("model", ["rfem", "mpp"])
def test_a_slack_chain_carries_no_compression(ropedyn_exe, tmp_path, model):
    """The top's acceleration reaches 0.03 (10 pi)^2 = 30 m/s^2: the chain below falls behind
    and goes slack. With the linear law its springs push (a negative axial force at some
    joint); carrying tension only, no joint's axial force is negative, and the chain still
    pulls when taut. (The pinned top is a support, not a spring of the line: it may push.)
    The balance T + V + dissipated - work - E0 stays at the integrator's error."""
    linear, balance_linear = shaken(ropedyn_exe, tmp_path, model, ".true.")
    slack, balance_slack = shaken(ropedyn_exe, tmp_path, model, ".false.")
    weight = 0.1 * 1.0 * 9.81
    assert linear.min() < -0.05 * weight, linear.min()
    assert slack.min() >= -1e-9 * weight, slack.min()     # rounding of the projections
    assert slack.max() > weight
    assert abs(balance_linear) < 1e-5 and abs(balance_slack) < 1e-5, (balance_linear,
                                                                     balance_slack)
