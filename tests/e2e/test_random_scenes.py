"""scripts/random_scenes (tools/ropedyn_tools/random_scenes.py): the outcomes are sorted as
documented (a crash is anything but exit 0, 2 or 3, or crash text), the draws depend on the
seed alone, and a short sweep runs."""
import random
import types

from ropedyn_tools import random_scenes as rs


def test_outcomes():
    ok, refused, failed = (types.SimpleNamespace(returncode=c) for c in (0, 2, 3))
    assert rs.outcome(ok, "  output x.h5") == "ok"
    assert rs.outcome(refused, "ropedyn: error: ...") == "refused"
    assert rs.outcome(failed, "ropedyn: error: erk failed at t = ...") == "failed"
    assert rs.outcome(types.SimpleNamespace(returncode=5), "modes: ...") == "crash"
    assert rs.outcome(ok, "At line 12\nFortran runtime error: ...") == "crash"
    assert rs.outcome(None, "timeout") == "crash"


def test_an_equilibrium_with_a_loose_residual_is_suspect():
    """A statics or modes summary that reports an equilibrium (exit 0) with a residual above
    LOOSE_RESIDUAL of the weight is a wrong result given as right; a run is not judged so."""
    ok = types.SimpleNamespace(returncode=0)
    line = "  residual        max |f| =  {} N ( {} of the weight   2.4953 N)\n"
    tight, loose = line.format("6.2E-16", "2.5E-16"), line.format("1.960E+01", "7.856E+00")
    assert rs.residual_ratio(loose) == 7.856
    assert rs.sorted_outcome(ok, tight, "statics") == "ok"
    assert rs.sorted_outcome(ok, loose, "statics") == "suspect"
    assert rs.sorted_outcome(ok, loose, "modes") == "suspect"
    assert rs.sorted_outcome(ok, loose, "run") == "ok"
    assert rs.sorted_outcome(types.SimpleNamespace(returncode=3), loose, "statics") == "failed"


def test_every_failure_of_the_statics_counts_as_no_equilibrium():
    stalled = ("ropedyn: error: s.nml: statics: no equilibrium in the current (&fluid current "
               "= 0.861, 0.213 m/s): the continuation in its speed stalled at 0.516 of it")
    still = ("ropedyn: error: s.nml: statics: no convergence in 2000 iterations (max |f| = "
             "1.0E-03 N, last step 1.0E-09 m or rad, shift 1.0E+00); the rope may have no "
             "stable equilibrium near the start, or needs more iterations (--max-iterations)")
    assert rs.no_equilibrium("failed", stalled) and rs.no_equilibrium("failed", still)
    assert not rs.no_equilibrium("failed", "ropedyn: error: erk failed at t = 0.1 s")
    assert not rs.no_equilibrium("ok", "statics: converged")


def test_draws_depend_on_the_seed_alone():
    first = [rs.draw(random.Random(7), "run") for _ in range(3)]
    again = [rs.draw(random.Random(7), "run") for _ in range(3)]
    other = [rs.draw(random.Random(8), "run") for _ in range(3)]
    assert first == again and first != other
    sets, _ = first[0]
    assert {"model.kind", "solver.method", "initial.shape"} <= set(sets)
    assert "solver.method" not in rs.draw(random.Random(7), "statics")[0]


def test_a_short_sweep(ropedyn_exe, capsys):
    assert rs.main(["statics", "--exe", str(ropedyn_exe), "--seed", "3", "--count", "4"]) == 0
    out = capsys.readouterr().out
    assert "random_scenes statics --seed 3 --count 4: ok " in out and "crash 0" in out
    assert "suspect 0" in out


def test_show_prints_the_outcomes_asked_for(ropedyn_exe, capsys, monkeypatch):
    """--show refused prints each refused case as a crash is printed: its last line and the
    command that repeats it (a bad value drawn: model.elements = 0 is refused)."""
    args = ["statics", "--exe", str(ropedyn_exe), "--seed", "3", "--count", "2"]
    draw = rs.draw
    monkeypatch.setattr(rs, "draw", lambda rng, command: (
        {**draw(rng, command)[0], "model.elements": 0}, False))
    assert rs.main(args + ["--show", "refused"]) == 0
    shown = capsys.readouterr().out
    assert rs.main(args) == 0
    quiet = capsys.readouterr().out
    assert shown.count("refused (case ") == 2 and "model.elements=0" in shown, shown
    assert "refused 2" in shown and "refused (case " not in quiet
