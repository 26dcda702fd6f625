"""scripts/symplectic_factors (tools/ropedyn_tools/studies/symplectic_factors.py): the
variant builds change RESONANT_SAFETY and nothing else, the windows and rows say what the
section's columns say, and every case runs (its scene and settings are valid)."""
import shutil

import numpy as np
import pytest

from ropedyn import io
from ropedyn_tools.repo import ROOT
from ropedyn_tools.studies import symplectic_factors as sf


def test_a_variant_changes_the_factor_and_nothing_else(tmp_path):
    (tmp_path / sf.SOURCE).parent.mkdir(parents=True)
    shutil.copy(ROOT / sf.SOURCE, tmp_path / sf.SOURCE)
    before = (tmp_path / sf.SOURCE).read_text()
    assert sf.code_factor(tmp_path) == sf.code_factor() > 0
    sf.with_factor(0.4)(tmp_path)
    after = (tmp_path / sf.SOURCE).read_text()
    assert sf.code_factor(tmp_path) == 0.4
    changed = [(a, b) for a, b in zip(before.splitlines(), after.splitlines()) if a != b]
    assert len(changed) == 1 and "RESONANT_SAFETY" in changed[0][1]
    (tmp_path / sf.SOURCE).write_text("module nothing\nend module nothing\n")
    with pytest.raises(SystemExit):
        sf.with_factor(0.4)(tmp_path)


def fake(t_end, slope, steps=100):
    t = np.arange(0.0, t_end + 1e-9, 0.1)
    return {"ok": True, "t": t, "drift": slope * t * np.cos(t), "elastic": 0.01 + 1e-4 * t,
            "steps": steps}


def test_windows_and_row():
    """Three windows of 100 s: the largest |B - E0| grows with a drift's slope, the means and
    the elastic energy per window; the row gives ranges over the starts and the steps over
    the code factor's."""
    r = fake(300.0, 1e-6)
    w = sf.windows(r)
    assert len(w) == 3
    assert w[0][0] < w[1][0] < w[2][0] <= 300e-6
    assert w[2][0] > 290e-6
    assert w[0][2] == pytest.approx(0.01 + 1e-4 * 50, rel=1e-3)
    row = sf.row("undamped", 20, 0.4, [fake(300.0, 1e-6, 90), fake(300.0, 2e-6, 110)], 125)
    cells = [c.strip() for c in row.split("|")[1:-1]]
    assert cells[:5] == ["undamped", "20", "0.4", "2", "0.80"]
    assert cells[6] == f"{w[2][0]:.1e} - {2 * w[2][0]:.1e}"
    assert cells[9] == ""
    failed = sf.row("undamped", 20, 0.4, [fake(300.0, 1e-6), {"ok": False, "why": "boom"}], 1)
    assert failed.rstrip(" |").endswith("boom")


def test_every_case_runs(ropedyn_exe, tmp_path):
    """The cases' runs, short, with this build at the code's factor: all finish, the
    lightly damped rope keeps its damping (it dissipates), the undamped does not."""
    results = sf.measure({sf.code_factor(): ropedyn_exe}, 0.5, tmp_path)
    assert len(results) == sum(len(angles) for *_, angles in sf.CASES)
    assert all(r["ok"] for r in results.values()), [r.get("why") for r in results.values()]
    for c, (label, _, n, _) in enumerate(sf.CASES):
        run = io.load_run(tmp_path / f"f{c}_{sf.code_factor():g}_0.h5")
        assert run.element_mass.size == n
        dissipated = float(run.energy["dissipated"][-1])
        assert (dissipated > 0.0) if label == "lightly damped" else (dissipated == 0.0), label
