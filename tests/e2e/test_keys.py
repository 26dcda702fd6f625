"""docs/reference/keys.md against the key table: `ropedyn keys` lists every key of a scene
file (the table in src/io/ropedyn_scene_keys.f90); the page's generated section must be
exactly what scripts/keys_reference makes of that listing, so a key added to the table, or
a default or rule changed, fails here until the page is written again."""
import pathlib
import re

import h5py
import pytest

from ropedyn_tools import keys_reference


def listing(run):
    result = run("keys")
    assert result.returncode == 0, result.stderr
    return keys_reference.listing(result.stdout)


def page_rows():
    """{(group, key): row cells} of the tables in the page's generated section."""
    section = keys_reference.section(keys_reference.PAGE.read_text())
    assert section is not None, f"{keys_reference.PAGE}: no keys markers"
    rows, group = {}, None
    for line in section.splitlines():
        heading = re.match(r"^## `&(\w+)`", line)
        if heading:
            group = heading.group(1)
        elif group and line.startswith("| `"):
            cells = [c.strip() for c in re.split(r"(?<!\\)\|", line.strip())[1:-1]]
            rows[(group, cells[0].strip("`"))] = cells
    return rows


def test_reference_is_written_from_the_current_table(run):
    rows = listing(run)
    written = keys_reference.section(keys_reference.PAGE.read_text())
    assert written == keys_reference.render(rows), (
        "docs/reference/keys.md is not what the key table gives: run scripts/keys_reference")


def test_every_key_has_one_row_with_its_default(run):
    rows = listing(run)
    documented = page_rows()
    assert set(documented) == {(r["group"], r["key"]) for r in rows}
    for r in rows:
        default = documented[(r["group"], r["key"])][3]
        assert default == keys_reference.code(r["default"]), (r, default)


def test_a_key_added_to_the_table_changes_the_section(run):
    """What the first test relies on: the section depends on every row."""
    rows = listing(run)
    written = keys_reference.section(keys_reference.PAGE.read_text())
    added = rows + [dict(group="rope", key="new_key", type="real", unit="m", default="1.0",
                         allowed="> 0", meaning="a key not yet on the page")]
    assert keys_reference.render(added) != written
    changed = [dict(r, default="2.0") if r["key"] == "length" else r for r in rows]
    assert keys_reference.render(changed) != written


@pytest.mark.parametrize("default,cell", [("1.0", "`1.0`"), ("not set", "not set"),
                                          ("not set: 0 with x", "not set: 0 with x"),
                                          ("not settle", "`not settle`"),
                                          ("", "–"), ("'rfem'", "`'rfem'`")])
def test_default_cells(default, cell):
    assert keys_reference.code(default) == cell


PAPER = pathlib.Path(__file__).resolve().parents[2] / "input" / "paper.nml"


def scene_warnings(proc):
    """The scene's warnings (each names its group; the run's own, of the summary, do not)."""
    return [x for x in proc.stderr.splitlines() if x.startswith("ropedyn: warning: ")
            and ": &" in x]


@pytest.mark.parametrize("sets,fragment", [
    (["supports.top_frequency=2"], "&supports: top_frequency = 2.0: does nothing: "
     "top_motion = 'fixed' (it is used with top_motion = 'harmonic')"),
    (["supports.top_amplitude=0.1, 0"], "top_amplitude = 0.1, 0.0: does nothing"),
    # without an amplitude a huge frequency moves nothing: no "work ... NaN J" refusal
    (["supports.top_frequency=1e300"], "top_frequency = 1.0e300: does nothing"),
    (["supports.bottom=pinned", "supports.bottom_angle_phase_deg=30"],
     "bottom_angle_phase_deg = 30.0: does nothing: bottom_motion = 'fixed'"),
    (["supports.top_motion=table", "supports.top_table=m.dat", "supports.top_ramp_time=2"],
     "top_ramp_time = 2.0: does nothing: top_motion = 'table'"),
    (["supports.top_motion=harmonic", "supports.top_frequency=2", "supports.top_table=m.dat"],
     "m.dat\": does nothing: top_motion = 'harmonic' (it is used with top_motion = 'table')"),
])
def test_a_motion_key_its_motion_does_not_use_is_warned_of(run, tmp_path, sets, fragment):
    """A key of a support's motion that the end's `*_motion` does not use does nothing:
    one warning naming the key, its value and the motion; the run goes ahead."""
    (tmp_path / "m.dat").write_text("0 0 0 0\n1 0 0.01 0\n")
    args = ["run", PAPER, "--set", "solver.t_end=1e-3", "--set", "output.file=w.h5"]
    for s in sets:  # the table relative to the scene file's directory: give it in full
        args += ["--set", s.replace("m.dat", str(tmp_path / "m.dat"))]
    proc = run(*args)
    assert proc.returncode == 0, proc.stderr
    warnings = scene_warnings(proc)
    assert len(warnings) == 1 and fragment in warnings[0], proc.stderr


@pytest.mark.parametrize("shape,starts", [("equilibrium", "starts at rest"),
                                          ("mode", "starts at rest")])
def test_a_velocity_the_start_does_not_use_is_warned_of(run, tmp_path, shape, starts):
    """`&initial velocity` with a start that sets the velocities itself did nothing without
    a word; the other starts (straight, hanging, folded) take it."""
    args = ["run", PAPER, "--set", "solver.t_end=1e-3", "--set", "output.file=v.h5",
            "--set", "initial.velocity=1,2"]
    proc = run(*args, "--set", f"initial.shape={shape}")
    assert proc.returncode == 0, proc.stderr
    assert scene_warnings(proc) == [
        "ropedyn: warning: --set initial.velocity=1,2: &initial: velocity = 1.0, 2.0: does "
        f"nothing: shape = '{shape}' {starts} (it is used with the shapes straight, hanging "
        "and folded)"], proc.stderr
    assert scene_warnings(run(*args, "--set", "initial.shape=hanging")) == []


def test_an_idle_motion_key_in_a_scene_file_names_the_file(run, tmp_path):
    (tmp_path / "s.nml").write_text("&model elements = 4 /\n&supports top_ramp_time = 2.0 /\n"
                                    "&solver t_end = 1e-3 /\n")
    proc = run("run", "s.nml")
    assert proc.returncode == 0, proc.stderr
    assert scene_warnings(proc) == ["ropedyn: warning: s.nml: &supports: top_ramp_time = 2.0: "
                                    "does nothing: top_motion = 'fixed' (it is used with "
                                    "top_motion = 'harmonic')"], proc.stderr


def test_a_warning_or_a_model_check_names_the_set_that_gave_the_value(run, tmp_path):
    """A value given by --set is named by that --set in a warning about it and in the
    checks made with the model (the mode a 'mode' start asks for), as in the key checks;
    a value from the file is named by the file."""
    (tmp_path / "s.nml").write_text("&model elements = 4 /\n&rope diameter = 0.5 /\n"
                                    "&solver t_end = 1e-3 /\n")
    proc = run("run", "s.nml", "--set", "supports.top_ramp_time=2.0")
    assert proc.returncode == 0, proc.stderr
    assert sorted(scene_warnings(proc)) == sorted([
        "ropedyn: warning: s.nml: &rope: diameter = 0.5: more than a tenth of the length "
        "(1.0 m): a diameter in mm? (the unit is m)",
        "ropedyn: warning: --set supports.top_ramp_time=2.0: &supports: top_ramp_time = "
        "2.0: does nothing: top_motion = 'fixed' (it is used with top_motion = "
        "'harmonic')"]), proc.stderr
    proc = run("run", "s.nml", "--set", "rope.diameter=0.005", "--set", "initial.shape=mode",
               "--set", "initial.mode=100", "--set", "output.file=m.h5")
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.strip() == ("ropedyn: error: --set initial.mode=100: &initial: mode = "
                                   "100: the model has only 12 modes"), proc.stderr
    # the method's refusal of the model, made once both exist
    proc = run("run", "s.nml", "--set", "rope.diameter=0.005", "--set", "model.kind=mpp",
               "--set", "solver.method=symplectic", "--set", "output.file=m.h5")
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.startswith("ropedyn: error: --set solver.method=symplectic: &solver: "
                                  "method = \"symplectic\": cannot integrate the mpp model"), \
        proc.stderr


def test_a_harmonic_support_with_its_keys_has_no_warning(run):
    """Its keys used, the ramp and the release within the run: no warning."""
    proc = run("run", PAPER, "--set", "solver.t_end=1e-3", "--set", "output.file=w.h5",
               "--set", "supports.top_motion=harmonic", "--set", "supports.top_frequency=2",
               "--set", "supports.top_amplitude=0, 0.01", "--set", "supports.top_ramp_time=1e-3",
               "--set", "supports.top_release_time=5e-4")
    assert proc.returncode == 0 and not scene_warnings(proc), proc.stderr


HARMONIC = ["supports.top_motion=harmonic", "supports.top_frequency=2",
            "supports.top_amplitude=0, 0.01"]


@pytest.mark.parametrize("sets,fragment", [
    (["supports.top_release_time=5"], "&supports: top_release_time = 5.0: at or after "
     "t_end = 0.001 s: the support is not released in the run"),
    (["supports.bottom=pinned", "supports.bottom_release_time=1e-3"],
     "bottom_release_time = 0.001: at or after t_end = 0.001 s"),
    (HARMONIC + ["supports.top_ramp_time=2e-3"], "&supports: top_ramp_time = 0.002: longer "
     "than the run (t_end = 0.001 s): the amplitudes reach only 50.0 % of their size"),
])
def test_a_release_or_ramp_the_run_ends_before_is_warned_of(run, sets, fragment):
    args = ["run", PAPER, "--set", "solver.t_end=1e-3", "--set", "output.file=w.h5"]
    for s in sets:
        args += ["--set", s]
    proc = run(*args)
    assert proc.returncode == 0, proc.stderr
    warnings = scene_warnings(proc)
    assert len(warnings) == 1 and fragment in warnings[0], proc.stderr


@pytest.mark.parametrize("sets,ends", [
    (["supports.top=clamped"], "the clamped top"),
    (["supports.end_compliance=split", "supports.bottom=pinned"],
     "the split pinned top and the split pinned bottom"),
    (["model.kind=mpp", "supports.end_compliance=split", "supports.bottom=clamped"],
     "the split clamped bottom"),
    (["supports.bottom=pinned"], None),                      # the pins' added springs
    (["model.kind=mpp", "supports.end_compliance=split"], None),   # the MPP's ideal top pin
    (["supports.top=clamped", "supports.top_release_time=0"], None),   # free from the start
])
def test_a_support_factor_on_the_ropes_own_end_section_is_warned_of(run, sets, ends):
    """A clamp's rotational spring is the rope's first half section in bending, and with
    'split' a held end's spring is its half section in tension: support_stiffness_factor
    stiffens that section too, a first-order error (a cantilever clamped at 1000 bent 10 %
    too little at 20 elements). Where the factor only scales the spring a pin adds, or
    nothing, there is no warning."""
    args = ["run", PAPER, "--set", "solver.t_end=1e-4", "--set", "output.file=w.h5",
            "--set", "supports.support_stiffness_factor=100"]
    for s in sets:
        args += ["--set", s]
    proc = run(*args)
    assert proc.returncode == 0, proc.stderr
    warnings = [w for w in scene_warnings(proc) if "support_stiffness_factor" in w]
    if ends is None:
        assert not warnings, proc.stderr
    else:
        assert len(warnings) == 1, proc.stderr
        assert warnings[0].startswith("ropedyn: warning: --set supports.support_stiffness_factor"
                                      "=100: &supports: "
                                      "support_stiffness_factor = 100.0: it scales the rope's "
                                      f"own end section too at {ends} "), warnings[0]


def test_keys_of_an_effect_that_is_off_are_warned_of(run, tmp_path):
    """A &ground or &fluid written but not switched on does nothing: a warning names the
    first key set away from its default and how many more there are; water's own keys warn
    with drag alone on; switched on, or echoed at their defaults (an effective scene), no
    warning."""
    (tmp_path / "idle.nml").write_text(
        "&model elements = 4 /\n&solver t_end = 1e-4 /\n"
        "&ground stiffness = 2e5, friction_coefficient = 0.3 /\n"
        "&fluid surface = 0.5, density = 1000 /\n")
    proc = run("run", "idle.nml", "--set", "output.file=a.h5")
    assert proc.returncode == 0, proc.stderr
    assert scene_warnings(proc) == [
        "ropedyn: warning: idle.nml: &ground: stiffness = 200000.0: does nothing: "
        "effects.ground is .false.; so does 1 more key of &ground",
        "ropedyn: warning: idle.nml: &fluid: density = 1000.0: does nothing: effects.drag "
        "and effects.water are .false.; so does 1 more key of &fluid"], proc.stderr
    proc = run("run", "idle.nml", "--set", "output.file=b.h5", "--set", "effects.drag=.true.",
               "--set", "effects.ground=.true.")
    assert scene_warnings(proc) == [
        "ropedyn: warning: idle.nml: &fluid: surface = 0.5: does nothing: effects.water is "
        ".false. (only water uses it)"], proc.stderr
    proc = run("run", "idle.nml", "--set", "output.file=c.h5", "--set", "effects.water=.true.",
               "--set", "effects.ground=.true.")
    assert proc.returncode == 0 and not scene_warnings(proc), proc.stderr
    proc = run("run", PAPER, "--set", "output.file=d.h5", "--set", "solver.t_end=1e-4")
    with h5py.File(tmp_path / "d.h5") as f:
        (tmp_path / "paper_echo.nml").write_text(f.attrs["scene"].decode())
    proc = run("run", "paper_echo.nml", "--set", "output.file=e.h5")
    assert proc.returncode == 0 and not scene_warnings(proc), proc.stderr


def test_a_current_or_drag_keys_under_water_without_drag_are_warned_of(run, tmp_path):
    """Under water with drag off the drag coefficients do nothing and a current drags
    nothing (it moves only the water's added mass): a towed cable whose drag was left off
    hangs straight down in its current. Each is warned of; with drag on, neither."""
    (tmp_path / "wet.nml").write_text(
        "&model elements = 4 /\n&solver t_end = 1e-4 /\n&effects water = .true. /\n"
        "&fluid density = 1025, surface = -1, tangential_drag_coefficient = 0.01, "
        "current = 0, -2 /\n")
    proc = run("run", "wet.nml", "--set", "output.file=a.h5")
    assert proc.returncode == 0, proc.stderr
    assert scene_warnings(proc) == [
        "ropedyn: warning: wet.nml: &fluid: current = 0.0, -2.0: effects.drag is .false.: "
        "the current drags nothing (it moves only the water's added mass); a rope in a "
        "current needs effects.drag = .true.",
        "ropedyn: warning: wet.nml: &fluid: tangential_drag_coefficient = 0.01: does nothing: "
        "effects.drag is .false. (only drag uses it)"], proc.stderr
    proc = run("run", "wet.nml", "--set", "output.file=b.h5", "--set", "effects.drag=.true.")
    assert proc.returncode == 0 and not scene_warnings(proc), proc.stderr
