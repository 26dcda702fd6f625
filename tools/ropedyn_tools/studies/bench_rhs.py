"""tests/bench/bench_rhs built from an earlier git revision, for the studies that time the
model kernels before and after a change (bench_effects, bench_kernels)."""
import os
import shutil
import subprocess

from ropedyn_tools.repo import ROOT


def build_bench_rhs(rev, workdir):
    """Build bench_rhs from git revision `rev` (git archive: the working tree is untouched)
    with this tree's bench_rhs.f90, in the folder `workdir`; the path of the executable.
    A revision from before bench_rhs existed gets its CMake target added, linked to the
    library of that revision (ropedyn_lib, or ropedyn_app once the layers had landed)."""
    src = workdir / "src"
    src.mkdir()
    archive = subprocess.run(["git", "-C", str(ROOT), "archive", rev], capture_output=True,
                             check=True)
    subprocess.run(["tar", "-x", "-C", str(src)], input=archive.stdout, check=True)
    (src / "tests" / "bench").mkdir(exist_ok=True)
    shutil.copy(ROOT / "tests" / "bench" / "bench_rhs.f90", src / "tests" / "bench")
    tests_cmake = src / "tests" / "CMakeLists.txt"
    if "bench_rhs" not in tests_cmake.read_text():
        lib = "ropedyn_app" if "ropedyn_app" in (src / "CMakeLists.txt").read_text() \
            else "ropedyn_lib"
        with open(tests_cmake, "a") as f:
            f.write("\nadd_executable(bench_rhs bench/bench_rhs.f90)\n"
                    "ropedyn_fortran_target(bench_rhs)\n"
                    f"target_link_libraries(bench_rhs PRIVATE {lib})\n")
    build_dir = workdir / "build"
    log = workdir / "build.log"
    with open(log, "w") as f:
        ok = subprocess.run(["cmake", "-S", str(src), "-B", str(build_dir),
                             "-DCMAKE_BUILD_TYPE=Release"], stdout=f, stderr=f).returncode == 0
        ok = ok and subprocess.run(["cmake", "--build", str(build_dir), "--target",
                                    "bench_rhs", "-j", str(os.cpu_count())], stdout=f,
                                   stderr=f).returncode == 0
    if not ok:
        raise SystemExit(f"baseline build of {rev} failed; log: {log.read_text()[-3000:]}")
    return build_dir / "tests" / "bench_rhs"
