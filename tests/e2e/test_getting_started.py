"""The getting-started page's own files and commands work as the page says.

scripts/getting_started makes the page's numbers and pictures from full runs; this checks,
in seconds, what a newcomer types: the scene and sweep files the page writes (its `cat >
FILE <<'EOF'` blocks, read from the page) are read by the program, the sweep has as many
cases as the page says, and every generated section has its markers."""
import re
import sys

from conftest import ROOT

sys.path.insert(0, str(ROOT / "tools"))
from ropedyn_tools.studies import getting_started  # noqa: E402

PAGE = getting_started.PAGE.read_text()


def scratch(tmp_path):
    work = tmp_path / "clone"
    work.mkdir()
    files, snippets = getting_started.scratch(work, PAGE)
    return work, files, snippets


def test_page_writes_its_scene_sweep_and_plot_snippet(tmp_path):
    work, files, snippets = scratch(tmp_path)
    assert set(files) == {"my/methods.nml", "my/my_rope.nml"}
    assert len(snippets) == 1 and "summary.csv" in snippets[0]
    assert (work / "input" / "paper.nml").is_file()


def test_sweep_has_the_cases_the_page_names(tmp_path, run):
    work, _, _ = scratch(tmp_path)
    stated = {int(n) for n in re.findall(r"--list\s+# the (\d+) cases", PAGE)}
    assert len(stated) == 1, "the page names the number of cases of its --list line"
    result = run("sweep", "my/methods.nml", "--list", cwd=work)
    assert result.returncode == 0, result.stderr
    cases = re.findall(r"^\d{4}\s+missing\b", result.stdout, re.M)
    assert len(cases) == stated.pop(), result.stdout


def test_own_scene_runs(tmp_path, run):
    work, _, _ = scratch(tmp_path)
    result = run("run", "my/my_rope.nml", "--set", "solver.t_end=0.05", cwd=work)
    assert result.returncode == 0, result.stderr
    assert (work / "out" / "my_rope.h5").is_file()
    assert "elements        40" in result.stdout


def test_every_generated_section_has_its_markers():
    for name, page in getting_started.SECTIONS.items():
        text = page.read_text()
        begin, end = getting_started.markers(name)
        assert text.count(begin) == 1 and text.count(end) == 1, (page, name)
        assert text.index(begin) < text.index(end), (page, name)
