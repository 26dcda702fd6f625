"""scripts/stiff_modes (tools/ropedyn_tools/studies/stiff_modes.py): the kinds of the rope's
modes and the step an IMEX method would gain. The turning share tells an element's turning
from its moving; the gains are rho over the other kinds' largest frequency; and the modes
of `ropedyn modes` and the spectrum a run estimates, two algorithms at two states, agree on
the spectral radius at n = 10 and 30 (the premise of reading the modes as what holds the
step; at n = 10 the first, unbalanced estimate is a Ritz value off the spectrum, which the
estimate on the balanced Jacobian corrects: docs/theory/auto.md)."""
import numpy as np
import pytest

from ropedyn_tools.studies import stiff_modes as sm


def test_turning_share_tells_turning_from_moving():
    # one element along x, end points a then b
    turning = np.array([[0.0, -1.0], [0.0, 1.0]])
    moving = np.array([[0.0, 1.0], [0.0, 1.0]])
    assert sm.turning_share(turning) == 1.0
    assert sm.turning_share(moving) == 0.0
    # the two together: |d|^2 = 1, |c|^2 = 1
    assert abs(sm.turning_share(turning + moving) - 0.5) < 1e-15
    # two elements, one turning and one at rest: still all turning
    assert sm.turning_share(np.vstack([turning, np.zeros((2, 2))])) == 1.0
    assert sm.turning_share(np.zeros((4, 2))) == 0.0


def test_kinds_take_the_largest_share():
    k = sm.kinds([0.9, 0.1, 0.2, 0.0], [0.05, 0.8, 0.3, 0.0])
    assert list(k) == [0, 1, 2, 2]


def test_step_gains_are_rho_over_the_other_kinds():
    omega = np.array([1.0, 5.0, 10.0, 4.0])
    kind = np.array([2, 0, 1, 2])
    gains = sm.step_gains(omega, kind)
    assert gains[1] == 2.0            # the fastest kind implicit: held by 5 next
    assert gains[0] == 1.0 and gains[2] == 1.0   # the fastest stays explicit


@pytest.mark.parametrize("n", [10, 30])
def test_modes_and_the_runs_estimate_agree_on_rho(ropedyn_exe, tmp_path, n):
    omega, zeta, kind = sm.modes_of(ropedyn_exe, tmp_path, n)
    assert len(omega) == 3 * n and np.all(omega > 0.0) and np.all(zeta >= 0.0)
    # every kind is there: n springs along the rope, elements turning, the pendulum across
    assert set(kind) == {0, 1, 2}
    assert np.sum(kind == 0) == n
    # the slowest mode is the pendulum's (across the rope), the fastest not
    assert kind[np.argmin(omega)] == 2
    rho = float(np.max(omega))
    estimate = sm.run_radius(ropedyn_exe, tmp_path, n)
    assert abs(estimate - rho) < 0.05 * rho, (estimate, rho)
    row = sm.row(ropedyn_exe, tmp_path, n)
    assert row.startswith(f"| {n} | {3 * n} |") and row.count("|") == sm.HEADER.count("|")
