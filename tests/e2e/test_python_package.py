"""The ropedyn Python package (python/ropedyn, used in place by .venv, set up
by scripts/setup) holds what a user imports; the studies and maintenance tools
(tools/ropedyn_tools) are not installed and the scripts/ commands find them there. The
package imports from any directory, its reader gives a run file's arrays with their units,
and every command answers --help (without building or running anything)."""
import importlib
import os
import pathlib
import re
import subprocess
import sys

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]

# scripts/NAME (bash) -> the module it runs
COMMANDS = {
    "animate": "ropedyn.animate",
    "plot": "ropedyn.plot.overview",
    "xdmf": "ropedyn.xdmf",
    "readme_figures": "ropedyn_tools.studies.readme_figures",
    "fig5": "ropedyn_tools.studies.fig5",
    "calibrate": "ropedyn_tools.studies.calibrate",
    "bench_effects": "ropedyn_tools.studies.bench_effects",
    "bench_kernels": "ropedyn_tools.studies.bench_kernels",
    "bench_models": "ropedyn_tools.studies.bench_models",
    "bench_rfem": "ropedyn_tools.studies.bench_rfem",
    "bench_step": "ropedyn_tools.studies.bench_step",
    "bench_sweep": "ropedyn_tools.studies.bench_sweep",
    "bench_peers": "ropedyn_tools.studies.bench_peers",
    "bench_library": "ropedyn_tools.studies.bench_library",
    "bench_symplectic": "ropedyn_tools.studies.bench_symplectic",
    "compositions": "ropedyn_tools.studies.compositions",
    "stiff_modes": "ropedyn_tools.studies.stiff_modes",
    "auto_table": "ropedyn_tools.studies.auto_table",
    "auto_accuracy": "ropedyn_tools.studies.auto_accuracy",
    "cost_model": "ropedyn_tools.studies.cost_model",
    "profile_step": "ropedyn_tools.studies.profile_step",
    "validation": "ropedyn_tools.studies.validation",
    "work_precision": "ropedyn_tools.studies.work_precision",
    "accuracy": "ropedyn_tools.studies.accuracy",
    "work_precision_testset": "ropedyn_tools.studies.work_precision_testset",
    "stability_report": "ropedyn_tools.studies.stability_report",
    "loose_tolerances": "ropedyn_tools.studies.loose_tolerances",
    "update_references": "ropedyn_tools.update_references",
    "mutation_check": "ropedyn_tools.mutation_check",
    "docs_status": "ropedyn_tools.docs_status",
    "docs_rerun": "ropedyn_tools.docs_rerun",
    "keys_reference": "ropedyn_tools.keys_reference",
}
# Python files under scripts/ that the README and docs/ call by path
SHIMS = {"plot_energy.py": "ropedyn.plot.energy",
         "mebdf_stability.py": "ropedyn_tools.studies.mebdf_stability"}


def test_import_from_another_directory(tmp_path):
    """The venv's Python finds this checkout's package wherever it runs, and only the
    package: the tools are not installed (without tools/ on the path they do not import)."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    result = subprocess.run([sys.executable, "-c", "import ropedyn, ropedyn.io;"
                             "print(ropedyn.__file__); print(ropedyn.load_run is ropedyn.io."
                             "load_run)"], cwd=tmp_path, capture_output=True, text=True, env=env)
    assert result.returncode == 0, result.stderr
    path, same = result.stdout.split()
    assert pathlib.Path(path) == ROOT / "python" / "ropedyn" / "__init__.py"
    assert same == "True"
    result = subprocess.run([sys.executable, "-c", "import ropedyn_tools"], cwd=tmp_path,
                            capture_output=True, text=True, env=env)
    assert "No module named 'ropedyn_tools'" in result.stderr


def test_dir_lists_the_lazy_names():
    """The package loads Scene, Simulation, run, ... on first use (module __getattr__);
    without a module __dir__ they were missing from dir(ropedyn), so a notebook's
    completion of "ropedyn." offered none of them."""
    import ropedyn
    assert set(ropedyn.__all__) <= set(dir(ropedyn))


def test_package_holds_no_tools():
    """What `pip install python/` installs is the user's package: no studies, no
    maintenance tools, no module that knows the repository's layout."""
    files = {p.relative_to(ROOT / "python" / "ropedyn").as_posix()
             for p in (ROOT / "python" / "ropedyn").rglob("*.py")}
    assert not {f for f in files if f.startswith("studies/")}, files
    assert not files & {"run.py", "compare.py", "architecture.py", "mutation_check.py"}
    source = "\n".join((ROOT / "python" / "ropedyn" / f).read_text() for f in files)
    assert not re.search(r"^\s*(from|import) ropedyn_tools", source, re.M)
    assert "scripts/build" not in source


def test_reader_gives_arrays_with_units(run, tmp_path):
    from ropedyn.io import load_run

    (tmp_path / "r.nml").write_text("&model kind = 'rfem', elements = 4 /\n"
                                    "&solver t_end = 0.1, output_interval = 0.01 /\n")
    assert run("run", "r.nml").returncode == 0
    r = load_run(tmp_path / "out" / "r.h5")
    records = r.time.size
    assert records == 11 and r.n == 4
    assert r.q.shape == r.qdot.shape == (records, 4, 3)
    assert r.points.shape == (records, 8, 2)
    assert r.element_length.shape == r.element_mass.shape == (4,)
    assert set(r.energy) == {"kinetic", "elastic", "gravity", "dissipated", "support_work",
                             "total"}
    assert all(e.shape == (records,) and e.dtype == np.float64 for e in r.energy.values())
    assert r.units["time"] == "s" and r.units["state/q"] == "m, m, rad"
    assert r.units["rope/points"] == "m" and r.units["energy/total"] == "J"
    assert r.units["rope/element_mass"] == "kg" and r.units["solver/cpu_time"] == "s"
    assert isinstance(r.stats["steps"], int) and r.stats["steps"] > 0
    assert isinstance(r.stats["cpu_time"], float)
    assert r.attrs["status"] == "complete" and r.status == "complete"
    assert r.model == "rfem" and r.group("model")["elements"] == 4
    assert r.group("solver")["t_end"] == 0.1


@pytest.mark.filterwarnings("ignore::DeprecationWarning")  # pyparsing, from matplotlib
@pytest.mark.parametrize("module", sorted(set(COMMANDS.values()) | set(SHIMS.values())))
def test_module_main_takes_argv(module, capsys):
    """Each command's module has main(argv=None), usable from Python."""
    main = importlib.import_module(module).main
    with pytest.raises(SystemExit) as stop:
        main(["--help"])
    assert stop.value.code == 0
    assert "usage:" in capsys.readouterr().out


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_command_answers_help(name):
    """scripts/NAME --help: exit 0 and the module's usage; no build (it would take minutes).
    It says what the command does in the whole first paragraph of its module's docstring
    (its first line alone stopped mid-sentence in most of them)."""
    result = subprocess.run(["bash", str(ROOT / "scripts" / name), "--help"],
                            capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith("usage:"), result.stdout
    first = importlib.import_module(COMMANDS[name]).__doc__.strip().split("\n\n")[0]
    assert " ".join(first.split()) in " ".join(result.stdout.split()), result.stdout


@pytest.mark.parametrize("name", sorted(SHIMS))
def test_shim_answers_help(name, tmp_path):
    result = subprocess.run([sys.executable, str(ROOT / "scripts" / name), "--help"],
                            cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith("usage:"), result.stdout


@pytest.mark.parametrize("module, extra", [
    ("ropedyn_tools.studies.bench_effects", ["--build", "/nonexistent"]),
    ("ropedyn_tools.studies.bench_kernels", ["--build", "/nonexistent"]),
    ("ropedyn_tools.studies.profile_step", ["--exe", "/nonexistent"]),
    ("ropedyn_tools.studies.bench_step", ["--exe", "/nonexistent"])])
def test_unknown_baseline_is_a_usage_error(module, extra, capsys):
    """--baseline naming no commit: a usage error naming the option and the value (exit 2),
    before anything is built (it used to end in git's traceback after the Release build)."""
    main = importlib.import_module(module).main
    with pytest.raises(SystemExit) as stop:
        main(["--baseline", "no-such-revision", *extra, "--no-write"])
    assert stop.value.code == 2
    assert "--baseline no-such-revision: not a commit" in capsys.readouterr().err


def test_baseline_revision_names_the_commit():
    """A revision git knows comes back as the short hash of its commit."""
    import argparse
    from ropedyn_tools.studies.common import baseline_revision
    head = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "HEAD"], capture_output=True,
                          text=True, check=True).stdout.strip()
    short = baseline_revision(argparse.ArgumentParser(), "HEAD")
    assert len(short) >= 7 and head.startswith(short)


def test_least_cpu_keeps_the_fastest_run_and_stops_at_a_failure():
    """The benchmarks' timing rule (bench_peers --repeat): the least CPU of the runs, and a
    run that did not complete is returned at once (its CPU means nothing)."""
    from ropedyn_tools.studies.common import least_cpu
    runs = iter([{"cpu": 3.0}, {"cpu": 1.0}, {"cpu": 2.0}])
    assert least_cpu(lambda: next(runs), 3) == {"cpu": 1.0}
    calls = []

    def run():
        calls.append(1)
        return {"cpu": 0.5 if len(calls) == 2 else 1.0, "ok": len(calls) != 2}
    r = least_cpu(run, 3, complete=lambda x: x["ok"])
    assert r == {"cpu": 0.5, "ok": False} and len(calls) == 2
    assert least_cpu(lambda: {"cpu": 4.0}, 0) == {"cpu": 4.0}


def test_long_horizon_cache_is_keyed_on_the_code(tmp_path):
    """The long-horizon cache survives a commit that changes no code (the executable is
    relinked for its version string only) but not a change to src/, solvers/ or
    CMakeLists.txt, committed or not; an executable older than the code is keyed on itself."""
    import os
    from ropedyn_tools.studies.long_horizon import code_fingerprint

    def git(*args):
        subprocess.run(["git", "-C", str(tmp_path), "-c", "user.name=t", "-c",
                        "user.email=t@t", *args], check=True, capture_output=True)

    for name in ("src/a.f90", "solvers/b.f90", "CMakeLists.txt", "docs/c.md"):
        (tmp_path / name).parent.mkdir(exist_ok=True)
        (tmp_path / name).write_text(name + "\n")
    git("init", "-q")
    git("add", ".")
    git("commit", "-qm", "one")
    exe = tmp_path / "build" / "ropedyn"
    exe.parent.mkdir()

    def relink(text):
        exe.write_text(text)
        later = max(p.stat().st_mtime_ns for p in tmp_path.rglob("*") if p.is_file()) + 10**9
        os.utime(exe, ns=(later, later))
        return code_fingerprint(exe, root=tmp_path)

    first = relink("version one")
    assert " code " in first
    (tmp_path / "docs/c.md").write_text("changed\n")
    git("commit", "-qam", "docs only")
    assert relink("version two, a longer string") == first
    (tmp_path / "src/a.f90").write_text("changed\n")
    edited = relink("version two-dirty")
    assert " code " in edited and edited != first
    git("commit", "-qam", "code")
    assert relink("version three") not in (first, edited)
    (tmp_path / "solvers/new.f90").write_text("untracked\n")
    untracked = relink("version three-dirty")
    assert untracked not in (first, edited)
    os.utime(exe, ns=(0, 0))
    assert " exe " in code_fingerprint(exe, root=tmp_path)
