"""The mutation list of scripts/mutation_check stays valid as the code moves: every
mutation's snippet occurs exactly once in its file, ids are unique, the declared tests exist
(CTest programs registered in tests/CMakeLists.txt, pytest files present), and the list is
as large as docs/testing.md promises. (The check itself takes minutes and runs on demand.)"""
import re

from conftest import ROOT
from ropedyn.studies.mutation_check import BEGIN, END, MUTATIONS, check_list


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
