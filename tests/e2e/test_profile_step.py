"""The split of scripts/profile_step (tools/ropedyn_tools/studies/profile_step.py): which
inclusive costs of a callgrind profile make each part of a step."""
from ropedyn_tools.studies import profile_step as ps


def test_erk_counts_the_combined_rhs_and_quadrature_call_as_rhs():
    # erk evaluates f and the quadratures' g in one call at every stage (rfem_rhs_quad);
    # before this was counted, the erk table showed RHS 0 % and rest 100 %
    costs = {"__ropedyn_erk_MOD_erk_advance_to": 100,
             "__ropedyn_rfem_MOD_rfem_rhs_quad": 70, "__ropedyn_rfem_MOD_forces": 60}
    parts, total = ps.split(costs, "erk")
    assert total == 100
    assert parts == [70, 0, 0, 0, 30]


def test_erk_counts_rhs_and_separate_quadratures_alike():
    costs = {"__ropedyn_erk_MOD_erk_advance_to": 100,
             "__ropedyn_rfem_MOD_rfem_rhs": 50, "__ropedyn_rfem_MOD_rfem_quad_rhs": 10}
    parts, total = ps.split(costs, "erk")
    assert parts == [60, 0, 0, 0, 40]
