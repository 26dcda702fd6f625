"""scripts/docs_rerun (tools/ropedyn_tools/docs_rerun.py): the commands that bring the stale
sections of docs/ up to date, each once and in an order that respects what they read, run
one at a time and stopped at the first that fails."""
import os
import subprocess

from ropedyn_tools import docs_rerun as dr


def test_the_command_is_the_first_script_in_the_sections_head(tmp_path):
    page = tmp_path / "p.md"
    page.write_text("<!-- a:begin -->\nCommand: `scripts/fig5 --t-end 3` (code: x). Run: "
                    "2026-01-01 00:00 UTC.\n<!-- a:end -->\n"
                    "<!-- b:begin -->\nWritten by `ropedyn run` and `scripts/auto_table`.\n"
                    "<!-- b:end -->\n<!-- c:begin -->\nby hand\n<!-- c:end -->\n")
    assert dr.section_command(page, "a") == "scripts/fig5 --t-end 3"
    assert dr.section_command(page, "b") == "scripts/auto_table"
    assert dr.section_command(page, "c") is None
    assert dr.section_command(page, "missing") is None


def test_the_plan_runs_each_command_once_in_the_order_they_read():
    analyse = "scripts/validation bergdahl --analyse-only --models rfem"
    items = [("x", "scripts/fig5"), ("y", "scripts/accuracy choosing"),
             ("z", analyse), ("w", "scripts/stability_report --cached-only"),
             ("v", "scripts/bench_peers bergdahl"), ("u", "scripts/fig5"),
             ("t", "scripts/stability_report"), ("s", None)]
    plan = dr.plan(items, derived={"y": ()})
    assert plan == [
        # the case files the analysis reads, first
        "scripts/validation bergdahl --models rfem",
        # what fig5 reads, then fig5 (once for its two sections)
        "scripts/calibrate", "scripts/fig5",
        # the long suite once, before the first stability report
        "scripts/test --only-long", "scripts/stability_report --cached-only",
        "scripts/bench_peers bergdahl", "scripts/stability_report",
        # after every other command: the analysis, then the derived section
        analyse, "scripts/accuracy choosing"]


def test_a_failing_command_stops_the_rerun(tmp_path):
    scripts = tmp_path / "scripts"
    scripts.mkdir()
    for name, code in (("ok", 0), ("bad", 3)):
        (scripts / name).write_text(f"#!/bin/sh\necho {name} \"$@\"\nexit {code}\n")
        os.chmod(scripts / name, 0o755)
    logs = tmp_path / "logs"
    failed = dr.run(["scripts/ok --a 'b c'", "scripts/bad", "scripts/ok"], tmp_path, logs)
    assert failed == 2
    assert (logs / "01-ok.log").read_text() == "ok --a b c\n"
    assert (logs / "02-bad.log").read_text() == "bad\n"
    assert not (logs / "03-ok.log").exists()
    assert dr.run(["scripts/ok"], tmp_path, logs) is None


def test_the_dry_run_on_a_checkout_with_a_stale_section(tmp_path, capsys):
    def git(*args):
        subprocess.run(["git", "-C", str(tmp_path), "-c", "user.name=t", "-c",
                        "user.email=t@t", *args], check=True, capture_output=True)
    (tmp_path / "src").mkdir()
    (tmp_path / "docs").mkdir()
    (tmp_path / "src" / "a.f90").write_text("1\n")
    (tmp_path / "docs" / "p.md").write_text(
        "<!-- old:begin -->\nCommand: `scripts/fig5 --t-end 3`. "
        "Run: 2000-01-01 00:00 UTC.\n<!-- old:end -->\n<!-- hand:begin -->\nno stamp\n"
        "<!-- hand:end -->\n")
    git("init", "-q")
    git("add", ".")
    git("commit", "-qm", "code and docs")
    (tmp_path / "src" / "a.f90").write_text("2\n")
    git("commit", "-qam", "code changed after both runs")
    # a section written after the change is current
    (tmp_path / "docs" / "q.md").write_text(
        "<!-- fresh:begin -->\nCommand: `scripts/bench_step`. Run: 2000-01-02 00:00 UTC.\n"
        "<!-- fresh:end -->\n")
    git("add", ".")
    git("commit", "-qm", "a study run on the changed code")
    assert dr.main(["--dry-run", "--root", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    # (the scratch page's path built, not written out: the docs link test reads every
    # docs/ path a test names as a page of the manual)
    assert f"left alone: {os.path.join('docs', 'p.md')} hand (no run time)" in out
    assert out.split("plan:\n")[1].split() == ["scripts/calibrate", "scripts/fig5",
                                               "--t-end", "3"]
