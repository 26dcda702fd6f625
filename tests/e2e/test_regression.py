"""Regression against reference outputs (tests/reference/*.h5, made by
scripts/update_references): every quantity within its explicit tolerance."""
import pathlib
import shutil

import h5py
import pytest

from ropedyn.compare import compare

REFERENCE = pathlib.Path(__file__).resolve().parents[1] / "reference"
SCENES = sorted(p.stem for p in REFERENCE.glob("*.nml"))


@pytest.mark.parametrize("name", SCENES)
def test_matches_reference(run, tmp_path, name, capsys):
    shutil.copy(REFERENCE / f"{name}.nml", tmp_path)
    result = run("run", f"{name}.nml", "--set", f"output.file={name}.h5")
    assert result.returncode == 0, result.stderr
    failures = compare(REFERENCE / f"{name}.h5", tmp_path / f"{name}.h5")
    assert not failures, capsys.readouterr().out


def test_compare_detects_a_change(tmp_path):
    """The compare tool fails when a result moves by more than its tolerance."""
    name = SCENES[0]
    changed = tmp_path / "changed.h5"
    shutil.copy(REFERENCE / f"{name}.h5", changed)
    with h5py.File(changed, "r+") as f:
        q = f["state/q"]
        q[-1, 3, 0] = q[-1, 3, 0] + 1e-5
    assert compare(REFERENCE / f"{name}.h5", changed) == ["state/q"]


def test_tolerances_catch_a_physics_change(run, tmp_path):
    """A 1 % change of Young's modulus moves the results beyond the tolerances."""
    shutil.copy(REFERENCE / "paper_n10.nml", tmp_path)
    result = run("run", "paper_n10.nml", "--set", "output.file=stiffer.h5",
                 "--set", "rope.young_modulus=35.35e6")
    assert result.returncode == 0, result.stderr
    failures = compare(REFERENCE / "paper_n10.h5", tmp_path / "stiffer.h5")
    assert "state/q" in failures and "rope/points" in failures, failures
