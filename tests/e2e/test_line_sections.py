"""A line given as engineers give it (&rope's section set: mass per length, EA, EI, the
joint's shear stiffness, damping coefficients) behaves as the same line given as a solid rod,
in both models, in a run, in statics and in modes; the two sets do not mix; a chain (EI = 0)
hangs in both models; values that are legal but probably a unit slip get one warning each."""
import math

import h5py
import numpy as np
import pytest

from conftest import ROOT

PAPER = ROOT / "input" / "paper.nml"

# the paper's rope (solid-rod set: E, G, d, rho, eta, eta_bar, chi) as a section
E, G, D, RHO, ETA, ETA_BAR, CHI = 35.0e6, 14.0e6, 0.005, 6000.0, 1.0e3, 400.0, 10.0 / 9.0
A, I = math.pi * D ** 2 / 4, math.pi * D ** 4 / 64
SECTION = {"mass_per_length": RHO * A, "axial_stiffness": E * A,
           "shear_stiffness": G * A / CHI, "bending_stiffness": E * I,
           "axial_damping": ETA * A, "shear_damping": ETA_BAR * A / CHI,
           "bending_damping": ETA * I}
SOLID_KEYS = ("density", "young_modulus", "shear_modulus", "normal_damping",
              "tangential_damping", "shape_factor")


def section_scene(tmp_path, **extra):
    """paper.nml with its &rope replaced by the section set (diameter kept)."""
    text = PAPER.read_text()
    start = text.index("&rope")
    end = text.index("\n/", start) + 2
    values = dict(SECTION, **extra)
    rope = "&rope length = 1.0, diameter = 0.005, " + ", ".join(
        f"{k} = {v!r}" for k, v in values.items()) + " /"
    path = tmp_path / "section.nml"
    path.write_text(text[:start] + rope + text[end:])
    return path


def states(run, tmp_path, scene, name, *sets):
    args = ["run", scene, "--set", f"output.file='{name}.h5'", "--set", "output.progress=.false."]
    for s in sets:
        args += ["--set", s]
    proc = run(*args)
    assert proc.returncode == 0, proc.stderr
    with h5py.File(tmp_path / f"{name}.h5") as f:
        return f["state/q"][()], f.attrs["scene"].decode()


@pytest.mark.parametrize("kind", ["rfem", "mpp"])
def test_the_paper_rope_as_a_section_runs_as_the_solid_rod(run, tmp_path, kind):
    sets = [f"model.kind='{kind}'", "model.elements=10", "solver.t_end=0.5",
            "solver.method='cvode'", "solver.rtol=1e-9", "solver.atol=1e-11"]
    solid, _ = states(run, tmp_path, PAPER, "solid", *sets)
    section, scene = states(run, tmp_path, section_scene(tmp_path), "section", *sets)
    # the same constants up to the rounding of their products: the same motion to the
    # integration error
    assert np.max(np.abs(solid - section)) < 1e-7
    # the effective scene says which set it used
    for key in SOLID_KEYS:
        assert f"! {key} = (not set" in scene, key
    assert "mass_per_length = " in scene and "! mass_per_length" not in scene


@pytest.mark.parametrize("command,dataset", [("statics", "rope/points"), ("modes", "modes/omega")])
def test_statics_and_modes_honour_the_section(run, tmp_path, command, dataset):
    results = []
    for scene in (PAPER, section_scene(tmp_path)):
        out = tmp_path / f"{command}_{scene.stem}.h5"
        proc = run(command, scene, "--set", "model.elements=12", "-o", out)
        assert proc.returncode == 0, proc.stderr
        with h5py.File(out) as f:
            results.append(f[dataset][()])
    assert np.allclose(results[0], results[1], rtol=1e-9, atol=1e-12)


def test_the_two_sets_do_not_mix(run, tmp_path):
    scene = section_scene(tmp_path)
    mixed = run("run", scene, "--set", "rope.density=7800")
    assert mixed.returncode == 2
    assert ("&rope: density = 7800.0: a key of the solid-rod set, but mass_per_length = "
            in mixed.stderr), mixed.stderr
    (tmp_path / "half.nml").write_text("&rope mass_per_length = 0.1 /\n&model /\n")
    half = run("run", "half.nml")
    assert half.returncode == 2
    assert "&rope: axial_stiffness = not set: needed with the section set" in half.stderr
    # a --set that made the scene wrong is named, not the file whose keys are right
    paper = run("run", ROOT / "input" / "paper.nml", "--set", "rope.axial_stiffness=1e4")
    assert paper.returncode == 2
    assert ("error: --set rope.axial_stiffness=1e4: &rope: density = 6000.0: a key of the "
            "solid-rod set, but axial_stiffness = 10000.0 gives") in paper.stderr, paper.stderr
    (tmp_path / "plain.nml").write_text("&model /\n")
    added = run("run", "plain.nml", "--set", "rope.axial_damping=1")
    assert added.returncode == 2
    assert ("error: --set rope.axial_damping=1: &rope: mass_per_length = not set: needed "
            "with the section set (given: axial_damping)") in added.stderr, added.stderr


def test_derived_defaults_of_the_section_set(run, tmp_path):
    (tmp_path / "line.nml").write_text(
        "&rope length = 2.0, mass_per_length = 0.5, axial_stiffness = 1.0e5,"
        " bending_stiffness = 2.0, axial_damping = 10.0, diameter = 0.01 /\n"
        "&model elements = 6 /\n&solver t_end = 0.01 /\n")
    assert run("run", "line.nml", "--set", "output.file='l.h5'").returncode == 0
    with h5py.File(tmp_path / "l.h5") as f:
        rope = f.attrs["scene"].decode().split("\n/")[0]
    values = {line.split("=")[0].strip(): line.split("=")[1].strip()
              for line in rope.splitlines() if "=" in line and "!" not in line}
    values = {k: float(v) for k, v in values.items() if not v.startswith(".")}  # logicals
    assert values["shear_stiffness"] == 1.0e5                  # EA
    assert values["shear_damping"] == 10.0                     # axial_damping GA/EA
    assert abs(values["bending_damping"] - 10.0 * 2.0 / 1.0e5) < 1e-18   # axial_damping EI/EA


@pytest.mark.parametrize("kind", ["rfem", "mpp"])
def test_a_chain_without_bending_stiffness_hangs(run, tmp_path, kind):
    (tmp_path / "chain.nml").write_text(
        "&rope length = 3.0, mass_per_length = 0.0818, axial_stiffness = 1.0e4,"
        " bending_stiffness = 0.0, diameter = 0.003654 /\n"
        f"&model kind = '{kind}', elements = 15 /\n"
        "&supports bottom = 'pinned', bottom_anchor = 0.5, 2.0 /\n"
        "&initial shape = 'hanging' /\n")
    proc = run("statics", "chain.nml", "-o", "c.h5")
    assert proc.returncode == 0, proc.stderr
    with h5py.File(tmp_path / "c.h5") as f:
        assert f["statics/residual_relative"][()] < 1e-8
        # a catenary between (0, 0) and (0.5, 2.0): the lowest point below the chord
        points = f["rope/points"][0]
    assert points[:, 0].max() > 0.5


@pytest.mark.parametrize("sets,fragment", [
    (["rope.diameter=5"], "&rope: diameter = 5.0: more than a tenth of the length"),
    (["rope.young_modulus=200"], "&rope: young_modulus = 200.0: the rope stretches by"),
    # a payload of 10 kg on the 1 m rope (EA 687 N): the rope alone stretches by 0.17 %
    (["attachments.mass_positions=1.0", "attachments.masses=10.0"],
     "&rope: young_modulus = 3.5e7: the rope stretches by 14.4 % under its own weight and its "
     "point masses ((m L + M) g / EA)"),
    (["rope.normal_damping=1e9"], "&rope: normal_damping = 1.0e9: an element's axial damping"),
    (["rope.normal_damping=1e-9"], "&rope: normal_damping = 1.0e-9: an element's axial damping"),
    (["effects.water=.true."], "&fluid: density = 1.225: water = .true. in a fluid this light"),
    (["effects.ground=.true.", "ground.point=0.5,0", "initial.shape='hanging'"],
     "&ground: point = 0.5, 0.0: the rope's hanging start reaches 0.5 m into the ground"),
    (["effects.ground=.true.", "ground.point=0.1,0"],
     "&ground: point = 0.1, 0.0: the rope's straight start reaches 0.159 m into the ground"),
    (["effects.ground=.true.", "ground.point=0.5,0", "supports.bottom='clamped'",
      "supports.bottom_anchor=0.9,0.3"],
     "&supports: bottom_anchor = 0.9, 0.3: the bottom end is clamped 0.4 m inside the ground"),
    # half a millimetre, under the thousandth of the length, but 43 times the 1.16e-5 m the
    # rope's 1.156 N/m sinks it into the default ground (1e5 N/m^2): the contact presses
    # the rope up against the anchor
    (["effects.ground=.true.", "ground.point=0.5,0", "supports.bottom='pinned'",
      "supports.bottom_anchor=0.5005,0.3"],
     "&supports: bottom_anchor = 0.5005, 0.3: the bottom end is pinned 0.0005 m inside the "
     "ground, more than 10 times the 1.16e-5 m the rope's weight sinks it"),
    # the paper's rope weighs 1.156 N/m: on 100 N/m^2 it sinks 11.6 mm, 1.2 % of its length
    (["effects.ground=.true.", "ground.stiffness=100"],
     "&ground: stiffness = 100.0: the rope's weight, 1.156 N/m, sinks it 0.0116 m into the "
     "ground, more than a thousandth of its length: a stiffness in kN/m^2?"),
    (["effects.ground=.true.", "ground.friction_coefficient=60"],
     "&ground: friction_coefficient = 60.0: above 1, more than a rope or chain has on the "
     "ground (0.1 .. 1): a percentage? (0.6, not 60)"),
    (["supports.bottom='pinned'", "supports.bottom_anchor=2.5,0.3"],
     "&supports: bottom_anchor = 2.5, 0.3: 2.518 m from the top anchor, more than the rope's "
     "length (1.0 m): the line must stretch by 152.0 % to reach it"),
])
def test_a_probable_unit_slip_gets_one_warning(run, tmp_path, sets, fragment):
    args = ["run", PAPER, "--set", "solver.t_end=1e-4", "--set", "solver.output_interval=1e-4",
            "--set", "output.file='w.h5'"]
    for s in sets:
        args += ["--set", s]
    proc = run(*args)
    # (an anchor far from the straight start is its own warning, of the run's summary)
    warnings = [x for x in proc.stderr.splitlines() if x.startswith("ropedyn: warning: ")
                and "the initial state leaves" not in x]
    assert len(warnings) == 1 and fragment in warnings[0], proc.stderr


#: a towed cable as a user gives it (docs/guide/examples.md, "A towed cable"): 200 m, 12 mm
TOWED = ("&model elements = 4 /\n"
         "&rope length = 200.0, diameter = 0.012, mass_per_length = 0.25, "
         "axial_stiffness = 2.0e6 /\n"
         "&initial shape = 'hanging' /\n&effects drag = .true., water = .true. /\n"
         "&fluid density = 1025.0, current = 0.0, -2.0 /\n"
         "&solver t_end = 1e-3, output_interval = 1e-3 /\n")


@pytest.mark.parametrize("sets,warned", [
    ([], False),
    # 12 mm written as 12 m is under a tenth of 200 m: its mean density, 0.00221 kg/m^3,
    # gives it away (its buoyancy lifts 450 kN and the cable floats)
    (["rope.diameter=12"], True),
    # in cm: 0.221 kg/m^3
    (["rope.diameter=1.2"], True),
    # the diameter used by neither drag nor water: no slip it matters for
    (["rope.diameter=12", "effects.drag=.false.", "effects.water=.false.",
      "fluid.density=1.225", "fluid.current=0,0"], False),
])
def test_a_diameter_in_mm_on_a_long_line_is_warned_of(run, tmp_path, sets, warned):
    (tmp_path / "towed.nml").write_text(TOWED)
    args = ["run", "towed.nml", "--set", "output.file='w.h5'"]
    for s in sets:
        args += ["--set", s]
    proc = run(*args)
    assert proc.returncode == 0, proc.stderr
    warnings = [x for x in proc.stderr.splitlines() if x.startswith("ropedyn: warning: ")]
    if not warned:
        assert warnings == [], proc.stderr
        return
    diameter = float(sets[0].split("=")[1])
    density = 0.25 / (math.pi * diameter ** 2 / 4)
    assert len(warnings) == 1, proc.stderr
    assert (f"&rope: diameter = {diameter!r}: the line's mean density, "
            f"mass_per_length / (pi d^2/4), is {density:.3g} kg/m^3") in warnings[0], warnings
    assert "a diameter in mm? (the unit is m)" in warnings[0], warnings


def test_a_rope_laid_on_the_ground_has_no_warning(run, tmp_path):
    """A straight start along the ground's surface touches it (depth 0): no warning."""
    proc = run("run", PAPER, "--set", "solver.t_end=1e-4", "--set", "solver.output_interval=1e-4",
               "--set", "output.file='w.h5'", "--set", "effects.ground=.true.",
               "--set", "ground.point=0,0", "--set", "initial.angle_deg=90")
    assert proc.returncode == 0 and "warning" not in proc.stderr, proc.stderr


def test_a_plausible_ground_law_has_no_warning(run, tmp_path):
    """A soft ground that sinks the paper's rope (1.156 N/m) by 0.58 mm, under a thousandth
    of its length, and a chain's lateral friction coefficient of 1: no warning."""
    proc = run("run", PAPER, "--set", "solver.t_end=1e-4", "--set", "solver.output_interval=1e-4",
               "--set", "output.file='w.h5'", "--set", "effects.ground=.true.",
               "--set", "ground.stiffness=2000", "--set", "ground.friction_coefficient=1.0")
    assert proc.returncode == 0 and "warning" not in proc.stderr, proc.stderr


def test_an_anchor_on_the_ground_has_no_warning(run, tmp_path):
    """A chain anchored on the seabed: its bottom anchor on the ground (depth 0), where the
    straight start at 36.87 degrees ends (so that the start meets its anchor too)."""
    proc = run("run", PAPER, "--set", "solver.t_end=1e-4", "--set", "solver.output_interval=1e-4",
               "--set", "output.file='w.h5'", "--set", "effects.ground=.true.",
               "--set", "ground.point=0.8,0", "--set", "supports.bottom='pinned'",
               "--set", "supports.bottom_anchor=0.8,0.6",
               "--set", "initial.angle_deg=36.86989764584402")
    assert proc.returncode == 0 and "warning" not in proc.stderr, proc.stderr


def test_the_shipped_paper_scene_has_no_warning(run, tmp_path):
    proc = run("run", PAPER, "--set", "solver.t_end=1e-4", "--set", "solver.output_interval=1e-4",
               "--set", "output.file='w.h5'")
    assert proc.returncode == 0 and "warning" not in proc.stderr, proc.stderr
