"""The build rebuilds what a change reaches. A submodule sees its parent module's private
entities (its constants among them), which are not in the parent's .mod file, the only file
of the parent CMake watches for it: without an explicit dependency on the parent's source, a
changed private constant (say MEBDF's Newton tolerance) left the submodules' objects stale,
and a benchmark measured the old code."""
import pathlib
import re

import pytest

from conftest import ROOT

SUBMODULE = re.compile(r"^\s*submodule\s*\(\s*(\w+)\s*\)", re.IGNORECASE | re.MULTILINE)


def submodules():
    """(submodule source, parent source) for every submodule of the code."""
    pairs = []
    for top in ("src", "solvers"):
        for path in sorted((ROOT / top).rglob("*.f90")):
            m = SUBMODULE.search(path.read_text())
            if m:
                pairs.append((path, path.parent / f"{m.group(1).lower()}.f90"))
    return pairs


def test_every_submodule_object_depends_on_its_parents_source(ropedyn_exe):
    build = pathlib.Path(ropedyn_exe).parent
    rules = "\n".join(p.read_text() for p in build.glob("CMakeFiles/*/build.make"))
    if not rules:
        pytest.fail(f"no Makefile rules under {build}/CMakeFiles (built with another generator?)")
    pairs = submodules()
    assert len(pairs) >= 10, "the scan found too few submodules"
    missing = []
    for source, parent in pairs:
        assert parent.is_file(), f"{source}: no parent source {parent}"
        rel = source.relative_to(ROOT).as_posix()
        line = re.compile(rf"^\S*/{re.escape(rel)}\.o: {re.escape(str(parent))}$", re.MULTILINE)
        if not line.search(rules):
            missing.append(f"{rel} -> {parent.relative_to(ROOT)}")
    assert not missing, "objects not rebuilt when their parent changes: " + ", ".join(missing)
