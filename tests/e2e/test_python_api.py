"""ropedyn in-process from Python (python/ropedyn: Scene, run, Simulation, Error over
libropedyn): a scene read, changed and written reads in again to the same scene; a bad
scene or call raises ropedyn.Error with the command line's message and exit code; run()
gives the command line's records bit for bit and writes no file; a Simulation advanced
to the output times gives the same bits too, also two of them in two threads; a coupled
top driven every 1 ms from the motion of a ramped harmonic top gives the command line's
trajectory to the integration tolerance, for RFEM and MPP; save/restore; and
`pip install ./python` builds a package that runs with its own library."""
import os
import re
import subprocess
import sys
import threading

import h5py
import numpy as np
import pytest

import ropedyn
from conftest import ROOT

PAPER = ROOT / "input" / "paper.nml"


def small(n=8, t_end=0.5):
    return ropedyn.Scene.from_file(PAPER).set("model.elements", n).set("solver.t_end", t_end)


def python_process(code, **kwargs):
    """`code` run by this Python in a process of its own (its output captured as text)."""
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          **{"timeout": 300, **kwargs})


def cli_error(run, *args):
    """The message after 'ropedyn: error: ' and the exit code of `ropedyn run ARGS`."""
    result = run("run", *args)
    line = [s for s in result.stderr.splitlines() if s.startswith("ropedyn: error: ")][-1]
    return line[len("ropedyn: error: "):], result.returncode


def test_scene_set_write_read_is_the_same_scene(tmp_path):
    scene = ropedyn.Scene.from_file(PAPER)
    assert scene.get("model.elements") == 30
    scene.set("model.elements", 17).set("solver.rtol", 1e-7).set("supports.top_anchor",
                                                                  (0.1, -0.2))
    scene.set("effects.drag", True).set("model.kind", "mpp")
    assert scene.get("model.elements") == 17 and scene.get("solver.rtol") == 1e-7
    assert scene.get("supports.top_anchor") == [0.1, -0.2]
    assert scene.get("effects.drag") is True and scene.get("model.kind") == "mpp"
    again = ropedyn.Scene.from_file(scene.write(tmp_path / "s.nml"))
    assert again == scene and again.text == scene.text
    # and from its text
    assert ropedyn.Scene(scene.text, name="s.nml") == scene


def test_bad_scene_and_bad_set_raise_the_cli_message(run, tmp_path):
    bad = tmp_path / "bad.nml"
    bad.write_text("&model\n    elements = 1\n/\n")
    message, code = cli_error(run, bad)
    with pytest.raises(ropedyn.Error) as error:
        ropedyn.Scene.from_file(bad)
    assert error.value.message == message and error.value.code == code == 2
    assert error.value.kind == "input"
    good = tmp_path / "good.nml"
    good.write_text("&model\n    elements = 4\n/\n")
    message, code = cli_error(run, good, "--set", "solver.rtol=-1")
    scene = ropedyn.Scene.from_file(good)
    with pytest.raises(ropedyn.Error) as error:
        scene.set("solver.rtol", -1)
    assert error.value.message == message and error.value.code == code
    assert scene.get("solver.rtol") == 1e-6   # unchanged
    with pytest.raises(ropedyn.Error, match="unknown key"):
        scene.set("solver.nosuchkey", 1)


def test_set_takes_numpy_numbers():
    """A numpy float64 (what a scan over np.linspace gives) is a float whose repr under
    numpy 2 is "np.float64(2.0)": the setting "rope.length=np.float64(2.0)" was refused
    ("cannot read length"). Other numpy scalars and arrays went through tolist()."""
    scene = small(n=4)
    scene.set("rope.length", np.float64(2.5)).set("model.elements", np.int64(6))
    scene.set({"solver.rtol": np.float32(1e-5), "supports.top_anchor": np.array([0.0, 0.1]),
               "effects.drag": np.bool_(True)})
    assert scene.get("rope.length") == 2.5 and scene.get("model.elements") == 6
    assert scene.get("solver.rtol") == float(np.float32(1e-5))
    assert scene.get("supports.top_anchor") == [0.0, 0.1] and scene.get("effects.drag")
    for ea in np.linspace(100.0, 300.0, 2):   # the loop of examples/scan_ea.py
        assert scene.copy().set("rope.young_modulus", ea).get("rope.young_modulus") == ea


def test_get_of_a_key_not_set_is_none():
    """An optional key with no default (rope.mass_per_length, output.progress, ...) is in
    the effective text as "! key = (not set: ...)": get raised KeyError for it, as for a
    key that does not exist. It gives None; a key that does not exist still raises."""
    scene = small(n=4)
    assert "! mass_per_length = (not set" in scene.text
    assert scene.get("rope.mass_per_length") is None
    assert scene.get("Output.Progress") is None
    with pytest.raises(KeyError):
        scene.get("rope.no_such_key")
    with pytest.raises(KeyError):
        scene.get("model.mass_per_length")   # a key of another group
    assert scene.set("output.progress", False).get("output.progress") is False


def test_a_method_that_cannot_integrate_the_model_is_bad_input(run, tmp_path):
    """The symplectic method named for the MPP: exit 2 and no file from the command line,
    an input error from the library, both naming &solver method and the reason."""
    scene = tmp_path / "mpp.nml"
    scene.write_text("&model\n    kind = 'mpp'\n    elements = 4\n/\n"
                     "&solver\n    method = 'symplectic'\n/\n&output\n    file = 'x.h5'\n/\n")
    message, code = cli_error(run, scene)
    assert code == 2 and not (tmp_path / "x.h5").exists()
    assert message.startswith(f"{scene}: &solver: method = \"symplectic\": cannot integrate "
                              "the mpp model of this scene: the mass matrix depends on the state")
    with pytest.raises(ropedyn.Error) as error:
        ropedyn.Simulation(ropedyn.Scene.from_file(scene))
    assert error.value.kind == "input" and error.value.code == 2
    assert "cannot integrate the mpp model" in error.value.message


def test_run_gives_the_cli_records_and_writes_no_file(run, tmp_path, monkeypatch):
    scene = small(n=8, t_end=0.5)
    path = scene.write(tmp_path / "s.nml")
    assert run("run", path, "--set", "output.file=cli.h5").returncode == 0
    monkeypatch.chdir(tmp_path)
    before = sorted(p.name for p in tmp_path.rglob("*"))
    result = ropedyn.run(scene)
    assert sorted(p.name for p in tmp_path.rglob("*")) == before
    with h5py.File(tmp_path / "cli.h5") as f:
        assert np.array_equal(f["time"][:], result.time)
        assert np.array_equal(f["state/q"][:], result.q)
        assert np.array_equal(f["rope/points"][:], result.points)
        assert np.array_equal(f["forces/axial"][:], result.forces["axial"])
    assert result.status == "complete" and result.stats["steps"] > 0
    written = ropedyn.run(scene, output=tmp_path / "asked.h5")
    assert (tmp_path / "asked.h5").is_file() and np.array_equal(written.q, result.q)
    # the file says where its scene came from; the command line, whose source is a file,
    # does not replace it and says what it holds
    with h5py.File(tmp_path / "asked.h5") as f:
        source = f.attrs["source"].decode()
    assert source.startswith("scene text given to the library, named "), source
    cli = run("run", path, "--set", "output.file=asked.h5")
    assert cli.returncode == 2 and f'holds the run of "{source}"' in cli.stderr, cli.stderr
    # a file ropedyn did not write is refused; the caller has no --force to be offered
    (tmp_path / "notes.h5").write_text("mine\n")
    with pytest.raises(ropedyn.Error) as error:
        ropedyn.run(scene, output=tmp_path / "notes.h5")
    assert error.value.code == 2 and error.value.message.startswith(
        f"{tmp_path / 'notes.h5'}: exists and is not an HDF5 file"), error.value.message
    assert error.value.message.endswith("not replaced (remove it, or write elsewhere)"), \
        error.value.message
    assert (tmp_path / "notes.h5").read_text() == "mine\n"
    # a statics result is not a run's file: refused (a Scene has no source to compare, so
    # the kind is what is checked; before, the run replaced it); a run's file is replaced
    assert run("statics", path, "-o", "st.h5").returncode == 0
    with pytest.raises(ropedyn.Error) as error:
        ropedyn.run(scene, output=tmp_path / "st.h5")
    assert error.value.code == 2 and error.value.message.endswith(
        "exists and holds a statics result, not a run one: not replaced; write elsewhere, "
        "or remove it"), error.value.message
    with h5py.File(tmp_path / "st.h5") as f:
        assert f.attrs["analysis"] in (b"statics", "statics")
    assert ropedyn.run(scene.set("solver.t_end", 0.02), output=tmp_path / "asked.h5").status \
        == "complete"


def test_a_run_keeps_its_warnings_where_the_cli_prints_them(run, tmp_path):
    """What a run warns of reaches a library user too: ropedyn.run's Run has the file's
    /solver/warnings, the lines the command line prints after 'ropedyn: warning: ' (here a
    scene warning, water in air, and a start warning, the lower end pinned 1.22 m from
    where the straight start puts it), in that order; a run without them has none."""
    scene = small(n=4, t_end=0.01).set({"supports.bottom": "'pinned'",
                                        "supports.bottom_anchor": "1.0, 0.0",
                                        "effects.water": ".true.", "fluid.density": 1.225})
    path = scene.write(tmp_path / "w.nml")
    cli = run("run", path, "--set", "output.file=cli.h5")
    assert cli.returncode == 0, cli.stderr
    printed = [line[len("ropedyn: warning: "):] for line in cli.stderr.splitlines()
               if line.startswith("ropedyn: warning: ")]
    assert len(printed) == 2 and "density = 1.225" in printed[0] \
        and "bottom_anchor = 1.0, 0.0" in printed[1], cli.stderr
    result = ropedyn.run(path)
    assert result.warnings == printed
    assert ropedyn.load_run(tmp_path / "cli.h5").warnings == printed
    assert ropedyn.run(small(n=4, t_end=0.01)).warnings == []


def advance_to_records(scene, times):
    with ropedyn.Simulation(scene) as sim:
        points = []
        for t in times:
            sim.advance(t)
            points.append(sim.points)
        return np.array(points), sim.state


def test_simulation_at_output_times_is_the_run(tmp_path):
    scene = small(n=8, t_end=0.5)
    result = ropedyn.run(scene)
    points, _ = advance_to_records(scene, result.time[1:])
    assert np.array_equal(points, result.points[1:])


def test_two_simulations_in_two_threads_give_the_same_bits():
    scene = small(n=8, t_end=1.0)
    times = np.arange(1, 101) * 0.01
    alone = advance_to_records(scene, times)[1]
    out = [None, None]

    def work(k):
        out[k] = advance_to_records(scene, times)[1]

    threads = [threading.Thread(target=work, args=(k,)) for k in range(2)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    assert np.array_equal(out[0], alone) and np.array_equal(out[1], alone)


def test_failed_advance_raises_the_cli_message(run, tmp_path):
    scene = small(n=6, t_end=0.5).set("effects.fault_nan_after", 0.123)
    path = scene.write(tmp_path / "fault.nml")
    message, code = cli_error(run, path, "--set", "output.file=f.h5")
    assert code == 3
    with ropedyn.Simulation(scene) as sim:
        with pytest.raises(ropedyn.Error) as error:
            for t in np.arange(1, 51) * 0.01:
                sim.advance(t)
        assert error.value.message == message and error.value.kind == "solver"
        with pytest.raises(ropedyn.Error):   # the simulation stays failed
            sim.advance(0.6)
    with pytest.raises(ropedyn.Error) as error:
        ropedyn.run(scene)
    assert error.value.code == 3 and error.value.run.status == "failed"


def test_a_spent_budget_speaks_of_the_simulation(run, tmp_path):
    """A Simulation's step budget is the scene's max_steps for all its advances: when it is
    spent, the message names that budget, the steps taken since the start (those before a
    restore too: the one step a restore of a spent budget still allows makes 41) and the
    key to raise, not the rest of a run to t_end, which a simulation does not have. The
    command line's run of the scene keeps its message."""
    scene = small(n=8, t_end=0.5).set("solver.max_steps", 40)
    path = scene.write(tmp_path / "budget.nml")
    message, code = cli_error(run, path, "--set", "output.file=b.h5")
    assert code == 3 and "max_steps exceeded (40 steps); at the size of the last " \
        "accepted step" in message and "the rest of the run, to t = 0.5 s" in message, message
    messages = []
    with ropedyn.Simulation(scene) as sim:
        snap = sim.save()
        for _ in range(2):
            with pytest.raises(ropedyn.Error) as error:
                sim.advance(0.5)
            assert error.value.code == 3, error.value.message
            messages.append(error.value.message)
            sim.restore(snap)
    for text, steps in zip(messages, (40, 41)):
        assert f"max_steps exceeded (40 steps): the budget of the whole simulation, which " \
            f"has taken {steps} steps since it started (those before a restore too); a " \
            "simulation that goes on longer needs a larger solver.max_steps in its scene" \
            in text, text
        assert "rest of the run" not in text and "0.5 s" not in text, text


def test_a_simulation_does_not_count_steps_to_the_scenes_t_end(run, tmp_path):
    """A Simulation is not stopped by the scene's t_end, so no method may refuse it for the
    steps to t_end: the symplectic method, which foresees a shortfall of its fixed step
    count, refused a simulation of a 300 s scene with 20,000 steps at its start although
    the caller advanced 0.5 s (about 1,100 steps); the command line's run of the same scene
    still refuses at once, naming the budget that reaches t_end."""
    scene = (small(n=10, t_end=300.0).set("solver.method", "symplectic")
             .set("solver.max_steps", 20000))
    path = scene.write(tmp_path / "long.nml")
    message, code = cli_error(run, path, "--set", "output.file=l.h5")
    assert code == 3 and "the rest of the run, to t = 300.0 s, takes about" in message, message
    with ropedyn.Simulation(scene) as sim:
        sim.advance(0.5)
        assert sim.t == pytest.approx(0.5, abs=1e-12)
        with pytest.raises(ropedyn.Error) as error:
            sim.advance(20.0)
        assert "the budget of the whole simulation" in error.value.message, error.value.message
        assert "300" not in error.value.message, error.value.message


def test_a_runaway_fails_the_advance_where_the_run_fails(run, tmp_path):
    """erk at rtol 0.3 on the paper's rope creates energy; the command line's run fails at
    the runaway (docs/theory/energy-balance.md, "A runaway ends the run"). A Simulation
    advanced on the output grid fails at the same advance with the same message, keeps the
    state it last looked at, and a state set by the caller (energy put in) is no runaway."""
    loose = (small(n=30, t_end=2).set("solver.method", "erk").set("solver.rtol", 0.3)
             .set("solver.atol", 3e-3))
    path = loose.write(tmp_path / "loose.nml")
    message, code = cli_error(run, path, "--set", "output.file=l.h5")
    assert code == 3 and "it created" in message, message
    times = np.arange(1, 201) * 0.01
    with ropedyn.Simulation(loose) as sim:
        with pytest.raises(ropedyn.Error) as error:
            for t in times:
                sim.advance(t)
                last = sim.state
        assert error.value.message == message and error.value.kind == "solver"
        t_fail = float(message.split("failed at t = ")[1].split(" s")[0])
        assert t_fail == pytest.approx(t, abs=1e-12)
        assert np.array_equal(sim.state, last)      # the state of the look before
    # the same scene with the rule off goes on (the gain is the method's)
    with ropedyn.Simulation(loose.set("solver.order_safety", "off")) as sim:
        for t in times:
            sim.advance(t)
    # a fine tolerance, and a state the caller sets with 5 m g L more kinetic energy: the
    # new start, no runaway
    with ropedyn.Simulation(small(n=8, t_end=2)) as sim:
        sim.advance(0.5)
        y = sim.state
        y[3 * 8:] *= 10.0            # every velocity ten times: energy from the caller
        sim.state = y
        assert sim.energy["kinetic"] > 5 * 1.156
        for t in 0.5 + np.arange(1, 51) * 0.01:
            sim.advance(t)


def test_a_runaway_at_the_first_look_fails_cleanly(tmp_path):
    """The runaway rule looks back to the previous look; at a simulation's first look that
    is its start. A simulation records nothing, so nothing had kept the start: one advance
    of the runaway scene over the whole run crashed the process (SIGSEGV, reading the
    unset previous state). It now fails that advance with the runaway's message and keeps
    the start. Run in a child process, so that a crash fails this test alone."""
    code = ("import numpy as np, ropedyn\n"
            f"s = ropedyn.Scene.from_file({str(PAPER)!r})\n"
            "s = s.set('solver.method', 'erk').set('solver.rtol', 0.3).set('solver.atol', 1e-3)\n"
            "with ropedyn.Simulation(s) as sim:\n"
            "    y0 = sim.state\n"
            "    try:\n"
            "        sim.advance(30.0)\n"
            "    except ropedyn.Error as e:\n"
            "        print(e.code, 'it created' in e.message, sim.t, np.array_equal(sim.state, y0))\n")
    result = python_process(code, cwd=tmp_path)
    assert result.returncode == 0, (result.returncode, result.stderr)
    assert result.stdout.split() == ["3", "True", "0.0", "True"], result.stdout


def test_simulation_calls_and_their_errors():
    scene = small(n=8)
    with ropedyn.Simulation(scene) as sim:
        assert sim.t == 0.0 and sim.points.shape == (16, 2) and sim.n == 8
        sim.advance(0.1)
        assert sim.t == 0.1
        assert set(sim.forces) == {"axial", "shear", "moment"}
        assert sim.forces["axial"].shape == (9,)
        assert sim.reaction("top").shape == (2,) and sim.reaction("top")[0] < 0
        assert np.all(np.isnan(sim.anchor("bottom")))
        with pytest.raises(ropedyn.Error, match="top_motion = 'coupled'"):
            sim.set_support("top", position=(0, 0))
        with pytest.raises(ropedyn.Error, match="lies before"):
            sim.advance(0.05)
        with pytest.raises(ropedyn.Error, match="unknown support"):
            sim.reaction("middle")
        # malformed arguments are ropedyn.Error too (bad call: code 2), not Python's own
        for bad in ((1.0,), (1.0, 2.0, 3.0), "xy", None):
            with pytest.raises(ropedyn.Error, match="two numbers each") as error:
                sim.set_support("top", position=bad)
            assert error.value.code == 2
        with pytest.raises(ropedyn.Error, match="numbers, not") as error:
            sim.state = ["a", "b"]
        # a t within rounding of the time reached does nothing (it ended the simulation:
        # "step size fell below the round-off limit")
        sim.advance(np.nextafter(0.1, 1.0))
        assert sim.t == 0.1
        snap = sim.save()
        sim.advance(0.3)
        first = sim.state
        sim.restore(snap)
        assert sim.t == 0.1
        sim.advance(0.3)
        assert np.array_equal(sim.state, first)
        y = sim.state
        y[0] += 1e-3
        sim.state = y
        assert np.array_equal(sim.state, y)
    with pytest.raises(ropedyn.Error, match="closed"):
        sim.advance(1.0)
    statics = ropedyn.Simulation(small(n=8).set("supports.bottom", "pinned")
                                 .set("supports.bottom_anchor", (0.9, 0.2)), statics=True)
    assert abs(statics.energy["kinetic"]) < 1e-20
    statics.close()


def test_a_snapshot_restores_only_into_the_same_rope():
    """A snapshot of one rope restored into a simulation of another rope with as many
    unknowns was taken silently (its state on the other rope, a support where the other has
    none): now refused, naming the first line of the two scenes that differs. Another
    method or tolerance (&solver) or start (&initial) is the same rope."""
    with ropedyn.Simulation(small(n=8)) as a:
        a.advance(0.1)
        snap = a.save()
        with ropedyn.Simulation(small(n=8).set("rope.length", 3.0)) as b:
            with pytest.raises(ropedyn.Error, match=r'restore: the snapshot is of another '
                               r'scene: its "length = 1.0" against this one\'s "length = '
                               r'3.0" \(&rope\)') as error:
                b.restore(snap)
            assert error.value.code == 2 and b.t == 0.0
        other = small(n=8).set("solver.method", "mebdf").set("initial.angle_deg", 10.0)
        with ropedyn.Simulation(other) as c:
            c.restore(snap)
            assert c.t == 0.1 and np.array_equal(c.state, a.state)


@pytest.mark.parametrize("model", ["rfem", "mpp"])
def test_coupled_top_is_the_harmonic_top(model, run, tmp_path):
    """The top driven through set_support every 1 ms from the ramped harmonic motion
    gives the command line's run of that motion, to the integration tolerance."""
    amplitude, frequency, ramp = 0.05, 1.5, 0.4
    t_end = 1.0
    harmonic = small(n=8, t_end=t_end).set({
        "model.kind": model, "solver.rtol": 1e-9, "solver.atol": 1e-11,
        "supports.top_motion": "harmonic", "supports.top_amplitude": (0.0, amplitude),
        "supports.top_frequency": frequency, "supports.top_ramp_time": ramp})
    reference = ropedyn.run(harmonic)
    coupled = harmonic.copy().set("supports.top_motion", "coupled")
    w = 2 * np.pi * frequency

    def motion(t):
        u = min(t / ramp, 1.0)
        r = u ** 3 * (10 - 15 * u + 6 * u * u)
        dr = 30 * u * u * (1 - u) ** 2 / ramp if t < ramp else 0.0
        y = r * amplitude * np.sin(w * t)
        v = r * amplitude * w * np.cos(w * t) + dr * amplitude * np.sin(w * t)
        return (0.0, y), (0.0, v)

    tips = []
    with ropedyn.Simulation(coupled) as sim:
        for k in range(1, int(round(t_end / 1e-3)) + 1):
            t = k * 1e-3
            position, velocity = motion(t)
            sim.set_support("top", position=position, velocity=velocity)
            sim.advance(t)
            if k % 10 == 0:
                tips.append(sim.points[-1])
    difference = np.abs(np.array(tips) - reference.points[1:, -1]).max()
    swing = np.abs(reference.points[:, -1] - reference.points[0, -1]).max()
    assert swing > 0.1
    # measured: 3e-11 m (RFEM), 3e-8 m (MPP: it takes the support's acceleration, of the
    # curves' second derivative); with the prescribed velocities dropped 4e-6 and 1.3e-3 m
    assert difference < 1e-6, difference


def test_pip_install_builds_a_package_with_its_own_library(tmp_path):
    """`pip install ./python` (scikit-build-core) builds libropedyn into the package; that
    package, imported from elsewhere without ROPEDYN_LIBRARY, runs a scene with it."""
    site = tmp_path / "site"
    build = subprocess.run(
        [sys.executable, "-m", "pip", "install", "--no-build-isolation", "--no-deps", "-q",
         "--target", str(site), "--config-settings=cmake.build-type=Debug",
         f"--config-settings=build-dir={tmp_path / 'build'}", str(ROOT / "python")],
        capture_output=True, text=True)
    assert build.returncode == 0, build.stdout[-3000:] + build.stderr[-3000:]
    assert (site / "ropedyn" / "libropedyn.so").is_file()
    env = {k: v for k, v in os.environ.items() if k != "ROPEDYN_LIBRARY"}
    env["PYTHONPATH"] = str(site)
    code = ("import ropedyn, ropedyn._lib as lib\n"
            f"s = ropedyn.Scene.from_file({str(PAPER)!r}).set('model.elements', 6)\n"
            "s.set('solver.t_end', 0.1)\n"
            "print(lib.library().path, ropedyn.run(s).status)\n")
    result = python_process(code, cwd=tmp_path, env=env)
    assert result.returncode == 0, result.stderr
    assert result.stdout.split() == [str(site / "ropedyn" / "libropedyn.so"), "complete"]


def test_a_missing_ropedyn_library_is_an_error(tmp_path):
    """ROPEDYN_LIBRARY naming no file is an error that names it; before, the package went
    on silently with the next library it found (this clone's build)."""
    missing = tmp_path / "nowhere" / "libropedyn.so"
    env = dict(os.environ, ROPEDYN_LIBRARY=str(missing))
    code = ("import ropedyn, ropedyn._lib as lib\n"
            "try:\n"
            "    print('loaded', lib.library().path)\n"
            "except ropedyn.Error as e:\n"
            "    print('error', e.code, e.message)\n")
    result = python_process(code, cwd=tmp_path, env=env)
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith("error 2 "), result.stdout
    assert f"ROPEDYN_LIBRARY={missing}" in result.stdout


def test_a_state_whose_forces_overflow_fails_the_advance_not_the_process():
    """A finite state whose forces overflow (the state times 1e200) gave auto's spectrum
    estimate a NaN, and LAPACK's dgeev refused it through xerbla: ' ** On entry to DGEBAL
    parameter number 3 had an illegal value' and the whole process stopped, with status 0.
    Now the advance fails (code 3) and the simulation can be restored."""
    code = (
        "import ropedyn\n"
        f"scene = ropedyn.Scene.from_file({str(PAPER)!r}).set('model.elements', 8)\n"
        "with ropedyn.Simulation(scene) as sim:\n"
        "    sim.advance(0.1)\n"
        "    snap = sim.save()\n"
        "    sim.state = sim.state * 1e200\n"
        "    try:\n"
        "        sim.advance(0.2)\n"
        "    except ropedyn.Error as error:\n"
        "        print('code', error.code)\n"
        "    sim.restore(snap)\n"
        "    sim.advance(0.2)\n"
        "    print('alive', sim.t)\n")
    result = python_process(code)
    assert "DGEBAL" not in result.stderr, result.stderr
    assert result.returncode == 0 and result.stdout.split() == ["code", "3", "alive", "0.2"], \
        (result.stdout, result.stderr)


def test_runs_in_one_process_keep_no_hdf5_types():
    """Each run opened the HDF5 library with h5open_f, which copies the Fortran
    interface's predefined types anew and never frees the copies: 55 type ids (about
    30 KB) a run into memory, 165 a run into a file, so a scan of 10^4 runs grew by
    hundreds of MB. The resident memory of 300 more runs now stays within 1 MB (before:
    9 MB) in one of two batches of 300: the other may hold a step of about 2 MB that the
    allocator takes or gives back once, at a moment that varies from process to process;
    a leak grows both."""
    code = (
        "import ropedyn\n"
        "scene = ropedyn.Scene(\"&model kind = 'rfem', elements = 4 /\\n\"\n"
        "                      \"&solver t_end = 0.02, output_interval = 0.01 /\\n\")\n"
        "def rss():\n"
        "    return int(open('/proc/self/statm').read().split()[1]) * 4\n"
        "for _ in range(50):\n"
        "    ropedyn.run(scene)\n"
        "growth = []\n"
        "for batch in range(2):\n"
        "    before = rss()\n"
        "    for _ in range(300):\n"
        "        ropedyn.run(scene)\n"
        "    growth.append(rss() - before)\n"
        "print(min(growth))\n")
    result = python_process(code)
    assert result.returncode == 0, result.stderr
    assert int(result.stdout) < 1024, f"grew by {result.stdout.strip()} KiB"


def test_bad_arguments_and_texts_are_ropedyn_errors(tmp_path):
    """What Python's own layers raised before: a message whose quoted value the library
    cut inside a character of several bytes (UnicodeDecodeError), an advance to a time that
    is no number (ctypes.ArgumentError), a restore of no Snapshot (AttributeError); a scene
    text with a NUL was read up to the NUL, silently. A scene file that is not UTF-8 (a
    Latin-1 string value, which the command line reads) reads, writes and runs."""
    with pytest.raises(ropedyn.Error, match="too long") as error:
        ropedyn.Scene("&model kind = '" + "é" * 200 + "' /")
    assert error.value.code == 2
    with pytest.raises(ropedyn.Error, match="NUL"):
        ropedyn.Scene("&model elements = 4 /\0&rope length = -1 /")
    with ropedyn.Simulation(small(n=4)) as sim:
        for bad in ("0.1", None):
            with pytest.raises(ropedyn.Error, match="advance: t is a time") as error:
                sim.advance(bad)
            assert error.value.code == 2
        with pytest.raises(ropedyn.Error, match="restore: a Snapshot"):
            sim.restore(None)
        sim.advance(0.01)
        assert sim.t == 0.01
    latin = tmp_path / "latin.nml"
    latin.write_bytes(PAPER.read_bytes().replace(b"out/paper.h5", b"out/caf\xe9.h5"))
    scene = ropedyn.Scene.from_file(latin).set({"model.elements": 4, "solver.t_end": 0.02})
    scene.write(tmp_path / "again.nml")
    assert b"out/caf\xe9.h5" in (tmp_path / "again.nml").read_bytes()
    assert ropedyn.Scene.from_file(tmp_path / "again.nml") == scene
    assert ropedyn.run(scene).time[-1] == 0.02


def test_a_failure_at_a_tiny_time_writes_the_times_exponent():
    """A failure message wrote t with ES12.5, which drops the E of a three-digit exponent:
    "auto: erk failed at t =  2.23463-153 s" (a coupled top sent to 1e300 m). The time
    must read back as a number."""
    scene = ropedyn.Scene.from_file(PAPER).set("supports.top_motion", "coupled")
    with ropedyn.Simulation(scene.set("model.elements", 8)) as sim:
        sim.set_support("top", position=(1e300, 0))
        with pytest.raises(ropedyn.Error, match="failed at t = ") as failed:
            sim.advance(1e-3)
    t = float(str(failed.value).split("failed at t = ")[1].split(" s")[0])
    assert 0.0 <= t < 1e-3, str(failed.value)


def test_statics_takes_only_a_bool():
    """Simulation(scene, statics="no") started at the static equilibrium: any truthy
    object was taken as True. Only a bool (or numpy bool) is taken."""
    for bad in ("no", "False", 1, 0.0, None, [False]):
        with pytest.raises(ropedyn.Error, match=r"statics is True or False, not ") as error:
            ropedyn.Simulation(small(n=4), statics=bad)
        assert error.value.code == 2 and repr(bad) in error.value.message
    for good in (False, np.bool_(False)):
        with ropedyn.Simulation(small(n=4), statics=good) as sim:
            assert sim.energy["kinetic"] == 0.0 and sim.t == 0.0


def test_state_takes_only_a_1d_sequence_of_its_length():
    """sim.state = y.reshape(2, -1) was flattened and taken. Only a 1-D sequence of the
    state's length is: the error names that length and the shape given. Texts and bools
    are no numbers; a ragged list is refused as one."""
    with ropedyn.Simulation(small(n=4)) as sim:
        y = sim.state
        size = sim.state_size
        for bad in (y.reshape(2, -1), y.reshape(-1, 1), [list(y)], y[:3], np.float64(y[0]),
                    np.append(y, 0.0)):
            shape = np.shape(bad)
            with pytest.raises(ropedyn.Error, match=rf"state: a 1-D sequence of {size} "
                               rf"numbers \(shape \({size},\)\), not one of shape "
                               rf"{re.escape(str(shape))}") as error:
                sim.state = bad
            assert error.value.code == 2
        for bad in ([str(v) for v in y], np.ones(size, dtype=bool), [[1.0, 2.0], [3.0]],
                    None, "y"):
            with pytest.raises(ropedyn.Error, match=rf"state: {size} numbers, not "):
                sim.state = bad
        assert np.array_equal(sim.state, y)
        z = y.copy()
        z[0] += 1e-3
        sim.state = list(z)
        assert np.array_equal(sim.state, z)
        sim.state = z.astype(np.float32)
        assert np.array_equal(sim.state, z.astype(np.float32))


def test_every_property_of_a_closed_simulation_raises():
    """sim.n, sim.state_size and sim.scene were still read after sim.close(), while the
    methods and the other properties raised "the simulation is closed". Every property
    raises that error now, as the methods do; so does a closed snapshot's t."""
    sim = ropedyn.Simulation(small(n=4))
    names = {k for k, v in vars(ropedyn.Simulation).items() if isinstance(v, property)}
    names = sorted(names | {"n", "state_size", "scene", "t", "points", "state"})
    for name in names:
        getattr(sim, name)
    snap = sim.save()
    assert snap.t == 0.0
    snap.close()
    with pytest.raises(ropedyn.Error, match="^the snapshot is closed$"):
        snap.t
    sim.close()
    with pytest.raises(ropedyn.Error) as method:
        sim.advance(1.0)
    for name in names:
        with pytest.raises(ropedyn.Error) as error:
            getattr(sim, name)
        assert (error.value.message, error.value.code) == (method.value.message, 2), name
    assert method.value.message == "the simulation is closed"
    assert "closed" in repr(sim)


def test_times_and_positions_take_only_real_numbers():
    """advance(True) integrated to 1 s and advance(np.array([2.5])) to 2.5 s;
    set_support took (True, False) as (1, 0), and a dict's or a set's two keys as (x, y);
    reaction(["top"]) raised Python's TypeError. Now a time is one real number (an int,
    a float, numpy's, a 0-d array) and a position or velocity a tuple, list or 1-D array
    of two; anything else raises ropedyn.Error of code 2, and nothing changes."""
    scene = small(n=4).set("supports.top_motion", "coupled")
    with ropedyn.Simulation(scene) as sim:
        for bad in (True, np.bool_(True), np.array([0.25]), np.array(True), "0.1", [0.1],
                    1j):
            with pytest.raises(ropedyn.Error, match="advance: t is a time in s") as error:
                sim.advance(bad)
            assert error.value.code == 2 and sim.t == 0.0
        with pytest.raises(ropedyn.Error, match="not finite"):
            sim.advance(10 ** 400)
        for bad in ((True, False), (0.0, np.bool_(True)), {0: 1.0, 1: 2.0}, {1.0, 2.0},
                    np.zeros((1, 2)), np.array(["0", "1"]), ("0.0", "0.1"), (0.0, None),
                    np.array(1.0), iter((0.0, 0.1))):
            for args in ((bad,), ((0.0, 0.0), bad)):
                with pytest.raises(ropedyn.Error, match="two numbers each") as error:
                    sim.set_support("top", *args)
                assert error.value.code == 2
        for bad in (["top"], 0, None, b"top"):
            with pytest.raises(ropedyn.Error, match="unknown support") as error:
                sim.reaction(bad)
            assert error.value.code == 2
        sim.set_support("top", np.array([0.0, 1e-4]), [np.float32(0.0), np.array(0)])
        sim.advance(np.array(0.01))
        sim.set_support("top", (0, np.int64(0)))
        sim.advance(np.int64(1) / 50)
        assert sim.t == 0.02 and sim.anchor("top")[1] == 0.0


def test_scene_arguments_of_the_wrong_type_are_refused(tmp_path):
    """str() was taken of what Scene and Scene.from_file were given: Scene(b"&model ...")
    read the text "b'&model ...'", Scene(path) the path as namelist text, name=None wrote
    out/None.h5, and Simulation(None) looked for a file "None". A 2-D array set as a pair
    was flattened into one ([[0.1, 0.2]] as 0.1, 0.2); get(5) raised AttributeError."""
    text = PAPER.read_text()
    for bad in (text.encode(), PAPER, None, 4):
        with pytest.raises(ropedyn.Error, match=r"Scene: text is namelist text \(a str\), "
                           r"not .*; Scene.from_file reads a scene file") as error:
            ropedyn.Scene(bad)
        assert error.value.code == 2
    with pytest.raises(ropedyn.Error, match="Scene: name is a file's path .*, not None"):
        ropedyn.Scene(text, name=None)
    for bad in (None, 3, ["input/paper.nml"]):
        with pytest.raises(ropedyn.Error, match=r"Scene.from_file: path is a file's path "
                           r"\(a str, bytes or a pathlib.Path\), not ") as error:
            ropedyn.Scene.from_file(bad)
        assert error.value.code == 2
        for call in (ropedyn.Simulation, ropedyn.run):
            with pytest.raises(ropedyn.Error, match="the scene is a Scene or a scene file's "
                               "path, not ") as error:
                call(bad)
            assert error.value.code == 2
    assert ropedyn.Scene.from_file(os.fsencode(PAPER)) == ropedyn.Scene.from_file(PAPER)
    assert ropedyn.Scene(text, name=tmp_path / "a.nml").name == str(tmp_path / "a.nml")
    scene = small(n=4)
    for bad in (np.array([[0.1, 0.2]]), [[0.1, 0.2]], ((0.1,), (0.2,)),
                [np.array([0.1]), np.array([0.2])]):
        with pytest.raises(ropedyn.Error, match="set: a value is a bool, a number, a string "
                           "or a pair, not ") as error:
            scene.set("supports.top_anchor", bad)
        assert error.value.code == 2 and scene.get("supports.top_anchor") == [0.0, 0.0]
    scene.set("supports.top_anchor", (np.array(0.1), np.float64(0.2)))
    assert scene.get("supports.top_anchor") == [0.1, 0.2]
    for bad in (5, None, ("model", "elements")):
        with pytest.raises(KeyError):
            scene.get(bad)


def test_a_simulation_keeps_its_own_scene():
    """sim.scene was the Scene given: a later scene.set changed sim.scene (40 elements)
    while the simulation went on with the old one (n = 4). It is a copy now. A Scene whose
    simulation failed is unchanged and runs again."""
    scene = small(n=4).set("supports.top_motion", "coupled")
    before = scene.copy()
    with ropedyn.Simulation(scene) as sim:
        scene.set("model.elements", 40)
        assert sim.scene.get("model.elements") == 4 == sim.n and sim.scene == before
        sim.scene.set("model.elements", 5)   # the copy's change reaches neither
        assert scene.get("model.elements") == 40 and sim.n == 4
    scene.set("model.elements", 4)
    assert scene == before
    with ropedyn.Simulation(scene) as sim:
        sim.set_support("top", position=(1e300, 0.0))
        with pytest.raises(ropedyn.Error) as failed:
            sim.advance(1e-3)
        assert failed.value.code == 3
    assert scene == before and scene.warnings == before.warnings
    with ropedyn.Simulation(scene) as sim:
        sim.advance(0.01)
        assert sim.t == 0.01


def test_an_output_that_is_no_path_is_refused(tmp_path, monkeypatch):
    """run(scene, output=True) wrote a run file named "True" (str() of the value), then
    failed to read it back with Python's TypeError; output=1 wrote "1", and output=0 or
    False ran in memory. Only None (in memory) or a path is taken now; so for
    Scene.write."""
    monkeypatch.chdir(tmp_path)
    scene = small(n=4, t_end=0.01)
    for bad in (True, False, 1, 0, 0.5, ["out.h5"]):
        with pytest.raises(ropedyn.Error, match=r"run: output is a file's path \(a str, bytes or "
                           r"a pathlib.Path\), not ") as error:
            ropedyn.run(scene, output=bad)
        assert error.value.code == 2
        with pytest.raises(ropedyn.Error, match="Scene.write: path is a file's path"):
            scene.write(bad)
    assert list(tmp_path.iterdir()) == []
    assert ropedyn.run(scene, output="").path.endswith("(in memory)")
    assert ropedyn.run(scene, output=tmp_path / "a.h5").time[-1] == 0.01
    assert ropedyn.Scene.from_file(scene.write(b"s.nml")) == scene


def test_set_resolves_derived_defaults_after_every_setting(run, tmp_path):
    """A derived default (tangential_damping from normal_damping) is resolved after all
    the settings, as after several --set. Scene.set rebuilt the scene from its effective
    text, where the default was already written out: a later normal_damping left
    tangential_damping at its first value (400, from the scene's 1000)."""
    (tmp_path / "only.nml").write_text("&model /\n&solver t_end = 0.01 /\n")
    for scene in (ropedyn.Scene("&model /\n&solver t_end = 0.01 /\n"),
                  ropedyn.Scene.from_file(tmp_path / "only.nml")):
        scene.set("rope.normal_damping", 0.1)
        assert scene.get("rope.tangential_damping") == pytest.approx(0.04)
        again = scene.copy().set("rope.normal_damping", 0.2)
        assert again.get("rope.tangential_damping") == pytest.approx(0.08)
        assert scene.get("rope.tangential_damping") == pytest.approx(0.04)
        # a bad setting changes nothing
        with pytest.raises(ropedyn.Error):
            scene.set("rope.length", -1.0)
        assert scene.set("rope.normal_damping", 0.3).get("rope.tangential_damping") == \
            pytest.approx(0.12)
    cli = run("run", tmp_path / "only.nml", "--set", "rope.normal_damping=0.1",
              "--set", "rope.normal_damping=0.2", "--set", "output.file=c.h5")
    assert cli.returncode == 0, cli.stderr
    with h5py.File(tmp_path / "c.h5") as f:
        line = [l for l in f.attrs["scene"].decode().splitlines()
                if l.strip().startswith("tangential_damping")][0]
    assert float(line.split("=")[1].split("!")[0]) == pytest.approx(0.08)
