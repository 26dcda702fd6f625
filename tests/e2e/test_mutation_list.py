"""The mutation list of scripts/mutation_check stays valid as the code moves: every
mutation's snippet occurs exactly once in its file, ids are unique, the declared tests exist
(CTest programs registered in tests/CMakeLists.txt, pytest files present), and the list is
as large as docs/development/testing.md promises. A snippet is found as Fortran (blanks, comments and
continuations aside), so reformatting keeps it and a change of the code loses it. (The
check itself takes minutes and runs on demand.)"""
import os
import re
import subprocess
import time

from conftest import ROOT
from ropedyn_tools.mutation_check import (BEGIN, END, MUTATIONS, Mutation, apply,
                                          check_list, find_anchor, sync_tree)


def test_every_snippet_occurs_once_in_its_file():
    assert check_list(ROOT) == []


SOURCE = """\
    subroutine f(a, b, c, x)
        x = a*b + c   ! the sum
        kappa = 2.0_wp
        write (*, '(a)') 'x = a*b + c! not code'
    end subroutine f
"""


def test_a_snippet_survives_reflowing_and_is_replaced_in_place(tmp_path):
    """The same statement with other spaces, split over continuation lines (with and without
    the leading &, a comment after the &), is still found once; the mutation replaces the
    matched text and leaves the rest of the file as it was."""
    snippet, replacement = "x = a*b + c", "x = a*b - c"
    reflowed = [
        SOURCE.replace("x = a*b + c   !", "x=a * b+c !"),
        SOURCE.replace("x = a*b + c   !", "x = a*b &\n            + c   !"),
        SOURCE.replace("x = a*b + c   !", "x = a* &  ! first factor\n          & b + &\n\n"
                                         "            c   !"),
    ]
    for text in [SOURCE] + reflowed:
        spans = find_anchor(text, snippet)
        assert len(spans) == 1, text
        (start, end), = spans
        assert text[start] == "x" and text[end - 1] == "c", text[start:end]
        (tmp_path / "f.f90").write_text(text)
        m = Mutation("t", "f.f90", snippet, replacement, "sign")
        assert check_list(tmp_path, [m]) == []
        assert apply(tmp_path, m) == text
        mutated = (tmp_path / "f.f90").read_text()
        assert mutated == text[:start] + replacement + text[end:]
        assert find_anchor(mutated, snippet) == [] and len(find_anchor(mutated, replacement)) == 1


def test_a_changed_statement_is_not_found():
    """A real change of the code loses the anchor: another operator, another name, a
    statement split in two (a line end without &), text only in a comment or a string, or a
    snippet that starts or ends inside a longer name."""
    assert find_anchor(SOURCE.replace("a*b + c", "a*b - c"), "x = a*b + c") == []
    assert find_anchor(SOURCE.replace("a*b + c", "a*d + c"), "x = a*b + c") == []
    assert find_anchor(SOURCE.replace("x = a*b + c", "x = a*b\n        x = x + c"),
                       "x = a*b + c") == []
    assert find_anchor(SOURCE, "the sum") == []
    assert find_anchor(SOURCE, "not code") == []
    assert find_anchor(SOURCE, "kappa = 2.0") == []         # 2.0 is the start of 2.0_wp
    assert find_anchor(SOURCE, "kapp") == [] and len(find_anchor(SOURCE, "kappa")) == 1
    assert find_anchor(SOURCE, "appa = 2.0_wp") == []       # the end of kappa
    twice = SOURCE.replace("kappa = 2.0_wp", "x = a*b + c")
    assert len(find_anchor(twice, "x = a * b + c")) == 2


def _reflow(text):
    """The file as a formatter might leave it: no blanks around = and after commas, every
    continued statement joined into one line, and every other line that holds a comma,
    no comment and no string split after its first comma."""
    text = re.sub(r"&[ \t]*(![^\n]*)?\n[ \t]*&?", " ", text)
    lines = []
    for i, line in enumerate(text.split("\n")):
        line = line.replace(" = ", "=").replace(", ", ",")
        if i % 2 and "," in line and not re.search("[!'\"]", line):
            head, tail = line.split(",", 1)
            line = head + ", &\n        & " + tail
        lines.append(line)
    return "\n".join(lines)


def test_the_whole_list_survives_reflowing_its_files(tmp_path):
    """Every mutation's file reformatted: each snippet still found once; and with the
    mutation applied to the reformatted file, its snippet is gone."""
    files = {m.file for m in MUTATIONS}
    for rel in files:
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / rel).write_text(_reflow((ROOT / rel).read_text()))
    for m in MUTATIONS:
        for test in m.pytest:
            (tmp_path / test.split("::")[0]).parent.mkdir(parents=True, exist_ok=True)
            (tmp_path / test.split("::")[0]).touch()
    assert sum((tmp_path / f).read_text() != (ROOT / f).read_text() for f in files) == len(files)
    assert check_list(tmp_path) == []
    for m in MUTATIONS:
        original = apply(tmp_path, m)
        problems = check_list(tmp_path, [m])
        assert problems == [f"{m.id}: snippet found 0 times in {m.file}"], problems
        (tmp_path / m.file).write_text(original)


def test_declared_ctest_programs_exist():
    registered = set(re.findall(r"^ropedyn_unit_test\((\w+)\s",
                                (ROOT / "tests" / "CMakeLists.txt").read_text(), re.M))
    missing = {t for m in MUTATIONS for t in m.ctest} - registered
    assert not missing, missing


def test_list_covers_every_area_and_the_page_names_it():
    assert len(MUTATIONS) >= 25
    areas = {m.file.split("/")[1] if m.file.startswith("src/") else m.file.split("/")[0]
             for m in MUTATIONS}
    assert {"models", "io", "studies", "solvers"} <= areas, areas
    page = (ROOT / "docs" / "development" / "testing.md").read_text()
    assert "scripts/mutation_check" in page and BEGIN in page and END in page


def test_a_file_left_mutated_is_restored_newer_than_its_build(tmp_path):
    """A run killed before it restored its mutation leaves the scratch file changed and
    newer than the build made from it. The next sync must bring the original back with a
    time after that build, or make keeps the mutated objects (the baseline then failed)."""
    root, tree = tmp_path / "root", tmp_path / "tree"
    (root / "src").mkdir(parents=True)
    (root / ".venv").mkdir()               # sync_tree links the tree's .venv to it
    source = root / "src" / "a.f90"
    source.write_text("x = 1\n")
    old = time.time() - 3600
    os.utime(source, (old, old))
    subprocess.run(["git", "init", "-q"], cwd=root, check=True)
    tree.mkdir()
    sync_tree(root, tree)
    copy = tree / "src" / "a.f90"
    assert copy.read_text() == "x = 1\n"
    copy.write_text("x = 2\n")            # the mutation, then its build
    built = time.time()
    sync_tree(root, tree)
    assert copy.read_text() == "x = 1\n"
    assert copy.stat().st_mtime >= built - 1.0, (copy.stat().st_mtime, built)
