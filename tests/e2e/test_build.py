"""The build rebuilds what a change reaches. A submodule sees its parent module's private
entities (its constants among them), which are not in the parent's .mod file, the only file
of the parent CMake watches for it: without an explicit dependency on the parent's source, a
changed private constant (say MEBDF's Newton tolerance) left the submodules' objects stale,
and a benchmark measured the old code."""
import pathlib
import re
import subprocess

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


# ------------------------------------------------------------------------------ version
# The version every output file records (/@version) is found at every build
# (cmake/version.cmake, run by the target ropedyn_version_file), not once when the build
# folder was configured: configured at one commit and built at the next, the files said the
# first, and an edited tree built with `cmake --build` said it was clean.

VERSION_SCRIPT = ROOT / "cmake" / "version.cmake"
TEMPLATE = ROOT / "src" / "core" / "ropedyn_version.f90.in"


def write_version(source, out, git="git"):
    """Run cmake/version.cmake on the tree `source` into `out`; the version it wrote."""
    subprocess.run(["cmake", f"-DGIT={git}", f"-DSOURCE_DIR={source}",
                    "-DPROJECT_VERSION=9.8.7", f"-DIN={TEMPLATE}", f"-DOUT={out}",
                    "-P", str(VERSION_SCRIPT)], check=True, capture_output=True)
    found = re.search(r'version_string\s*=\s*"([^"]*)"', out.read_text())
    assert found, out.read_text()
    return found.group(1)


def git(tree, *args):
    return subprocess.run(["git", "-c", "user.name=t", "-c", "user.email=t@t", *args],
                          cwd=tree, check=True, capture_output=True, text=True).stdout.strip()


def test_version_follows_commits_and_edits_of_the_tree(tmp_path):
    tree = tmp_path / "tree"
    tree.mkdir()
    git(tree, "init", "-q")
    (tree / "a.txt").write_text("a\n")
    git(tree, "add", "a.txt")
    git(tree, "commit", "-qm", "first")
    out = tmp_path / "ropedyn_version.f90"
    first = git(tree, "rev-parse", "--short", "HEAD")
    assert write_version(tree, out) == f"9.8.7+g{first}"
    stamp = out.stat().st_mtime_ns
    assert write_version(tree, out) == f"9.8.7+g{first}"
    assert out.stat().st_mtime_ns == stamp, "an unchanged version rewrote the file"
    # an edit: "-dirty" and a digest of the edits to the code, the same for the same edits
    (tree / "src").mkdir()
    (tree / "src" / "b.f90").write_text("b\n")
    git(tree, "add", "src/b.f90")
    git(tree, "commit", "-qm", "code")
    first = git(tree, "rev-parse", "--short", "HEAD")
    (tree / "src" / "b.f90").write_text("c\n")
    edited = write_version(tree, out)
    assert re.fullmatch(rf"9\.8\.7\+g{first}-dirty\.[0-9a-f]{{8}}", edited), edited
    assert write_version(tree, out) == edited
    (tree / "src" / "b.f90").write_text("d\n")
    other = write_version(tree, out)
    assert other != edited and other.startswith(f"9.8.7+g{first}-dirty."), other
    (tree / "src" / "b.f90").write_text("c\n")
    assert write_version(tree, out) == edited
    # a new source not in git yet counts too, with its contents
    (tree / "src" / "new.f90").write_text("n\n")
    added = write_version(tree, out)
    assert added.startswith(f"9.8.7+g{first}-dirty.") and added not in (edited, other)
    (tree / "src" / "new.f90").write_text("m\n")
    assert write_version(tree, out) not in (added, edited, other)
    (tree / "src" / "new.f90").unlink()
    # an edit outside what the build is made of: the commit's version
    (tree / "src" / "b.f90").write_text("b\n")
    (tree / "a.txt").write_text("b\n")
    assert write_version(tree, out) == f"9.8.7+g{first}"
    (tree / "src" / "b.f90").write_text("c\n")
    git(tree, "commit", "-qam", "second")
    assert write_version(tree, out) == f"9.8.7+g{git(tree, 'rev-parse', '--short', 'HEAD')}"
    # no git, or no checkout: the project's version alone
    assert write_version(tree, out, git="") == "9.8.7"
    bare = tmp_path / "bare"
    bare.mkdir()
    assert write_version(bare, out) == "9.8.7"


def test_every_build_writes_the_version(ropedyn_exe):
    build = pathlib.Path(ropedyn_exe).parent
    rules = build / "CMakeFiles" / "ropedyn_version_file.dir" / "build.make"
    if not rules.is_file():
        pytest.fail(f"no rules of the target ropedyn_version_file in {build}")
    assert str(VERSION_SCRIPT) in rules.read_text()
    depends = build / "CMakeFiles" / "Makefile2"
    assert re.search(r"^CMakeFiles/ropedyn_core\.dir/all: CMakeFiles/ropedyn_version_file\.dir/all$",
                     depends.read_text(), re.MULTILINE), "the core does not wait for the version"
