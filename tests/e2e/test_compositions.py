"""scripts/compositions (tools/ropedyn_tools/studies/compositions.py): the compositions the
symplectic method could use, judged from their coefficients. Its SRKN6b is the method's
(read from the Fortran table), its stability limit is the one the method steps by, and its
order and stability tests tell a wrong composition from a right one."""
import re

import numpy as np
import pytest

from ropedyn_tools.studies import compositions as cs


def test_method_coefficients_are_read_from_the_fortran_table(tmp_path, monkeypatch):
    (a1, a2), (b1, b2, b3) = cs.method_coefficients()
    assert (a1, b1) == (0.245298957184271, 0.0829844064174052)
    text = cs.TABLES.read_text()
    monkeypatch.setattr(cs, "TABLES", tmp_path / "t.f90")
    (tmp_path / "t.f90").write_text(text.replace("b3 = ", "c3 = "))
    with pytest.raises(ValueError, match="b3"):
        cs.method_coefficients()


def test_the_methods_limit_is_the_tables():
    """The first instability of SRKN6b found here is the undamped limit the method steps by
    (LIMIT_BM6 at zeta = 0, scanned in steps of 5e-4 there)."""
    a, b = cs.symmetric(*cs.method_coefficients(), 6)
    table = float(re.search(r"LIMIT_BM6\(NZ\) = \[([0-9.]+)_wp", cs.TABLES.read_text())[1])
    limit = cs.unstable_intervals(a, b)[0][0]
    assert abs(limit - table) < 1e-3
    # the narrow gap just past pi, then stable again
    lo, hi = cs.unstable_intervals(a, b)[0]
    assert hi - lo < 0.01 and cs.unstable_intervals(a, b)[1][0] > 5.0


def test_order_conditions_tell_order_4_from_order_2():
    for name, _, a, b in cs.compositions():
        res = np.abs(cs.order4_residuals(a, b)).max()
        assert (res < 1e-13) == (name != "Stormer-Verlet"), name
    a, b = cs.symmetric(*cs.method_coefficients(), 6)
    b = b.copy()
    b[[0, -1]] += 1e-6
    b[3] -= 2e-6          # still consistent (sum b = 1), no longer 4th order
    assert np.abs(cs.order4_residuals(a, b)).max() > 1e-8


def test_verlet_energy_spread_is_the_known_one():
    """Velocity Verlet conserves (v^2 + (1 - x^2/4) q^2)/2 on the oscillator: the spread of
    the energy is x^2/4 / (1 - x^2/4)."""
    x = 0.8
    assert cs.energy_spread(np.array([1.0]), np.array([0.5, 0.5]), x) == pytest.approx(
        (x * x / 4) / (1 - x * x / 4), rel=1e-12)


def test_study_prints_every_composition(capsys):
    assert cs.main(["--no-write"]) == 0
    rows = [r for r in capsys.readouterr().out.splitlines() if r.startswith("| ")]
    assert len(rows) == len(cs.compositions()) + 1
    # SRKN6b: 6 evaluations per step at SAFETY of its first instability, 3.1635
    assert rows[2].startswith("| Blanes-Moan SRKN6b") and \
        f"| {6 / (cs.SAFETY * 3.1635):.2f} |" in rows[2]


@pytest.mark.parametrize("name", ["VERLET", "BM6", "CHIN"])
def test_the_stability_tables_are_the_methods_own_step(name):
    """ropedyn_split_tables' stable h w at every damping is the scan of the method's step
    (the D-map, its predicted velocity, a gradient kick) replicated here: digit for digit."""
    a, b = cs.symmetric(*cs.method_coefficients(), 6)
    coefficients = {"VERLET": (np.array([1.0]), np.array([0.5, 0.5]), None),
                    "BM6": (a, b, None), "CHIN": cs.CHIN}[name]
    assert cs.damped_limits(*coefficients) == cs.fortran_limits(name)


def test_the_scan_tells_a_wrong_step_from_the_right_one():
    """Without the gradient kick Chin's composition is another method: its table differs."""
    a, b, grad = cs.CHIN
    assert cs.damped_limits(a, b, 0 * grad)[:3] != cs.fortran_limits("CHIN")[:3]
