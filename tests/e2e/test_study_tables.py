"""The study tools (tools/ropedyn_tools/studies): auto_accuracy shows a fixed method's run
that needs more CPU than its cap as such, not as a failure of the method; the method chains
count switches, not the symplectic method's changes of step; bench_step runs again where a
run of another build left its file; calibrate runs its fit (each run to a file of its
own); bench_peers at equal accuracy takes the loosest rung of a half-decade ladder whose tip
error is within MoorDyn's; the stability report's stamp names the command that remakes
what it wrote."""
from ropedyn_tools.repo import ROOT
from ropedyn_tools.studies import auto_accuracy as aa


def test_a_run_over_its_cap_is_not_a_failure(ropedyn_exe, tmp_path):
    # cvode at rtol 1e-10 over the paper's 30 s takes several seconds: killed at 1 s of CPU
    scene = ROOT / "input" / "paper.nml"
    got = aa.measured(ropedyn_exe, scene, tmp_path, "cvode", 30.0,
                      ["solver.rtol=1e-10", "solver.atol=1e-12"], 1, 0.5, None)
    assert got == "cap"
    assert aa.error_cell(got, 0.5) == "> 0.5 s"
    # a run that ends with its diagnosis is a failure
    got = aa.measured(ropedyn_exe, scene, tmp_path, "erk", 30.0, ["solver.max_steps=10"], 1,
                      None, None)
    assert got is None and aa.error_cell(got, 3.0) == "failed"
    assert aa.error_cell("n/a", 3.0) == "n/a"
    assert aa.error_cell((0.1, 2.5e-7, ["erk 4"]), 3.0) == "2.5e-07"


def test_a_change_of_step_is_not_a_switch():
    """The study tables' method chains: the symplectic method's own events (a change of
    its step) are not switches; a real switch back to a method is."""
    from ropedyn_tools.studies.auto_table import choice_text
    from ropedyn_tools.studies.common import method_chain
    assert method_chain(["symplectic"] * 20) == "symplectic"
    assert method_chain(["erk 4", "symplectic", "symplectic", "erk 4"]) == \
        "erk 4 -> symplectic -> erk 4"
    assert method_chain(["erk 4", "erk 5"] * 4) == "erk 4 -> erk 5 -> erk 4 -> ... (7 switches)"
    assert choice_text([(0.0, "erk", 4), (0.0256, "symplectic", 4), (0.0256, "symplectic", 4),
                        (26.8, "symplectic", 4)]) == "erk 4, 0.0256 s: symplectic 4"
    assert choice_text([(0.0, "mebdf", 4), (1.0, "mebdf", 5)]) == "mebdf 4, 1 s: mebdf 5"


def test_bench_step_runs_again_in_the_same_folder(ropedyn_exe, tmp_path):
    """bench_step runs the baseline's and this tree's executables one after the other into the
    same folder; ropedyn replaces no file of another run, so each run's file must go after it
    (the study stopped at its second run when it did not)."""
    from ropedyn_tools.studies import bench_step
    first = bench_step.run(ropedyn_exe, "rfem", 4, "cvode", 0.05, tmp_path)
    second = bench_step.run(ropedyn_exe, "rfem", 4, "cvode", 0.1, tmp_path)
    assert first[0] > 0 and second[0] > first[0]
    assert not list(tmp_path.glob("*.h5"))


def test_calibrate_fits_with_a_file_for_each_run(ropedyn_exe, tmp_path):
    """scripts/calibrate ran every MPP run of its fit into one file; since ropedyn replaces
    no file of another run, its second run stopped the study. A short fit (n = 4, 0.2 s,
    four runs of the MPP) writes its CSV."""
    import csv
    from ropedyn_tools.studies import calibrate
    data = tmp_path / "fit.csv"
    assert calibrate.main(["--exe", str(ropedyn_exe), "--elements", "4", "--t-fit", "0.2",
                           "--window", "0.05", "--max-evals", "4", "--data", str(data)]) == 0
    with open(data) as f:
        (row,) = list(csv.DictReader(f))
    assert int(row["mpp_runs"]) >= 3 and float(row["a"]) > 0 and float(row["b"]) > 0


def test_auto_table_runs_again_after_a_run_killed_at_its_cap(ropedyn_exe, tmp_path):
    """A run killed at its CPU cap leaves its partial file and lock (kept for --resume);
    auto_table's pass at max_steps 1e7 runs into the same file, which ropedyn then refused:
    the table showed "failed" where the method was only over its cap."""
    from ropedyn_tools.studies import auto_table
    scene = ROOT / "input" / "paper.nml"
    sets = ("solver.rtol=1e-10", "solver.atol=1e-12")
    for _ in range(2):
        got = auto_table.run(ropedyn_exe, scene, tmp_path, "cvode", 30.0, cap=1, extra=sets)
        assert got["status"] == "cap", got
    assert not list(tmp_path.iterdir())


def test_equal_accuracy_takes_the_loosest_rung_within_moordyns_error(monkeypatch):
    """bench_peers at equal accuracy: the rungs are tried loosest first and half a decade
    apart, and the first whose tip error is within MoorDyn's is taken (here 0.03: 0.1 errs
    more than MoorDyn, 0.01 less but is tighter)."""
    from ropedyn_tools.studies import bench_peers as bp
    ladder = bp.EQUAL_RTOLS
    assert all(a > b for a, b in zip(ladder, ladder[1:]))
    assert all(a / b <= 3.5 for a, b in zip(ladder, ladder[1:]))
    errors = {0.1: 5.0e-3, 0.03: 1.4e-3, 0.01: 3.0e-4}
    tried = []

    def fake_run(exe, work, n, t_end, sets=(), name="run"):
        rtol = float(next(s for s in sets if s.startswith("solver.rtol="))[12:])
        tried.append(rtol)
        return {"status": "complete", "cpu": 1.0, "steps": 10, "methods": "erk 4",
                "balance": 0.0, "time": rtol, "tip": None}

    monkeypatch.setattr(bp, "run_ropedyn", fake_run)
    monkeypatch.setattr(bp, "tip_l2", lambda time, tip, ref: errors.get(time, 0.0))
    row = bp.at_equal_accuracy("exe", None, 30, 30.0, None, {"cpu": 4.0}, 3.1e-3)
    cells = [c.strip() for c in row.split("|")[1:-1]]
    assert tried == [0.1, 0.03]
    assert cells[2] == "0.03" and cells[-1] == "4.00"
    # a method with its order: both settings reach the run, the row names it
    said = []
    monkeypatch.setattr(bp, "run_ropedyn", lambda *a, sets=(), name="run": (
        said.append(list(sets)) or fake_run(*a, sets=sets, name=name)))
    row = bp.at_equal_accuracy("exe", None, 30, 30.0, None, {"cpu": 4.0}, 3.1e-3,
                               method="cvode:3")
    assert "solver.method='cvode'" in said[0] and "solver.max_order=3" in said[0]
    assert "| cvode:3 (erk 4) |" in row
    monkeypatch.setattr(bp, "run_ropedyn", lambda *a, sets=(), name="run": dict(
        fake_run(*a, sets=sets, name=name), methods=""))
    row = bp.at_equal_accuracy("exe", None, 30, 30.0, None, {"cpu": 4.0}, 3.1e-3,
                               method="mebdf")
    assert "| mebdf | " in row                     # no switch log: no parentheses
    assert bp.method_sets("mebdf") == {"solver.method": "'mebdf'"}


def test_the_stability_reports_stamp_names_its_part():
    """A report run for one part stamps the command that remakes that part, so that
    docs_rerun runs no more than it needs."""
    from ropedyn_tools.studies.stability_report import command_text
    assert command_text(False, None) == "Command: `scripts/stability_report`"
    assert command_text(False, "hard-scenes") == \
        "Command: `scripts/stability_report --only hard-scenes`"
    assert command_text(True, "cvode-order") == \
        "Command: `scripts/stability_report --quick --only cvode-order`"
    assert command_text(False, None, cached_only=True) == \
        "Command: `scripts/stability_report --only long-horizon --cached-only`"


def test_a_command_line_shows_no_exe_path():
    """The Command line of a study's section is the command a reader reruns: --exe PATH (a
    path of the machine that ran it) is left out, in either form, and nothing else."""
    from ropedyn_tools.studies.bench_peers import command_text
    from ropedyn_tools.studies.common import shown_arguments
    assert shown_arguments(["--perimeter", "--exe", "build/release/ropedyn",
                            "--convergence", "--exe=/x/ropedyn"]) == ["--perimeter",
                                                                       "--convergence"]
    assert command_text(["--elements", "10 30", "--exe", "b/ropedyn"]) == \
        "scripts/bench_peers --elements '10 30'"
