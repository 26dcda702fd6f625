"""Builds beyond Debian-as-root: scripts/setup without root installs nothing and lists what
is missing with the package that provides it (Debian, RHEL, Spack, module); a copy of the
clone (with its build folder) configures and builds afresh, with SUNDIALS and HDF5 found
from prefixes given; the venv names the package folder relative to itself, so that a
copied venv imports its own clone's package; SUNDIALS is found under a prefix elsewhere."""
import os
import pathlib
import shutil
import subprocess

import pytest

from conftest import ROOT

NOBODY = 65534


@pytest.mark.skipif(os.geteuid() != 0 or shutil.which("setpriv") is None,
                    reason="needs root and setpriv to run scripts/setup as another user")
def test_setup_without_root_lists_what_is_missing(tmp_path):
    env = dict(os.environ, FC="no-such-fortran-compiler", HOME=str(tmp_path))
    result = subprocess.run(["setpriv", f"--reuid={NOBODY}", f"--regid={NOBODY}",
                             "--clear-groups", str(ROOT / "scripts" / "setup")],
                            cwd=tmp_path, env=env, capture_output=True, text=True)
    assert result.returncode == 1, result.stderr
    err = result.stderr
    assert "nothing installed: not root" in err
    assert "  gfortran\n" in err
    assert "Debian: apt-get install gfortran" in err
    assert "RHEL:   dnf install gcc-gfortran" in err
    assert "Spack:  spack install gcc" in err
    assert "module: module load gcc" in err
    assert "SUNDIALS_DIR=PREFIX" in err
    # only what is missing is listed
    needs = [line.strip() for line in err.splitlines()
             if line.startswith("  ") and not line.startswith("   ") and ":" not in line]
    assert needs == ["gfortran"]


def test_copied_clone_configures_anew_with_prefixes(tmp_path):
    copy = tmp_path / "clone"
    files = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True,
                           check=True).stdout.decode().split("\0")
    for name in filter(None, files):
        target = copy / name
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(ROOT / name, target)
    # the original's build folder comes along
    stale = copy / "build" / "debug"
    stale.mkdir(parents=True)
    shutil.copy2(ROOT / "build" / "debug" / "CMakeCache.txt", stale / "CMakeCache.txt")
    env = dict(os.environ, SUNDIALS_DIR="/usr", HDF5_ROOT="/usr")
    result = subprocess.run([str(copy / "scripts" / "build"), "Debug", "ropedyn_core"],
                            cwd=copy, env=env, capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    assert "configuring it anew" in result.stderr
    cache = (stale / "CMakeCache.txt").read_text()
    assert f"CMAKE_HOME_DIRECTORY:INTERNAL={copy}" in cache
    assert str(ROOT) not in cache
    assert (stale / "libropedyn_core.a").is_file()


def test_venv_names_the_package_relative_to_itself():
    pth = list((ROOT / ".venv").glob("lib/python*/site-packages/ropedyn-source.pth"))
    assert len(pth) == 1
    line = pth[0].read_text().strip()
    assert not os.path.isabs(line)
    assert (pth[0].parent / line).resolve() == (ROOT / "python").resolve()


def test_sundials_from_a_prefix_elsewhere(tmp_path):
    """SUNDIALS installed under another prefix (here the system's files linked into one,
    in Debian's layout) is found from SUNDIALS_DIR=PREFIX: its config, its libraries and
    its Fortran modules come from there, not from /usr; the solvers build against it."""
    system = pathlib.Path("/usr/lib/x86_64-linux-gnu")
    if not (system / "cmake" / "sundials" / "SUNDIALSConfig.cmake").is_file():
        pytest.skip("needs Debian's SUNDIALS (libsundials-dev) to make the prefix from")
    prefix = tmp_path / "sundials"
    lib = prefix / "lib" / "x86_64-linux-gnu"
    (lib / "cmake").mkdir(parents=True)
    shutil.copytree(system / "cmake" / "sundials", lib / "cmake" / "sundials")
    for so in system.glob("libsundials_*"):
        (lib / so.name).symlink_to(so)
    (prefix / "include").symlink_to("/usr/include")
    (prefix / "fortran").symlink_to("/usr/include/sundials/fortran")
    build = tmp_path / "build"
    result = subprocess.run(["cmake", "-S", str(ROOT), "-B", str(build),
                             "-DCMAKE_BUILD_TYPE=Debug", f"-DSUNDIALS_DIR={prefix}",
                             "-DHDF5_ROOT=/usr"], capture_output=True, text=True)
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    cache = (build / "CMakeCache.txt").read_text()
    assert f"SUNDIALS_DIR:PATH={lib / 'cmake' / 'sundials'}" in cache
    assert f"SUNDIALS_FORTRAN_MODULE_DIR:PATH={prefix / 'fortran'}" in cache
    result = subprocess.run(["cmake", "--build", str(build), "-j2", "--target",
                             "ropedyn_solvers"], capture_output=True, text=True)
    assert result.returncode == 0, result.stdout[-3000:]


def test_setup_never_clears_a_linked_venv(tmp_path):
    """A .venv that is a link (to another clone's venv, say) is replaced by the clone's own
    venv; the link's target keeps its files. (Made through the link, the venv's --clear
    emptied the other clone's venv.)"""
    clone = tmp_path / "clone"
    (clone / "scripts").mkdir(parents=True)
    (clone / "python").mkdir()
    for name in ("setup", "requirements.txt"):
        shutil.copy2(ROOT / "scripts" / name, clone / "scripts" / name)
    other = tmp_path / "other_venv"
    other.mkdir()
    (other / "keep").write_text("the other clone's")
    (clone / ".venv").symlink_to(other)
    result = subprocess.run([str(clone / "scripts" / "setup")], capture_output=True, text=True)
    assert (other / "keep").exists(), "the linked venv was cleared"
    assert result.returncode == 0, result.stderr
    assert not (clone / ".venv").is_symlink()
    assert (clone / ".venv" / "bin" / "python").exists()
