"""The guard of a run's output file (docs/guide/output.md, "Write, lock and resume rules"):
a rerun of the same scene replaces its own file; a --set variant, another scene, a file ropedyn
did not write or an input of the run is never replaced (exit 2, the file unchanged) unless
--force (never an input); a second run on a locked file is refused; a killed run leaves the
earlier file whole and its data in FILE.part; an interrupted run ends in FILE."""
import hashlib
import shutil
import socket
import signal
import subprocess
import time

import h5py
import numpy as np
import pytest

from conftest import ROOT

PAPER = ROOT / "input" / "paper.nml"


def digest(path):
    return hashlib.sha256(path.read_bytes()).hexdigest()


@pytest.fixture
def scene(tmp_path):
    path = tmp_path / "paper.nml"
    path.write_text(PAPER.read_text())
    return path


def created(path):
    with h5py.File(path) as f:
        return f.attrs["created"], f.attrs["source"].decode()


def test_a_rerun_replaces_its_own_file_and_a_variant_is_refused(run, tmp_path, scene):
    first = run("run", scene, "--set", "solver.t_end=0.05")
    assert first.returncode == 0, first.stderr
    out = tmp_path / "out" / "paper.h5"
    source = created(out)[1]
    assert source == f"{scene} --set solver.t_end=0.05"
    time.sleep(1.1)
    again = run("run", scene, "--set", "solver.t_end=0.05", "--set", "output.progress=.false.")
    assert again.returncode == 0, again.stderr
    before = digest(out)
    variant = run("run", scene, "--set", "solver.t_end=0.06")
    assert variant.returncode == 2
    # the refusal names the key that gave the file, where it was given (the scene file)
    assert (f'{scene}: &output: file = "out/paper.h5": exists and holds the run of '
            f'"{source}", not of this run' in variant.stderr), variant.stderr
    assert digest(out) == before
    forced = run("run", scene, "--set", "solver.t_end=0.06", "--force")
    assert forced.returncode == 0, forced.stderr
    assert created(out)[1].endswith("--set solver.t_end=0.06")
    assert not list((tmp_path / "out").glob("*.part")) and not list((tmp_path / "out").glob("*.lock"))


@pytest.mark.parametrize("content", [b"my notes\n", b"\x89HDF\r\n\x1a\n" + bytes(600)])
def test_a_file_ropedyn_did_not_write_is_never_replaced_silently(run, tmp_path, scene, content):
    out = tmp_path / "mine.h5"
    if content.startswith(b"\x89HDF"):
        with h5py.File(out, "w") as f:
            f["data"] = [1.0, 2.0]
    else:
        out.write_bytes(content)
    before = digest(out)
    proc = run("run", scene, "--set", "output.file='mine.h5'", "--set", "solver.t_end=0.01")
    assert proc.returncode == 2, proc.stderr
    assert ("--set output.file='mine.h5': &output: file = \"mine.h5\": exists and is"
            in proc.stderr), proc.stderr
    assert "not replaced" in proc.stderr and "(--force replaces it)" in proc.stderr
    assert digest(out) == before


def test_an_input_is_never_the_output(run, tmp_path, scene):
    table = tmp_path / "top.dat"
    table.write_text("0 0 0 0\n1 0.1 0 0\n")
    before = {p: digest(p) for p in (scene, table)}
    for target in ("paper.nml", "top.dat"):
        proc = run("run", scene, "--set", f"output.file='{target}'", "--set",
                   "supports.top_motion='table'", "--set", "supports.top_table='top.dat'",
                   "--force")
        assert proc.returncode == 2, proc.stderr
        assert "writing it would destroy an input of this run" in proc.stderr
    assert {p: digest(p) for p in before} == before


def test_an_output_that_is_a_directory_names_its_key(run, tmp_path, scene):
    """An output path that is a directory (or a device) is bad input of &output file: the
    message names where the key was set (the scene file or the --set argument), the group,
    the key and the value, with exit code 2 as the other refusals of an output; the
    directory stays as it was."""
    (tmp_path / "somedir").mkdir()
    (tmp_path / "somedir" / "kept.txt").write_text("kept\n")
    reason = ': &output: file = "somedir": exists and is a directory, not a file: not replaced'
    proc = run("run", scene, "--set", "output.file=somedir", "--set", "solver.t_end=0.01")
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.strip() == f"ropedyn: error: --set output.file=somedir{reason}"
    given = tmp_path / "given.nml"
    given.write_text(scene.read_text().replace("'out/paper.h5'", "'somedir'"))
    proc = run("run", given, "--set", "solver.t_end=0.01")
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.strip() == f"ropedyn: error: {given}{reason}"
    assert [p.name for p in (tmp_path / "somedir").iterdir()] == ["kept.txt"]
    (tmp_path / "null.h5").symlink_to("/dev/null")
    proc = run("run", given, "--set", "output.file=null.h5", "--set", "solver.t_end=0.01")
    assert proc.returncode == 2, proc.stderr
    assert '--set output.file=null.h5: &output: file = "null.h5": exists and is a ' \
        "character device" in proc.stderr, proc.stderr


def long_run(ropedyn_exe, cwd, scene, *extra):
    return subprocess.Popen([str(ropedyn_exe), "run", str(scene), "--set", "solver.t_end=30",
                             "--set", "model.elements=60", "--set", "output.progress=.false.",
                             *extra],
                            cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def records_in(part):
    """The complete records of the file a running ropedyn writes, as its last flush left
    them (/time is extended last in a record); 0 while it cannot be read (not yet created,
    or caught between writes). Read without HDF5's file lock, which the writer holds."""
    try:
        with h5py.File(part, "r", locking=False) as f:
            return len(f["time"]) if "time" in f else 0
    except (OSError, KeyError, ValueError, RuntimeError):  # (caught between writes)
        return 0


def counted_steps(part):
    """/solver/steps of the file a running ropedyn writes, as its last flush left it (0
    while there is none). Read without HDF5's file lock, which the writer holds."""
    try:
        with h5py.File(part, "r", locking=False) as f:
            return int(f["solver/steps"][()]) if "solver/steps" in f else 0
    except (OSError, KeyError, ValueError, RuntimeError):  # (caught between writes)
        return 0


def wait_for_records(part, proc, count=2, timeout=120):
    """Wait until the run `proc` has flushed `count` records into `part`. Record 0 is
    written while the run opens its file, before it catches SIGINT and SIGTERM; from
    record 1 on it has caught them (a signal ends it in order, exit 130), and a killed run
    leaves records to resume from. A condition, not a sleep: a loaded machine (a rebuild
    beside the tests) only makes it wait longer."""
    deadline = time.monotonic() + timeout
    while records_in(part) < count:
        assert proc.poll() is None, f"the run ended early: {proc.communicate()[1]}"
        assert time.monotonic() < deadline, f"no {count} records in {part} after {timeout} s"
        time.sleep(0.02)


def test_a_second_run_on_a_locked_file_is_refused(run, ropedyn_exe, tmp_path, scene):
    first = long_run(ropedyn_exe, tmp_path, scene)
    try:
        wait_for_records(tmp_path / "out" / "paper.h5.part", first)
        second = run("run", scene, "--set", "solver.t_end=30", "--set", "model.elements=60")
        assert second.returncode != 0
        assert "out/paper.h5: " in second.stderr and "lock" in second.stderr, second.stderr
    finally:
        first.send_signal(signal.SIGTERM)
        first.wait(60)
    assert first.returncode == 130, first.stderr
    with h5py.File(tmp_path / "out" / "paper.h5") as f:
        assert f.attrs["status"] == b"interrupted"      # the interrupted run ends in FILE


def test_a_killed_run_leaves_the_earlier_file_whole(run, ropedyn_exe, tmp_path, scene):
    sets = ["--set", "solver.t_end=30", "--set", "model.elements=60"]
    (tmp_path / "out").mkdir()
    earlier = run("run", scene, *sets[:2], "--set", "solver.t_end=0.02", "--set",
                  "model.elements=60", "--force")
    assert earlier.returncode == 0, earlier.stderr
    out = tmp_path / "out" / "paper.h5"
    before = digest(out)
    proc = long_run(ropedyn_exe, tmp_path, scene, "--force")
    part = tmp_path / "out" / "paper.h5.part"
    wait_for_records(part, proc)
    # a flush writes the run's counters with its records
    deadline = time.monotonic() + 120
    while counted_steps(part) <= 0:
        assert proc.poll() is None and time.monotonic() < deadline, "no counters flushed"
        time.sleep(0.02)
    proc.kill()
    proc.wait(60)
    assert digest(out) == before and part.exists()
    killed_steps = counted_steps(part)
    refused = run("run", scene, *sets)
    assert refused.returncode == 2
    assert "paper.h5.part: left by a run of out/paper.h5 that was killed" in refused.stderr
    assert ("that was killed: continue it (ropedyn run --resume out/paper.h5.part) or "
            "remove it, or give --force") in refused.stderr
    with h5py.File(part, "r") as f:
        assert f.attrs["status"] == b"running" and len(f["time"]) >= 2
        last = f["time"][-1]
    # a refused resume takes the killed run's lock and gives it back: it goes on naming
    # the killed writer
    nothing = run("run", "--resume", "out/paper.h5.part", "--set", f"solver.t_end={last}")
    assert nothing.returncode == 2 and "nothing to continue" in nothing.stderr, nothing.stderr
    handed_back = (tmp_path / "out" / "paper.h5.lock").read_text()
    assert handed_back.startswith("ropedyn sweep case lock\n") and \
        f"pid={proc.pid}" in handed_back, handed_back
    # its writer is gone (no live lock): continued as it is, with a warning
    resumed = run("run", "--resume", "out/paper.h5.part", "--set", f"solver.t_end={last + 0.05}")
    assert resumed.returncode == 0, resumed.stderr
    assert ("status running: its writer ended without finishing: killed or crashed "
            f"(host {socket.gethostname()}, pid {proc.pid}" in resumed.stderr), resumed.stderr
    assert not (tmp_path / "out" / "paper.h5.lock").exists()
    # the killed part's steps, as of its last flush, are the run's before the resume (the
    # file keeps its .part name: paper.h5 holds a run of another variant)
    with h5py.File(part) as f:
        assert f["solver/restarts/steps"][0] == killed_steps > 0
        assert f["solver/steps"][()] > killed_steps
    assert digest(out) == before


CATENARY = ROOT / "input" / "catenary.nml"


def test_statics_and_modes_replace_only_their_own_result(run, tmp_path):
    """`ropedyn statics|modes -o FILE` followed the run's rules only for inputs and special
    files: before, it replaced any regular file (a run's, a text file) without a word. Now
    it replaces only the same analysis of the same source (a rerun), else exit 2 with the
    file unchanged, unless --force; and a run does not replace a statics or modes file."""
    scene = tmp_path / "c.nml"
    scene.write_text(CATENARY.read_text())
    assert run("run", scene, "--set", "solver.t_end=0.02", "--set",
               "output.file='r.h5'").returncode == 0
    (tmp_path / "notes.txt").write_text("my notes\n")
    kept = {name: digest(tmp_path / name) for name in ("r.h5", "notes.txt")}
    refused = [(("statics", scene, "-o", "r.h5"), "r.h5: exists and holds a run result, "
                "not a statics one: not replaced"),
               (("modes", scene, "-o", "notes.txt"), "notes.txt: exists and is not an HDF5 "
                "file (not written by ropedyn): not replaced (--force replaces it)")]
    for args, words in refused:
        proc = run(*args)
        assert proc.returncode == 2 and words in proc.stderr, proc.stderr
    assert {name: digest(tmp_path / name) for name in kept} == kept

    first = run("statics", scene, "-o", "s.h5")
    assert first.returncode == 0, first.stderr
    with h5py.File(tmp_path / "s.h5") as f:
        assert f.attrs["source"].decode() == str(scene)
    assert run("statics", scene, "-o", "s.h5").returncode == 0       # a rerun
    before = digest(tmp_path / "s.h5")
    for args, words in [
            (("statics", scene, "-o", "s.h5", "--set", "model.elements=20"),
             f's.h5: exists and holds the statics of "{scene}", not of this statics'),
            (("modes", scene, "-o", "s.h5", "--count", "2"),
             "s.h5: exists and holds a statics result, not a modes one"),
            (("run", scene, "--set", "solver.t_end=0.02", "--set", "output.file='s.h5'"),
             "--set output.file='s.h5': &output: file = \"s.h5\": exists and holds a "
             "statics result, not a run one")]:
        proc = run(*args)
        assert proc.returncode == 2 and words in proc.stderr, proc.stderr
    assert digest(tmp_path / "s.h5") == before
    forced = run("modes", scene, "-o", "s.h5", "--count", "2", "--force")
    assert forced.returncode == 0, forced.stderr
    with h5py.File(tmp_path / "s.h5") as f:
        assert f.attrs["analysis"].decode() == "modes" and len(f["modes/omega"]) == 2
    assert not list(tmp_path.glob("*.part"))


def test_statics_and_modes_leave_a_foreign_part_file(run, tmp_path):
    """`ropedyn statics|modes -o FILE` writes FILE.part and renames it: it created that
    name over whatever was there, a killed run's records or a file of the user's. Now a
    FILE.part that is not a statics or modes result (one a killed analysis left) is
    refused with exit 2 and left as it was, unless --force."""
    scene = tmp_path / "c.nml"
    scene.write_text(CATENARY.read_text())
    assert run("run", scene, "--set", "solver.t_end=0.02", "--set",
               "output.file='r.h5'").returncode == 0
    assert run("statics", scene, "-o", "done.h5").returncode == 0
    (tmp_path / "a.h5.part").write_bytes((tmp_path / "r.h5").read_bytes())   # a run's
    (tmp_path / "b.h5.part").write_text("my notes\n")
    (tmp_path / "c.h5.part").write_bytes((tmp_path / "done.h5").read_bytes())
    for name in ("a.h5", "b.h5"):
        before = digest(tmp_path / f"{name}.part")
        for command in ("statics", "modes"):
            proc = run(command, scene, "-o", name)
            assert proc.returncode == 2, proc.stderr
            assert (f"{name}.part: there already, and not a statics or modes result (the file "
                    f"of a run that was killed or goes on: ropedyn run --resume {name}.part "
                    "continues a killed one): not replaced; remove it, or give --force") \
                in proc.stderr, proc.stderr
        assert digest(tmp_path / f"{name}.part") == before
        assert not (tmp_path / name).exists()
    # an analysis' own leftover is taken over; --force takes any
    assert run("modes", scene, "-o", "c.h5", "--count", "2").returncode == 0
    assert run("statics", scene, "-o", "b.h5", "--force").returncode == 0
    assert not (tmp_path / "c.h5.part").exists() and not (tmp_path / "b.h5.part").exists()


def test_a_killed_part_that_cannot_be_read_back_is_not_offered_to_resume(run, tmp_path, scene):
    """A run killed in its first milliseconds, before its first flush, leaves a FILE.part
    that does not open as a run file (only HDF5's superblock: 96 bytes). A resume of it is
    refused; so the next run does not tell to resume it, but to remove it or give --force."""
    out = tmp_path / "out"
    out.mkdir()
    part = out / "paper.h5.part"
    # as a run killed 25 ms after its start left it: HDF5's superblock, its end of file
    # at 2048 bytes
    part.write_bytes(bytes.fromhex(
        "894844460d0a1a0a000000000008080004001000010000000000000000000000"
        "ffffffffffffffff0008000000000000ffffffffffffffff0000000000000000"
        "600000000000000001000000000000008800000000000000a802000000000000"
    ))
    gone = subprocess.Popen(["true"])
    gone.wait()
    (out / "paper.h5.lock").write_text(
        f"ropedyn sweep case lock\nhost={socket.gethostname()}\npid={gone.pid}\n")
    resume = run("run", "--resume", "out/paper.h5.part")
    assert resume.returncode == 2, resume.stderr
    refused = run("run", scene)
    assert refused.returncode == 2
    assert ("out/paper.h5.part: left by a run of out/paper.h5 that was killed, and cannot be "
            "continued (") in refused.stderr, refused.stderr
    assert "remove it, or give --force" in refused.stderr and "--resume" not in refused.stderr
    assert part.stat().st_size == 96                   # left as it is
    forced = run("run", scene, "--set", "solver.t_end=0.02", "--force")
    assert forced.returncode == 0, forced.stderr
    assert not part.exists() and not (out / "paper.h5.lock").exists()


@pytest.mark.skipif(shutil.which("strace") is None,
                    reason="needs strace to kill inside a flush (scripts/setup --tests)")
def test_a_kill_inside_a_flush_leaves_the_counters_no_further_than_the_records(
        run, ropedyn_exe, tmp_path):
    """A run's counters go with its records at each flush. HDF5 writes small datasets first,
    so when the counters were written before the records' flush, a kill inside it left
    counters of records the file did not hold (4852 steps with 33 records, 2444 steps to
    them): a resume counted the lost steps twice. Killed at write after write across
    several flushes (strace), every file's counters are at most those of a run to its last
    record."""
    scene = tmp_path / "s.nml"
    scene.write_text((ROOT / "input" / "paper.nml").read_text()
                     .replace("elements = 30", "elements = 60")
                     .replace("t_end = 30.0 ", "t_end = 2.0 "))
    steps_to = {}
    checked = 0
    for when in range(100, 160, 4):
        part = tmp_path / "out" / "paper.h5.part"
        part.unlink(missing_ok=True)
        (tmp_path / "out" / "paper.h5.lock").unlink(missing_ok=True)
        subprocess.run(["strace", "-f", "-o", "/dev/null", "-e", "trace=pwrite64", "-e",
                        f"inject=pwrite64:signal=KILL:when={when}", str(ropedyn_exe), "run",
                        str(scene), "--set", "output.progress=.false."],
                       cwd=tmp_path, capture_output=True, timeout=300)
        try:
            with h5py.File(part, "r") as f:
                last = float(f["time"][-1])
                steps = int(f["solver/steps"][()]) if "solver/steps" in f else 0
        except (OSError, KeyError, ValueError, RuntimeError):
            continue        # killed before its first whole flush: nothing to compare
        if last not in steps_to:
            ref = run("run", scene, "--set", f"solver.t_end={last!r}", "--set",
                      f"output.file=ref{len(steps_to)}.h5")
            assert ref.returncode == 0, ref.stderr
            with h5py.File(tmp_path / f"ref{len(steps_to)}.h5") as f:
                steps_to[last] = int(f["solver/steps"][()])
        assert steps <= steps_to[last], (when, last, steps, steps_to[last])
        checked += 1
    assert checked >= 5, checked


@pytest.mark.skipif(shutil.which("strace") is None,
                    reason="needs strace to kill at a write (scripts/setup --tests)")
def test_a_run_killed_while_taking_its_lock_leaves_no_empty_lock(run, ropedyn_exe, tmp_path,
                                                                 scene):
    """A lock was created, then its holder written into it: a run killed in between left an
    empty FILE.lock, which held FILE for 120 s ("live while young", as nobody could tell its
    writer). The lock now appears with its holder or not at all. Killed at its first write
    (the holder's lines), the run leaves no lock, or a whole one, and a run at once goes on."""
    lock = tmp_path / "out" / "paper.h5.lock"
    subprocess.run(["strace", "-f", "-o", "/dev/null", "-e", "trace=write", "-e",
                    "inject=write:signal=KILL:when=1", str(ropedyn_exe), "run", str(scene),
                    "--set", "solver.t_end=0.02", "--set", "output.progress=.false."],
                   cwd=tmp_path, capture_output=True, timeout=300)
    assert not lock.exists() or lock.read_text().startswith("ropedyn sweep case lock\nhost=")
    assert not list((tmp_path / "out").glob("paper.h5.lock.*")), \
        list((tmp_path / "out").iterdir())
    again = run("run", scene, "--set", "solver.t_end=0.02")
    assert again.returncode == 0, again.stderr
    assert (tmp_path / "out" / "paper.h5").exists() and not lock.exists()


def test_a_killed_file_is_continued_from_its_last_whole_record(run, tmp_path, scene):
    """A run killed inside a flush can leave series of unequal length (HDF5 writes them one
    after the other). The resume of such a file (status running) was refused (exit 4,
    "/forces/shear: fewer records than /time"), and the user's only way on was --force, a
    new run. It now continues from the last record every series reads back, cuts the
    others, and says so."""
    assert run("run", scene, "--set", "solver.t_end=0.5", "--set",
               "output.file='k.h5'").returncode == 0
    with h5py.File(tmp_path / "k.h5", "r+") as f:
        f.attrs["status"] = np.bytes_("running")
        records = f["time"].shape[0]
        f["forces/shear"].resize(records - 3, axis=0)
    resumed = run("run", "--resume", "k.h5", "--set", "solver.t_end=0.6")
    assert resumed.returncode == 0, resumed.stderr
    assert (f"continued from its last whole record (record {records - 4}; the 3 after it "
            "did not all read back: the run was killed while writing them)") in resumed.stderr
    with h5py.File(tmp_path / "k.h5") as f:
        assert f.attrs["status"] == b"complete"
        assert f["solver/restarts/record"][:].tolist() == [records - 4]
        assert abs(f["time"][-1] - 0.6) < 1e-12
        assert all(f[name].shape[0] == f["time"].shape[0]
                   for name in ("forces/shear", "forces/axial", "state/y", "energy/total"))


def test_a_resume_of_a_file_is_refused_while_its_killed_rerun_is_there(run, tmp_path, scene):
    """A rerun of FILE, killed, leaves FILE.part (status running), which replaces FILE when
    it is continued. A resume of FILE in between went on, and the later resume of FILE.part
    replaced what it had added, without a word (the file-safety probe). It is refused, as a
    new run of FILE is, before FILE's lock is taken (the killed writer's). A killed run of
    another variant keeps its .part name when continued: then the resume goes on."""
    assert run("run", scene, "--set", "solver.t_end=0.05", "--set",
               "output.file='r.h5'").returncode == 0
    part, lock = tmp_path / "r.h5.part", tmp_path / "r.h5.lock"
    part.write_bytes((tmp_path / "r.h5").read_bytes())
    with h5py.File(part, "r+") as f:
        f.attrs["status"] = np.bytes_("running")
    gone = subprocess.Popen(["true"])
    gone.wait()
    lock.write_text(f"ropedyn sweep case lock\nhost={socket.gethostname()}\npid={gone.pid}\n")
    before = digest(tmp_path / "r.h5")
    refused = run("run", "--resume", "r.h5", "--set", "solver.t_end=0.1")
    assert refused.returncode == 2, refused.stderr
    assert ("r.h5: r.h5.part is there, left by a rerun of r.h5 that was killed: continued, "
            "it replaces r.h5 at its end") in refused.stderr, refused.stderr
    assert digest(tmp_path / "r.h5") == before and f"pid={gone.pid}" in lock.read_text()
    with h5py.File(part, "r+") as f:
        f.attrs["source"] = np.bytes_("another variant")
    resumed = run("run", "--resume", "r.h5", "--set", "solver.t_end=0.1")
    assert resumed.returncode == 0, resumed.stderr


def test_a_new_run_offers_to_continue_a_killed_part_with_a_whole_record(run, tmp_path, scene):
    """A FILE.part whose last record a kill cut (here /state/y three records short) has
    earlier whole records: a resume goes on from the last of them. The refusal of a new run
    of FILE said it could not be continued (the last record does not read back) and left
    only removing it or --force; it now offers the resume, which then goes on."""
    sets = ("--set", "solver.t_end=0.05", "--set", "output.file='k.h5'")
    assert run("run", scene, *sets).returncode == 0
    part = tmp_path / "k.h5.part"
    (tmp_path / "k.h5").rename(part)
    with h5py.File(part, "r+") as f:
        f.attrs["status"] = np.bytes_("running")
        f["state/y"].resize(f["time"].shape[0] - 3, axis=0)
    refused = run("run", scene, *sets)
    assert refused.returncode == 2, refused.stderr
    assert ("k.h5.part: left by a run of k.h5 that was killed: continue it (ropedyn run "
            "--resume k.h5.part)") in refused.stderr, refused.stderr
    resumed = run("run", "--resume", "k.h5.part")
    assert resumed.returncode == 0, resumed.stderr
    assert "continued from its last whole record" in resumed.stderr
