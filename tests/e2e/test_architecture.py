"""The layer rule holds in the code and docs/architecture.md is its current picture
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
