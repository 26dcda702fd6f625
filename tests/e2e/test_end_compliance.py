"""A pinned end's axial compliance (supports.end_compliance): with 'added' (the paper's RFEM)
the support's spring adds one section's compliance to the rope's L/EA, and the static tension
of an elastic catenary converges at first order in the element length; with 'split' the end
section is shared with the support and it converges at second order. Both models."""
import pathlib
import re
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
# the Bergdahl chain in air without the floor: 33 m, EA = 10 kN, an elastic catenary between
# the fairlead and an anchor 32.554 m away
SCENE = ROOT / "input" / "validation" / "bergdahl" / "base.nml"
FORCE = re.compile(r"top support force on the rope \(x, y, \|F\|\) N:\s+\S+\s+\S+\s+(\S+)")


def top_tension(exe, tmp_path, model, elements, compliance):
    out = tmp_path / f"{model}_{elements}_{compliance}.h5"
    sets = [f"model.kind={model}", f"model.elements={elements}",
            f"supports.end_compliance={compliance}", "effects.water=.false.",
            "effects.ground=.false.", f"output.file={out}"]
    result = subprocess.run([str(exe), "statics", str(SCENE),
                             *[a for s in sets for a in ("--set", s)]],
                            capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    return float(FORCE.search(result.stdout).group(1))


@pytest.mark.parametrize("model", ["rfem", "mpp"])
def test_split_end_sections_converge_at_second_order(ropedyn_exe, tmp_path, model):
    """Element lengths 1.65, 0.825, 0.41 m: the ratio of the successive changes of the top
    tension is about 2 (first order) with 'added' and about 4 (second order) with 'split'
    (measured: RFEM 2.04 and 3.93, MPP 2.07 and 3.33), and 'split' at the coarsest length
    is nearer the limit than 'added' at the finest."""
    ratios, tension = {}, {}
    for compliance in ("added", "split"):
        t = [top_tension(ropedyn_exe, tmp_path, model, n, compliance) for n in (21, 41, 81)]
        ratios[compliance] = (t[1] - t[0]) / (t[2] - t[1])
        tension[compliance] = t
    assert 1.7 < ratios["added"] < 2.5, ratios
    assert ratios["split"] > 3.0, ratios
    # both rise towards the same limit; split's coarsest is already above added's finest
    limit = tension["split"][2] + (tension["split"][2] - tension["split"][1]) / 3
    assert tension["split"][0] > tension["added"][2]
    assert abs(tension["added"][2] - limit) / limit < 0.01


TAUT = """&model kind = 'mpp', elements = 10, mpp_axial_damping_factor = {factor} /
&rope length = 1.0, mass_per_length = 0.1, axial_stiffness = 1000.0, axial_damping = 0.01 /
&supports top = 'pinned', bottom = 'pinned', bottom_anchor = 1.01, 0.0,
    end_compliance = 'split', support_stiffness_factor = 2.0 /
&effects gravity = .false. /
&initial shape = 'straight', angle_deg = 0.0 /
"""


@pytest.mark.parametrize("factor", [1.0, 3.0])
def test_split_pin_damps_as_the_member_it_shares(ropedyn_exe, tmp_path, factor):
    """MPP, 'split': the pin's half of the last section damps as the member's other half.
    A straight line stretched between two pins without gravity has axial damping
    proportional to its axial stiffness (d/k = factor eta/E for every member), so each axial
    mode's damping ratio is omega d/(2 k). Before, the pin took the rope's damping without
    the MPP's damping factor: at factor 3 the axial modes' ratios fell 0.87 .. 0.998 of it."""
    import h5py
    (tmp_path / "t.nml").write_text(TAUT.format(factor=factor))
    result = subprocess.run([str(ropedyn_exe), "modes", "t.nml", "--count", "30", "-o",
                             "m.h5"], cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    with h5py.File(tmp_path / "m.h5") as f:
        omega, zeta = f["modes/omega"][()], f["modes/damping_ratio"][()]
        axial = f["modes/axial_fraction"][()] > 0.99
    assert axial.sum() >= 8
    expected = factor * 0.01 / 1000.0 / 2.0
    ratios = zeta[axial] / omega[axial] / expected
    assert abs(ratios - 1.0).max() < 1e-6, ratios


@pytest.mark.parametrize("model", ["rfem", "mpp"])
def test_a_bottom_released_at_the_start_shares_no_section(ropedyn_exe, tmp_path, model):
    """A bottom pin released at t = 0 is a free end: with 'split' (the top pin's section
    shared in both runs) its last section must not keep the doubled spring. Before, the MPP doubled it anyway (its release was resolved
    after the springs): its hanging rope's lower end sat 5e-5 m higher than the free one's."""
    lower = re.compile(r"lower end\s+x =\s+(\S+) m")
    ends = []
    for sets in (["supports.end_compliance=split"],
                 ["supports.bottom=pinned", "supports.end_compliance=split",
                  "supports.bottom_release_time=0"]):
        result = subprocess.run(
            [str(ropedyn_exe), "statics", str(ROOT / "input" / "paper.nml"), "--set",
             f"model.kind={model}", "--set", "model.elements=4",
             *[a for s in sets for a in ("--set", s)], "-o", str(tmp_path / "s.h5"), "--force"],
            capture_output=True, text=True, timeout=120)
        assert result.returncode == 0, result.stderr
        ends.append(float(lower.search(result.stdout).group(1)))
    assert ends[0] == pytest.approx(ends[1], rel=1e-12, abs=1e-12), ends
