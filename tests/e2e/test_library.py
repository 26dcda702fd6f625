"""The library as a C user sees it (include/ropedyn.h, libropedyn): it exports the header's
functions and nothing else, and an installed copy is found by find_package(ropedyn) from C,
C++ and Fortran (tests/lib/consumer), all three getting the same numbers."""
import re
import shutil
import subprocess

import pytest

from conftest import ROOT

HEADER = ROOT / "include" / "ropedyn.h"
MAP = ROOT / "src" / "lib" / "ropedyn.map"


def header_functions():
    text = re.sub(r"/\*.*?\*/", "", HEADER.read_text(), flags=re.S)
    return set(re.findall(r"\b(ropedyn_\w+)\s*\(", text))


def test_header_map_and_exports_agree(ropedyn_library):
    """The version script lists exactly the header's functions, and the library exports
    exactly those (the layers' Fortran and C symbols stay inside)."""
    functions = header_functions()
    assert len(functions) >= 20
    listed = set(re.findall(r"^\s*(ropedyn_\w+);", MAP.read_text(), re.M))
    assert listed == functions
    nm = subprocess.run(["nm", "-D", "--defined-only", str(ropedyn_library)],
                        capture_output=True, text=True, check=True).stdout
    exported = {line.split()[-1] for line in nm.splitlines()
                if line.split()[-2:-1] == ["T"]}
    assert exported == functions


def test_every_function_goes_through_the_lock():
    """The header's functions are defined by the lock's wrappers (src/lib/ropedyn_serial.c,
    docs/development/internals.md "The library's lock"), each calling the Fortran function
    bound as ropedyn_f_NAME: no Fortran function binds a header name itself (it would be
    exported without the lock), and every wrapper but ropedyn_version takes the lock."""
    capi = (ROOT / "src" / "lib" / "ropedyn_capi.f90").read_text()
    bound = set(re.findall(r"bind\(C, name='(\w+)'\)", capi))
    functions = header_functions()
    assert bound == {"ropedyn_f_" + f[len("ropedyn_"):] for f in functions}
    serial = (ROOT / "src" / "lib" / "ropedyn_serial.c").read_text()
    for f in functions:
        body = re.search(rf"^[^\n]*\b{f}\([^;{{]*\)\s*\{{(.*?)^\}}", serial, re.M | re.S)
        assert body, f"{f}: no wrapper in ropedyn_serial.c"
        call = "ropedyn_f_" + f[len("ropedyn_"):] + "("
        assert call in body[1], f
        locked = "pthread_mutex_lock(&lock);" in body[1] and \
            "pthread_mutex_unlock(&lock);" in body[1]
        assert locked == (f != "ropedyn_version"), f


@pytest.mark.skipif(shutil.which("g++") is None, reason="no C++ compiler (g++)")
def test_installed_library_found_from_c_cxx_fortran(ropedyn_library, tmp_path):
    build = ropedyn_library.parent
    prefix = tmp_path / "prefix"
    subprocess.run(["cmake", "--install", str(build), "--prefix", str(prefix)],
                   capture_output=True, text=True, check=True)
    assert (prefix / "include" / "ropedyn.h").is_file()
    assert (prefix / "lib" / "cmake" / "ropedyn" / "ropedynConfig.cmake").is_file()
    consumer = tmp_path / "consumer"
    configure = subprocess.run(["cmake", "-S", str(ROOT / "tests" / "lib" / "consumer"), "-B",
                                str(consumer), f"-DCMAKE_PREFIX_PATH={prefix}"],
                               capture_output=True, text=True)
    assert configure.returncode == 0, configure.stdout + configure.stderr
    built = subprocess.run(["cmake", "--build", str(consumer)], capture_output=True, text=True)
    assert built.returncode == 0, built.stdout + built.stderr
    forces = {}
    for language in ("c", "cxx", "fortran"):
        out = subprocess.run([str(consumer / f"consumer_{language}"),
                              str(ROOT / "input" / "paper.nml")],
                             capture_output=True, text=True, check=True).stdout.split()
        forces[language] = tuple(float(v) for v in out[1:])
    assert forces["c"] == forces["cxx"] == forces["fortran"]
    assert forces["c"][0] < 0   # the top pulls the rope up (x down)
