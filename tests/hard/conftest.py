"""Fixtures of the stiff-case suite: the ropedyn executable and a pool that runs many scenes
at once (each run is a separate process; CI has 2 cores)."""
import concurrent.futures
import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def ropedyn_exe():
    exe = pathlib.Path(os.environ.get("ROPEDYN_EXE", ROOT / "build" / "debug" / "ropedyn")).resolve()
    if not exe.is_file():
        pytest.fail(f"ropedyn executable not found at {exe} (set ROPEDYN_EXE)")
    return exe


def _run_many(exe, jobs, workdir, timeout=900):
    """Run every job {key: (scene, [overrides])} with output into workdir/<key>.h5, two at
    a time; returns {key: (CompletedProcess, h5 path)}."""
    def one(key, scene, overrides):
        out = pathlib.Path(workdir) / f"{key}.h5"
        cmd = [str(exe), "run", str(scene), "--set", f"output.file={out}"]
        for o in overrides:
            cmd += ["--set", o]
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, cwd=workdir)
        return proc, out

    workers = max(1, min(2, os.cpu_count() or 1))
    with concurrent.futures.ThreadPoolExecutor(max_workers=workers) as pool:
        futures = {key: pool.submit(one, key, scene, ov) for key, (scene, ov) in jobs.items()}
        return {key: fut.result() for key, fut in futures.items()}


@pytest.fixture(scope="session")
def run_many(ropedyn_exe):
    """run_many(jobs, workdir): see _run_many (jobs are started in the order given)."""
    return lambda jobs, workdir, timeout=900: _run_many(ropedyn_exe, jobs, workdir, timeout)
