"""The studies' list options: a list that is not numbers, or a number not above 0, is one
usage error (exit 2) naming the option, the list and the bad item, before anything is
built or run (tools/ropedyn_tools/arguments.py); before, the studies traced back where
they first converted the list."""
import argparse
import importlib

import pytest

from ropedyn_tools.arguments import (check_names, choice, list_text, listing, named_lists,
                                  positive)

BAD = [
    ("stiff_modes", "--elements", "abc", "'abc'"),
    ("bench_kernels", "--rfem-elements", "30 x", "'x'"),
    ("bench_kernels", "--mpp-elements", "0", "must be above 0"),
    ("bench_peers", "--elements", "10,30", "'10,30'"),
    ("bench_peers", "--undamped-elements", "20 a", "'a'"),
    ("bench_peers", "--coupled-elements", "-3", "must be above 0"),
    ("bench_peers", "--methods", "cvode:x", "'x'"),
    ("bench_peers", "--methods", "mebdf:0", "must be above 0"),
    ("accuracy", "--methods", "mebdf:x", "'x'"),
    ("accuracy", "--methods", "cvode,mebdf:0", "must be above 0"),
    ("bench_symplectic", "--elements", "2.5", "not a whole number"),
    ("fig5", "--elements", "30 70", "'30 70'"),
    ("bergdahl", "--periods", "1.25,,2", "not a number: ''"),
    ("bergdahl", "--radii", "x", "'x'"),
    ("bergdahl", "--quick", "4", "2 values"),
    ("bench_peers_bergdahl", "--periods", "a", "'a'"),
    ("bench_peers_bergdahl", "--radii", "0", "must be above 0"),
    ("work_precision", "--elements", "10;30", "'10;30'"),
    ("work_precision", "--rtols", "1e-3,abc", "'abc'"),
    ("bench_rfem", "--elements", "ten", "'ten'"),
    ("bench_models", "--elements", "ten", "'ten'"),
    ("cost_model", "--rtols", "1e-3 0", "must be above 0"),
    ("work_precision", "--max-orders", "cvode", "'cvode': not NAME=VALUES"),
    ("work_precision", "--max-orders", "cvode=2+5,mebdf=x", "'mebdf=x': 'x'"),
    ("work_precision", "--model-elements", "mpp=a", "'mpp=a': 'a'"),
]


@pytest.mark.parametrize("study,option,value,words", BAD,
                         ids=[f"{s}{o}" for s, o, _, _ in BAD])
def test_bad_list_is_a_usage_error(study, option, value, words, capsys):
    module = importlib.import_module(f"ropedyn_tools.studies.{study}")
    with pytest.raises(SystemExit) as e:
        module.main([option, value, "--exe", "/nonexistent"])
    assert e.value.code == 2
    err = capsys.readouterr().err
    assert f"argument {option}:" in err and words in err, err
    assert "Traceback" not in err


def test_list_types_keep_or_convert_the_text():
    """list_text returns the text as given (a study quotes it in its Command line);
    listing returns the numbers; each separator splits as documented."""
    assert list_text(positive(int))("10 30  100") == "10 30  100"
    assert listing(positive(int))("10 30  100") == [10, 30, 100]
    assert listing(positive(float), ",")("1.25,2") == [1.25, 2.0]
    assert listing(positive(int), ", ")("10,30 70") == [10, 30, 70]
    for text, sep in (("10,30", None), ("10 30", ","), ("", None), ("1,0", ", ")):
        with pytest.raises(argparse.ArgumentTypeError):
            listing(positive(int), sep)(text)
    with pytest.raises(argparse.ArgumentTypeError):
        listing(positive(int), ",", length=2)("4,5,6")


def test_named_lists_keep_the_text():
    assert named_lists(positive(int), "+", entries=",")("cvode=2+5,mebdf=4+7") == \
        "cvode=2+5,mebdf=4+7"
    assert named_lists(positive(int), ", ")("mpp=10,30 70") == "mpp=10,30 70"
    for text in ("=2", "cvode2", "cvode=", "cvode=0"):
        with pytest.raises(argparse.ArgumentTypeError):
            named_lists(positive(int), "+")(text)


# the name lists, checked against the executable's own list (`ropedyn keys`) once the study
# knows it, before anything runs: (study, arguments, option, bad name)
BAD_NAMES = [
    ("calibrate", ["--method", "rk4"], "--method", "'rk4'"),
    ("fig5", ["--method", "Auto"], "--method", "'Auto'"),
    ("bench_rfem", ["--solvers", "cvode bogus"], "--solvers", "'bogus'"),
    ("accuracy", ["windows", "--methods", "cvode:2,mebd:4"], "--methods", "'mebd'"),
    ("accuracy", ["windows", "--methods", "cvode,,erk"], "--methods", "''"),
    ("bench_peers", ["--methods", "cvode mebd:4"], "--methods", "'mebd'"),
    ("work_precision", ["--models", "rfem,bogus"], "--models", "'bogus'"),
    ("work_precision", ["--methods", "cvode,,erk"], "--methods", "''"),
    ("work_precision", ["--max-orders", "cvod=2"], "--max-orders", "'cvod'"),
    ("profile_step", ["--methods", "erk rk4"], "--methods", "'rk4'"),
]


@pytest.mark.parametrize("study,arguments,option,words", BAD_NAMES,
                         ids=[f"{s}{o}" for s, _, o, _ in BAD_NAMES])
def test_bad_name_is_a_usage_error(study, arguments, option, words, ropedyn_exe, capsys,
                                   monkeypatch, tmp_path):
    """Before, bergdahl --models bogus (and the like) failed only when its runs started, or
    a study skipped the name with a message."""
    monkeypatch.chdir(tmp_path)            # nothing may be written; if it were, not in docs/
    module = importlib.import_module(f"ropedyn_tools.studies.{study}")
    with pytest.raises(SystemExit) as e:
        module.main([*arguments, "--exe", str(ropedyn_exe)])
    assert e.value.code == 2
    err = capsys.readouterr().err
    assert f"argument {option}: unknown: {words}" in err or \
        (words == "''" and f"argument {option}: unknown" in err), err
    assert "allowed: " in err and "Traceback" not in err


def test_study_labels_are_checked_when_parsed(capsys):
    """bergdahl's labels are the study's own (MODEL or MODEL_VARIANT): no executable needed."""
    module = importlib.import_module("ropedyn_tools.studies.bergdahl")
    for option, value in (("--models", "rfem,mpp_bogus"), ("--convergence-models", "rfem_x")):
        with pytest.raises(SystemExit) as e:
            module.main([option, value, "--exe", "/nonexistent"])
        assert e.value.code == 2
        err = capsys.readouterr().err
        assert f"argument {option}:" in err and "unknown" in err, err
    assert choice(module.LABELS)("rfem_perimeter") == "rfem_perimeter"


def test_check_names_reads_the_code_list(ropedyn_exe):
    """The allowed names are those of `ropedyn keys`: every method and model the scene
    reader takes passes, in any list; an empty list does not."""
    from ropedyn_tools.keys_reference import allowed
    parser = argparse.ArgumentParser()
    methods = allowed(ropedyn_exe, "solver", "method")
    assert {"auto", "cvode", "mebdf", "erk", "symplectic"} <= set(methods)
    check_names(parser, ropedyn_exe, "--methods", methods, "solver", "method")
    check_names(parser, ropedyn_exe, "--models", ["mpp", "rfem"], "model", "kind")
    with pytest.raises(SystemExit):
        check_names(parser, ropedyn_exe, "--models", [], "model", "kind")


def test_fig5_no_write_touches_nothing(ropedyn_exe, tmp_path, monkeypatch):
    """fig5 --no-write prints its runs and writes no figure, data or page section (it
    wrote docs/figures and docs/data before, under the old --no-doc); without it, it
    writes all three (the paths moved into tmp_path)."""
    from ropedyn_tools.studies import fig5
    docs = tmp_path / "docs"
    (docs / "validation").mkdir(parents=True)
    page = docs / "validation" / "fig5.md"
    page.write_text(f"# Figure 5\n\n{fig5.BEGIN}\n{fig5.END}\n")
    monkeypatch.setattr(fig5, "DOCS", docs)
    monkeypatch.setattr(fig5, "PAGE", page)
    argv = ["--exe", str(ropedyn_exe), "--t-end", "0.02", "--elements", "2", "--jobs", "1",
            "--outdir", str(tmp_path / "runs")]
    before = page.read_text()
    assert fig5.main(argv + ["--no-write"]) == 0
    assert sorted(p.name for p in docs.rglob("*") if p.is_file()) == ["fig5.md"]
    assert page.read_text() == before
    assert fig5.main(argv) == 0
    assert (docs / "figures" / "fig5_energy.png").is_file()
    assert (docs / "data" / "fig5_energy.csv").is_file()
    assert page.read_text() != before
