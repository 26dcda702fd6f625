"""The mutation list of scripts/mutation_check stays valid as the code moves: every
mutation's snippet occurs exactly once in its file, ids are unique, the declared tests exist
(CTest programs registered in tests/CMakeLists.txt, pytest files present), and the list is
as large as docs/testing.md promises. (The check itself takes minutes and runs on demand.)"""
import os
import re
import subprocess
import time

from conftest import ROOT
from ropedyn_tools.mutation_check import BEGIN, END, MUTATIONS, check_list, sync_tree


def test_every_snippet_occurs_once_in_its_file():
    assert check_list(ROOT) == []


def test_declared_ctest_programs_exist():
    registered = set(re.findall(r"ropedyn_unit_test\((\w+)\)",
                                (ROOT / "tests" / "CMakeLists.txt").read_text()))
    missing = {t for m in MUTATIONS for t in m.ctest} - registered
    assert not missing, missing


def test_list_covers_every_area_and_the_page_names_it():
    assert len(MUTATIONS) >= 25
    areas = {m.file.split("/")[1] if m.file.startswith("src/") else m.file.split("/")[0]
             for m in MUTATIONS}
    assert {"models", "io", "studies", "solvers"} <= areas, areas
    page = (ROOT / "docs" / "testing.md").read_text()
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
