"""scripts/cost_model (tools/ropedyn_tools/studies/cost_model.py): auto's counted cost against CPU.
Its counts must be auto's: the constants come from the Fortran source, and a run's counted
cost follows auto's formula on the RFEM's band."""
import re

from ropedyn_tools.studies import cost_model as cm


def test_constants_are_read_from_the_fortran_source(tmp_path):
    constants = cm.auto_constants()
    text = cm.AUTO_SOURCE.read_text()
    for name, value in constants.items():
        m = re.search(rf"{name}\s*=\s*([0-9.]+)_wp", text)
        assert m and float(m.group(1)) == value, name
    # a source without one of them is an error naming it
    (tmp_path / "auto.f90").write_text(text.replace("BDF_STEP_COST", "XDF_STEP_COST"))
    try:
        cm.auto_constants(tmp_path / "auto.f90")
    except ValueError as e:
        assert "BDF_STEP_COST" in str(e)
    else:
        raise AssertionError("missing constant not reported")


def test_counted_cost_is_autos_formula():
    c = {"IMPLICIT_STEP_COST": 6.0, "BDF_STEP_COST": 5.0, "FACTOR_BASE": 3.0,
         "JACOBIAN_COST": 4.0}
    stats = {"rhs_evals": 100, "steps": 10, "jac_evals": 2, "lin_setups": 7}
    assert cm.counted("erk", stats, c) == 100
    assert cm.counted("mebdf", stats, c) == 100 + 60 + 21 + 8
    assert cm.counted("cvode", stats, c) == 100 + 50 + 21 + 8


def test_study_runs_and_prints_a_row_per_method(ropedyn_exe, capsys):
    assert cm.main(["--exe", str(ropedyn_exe), "--t-end", "0.05", "--elements", "4",
                    "--rtols", "1e-3", "--repeat", "1", "--no-write"]) == 0
    rows = [line for line in capsys.readouterr().out.splitlines()
            if line.startswith("| 4 |")]
    assert [r.split("|")[3].strip() for r in rows] == ["erk", "mebdf", "cvode"]
    assert rows[0].split("|")[-2].strip() == "1.00"      # erk over itself
    for r in rows[1:]:
        assert float(r.split("|")[-2]) > 0.0


def test_bad_arguments_are_named(capsys):
    """A list that is not numbers, or a value not above 0, is a usage error (exit 2)
    naming the option and the value, before anything runs."""
    for args, words in ((["--elements", "ten"], ["--elements", "'ten'"]),
                        (["--rtols", "1e-3 0"], ["--rtols", "'0'"]),
                        (["--repeat", "-1"], ["--repeat", "'-1'"])):
        try:
            cm.main([*args, "--exe", "/nonexistent", "--no-write"])
        except SystemExit as e:
            assert e.code == 2
        else:
            raise AssertionError(f"{args} accepted")
        err = capsys.readouterr().err
        assert all(w in err for w in words), err
