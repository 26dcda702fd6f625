"""scripts/mebdf_stability.py (tools/ropedyn_tools/studies/mebdf_stability.py): the BDF
angles against their published values, and the script from a Python without numpy."""
import pathlib
import subprocess

from ropedyn_tools.studies import mebdf_stability as ms

ROOT = pathlib.Path(__file__).resolve().parents[2]


def test_bdf_angles_are_the_published_ones():
    """A(alpha) of BDF3 .. 5: 86.03, 73.35 and 51.84 degrees, the values the texts on BDF
    give (docs/theory/cvode.md). Sampling each ray at 400 radii alone gave 73.36 and 51.85."""
    angles = [round(ms.a_alpha(ms.bdf_matrix, ms.coefficients(p)), 2) for p in (3, 4, 5)]
    assert angles == [86.03, 73.35, 51.84]


def test_the_mebdf_orders_up_to_4_are_a_stable():
    table = ms.rows(3)
    assert [round(table[p][0], 2) for p in (2, 3, 4)] == [90.0, 90.0, 90.0]
    assert table[4][1] == "1.000" and table[4][3].startswith("1.191 (h ω < 4.71")


def test_runs_from_a_python_without_numpy():
    """The shebang's python3 has no numpy: the script runs itself with the venv."""
    result = subprocess.run(["/usr/bin/python3", str(ROOT / "scripts" / "mebdf_stability.py"),
                             "--kmax", "1", "--no-write"], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    assert "| 2 | 90.00 | 1.000 | 90.00 | 1.000 |" in result.stdout
