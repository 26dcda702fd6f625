"""The guard of a resume and of the rename at a run's end (docs/guide/output.md, "A run's own
file: the lock, FILE.part and what it may replace"): a resume through a symbolic link takes
the lock of the file the link points to and renames that file (not the link); a file put at
FILE while the run goes on is not replaced by its FILE.part; a user's FILE.lock that is not a
lock of ropedyn is never removed; a sweep case's .part is not resumed by hand."""
import os
import signal
import time

import h5py

from test_output_guard import long_run, records_in, wait_for_records, scene  # noqa: F401


def status(path):
    with h5py.File(path, "r", locking=False) as f:
        return f.attrs["status"].decode(), len(f["time"]), f["time"][-1]


def test_a_resume_through_a_link_to_a_part_renames_the_file(run, ropedyn_exe, tmp_path, scene):
    """Was: the lock taken was the link's (L.h5.lock, not out/paper.h5.lock) and the link was
    renamed to L.h5, leaving out/paper.h5.part complete under its .part name."""
    proc = long_run(ropedyn_exe, tmp_path, scene)
    part = tmp_path / "out" / "paper.h5.part"
    wait_for_records(part, proc)
    proc.kill()
    proc.wait(60)
    (tmp_path / "L.h5.part").symlink_to(part)
    last = status(part)[2]
    resumed = run("run", "--resume", "L.h5.part", "--set", f"solver.t_end={last + 0.05}")
    assert resumed.returncode == 0, resumed.stderr
    assert f"(lock {tmp_path}/out/paper.h5.lock)" in resumed.stderr, resumed.stderr
    assert status(tmp_path / "out" / "paper.h5")[0] == "complete"
    assert not part.exists() and not (tmp_path / "out" / "paper.h5.lock").exists()
    assert (tmp_path / "L.h5.part").is_symlink() and not (tmp_path / "L.h5").exists()


def test_a_resume_through_a_link_holds_the_files_lock(run, ropedyn_exe, tmp_path, scene):
    """Was: a resume of L.h5 -> out/paper.h5 held L.h5.lock, so a --force rerun of the scene
    took out/paper.h5.lock, renamed its file over out/paper.h5 and the resume's records went
    to a removed file."""
    proc = long_run(ropedyn_exe, tmp_path, scene)
    wait_for_records(tmp_path / "out" / "paper.h5.part", proc)
    proc.send_signal(signal.SIGTERM)
    proc.wait(60)
    out = tmp_path / "out" / "paper.h5"
    assert proc.returncode == 130 and status(out)[0] == "interrupted"
    (tmp_path / "L.h5").symlink_to(out)
    before = status(out)[1]
    resume = subprocess_resume(ropedyn_exe, tmp_path, "L.h5")
    try:
        wait_for_records(out, resume, count=before + 2)
        forced = run("run", scene, "--set", "solver.t_end=30", "--set", "model.elements=60",
                     "--force")
        assert forced.returncode == 4, forced.stderr
        assert "out/paper.h5.lock): a file is written by one process at a time" \
            in forced.stderr, forced.stderr
    finally:
        resume.send_signal(signal.SIGTERM)
        resume.wait(60)
    assert resume.returncode == 130, resume.stderr
    assert status(out)[1] > before


def subprocess_resume(ropedyn_exe, cwd, name):
    import subprocess
    return subprocess.Popen([str(ropedyn_exe), "run", "--resume", name, "--set",
                             "output.progress=.false."], cwd=cwd, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)


def test_a_file_put_at_the_output_while_the_run_goes_on_is_kept(ropedyn_exe, tmp_path, scene):
    """Was: FILE.part was renamed over whatever was at FILE when the run ended, a file the
    user put there meanwhile too."""
    proc = long_run(ropedyn_exe, tmp_path, scene)
    part = tmp_path / "out" / "paper.h5.part"
    wait_for_records(part, proc)
    out = tmp_path / "out" / "paper.h5"
    out.write_text("my notes\n")
    proc.send_signal(signal.SIGTERM)
    stderr = proc.communicate(timeout=60)[1]
    assert proc.returncode == 130, stderr
    assert out.read_text() == "my notes\n"
    assert status(part)[0] == "interrupted"
    assert "paper.h5.part keeps its name:" in stderr and "was put there while the run went on" \
        in stderr, stderr


def test_a_users_file_named_like_the_lock_is_left(run, tmp_path, scene):
    """Was: a FILE.lock without a writer's pid, older than 120 s, was taken over: removed."""
    (tmp_path / "out").mkdir()
    lock = tmp_path / "out" / "paper.h5.lock"
    lock.write_text("my notes\n")
    old = time.time() - 3600
    os.utime(lock, (old, old))
    proc = run("run", scene, "--set", "solver.t_end=0.01")
    assert proc.returncode == 4, proc.stderr
    assert "paper.h5.lock: not a lock of ropedyn" in proc.stderr, proc.stderr
    assert lock.read_text() == "my notes\n"
    assert not (tmp_path / "out" / "paper.h5").exists()


def test_a_sweep_case_part_is_not_resumed_by_hand(run, ropedyn_exe, tmp_path, scene):
    """Was: `ropedyn run --resume out/sw/.case_0001.h5.part` took .case_0001.h5.lock, not the
    case's .case_0001.lock, and renamed the file to the hidden .case_0001.h5, which the sweep
    does not read (it ran the case anew; beside a sweep resuming it, records were lost)."""
    proc = long_run(ropedyn_exe, tmp_path, scene)
    killed = tmp_path / "out" / "paper.h5.part"
    wait_for_records(killed, proc)
    proc.kill()
    proc.wait(60)
    part = tmp_path / "out" / "sw" / ".case_0001.h5.part"
    part.parent.mkdir(parents=True)
    killed.rename(part)
    data = part.read_bytes()
    proc = run("run", "--resume", "out/sw/.case_0001.h5.part")
    assert proc.returncode == 2, proc.stderr
    assert "the file of a sweep case being written" in proc.stderr, proc.stderr
    assert part.read_bytes() == data
    assert not list(part.parent.glob("*.lock"))
