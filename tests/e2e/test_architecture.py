"""The layer rule holds in the code and docs/development/architecture.md is its current picture
(scripts/architecture --check: every `use` goes to the same or a lower layer, solvers and
models never use each other; the generated tables match the code)."""
import os
import subprocess
import sys

from conftest import ROOT
from ropedyn_tools import architecture as arch


def test_layers_and_architecture_page_current():
    result = subprocess.run([sys.executable, "-m", "ropedyn_tools.architecture", "--check"],
                            cwd=ROOT, capture_output=True, text=True,
                            env=dict(os.environ, PYTHONPATH=str(ROOT / "tools")))
    assert result.returncode == 0, result.stderr


def test_check_catches_an_upward_use():
    units = arch.scan()
    assert not arch.violations(units)
    # a model that used the scene (io) would break the rule
    units["ropedyn_rfem"]["uses"].add("ropedyn_scene")
    assert any("ropedyn_rfem" in v for v in arch.violations(units))
    units["ropedyn_rfem"]["uses"].discard("ropedyn_scene")
    units["ropedyn_mebdf"]["uses"].add("ropedyn_rope_model")   # solvers -> models
    assert any("ropedyn_mebdf" in v for v in arch.violations(units))
    units["ropedyn_mebdf"]["uses"].discard("ropedyn_rope_model")
    # the library (src/lib) and the executable (src/app) are side by side: neither uses
    # the other, and nothing below uses the library
    assert units["ropedyn_capi"]["layer"] == "lib"
    units["ropedyn_cmd_run"]["uses"].add("ropedyn_lib")   # app -> lib
    assert any("ropedyn_cmd_run" in v for v in arch.violations(units))
    units["ropedyn_cmd_run"]["uses"].discard("ropedyn_lib")
    units["ropedyn_run"]["uses"].add("ropedyn_lib")       # studies -> lib
    assert any("ropedyn_run (studies) uses ropedyn_lib (lib)" in v
               for v in arch.violations(units))


def _tree(root, files):
    for rel, text in files.items():
        (root / rel).parent.mkdir(parents=True, exist_ok=True)
        (root / rel).write_text(text)


def test_scan_reads_the_uses_from_the_files(tmp_path):
    """From the source text: a wrong-way `use` in a procedure after an interface of
    separate module procedures (`module pure function`: no unit) is the module's, and is
    reported by file and layers."""
    _tree(tmp_path, {
        "src/io/ropedyn_scene.f90": "module ropedyn_scene\nend module ropedyn_scene\n",
        "src/models/ropedyn_rope.f90": (
            "module ropedyn_rope\n"
            "    interface\n"
            "        module pure function length(x) result(l)\n"
            "        end function length\n"
            "        module subroutine step(x)\n"
            "        end subroutine step\n"
            "    end interface\n"
            "contains\n"
            "    subroutine read_it()\n"
            "        use ropedyn_scene, only: x  ! io from models: not allowed\n"
            "    end subroutine read_it\n"
            "end module ropedyn_rope\n"),
    })
    units = arch.scan(tmp_path)
    assert set(units) == {"ropedyn_scene", "ropedyn_rope"}
    assert units["ropedyn_rope"]["uses"] == {"ropedyn_scene"}
    assert arch.violations(units) == [
        "src/models/ropedyn_rope.f90: ropedyn_rope (models) uses ropedyn_scene (io)"]


def test_each_test_program_links_the_lowest_layer_it_needs(tmp_path):
    """tests/CMakeLists.txt: a test links the lowest layer whose library holds what it uses
    (solvers and models together: io; through a test helper: what the helper uses;
    SUNDIALS's modules: solvers). A layer too high is reported (one too low does not
    build), and so is SCENE_RUNS without ropedyn_test_run or the other way round."""
    module = "module {0}\n{1}end module {0}\n"
    program = "program {0}\n{1}end program {0}\n"
    _tree(tmp_path, {
        "src/core/ropedyn_kinds.f90": module.format("ropedyn_kinds", ""),
        "solvers/ropedyn_integrator.f90": module.format("ropedyn_integrator",
                                                        "    use ropedyn_kinds\n"),
        "src/models/ropedyn_rope.f90": module.format("ropedyn_rope", ""),
        "src/studies/ropedyn_simulation.f90": module.format("ropedyn_simulation", ""),
        "tests/unit/ropedyn_test_run.f90": module.format("ropedyn_test_run",
                                                         "    use ropedyn_simulation\n"),
        "tests/unit/test_a.f90": program.format(
            "test_a", "    use, intrinsic :: iso_fortran_env\n    use ropedyn_kinds\n"),
        "tests/unit/test_b.f90": program.format(
            "test_b", "    use ropedyn_integrator, only: x\n    use ropedyn_rope\n"),
        "tests/unit/test_c.f90": program.format("test_c", "    use ropedyn_test_run\n"),
        "tests/unit/test_d.f90": program.format("test_d", "    use fsundials_context_mod\n"),
        "tests/bench/bench_x.f90": program.format("bench_x", "    use ropedyn_rope\n"),
    })
    cmake = tmp_path / "tests" / "CMakeLists.txt"

    def report(a, b, c, d, bench):
        cmake.write_text(f"function(ropedyn_unit_test name layer)\nendfunction()\n"
                         f"ropedyn_unit_test(test_a {a})\nropedyn_unit_test(test_b {b})\n"
                         f"ropedyn_unit_test(test_c {c})\nropedyn_unit_test(test_d {d})\n"
                         f"add_executable(bench_x bench/bench_x.f90)\n"
                         f"target_link_libraries(bench_x PRIVATE ropedyn_{bench})\n")
        return arch.link_violations(arch.scan(tmp_path), tmp_path)

    assert report("core", "io", "studies SCENE_RUNS", "solvers", "models") == []
    where = "tests/CMakeLists.txt: "
    assert report("app", "solvers", "studies SCENE_RUNS", "io", "app") == [
        where + "bench_x links ropedyn_app, but what it uses is in ropedyn_models",
        where + "test_a links ropedyn_app, but what it uses is in ropedyn_core",
        where + "test_b links ropedyn_solvers, but what it uses is in ropedyn_io",
        where + "test_d links ropedyn_io, but what it uses is in ropedyn_solvers"]
    assert report("core SCENE_RUNS", "io", "studies", "solvers", "models") == [
        where + "test_a: SCENE_RUNS without a use of ropedyn_test_run",
        where + "test_c: SCENE_RUNS missing (it uses ropedyn_test_run)"]


def test_check_reports_a_routine_longer_than_a_screen(tmp_path):
    """A routine longer than ROUTINE_LIMIT lines (its internal procedures counted in) is
    reported by file and name, a model's kernel too (they were kept whole until they were
    split without a change of bits or speed); one at the limit is not; the tree itself has
    none."""
    assert arch.long_routines() == []
    limit = arch.ROUTINE_LIMIT

    def routine(kind, name, lines, inner=""):
        body = "".join(f"        x = x + {i}\n" for i in range(lines - 3 - inner.count("\n")))
        head = f"    {kind} {name}(x)\n        real, intent(inout) :: x\n"
        return head + body + inner + f"    end {kind.split()[-1]} {name}\n"

    inner = "    contains\n        subroutine helper()\n        end subroutine helper\n"
    _tree(tmp_path, {
        "src/core/ropedyn_long.f90": (
            "module ropedyn_long\ncontains\n"
            + routine("subroutine", "at_limit", limit)
            + routine("pure real function", "too_long", limit + 1, inner)
            + "end module ropedyn_long\n"),
        "src/models/rfem/ropedyn_rfem_kernels.f90": (
            "submodule (ropedyn_rfem) ropedyn_rfem_kernels\ncontains\n"
            + routine("module procedure", "forces", limit + 20).replace("(x)", "")
            + "end submodule ropedyn_rfem_kernels\n"),
    })
    found = arch.long_routines(tmp_path)
    assert found == [f"src/core/ropedyn_long.f90: too_long has {limit + 1} lines "
                     f"(at most {limit}: split it where its ideas split)",
                     f"src/models/rfem/ropedyn_rfem_kernels.f90: forces has {limit + 20} "
                     f"lines (at most {limit}: split it where its ideas split)"], found
