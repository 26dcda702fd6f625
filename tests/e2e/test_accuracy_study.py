"""The analysis of scripts/accuracy (tools/ropedyn_tools/studies/accuracy.py) on small made-up
data: the choices docs/guide/choosing.md states come out of these functions, so each must pick
what its description says."""
import math

from ropedyn_tools.studies import accuracy as acc


def window_row(method, rtol, tip, cpu, t0=0.0, model="rfem", n=30):
    return dict(model=model, n=str(n), t0=str(t0), method=method, rtol=str(rtol),
                tip=str(tip), cpu=str(cpu), status="ok")


def test_cheapest_in_windows_takes_each_methods_loosest_rtol_that_reaches_the_target():
    win = [window_row("a", 1e-2, 5e-3, 0.1), window_row("a", 1e-3, 5e-4, 0.2),
           window_row("a", 1e-4, 5e-5, 0.4),
           window_row("b", 1e-2, 8e-4, 0.3), window_row("b", 1e-3, 8e-5, 0.5)]
    best = acc.cheapest_in_windows(win, "rfem", 30, 1e-3)
    # a reaches 1e-3 only at rtol 1e-3 (0.2 s), b already at 1e-2 (0.3 s)
    assert [(m, rtol) for _, m, rtol in best] == [("a", 1e-3), ("b", 1e-2)]
    assert acc.cheapest_in_windows(win, "rfem", 30, 1e-5) == []
    # another model or n is not mixed in
    assert acc.cheapest_in_windows(win, "mpp", 30, 1e-3) == []


def test_later_over_first_is_the_ratio_of_later_windows_to_the_first():
    win = [window_row("a", r, tip, 0.1, t0) for r in (1e-3, 1e-4)
           for t0, tip in ((0.0, 1e-6 * r / 1e-4), (5.0, 4e-6 * r / 1e-4),
                           (10.0, 4e-6 * r / 1e-4))]
    (m, median, p90), = acc.later_over_first(win)
    assert m == "a" and math.isclose(median, 4.0) and math.isclose(p90, 4.0)


def chaos_row(method, rtol, mean, spread, starts=8):
    return dict(method=method, rtol=str(rtol), starts=str(starts), mean=str(mean),
                spread=str(spread), cpu="1")


def test_chaos_z_measures_the_difference_in_standard_errors():
    rows = [chaos_row("tight", 1e-8, 3.0e-3, 4e-4),
            chaos_row("same", 1e-3, 3.1e-3, 4e-4),      # 0.1e-3 apart: within the noise
            chaos_row("shifted", 1e-3, 4.0e-3, 4e-4)]   # 1e-3 apart: far outside
    z = acc.chaos_z(rows)
    se = 4e-4 * math.sqrt(8 / 7) / math.sqrt(8)
    assert z[0] == 0.0
    assert math.isclose(z[1], 0.1e-3 / math.hypot(se, se), rel_tol=1e-9) and z[1] < 2
    assert z[2] > 2


def test_cases_option_names_a_bad_value():
    import argparse
    import pytest
    assert acc.model_cases("mpp:100,rfem:30") == [("mpp", 100), ("rfem", 30)]
    for bad in ("mpp100", "beam:10", "rfem:1", "rfem:x"):
        with pytest.raises(argparse.ArgumentTypeError, match=bad):
            acc.model_cases(bad)


def test_merged_replaces_only_the_cases_and_methods_that_were_run():
    old = [window_row("erk", 1e-3, 1.0, 0.1), window_row("cvode", 1e-3, 2.0, 0.1),
           window_row("erk", 1e-3, 3.0, 0.1, n=100), window_row("erk", 1e-3, 4.0, 0.1,
                                                                  model="mpp")]
    new = [window_row("erk", 1e-3, 9.0, 0.2)]
    rows = acc.merged(old, new, [("rfem", 30)], ["erk"])
    # rfem 30 erk replaced; rfem 30 cvode, rfem 100 erk and mpp 30 erk kept
    assert sorted(float(r["tip"]) for r in rows) == [2.0, 3.0, 4.0, 9.0]
    # all methods of the case: every row of rfem 30 is replaced
    rows = acc.merged(old, new, [("rfem", 30)], ["erk", "cvode"])
    assert sorted(float(r["tip"]) for r in rows) == [3.0, 4.0, 9.0]
    # in the order of a full run: per case, window, method (cvode before erk), rtol
    old = [window_row("cvode", r, 1.0, 0.1, t0) for t0 in (0.0, 5.0) for r in (1e-2, 1e-3)]
    new = [window_row("erk", r, 2.0, 0.1, t0) for t0 in (0.0, 5.0) for r in (1e-2, 1e-3)]
    rows = acc.merged(old, new, [("rfem", 30)], ["erk"])
    assert [(r["t0"], r["method"], float(r["rtol"])) for r in rows] == [
        (t0, m, r) for t0 in ("0.0", "5.0") for m in ("cvode", "erk") for r in (1e-2, 1e-3)]


def test_the_guide_takes_the_symplectic_bound_from_the_energy_page(tmp_path):
    """The guide's item on long runs quotes the largest error of the symplectic rows of
    bench_symplectic's table, not a number of its own."""
    page = tmp_path / "energy.md"
    page.write_text("\n".join([
        "<!-- symplectic-targets:begin -->",
        "| n | method | at 30 s | at the end | max abs to 30 s | max abs to the end | growth |",
        "|---|---|---|---|---|---|---|",
        "| 20 | auto at abc (the former default) | -8e-02 | -1e-01 | 8e-02 | 1.5e-01 | 1.7 |",
        "| 20 | symplectic | +3.8e-06 | +1.5e-05 | 1.6e-05 | 1.1e-04 | 6.8 |",
        "| 100 | symplectic | +4.0e-06 | +3.8e-06 | 8.5e-06 | 2.9e-05 | 3.5 |",
        "<!-- symplectic-targets:end -->", ""]))
    assert acc.symplectic_bound(page) == "1.1e-04"
    page.write_text("no table\n")
    assert acc.symplectic_bound(page) is None
    bound = acc.symplectic_bound()      # the real page
    assert bound and f"within {bound} m g L" in acc.long_runs()


def test_the_long_runs_item_counts_the_symplectic_ensembles():
    """The guide's long-runs item says at how many tolerances the symplectic method's chaos
    statistic reproduces the tightest ensemble, from the chaos study's rows."""
    row = lambda method, rtol, mean: {"method": method, "rtol": str(rtol), "starts": "8",
                                      "mean": str(mean), "spread": "1e-4", "cpu": "1"}
    rows = [row("cvode", 1e-8, 3.0e-3), row("symplectic", 1e-3, 3.01e-3),
            row("symplectic", 1e-5, 3.5e-3), row("symplectic", 1e-7, 2.99e-3)]
    assert "at 2 of 3 tolerances" in acc.long_runs(rows)


def test_the_guide_is_as_current_as_its_oldest_input(tmp_path):
    """The choosing section reads the data of every subcommand: its stamp is the oldest of
    theirs (rerunning one leaves the others' data as they were), not the time it was
    written; a section without a stamp gives none."""
    page = tmp_path / "accuracy.md"
    stamps = {"windows": "2026-11-30 05:56 UTC, commit `ffc3f58`",
              "discretization": "2026-11-30 14:14 UTC, commit `3ad199a`",
              "chaos": "2026-11-30 07:54 UTC, commit `53d85c5`",
              "fig4": "2026-11-29 23:10 UTC, commit `ca9a2aa`"}
    page.write_text("".join(f"<!-- accuracy-{name}:begin -->\nCommand: `scripts/accuracy "
                            f"{name}` (1.0 min, {stamp}).\n<!-- accuracy-{name}:end -->\n"
                            for name, stamp in stamps.items()))
    assert acc.oldest_input(page) == (stamps["fig4"], "fig4")
    assert acc.oldest_input(page, ["windows", "chaos"]) == (stamps["windows"], "windows")
    page.write_text(page.read_text().replace(stamps["chaos"], "2026-11-30"))
    assert acc.oldest_input(page) == (None, None)
