"""scripts/docs_status: which generated sections of docs/ predate a change of their code."""
import os
import subprocess

import pytest

from ropedyn_tools import docs_status


def _rev(root, rev="HEAD"):
    """The short hash of `rev` in the checkout at root."""
    return subprocess.run(["git", "-C", str(root), "rev-parse", "--short", rev],
                          capture_output=True, text=True, check=True).stdout.strip()


def _commit(root, message, files, date=None):
    """Write `files` ({path: text}) into the checkout at root and commit them all (at
    `date`, ISO, when given); the new commit's short hash."""
    for name, text in files.items():
        (root / name).parent.mkdir(parents=True, exist_ok=True)
        (root / name).write_text(text)
    env = dict(os.environ, GIT_COMMITTER_DATE=date, GIT_AUTHOR_DATE=date) if date else None
    subprocess.run(["git", "-C", str(root), "add", "."], check=True, env=env)
    subprocess.run(["git", "-C", str(root), "-c", "user.name=t", "-c", "user.email=t@t",
                    "commit", "-qm", message], check=True, env=env)
    return _rev(root)


def _repo(tmp_path):
    """A scratch checkout: code committed on Jan 1, changed on Jan 2 (counts), changed again
    on Jan 3 with a Numbers-unchanged line (does not count), docs changed on Jan 4."""
    def commit(date, message, files):
        return _commit(tmp_path, message, files, date)

    subprocess.run(["git", "init", "-q", str(tmp_path)], check=True)
    first = commit("2026-01-01T12:00:00Z", "start", {"src/a.f90": "1\n", "docs/x.md": "x\n"})
    second = commit("2026-01-02T12:00:00Z", "change a", {"src/a.f90": "2\n"})
    commit("2026-01-03T12:00:00Z", "comment\n\nNumbers-unchanged: a comment",
           {"src/a.f90": "2 ! why\n"})
    commit("2026-01-04T12:00:00Z", "docs", {"docs/y.md": "y\n"})
    # a study run on the working tree at 06:00, committed with the code it ran at 13:00;
    # the code changes again the next day
    with_page = commit("2026-01-05T13:00:00Z", "study and its page", {
        "src/a.f90": "3\n",
        "docs/committed.md": "<!-- run:begin -->\nCommand: `scripts/fig5`. "
                             "Run: 2026-01-05 06:00 UTC.\n<!-- run:end -->\n"})
    later = commit("2026-01-06T12:00:00Z", "change a again", {"src/a.f90": "4\n"})
    (tmp_path / "docs" / "page.md").write_text(f"""# Page
<!-- before:begin -->
Command: `scripts/fig5` (Release). Run: 2026-01-02 06:00 UTC.
| a |
<!-- before:end -->
<!-- after:begin -->
Written by `scripts/auto_table` (0.1 min, 2026-01-02 13:00 UTC, this machine)
<!-- after:end -->
<!-- by-commit:begin -->
Last run: 2026-01-05, commit `{first}`, 3 mutations (`scripts/mutation_check`).
<!-- by-commit:end -->
<!-- testset:begin -->
Command: `scripts/work_precision_testset`. Run: 2026-01-02 06:00 UTC.
<!-- testset:end -->
<!-- undated:begin -->
A table someone wrote by hand.
<!-- undated:end -->
<!-- before erk:begin -->
Command: `scripts/fig5` (Release). Run: 2026-01-02 06:00 UTC.
<!-- before erk:end -->
A study writes between `<!-- quoted:begin -->` and `<!-- quoted:end -->` markers.
""")
    return second, with_page, later


def test_sections_count_the_code_commits_since_their_run(tmp_path):
    second, with_page, later = _repo(tmp_path)
    rows = {r["name"]: r for r in docs_status.status(tmp_path)}
    hashes = {name: [c[0] for c in r["commits"]] for name, r in rows.items()
              if r["commits"] is not None}
    # page.md is not committed: judged by its runs' times (the comment-only commit of
    # Jan 3, marked Numbers-unchanged, never counts)
    assert hashes["before"] == [later, with_page, second]
    assert rows["before"]["script"] == "fig5"
    assert hashes["after"] == [later, with_page]
    # a section that names its commit is judged from the commit, not from the date
    assert hashes["by-commit"] == [later, with_page, second]
    # the test set's numbers do not come from src/
    assert hashes["testset"] == []
    assert rows["undated"]["commits"] is None
    # a marker quoted in a sentence is no section
    assert "quoted" not in rows
    # a committed stamp is judged from the commit that wrote it: the code committed with it
    # (after the run's time) does not count, the next day's change does
    assert hashes["run"] == [later]


def test_a_moved_section_is_judged_from_the_commit_that_first_wrote_it(tmp_path):
    """A page moved into a folder (or split: its sections written into new pages) keeps
    the commit of its run: the move writes the stamp again, but into docs/ it was first
    written by the run's commit."""
    second, with_page, later = _repo(tmp_path)
    (tmp_path / "docs" / "sub").mkdir()
    subprocess.run(["git", "-C", str(tmp_path), "mv", "docs/committed.md",
                    "docs/sub/moved.md"], check=True)
    subprocess.run(["git", "-C", str(tmp_path), "-c", "user.name=t", "-c", "user.email=t@t",
                    "commit", "-qm", "move the page"], check=True)
    rows = {r["name"]: r for r in docs_status.status(tmp_path)}
    assert rows["run"]["page"] == "docs/sub/moved.md"
    assert [c[0] for c in rows["run"]["commits"]] == [later]


def test_a_section_watches_the_module_its_command_runs_and_its_imports(tmp_path):
    """A wrapper that branches on its first argument (`scripts/survey chain` runs
    survey_chain.py, `scripts/survey` survey.py) has each section watch the module its own
    command runs, and the study modules that module imports (directly or through another),
    not the other branch's."""
    _repo(tmp_path)
    wrapper = ('#!/usr/bin/env bash\nif [ "${1:-}" = "chain" ]; then\n    shift\n'
               '    exec python -m ropedyn_tools.studies.survey_chain "$@"\nfi\n'
               'exec python -m ropedyn_tools.studies.survey "$@"\n')
    studies = "tools/ropedyn_tools/studies"

    def commit(message, files):
        return _commit(tmp_path, message, files)

    ran = commit("the survey and its pages", {
        "scripts/survey": wrapper,
        f"{studies}/survey.py": "x = 1\n",
        f"{studies}/survey_chain.py": "from ropedyn_tools.studies import chain_cases as c\n",
        f"{studies}/chain_cases.py": "from ropedyn_tools.studies.cases_core import y\n",
        f"{studies}/cases_core.py": "y = 1\n",
        "docs/survey.md": "<!-- plain:begin -->\nCommand: `scripts/survey --fast`.\n"
                          "Run: 2026-01-07 06:00 UTC.\n<!-- plain:end -->\n"
                          "<!-- chain:begin -->\nCommand: `scripts/survey chain --all`.\n"
                          "Run: 2026-01-07 06:00 UTC.\n<!-- chain:end -->\n"})
    chain = commit("change the chain's study", {f"{studies}/survey_chain.py": "z = 2\n" +
                   "from ropedyn_tools.studies import chain_cases as c\n"})
    core = commit("change what the chain's cases import", {f"{studies}/cases_core.py": "y = 2\n"})
    plain = commit("change the plain survey", {f"{studies}/survey.py": "x = 2\n"})
    rows = {r["name"]: [c[0] for c in r["commits"]] for r in docs_status.status(tmp_path)
            if r["name"] in ("plain", "chain")}
    assert ran not in rows["chain"] + rows["plain"]
    assert rows["chain"] == [core, chain]
    assert rows["plain"] == [plain]
    assert docs_status.wrapper_module(tmp_path, "survey", "chain") == "survey_chain"
    assert docs_status.wrapper_module(tmp_path, "survey", "fast") == "survey"
    assert docs_status.wrapper_module(tmp_path, "gone") == "gone"


def test_check_fails_on_a_stale_section(tmp_path, capsys):
    _repo(tmp_path)
    assert docs_status.main(["--root", str(tmp_path)]) == 0
    capsys.readouterr()
    assert docs_status.main(["--root", str(tmp_path), "--check"]) == 1
    out = capsys.readouterr().out
    listed = [line.split(" | ")[1] for line in out.splitlines() if line.startswith("| docs")]
    assert {"before", "after", "by-commit", "undated", "run"} <= set(listed)
    assert "testset" not in listed


def test_a_commit_listed_as_numbers_unchanged_does_not_count(tmp_path):
    """docs/numbers-unchanged.txt marks a committed code change whose results were checked
    to be the same; it counts against no section (comments after # are ignored)."""
    second, with_page, later = _repo(tmp_path)
    (tmp_path / "docs" / "numbers-unchanged.txt").write_text(
        f"# commit  how it was checked\n{later}  every scene's steps identical\n")
    rows = {r["name"]: [c[0] for c in r["commits"]] for r in docs_status.status(tmp_path)
            if r["commits"] is not None}
    assert rows["run"] == []
    assert rows["before"] == [with_page, second]


def test_a_commit_listed_for_some_sections_counts_against_the_others(tmp_path):
    """A line `HASH  sections=A,B  how` of docs/numbers-unchanged.txt: the commit does not
    count against sections A and B, and counts against every other."""
    second, with_page, later = _repo(tmp_path)
    (tmp_path / "docs" / "numbers-unchanged.txt").write_text(
        f"{later}  sections=run,after  the runs of run and after take the same steps\n")
    rows = {r["name"]: [c[0] for c in r["commits"]] for r in docs_status.status(tmp_path)
            if r["commits"] is not None}
    assert rows["run"] == []
    assert later not in rows["after"]
    assert rows["before"] == [later, with_page, second]
    assert rows["before erk"] == [later, with_page, second]


def test_a_section_name_stands_for_its_variants(tmp_path):
    """`sections=before` covers "before erk" too (a section name with a space, which a word
    of the file cannot hold), and not a section whose name merely starts with the same
    letters."""
    second, with_page, later = _repo(tmp_path)
    (tmp_path / "docs" / "numbers-unchanged.txt").write_text(
        f"{later}  sections=before,aft  checked\n")
    with pytest.raises(SystemExit, match="section 'aft' is in no page"):
        docs_status.status(tmp_path)
    (tmp_path / "docs" / "numbers-unchanged.txt").write_text(
        f"{later}  sections=before  checked\n")
    rows = {r["name"]: [c[0] for c in r["commits"]] for r in docs_status.status(tmp_path)
            if r["commits"] is not None}
    assert rows["before"] == rows["before erk"] == [with_page, second]
    assert later in rows["after"]


def test_a_section_no_page_has_is_named(tmp_path):
    """A `sections=` word of docs/numbers-unchanged.txt naming a section that no page of
    docs/ has (a typo would keep the commit counting without a word): an error naming the
    file, the line and the section."""
    _, _, later = _repo(tmp_path)
    (tmp_path / "docs" / "numbers-unchanged.txt").write_text(
        f"# commit  how checked\n{later}  sections=run,aftre  checked\n")
    with pytest.raises(SystemExit) as stop:
        docs_status.status(tmp_path)
    assert "numbers-unchanged.txt: line 2: section 'aftre' is in no page of docs/" in \
        str(stop.value)


def test_a_bad_line_in_numbers_unchanged_is_named(tmp_path):
    """A line of docs/numbers-unchanged.txt that names no commit: an error naming the file,
    the line and the word (not git's traceback)."""
    _repo(tmp_path)
    (tmp_path / "docs" / "numbers-unchanged.txt").write_text(
        "# commit  how checked\n\nnot-a-commit  typed by hand\n")
    with pytest.raises(SystemExit) as stop:
        docs_status.status(tmp_path)
    message = str(stop.value)
    assert "numbers-unchanged.txt: line 3: 'not-a-commit' is not a commit" in message


def test_a_section_a_test_keeps_current_is_not_listed(tmp_path):
    """The key reference is written exactly from the program (no run, no date): its test
    checks it, not docs_status."""
    _repo(tmp_path)
    (tmp_path / "docs" / "keys.md").write_text(
        "<!-- keys:begin -->\nWritten by `scripts/keys_reference` from `ropedyn keys`.\n"
        "<!-- keys:end -->\n")
    names = {r["name"] for r in docs_status.status(tmp_path)}
    assert "keys" not in names and "run" in names


def test_a_derived_section_is_as_current_as_its_inputs(tmp_path, monkeypatch):
    """A section made from other sections' data (the choosing guide from the accuracy
    studies) counts the commits that count against any of them, not its own stamp's."""
    second, with_page, later = _repo(tmp_path)
    monkeypatch.setattr(docs_status, "DERIVED", {"run": ("before", "after")})
    rows = {r["name"]: r["commits"] for r in docs_status.status(tmp_path)}
    union = {c[0] for c in rows["before"] + rows["after"]}
    assert [c[0] for c in rows["run"]] == [later, with_page, second] and union == {
        later, with_page, second}
    monkeypatch.setattr(docs_status, "DERIVED", {"run": ("before", "undated")})
    assert {r["name"]: r["commits"] for r in docs_status.status(tmp_path)}["run"] is None


def test_same_code_by_the_rule_of_the_sections(tmp_path):
    """Two builds' versions name the same code for a section when no commit between them
    counts against it (a study keeps its case files by this): docs, a Numbers-unchanged
    commit and one listed for that section do not count; a code change does, in either
    order; a build with uncommitted changes matches only its own text."""
    second, with_page, later = _repo(tmp_path)
    (tmp_path / "docs" / "numbers-unchanged.txt").write_text(f"{later}  sections=run  same\n")
    # the first commit of _repo: its code changes on Jan 2
    first = subprocess.run(["git", "-C", str(tmp_path), "rev-list", "--max-parents=0",
                            "HEAD"], capture_output=True, text=True, check=True).stdout[:7]

    def same(a, b, section="run"):
        return docs_status.same_code(f"0.1.0+g{a}", f"0.1.0+g{b}", section, root=tmp_path)

    assert same(second, second) and same(second, "v1.0-3-g" + second)
    assert not same(first, second) and not same(second, first)
    # Jan 3 (Numbers-unchanged) and Jan 4 (docs) do not count; Jan 5 changes the code
    third = _rev(tmp_path, f"{with_page}~2")
    assert same(second, third) and same(third, second)
    assert not same(second, with_page)
    # Jan 6 is listed for `run` only
    assert same(with_page, later) and not same(with_page, later, section="before")
    assert docs_status.same_code(f"0.1.0+g{later}-dirty.0123abcd",
                                 f"0.1.0+g{later}-dirty.0123abcd", "run", root=tmp_path)
    assert not docs_status.same_code(f"0.1.0+g{later}-dirty.0123abcd", f"0.1.0+g{later}",
                                     "run", root=tmp_path)
    assert not same("fedcba9", later)                     # a commit this clone does not know
    # a commit on another line of history, from with_page, with no code change of its own:
    # it and `later` (whose code change counts not against `run`) follow with_page apart,
    # so nothing says which code either build holds against the other
    subprocess.run(["git", "-C", str(tmp_path), "checkout", "-q", "-b", "side", with_page],
                   check=True)
    side = _commit(tmp_path, "side", {"docs/side.md": "side\n"})
    assert same(with_page, side) and same(side, with_page)      # docs only between
    assert not same(side, later) and not same(later, side)
