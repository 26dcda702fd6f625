"""Hostile runs: what the hostile corpus (test_hostile.py) cannot hold because it needs a
run file, a running process or a special file. Resumes and starts from run files edited
with h5py; outputs that are special files or held by another program; FIFOs and devices
as inputs; a full file system (an LD_PRELOAD shim that fails writes as a full disk does,
`ulimit -f`, and a small tmpfs where mounting is allowed); the resume from a record with
velocities of 1e50, which hung; two runners on one sweep. Each case asserts the exit code,
its one message line, that no protected file changed (checksums) and that no run file is
left 'running' (docs/guide/output.md, "Write, lock and resume rules")."""
import hashlib
import os
import shutil
import signal
import subprocess
import time

import h5py
import numpy as np
import pytest

CRASH_TEXT = ("Fortran runtime", "Backtrace", "Segmentation", "Error termination",
              "Program received signal", "SIGSEGV", "SIGABRT", "malloc")



def scene(initial="shape = 'straight', angle_deg = 30.0", file="run.h5", extra=""):
    """A light rope (0.12 kg): 21 records of 6 elements in well under a second."""
    return f"""&rope length = 1.0, density = 6000.0, diameter = 0.005 /
&model kind = 'rfem', elements = 6 /
&initial {initial} /
&solver method = 'cvode', t_end = 0.2, output_interval = 0.01 /
&output file = '{file}' /
{extra}"""


SCENE = scene()
# many records, for the full-disk cases (a file of several MiB)
LONG_SCENE = """&model kind = 'rfem', elements = 10 /
&solver t_end = 20.0, output_interval = 0.001 /
&output file = 'long.h5' /
"""
SWEEP = """&sweep base = 'long.nml'
  elements = 10, 11
  set = 'solver.t_end=5.0'
  output_dir = 'out'
/
"""


def run_in(ropedyn_exe, cwd, *args, timeout=120, env=None, preexec=None):
    return subprocess.run([str(ropedyn_exe), *map(str, args)], cwd=cwd, capture_output=True,
                          text=True, errors="replace", timeout=timeout, env=env,
                          preexec_fn=preexec)


def checksums(root):
    """sha256 of every regular file below root (FIFOs, devices, links to them skipped)."""
    sums = {}
    for p in sorted(root.rglob("*")):
        if p.is_file() and not p.is_fifo() and not p.is_char_device():
            sums[p.relative_to(root)] = hashlib.sha256(p.read_bytes()).hexdigest()
    return sums


def statuses(root):
    """The status of every HDF5 file below root that can be read."""
    found = {}
    for p in root.rglob("*.h5*"):
        if not p.is_file() or p.is_fifo():
            continue
        try:
            with h5py.File(p, "r") as f:
                status = f.attrs.get("status")
        except OSError:
            continue
        if isinstance(status, bytes):
            status = status.decode()
        found[p.name] = status
    return found


def attr(f, name):
    value = f.attrs[name]
    return value.decode() if isinstance(value, bytes) else str(value)


def assert_fails(result, code, fragment):
    """The exit code, one 'ropedyn: error:' line holding `fragment`, no crash text."""
    assert result.returncode == code, result.stderr
    lines = [x for x in result.stderr.splitlines() if x.startswith("ropedyn: error: ")]
    assert len(lines) == 1, result.stderr
    assert fragment in lines[0], f"{fragment!r} not in {lines[0]!r}"
    for text in CRASH_TEXT:
        assert text not in result.stderr + result.stdout, result.stderr


def assert_none_running(root):
    running = [name for name, status in statuses(root).items() if status == "running"]
    assert not running, running


@pytest.fixture
def work(tmp_path, ropedyn_exe):
    """A directory with the scene and its complete run file run.h5 (0 .. 0.2 s)."""
    (tmp_path / "s.nml").write_text(SCENE)
    done = run_in(ropedyn_exe, tmp_path, "run", "s.nml")
    assert done.returncode == 0, done.stderr
    return tmp_path


def refused(ropedyn_exe, root, args, code, fragment, **kw):
    """Run, expect a refusal, and that nothing changed and nothing is 'running'."""
    before = checksums(root)
    result = run_in(ropedyn_exe, root, *args, **kw)
    assert_fails(result, code, fragment)
    assert checksums(root) == before, "a refused run must not change a file"
    assert_none_running(root)
    return result


def set_y(f, value):
    f["state/y"][-1, :] = value


def set_time(f, value):
    f["time"][-1] = value


def reverse_time(f):
    f["time"][...] = f["time"][()][::-1]


def set_status(value):
    def edit(f):
        del f.attrs["status"]
        f.attrs["status"] = value
    return edit


def nan_energy(f):
    f["energy/kinetic"][0] = np.nan


def fixed(name):
    def edit(f):
        values = f[name][()]
        del f[name]
        f[name] = values
    return edit


def fixed_restarts(f):
    f.create_group("solver/restarts")["time"] = np.zeros(1)


# resuming a run file edited with h5py (with a longer t_end: the file is complete)
RESUME_EDITS = [
    ("velocity_1e200", lambda f: set_y(f, 1e200), 2,
     "/state/y: record 20 (t = 0.2 s): value 1 = 1.0e200: beyond the limits of a scene"),
    ("time_1e16", lambda f: set_time(f, 1e16), 2, "/time: record 20: t = 1.0e16 s: not a time"),
    ("time_reversed", reverse_time, 2, "/time: record 1 (t = 0.19 s) is not after record 0"),
    ("status_banana", set_status("banana"), 2, 'status "banana": not a status'),
    ("status_integer", set_status(np.int32(3)), 2, "attribute status: not a string"),
    ("energy_nan", nan_energy, 2, "/energy/kinetic: record 0 (t = 0.0 s): value 1 = NaN"),
    ("state_y_fixed", fixed("state/y"), 2, "/state/y: not extendible"),
    ("kinetic_fixed", fixed("energy/kinetic"), 2, "/energy/kinetic: not extendible"),
    ("restarts_replaced", fixed_restarts, 2, "/solver/restarts/time: not extendible"),
]


@pytest.mark.parametrize("edit,code,fragment", [pytest.param(*c[1:], id=c[0])
                                                for c in RESUME_EDITS])
def test_resume_of_an_edited_file_is_refused(ropedyn_exe, work, edit, code, fragment):
    with h5py.File(work / "run.h5", "r+") as f:
        f.attrs["status"] = "interrupted"
        f.attrs["reason"] = "stopped for the test"
        edit(f)
    refused(ropedyn_exe, work, ["run", "--resume", "run.h5", "--set", "solver.t_end=0.4"],
            code, fragment)
    if "status" not in fragment:
        with h5py.File(work / "run.h5", "r") as f:   # a refused file keeps its status
            assert attr(f, "status") == "interrupted" and "reason" in f.attrs


@pytest.mark.parametrize("override,fragment", [
    ("OUTPUT.FILE=other.h5", "--resume appends to run.h5; output.file cannot be set"),
    (" output.file = other.h5", "--resume appends to run.h5; output.file cannot be set"),
    ("solver.output_interval=0.02", "a resume keeps the output grid of the file"),
])
def test_resume_keeps_file_and_grid(ropedyn_exe, work, override, fragment):
    refused(ropedyn_exe, work, ["run", "--resume", "run.h5", "--set", "solver.t_end=0.4",
                                "--set", override], 2, fragment)
    assert not (work / "other.h5").exists()


def test_start_from_an_edited_state_file_is_refused(ropedyn_exe, work):
    with h5py.File(work / "run.h5", "r+") as f:
        f["state/qdot"][-1, :, :] = 1e200
    (work / "from.nml").write_text(scene("shape = 'state', state_file = 'run.h5'", "from.h5"))
    refused(ropedyn_exe, work, ["run", "from.nml"], 2,
            "/state/qdot: record 20 (t = 0.2 s): value 1 = 1.0e200: beyond the limits")


def light_velocity_file(work):
    """run.h5 with velocities of 1e50 at its last record: within the light rope's limits
    (2.9e50), far beyond anything an integrator can follow."""
    with h5py.File(work / "run.h5", "r+") as f:
        f.attrs["status"] = "interrupted"
        f["state/y"][-1, 18:] = 1e50


def test_resume_at_velocity_1e50_ends(ropedyn_exe, work):
    """Hung for ever inside auto (its look-ahead rounded back to t); now a failed run."""
    light_velocity_file(work)
    result = run_in(ropedyn_exe, work, "run", "--resume", "run.h5", "--set",
                    "solver.t_end=0.4", "--set", "solver.method='auto'", timeout=60)
    assert_fails(result, 3, "auto: ")
    assert_none_running(work)
    with h5py.File(work / "run.h5", "r") as f:
        assert attr(f, "status") == "failed"


def test_resume_at_velocity_1e50_ends_on_sigterm(ropedyn_exe, work):
    light_velocity_file(work)
    proc = subprocess.Popen([str(ropedyn_exe), "run", "--resume", "run.h5", "--set",
                             "solver.t_end=0.4", "--set", "solver.method='erk'"], cwd=work,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    proc.send_signal(signal.SIGTERM)
    _, stderr = proc.communicate(timeout=60)
    # ended by the signal itself (before its handler was set), interrupted, or failed
    assert proc.returncode in (3, 130, -signal.SIGTERM, 128 + signal.SIGTERM), stderr
    assert_none_running(work)


def test_output_link_to_a_device_is_refused(ropedyn_exe, work):
    (work / "null.h5").symlink_to("/dev/null")
    refused(ropedyn_exe, work, ["run", "s.nml", "--set", "output.file=null.h5"], 2,
            'output.file=null.h5: &output: file = "null.h5": exists and is a character '
            "device, not a regular file: not replaced")


def test_output_held_by_a_reader_is_not_truncated(ropedyn_exe, work):
    """A rerun writes run.h5.part and renames it over run.h5: the reader keeps reading the
    file it opened, whole, and then finds the new one (truncating it in place, the run
    emptied the reader's file)."""
    with h5py.File(work / "run.h5", "r") as held:
        result = run_in(ropedyn_exe, work, "run", "s.nml")
        assert result.returncode == 0, result.stderr
        assert attr(held, "status") == "complete" and len(held["time"]) == 21
    with h5py.File(work / "run.h5", "r") as f:
        assert attr(f, "status") == "complete" and len(f["time"]) == 21


def test_resume_of_a_file_being_written_names_the_writer(ropedyn_exe, work):
    """A file another program holds open is an output being written: exit 4, as for a
    live lock (docs/reference/exit-codes.md), not the 2 of a file that is no run file."""
    with h5py.File(work / "run.h5", "a"):
        refused(ropedyn_exe, work, ["run", "--resume", "run.h5", "--set", "solver.t_end=0.4"],
                4, f"run.h5: cannot open: locked by pid {os.getpid()}")


@pytest.mark.parametrize("name,fragment", [
    ("x" * 300 + ".h5", "cannot create file: File name too long"),
    ("loop.h5", "loop.h5: cannot create file: Too many levels of symbolic links"),
    ("s.nml/x.h5", 'cannot create directory "s.nml": Not a directory'),
])
def test_create_errors_give_the_system_reason(ropedyn_exe, work, name, fragment):
    (work / "loop.h5").symlink_to("loop2.h5")
    (work / "loop2.h5").symlink_to("loop.h5")
    refused(ropedyn_exe, work, ["run", "s.nml", "--set", f"output.file={name}"], 4, fragment)


def test_a_link_to_a_file_not_there_yet_is_written_through(ropedyn_exe, work):
    """An output that is a link to a file not there yet (a dangling link, also through a
    second link) is written where the link points, in directories made for it, and the
    links stay; before, canonical_path kept the link's own name and the run's file
    replaced the link, the target never written. So for statics and modes."""
    (work / "lk.h5").symlink_to("sub/new.h5")
    (work / "hop.h5").symlink_to("lk2.h5")
    (work / "lk2.h5").symlink_to("deeper/dir/st.h5")
    result = run_in(ropedyn_exe, work, "run", "s.nml", "--set", "output.file=lk.h5")
    assert result.returncode == 0, result.stderr
    result = run_in(ropedyn_exe, work, "statics", "s.nml", "-o", "hop.h5")
    assert result.returncode == 0, result.stderr
    for link, target in (("lk.h5", "sub/new.h5"), ("hop.h5", "lk2.h5"),
                         ("lk2.h5", "deeper/dir/st.h5")):
        assert (work / link).is_symlink() and os.readlink(work / link) == target
    with h5py.File(work / "sub" / "new.h5", "r") as f:
        assert attr(f, "status") == "complete"
    with h5py.File(work / "deeper" / "dir" / "st.h5", "r") as f:
        assert attr(f, "analysis") == "statics"


def test_statics_and_modes_never_write_their_scene(ropedyn_exe, work):
    (work / "link.h5").symlink_to("s.nml")
    os.link(work / "s.nml", work / "hard.h5")
    refused(ropedyn_exe, work, ["statics", "s.nml", "-o", "link.h5"], 2,
            'link.h5: the output file is the scene file "s.nml"')
    refused(ropedyn_exe, work, ["modes", "s.nml", "-o", "hard.h5"], 2,
            'hard.h5: the output file is the scene file "s.nml"')
    # a run names the key that gave the file
    refused(ropedyn_exe, work, ["run", "s.nml", "--set", "output.file=link.h5"], 2,
            '--set output.file=link.h5: &output: file = "link.h5": the output file is the '
            'scene file "s.nml"')


@pytest.mark.parametrize("what", ["scene", "table", "sweep", "state", "resume", "lock"])
def test_a_fifo_is_not_read(ropedyn_exe, work, what):
    """A FIFO blocked every reader for ever; it is refused before it is opened."""
    os.mkfifo(work / "fifo")
    if what == "scene":
        args, fragment = ["run", "fifo"], "fifo: cannot read: a FIFO (named pipe)"
    elif what == "table":
        (work / "t.nml").write_text(scene(extra="&supports top_motion = 'table', "
                                          "top_table = 'fifo' /\n"))
        args, fragment = ["run", "t.nml"], 'top_table = "' + str(work / "fifo") + \
            '": cannot read: a FIFO'
    elif what == "sweep":
        args, fragment = ["sweep", "fifo", "--list"], "fifo: cannot read: a FIFO"
    elif what == "state":
        (work / "t.nml").write_text(scene("shape = 'state', state_file = 'fifo'", "t.h5"))
        args, fragment = ["run", "t.nml"], "fifo: cannot open: a FIFO (named pipe)"
    elif what == "resume":
        args, fragment = ["run", "--resume", "fifo"], "fifo: cannot open: a FIFO"
    else:
        (work / "long.nml").write_text(LONG_SCENE)
        (work / "sweep.nml").write_text(SWEEP)
        (work / "out").mkdir()
        os.mkfifo(work / "out" / ".case_0001.lock")
        args, fragment = ["sweep", "sweep.nml", "--task", "1"], \
            ".case_0001.lock: a FIFO (named pipe), not a regular file (a lock is a regular"
    code = 4 if what == "lock" else 2
    refused(ropedyn_exe, work, args, code, fragment, timeout=30)


def test_byte_order_mark_is_skipped(ropedyn_exe, work):
    (work / "bom.nml").write_bytes(b"\xef\xbb\xbf" + scene(file="b.h5").encode())
    result = run_in(ropedyn_exe, work, "run", "bom.nml")
    assert result.returncode == 0, result.stderr


# --- a full file system -------------------------------------------------------------------

SHIM = r"""
/* A full file system for the test: a write to a regular file that ends beyond
 * FULL_DISK_BYTES fails with ENOSPC unless that room was reserved before (fallocate), and
 * reserving beyond it fails too: a file system with that many bytes free. */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <errno.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>
static long long limit = -2;
static struct { ino_t ino; off_t end; } kept[64];
static long long get_limit(void)
{
    if (limit == -2) { const char *s = getenv("FULL_DISK_BYTES"); limit = s ? atoll(s) : -1; }
    return limit;
}
static off_t kept_end(ino_t ino)
{
    for (int k = 0; k < 64; k++) if (kept[k].ino == ino) return kept[k].end;
    return 0;
}
static void keep(ino_t ino, off_t end)
{
    for (int k = 0; k < 64; k++)
        if (kept[k].ino == ino || kept[k].ino == 0) {
            kept[k].ino = ino;
            if (end > kept[k].end) kept[k].end = end;
            return;
        }
}
static int full(int fd, off_t end)
{
    struct stat st;
    if (get_limit() < 0 || fd < 3 || fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) return 0;
    return end > limit && end > kept_end(st.st_ino);
}
ssize_t pwrite(int fd, const void *b, size_t n, off_t off)
{
    static ssize_t (*real)(int, const void *, size_t, off_t);
    if (!real) real = (ssize_t (*)(int, const void *, size_t, off_t))dlsym(RTLD_NEXT, "pwrite");
    if (full(fd, off + (off_t)n)) { errno = ENOSPC; return -1; }
    return real(fd, b, n, off);
}
ssize_t pwrite64(int fd, const void *b, size_t n, off_t off) { return pwrite(fd, b, n, off); }
ssize_t write(int fd, const void *b, size_t n)
{
    static ssize_t (*real)(int, const void *, size_t);
    off_t cur;
    if (!real) real = (ssize_t (*)(int, const void *, size_t))dlsym(RTLD_NEXT, "write");
    if (fd >= 3 && (cur = lseek(fd, 0, SEEK_CUR)) >= 0 && full(fd, cur + (off_t)n)) {
        errno = ENOSPC;
        return -1;
    }
    return real(fd, b, n);
}
int fallocate(int fd, int mode, off_t off, off_t len)
{
    struct stat st;
    static int (*real)(int, int, off_t, off_t);
    if (!real) real = (int (*)(int, int, off_t, off_t))dlsym(RTLD_NEXT, "fallocate");
    if (get_limit() >= 0 && fstat(fd, &st) == 0 && S_ISREG(st.st_mode)) {
        if (off + len > limit) { errno = ENOSPC; return -1; }
        keep(st.st_ino, off + len);
    }
    return real(fd, mode, off, len);
}
int fallocate64(int fd, int mode, off_t off, off_t len) { return fallocate(fd, mode, off, len); }
"""


@pytest.fixture(scope="session")
def full_disk_shim(tmp_path_factory):
    compiler = shutil.which("cc") or shutil.which("gcc")
    if not compiler:
        pytest.skip("no C compiler for the full-disk shim")
    d = tmp_path_factory.mktemp("shim")
    (d / "full_disk.c").write_text(SHIM)
    subprocess.run([compiler, "-shared", "-fPIC", "-O1", "-o", str(d / "full_disk.so"),
                    str(d / "full_disk.c"), "-ldl"], check=True)
    return d / "full_disk.so"


def shim_env(shim, free_bytes):
    return dict(os.environ, LD_PRELOAD=str(shim), FULL_DISK_BYTES=str(free_bytes))


@pytest.mark.parametrize("free_bytes", [100_000, 3_000_000])
def test_full_disk_ends_in_a_failed_file(ropedyn_exe, tmp_path, full_disk_shim, free_bytes):
    """Before: SIGSEGV inside HDF5 at exit, or 'cannot write record N' with the file
    'running'. Now the run stops while it can still close its file, marked failed."""
    (tmp_path / "long.nml").write_text(LONG_SCENE)
    result = run_in(ropedyn_exe, tmp_path, "run", "long.nml",
                    env=shim_env(full_disk_shim, free_bytes))
    assert_fails(result, 4, "long.h5: No space left on device")
    assert "the file is closed with status failed" in result.stderr
    with h5py.File(tmp_path / "long.h5", "r") as f:
        assert attr(f, "status") == "failed"
        assert "No space left on device" in attr(f, "reason")
        assert len(f["time"]) < 20001 and f["state/y"].shape[0] >= len(f["time"])


def test_file_size_limit_ends_in_a_failed_file(ropedyn_exe, tmp_path):
    """ulimit -f: SIGXFSZ ended the run (exit 153), its file 'running'."""
    import resource

    def limit():
        resource.setrlimit(resource.RLIMIT_FSIZE, (6_000_000, 6_000_000))

    (tmp_path / "long.nml").write_text(LONG_SCENE)
    result = run_in(ropedyn_exe, tmp_path, "run", "long.nml", preexec=limit)
    assert_fails(result, 4, "long.h5: File too large")
    with h5py.File(tmp_path / "long.h5", "r") as f:
        assert attr(f, "status") == "failed" and len(f["time"]) > 0
        # the reason the file keeps names it where it is, as the message does (it named
        # long.h5.part, where the run wrote it)
        assert attr(f, "reason").startswith("long.h5: File too large"), attr(f, "reason")


def test_tmpfs_full(ropedyn_exe, tmp_path):
    """A real full file system: a tmpfs of 3 MiB (root only; skipped elsewhere)."""
    mnt = tmp_path / "mnt"
    mnt.mkdir()
    if os.geteuid() != 0 or not shutil.which("mount"):
        pytest.skip("mounting a tmpfs needs root (the LD_PRELOAD and ulimit cases cover it)")
    mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=3m", "tmpfs", str(mnt)],
                             capture_output=True, text=True)
    if mounted.returncode != 0:
        pytest.skip(f"mount not allowed here: {mounted.stderr.strip()}")
    try:
        (tmp_path / "long.nml").write_text(LONG_SCENE)
        result = run_in(ropedyn_exe, tmp_path, "run", "long.nml", "--set",
                        "output.file=mnt/long.h5")
        assert_fails(result, 4, "mnt/long.h5: No space left on device")
        with h5py.File(mnt / "long.h5", "r") as f:
            assert attr(f, "status") == "failed" and len(f["time"]) > 0
    finally:
        subprocess.run(["umount", str(mnt)], check=False)


def test_sweep_on_a_full_disk_reports_failed_cases(ropedyn_exe, tmp_path, full_disk_shim):
    """Every worker ended by signal 11 before."""
    (tmp_path / "long.nml").write_text(LONG_SCENE)
    (tmp_path / "sweep.nml").write_text(SWEEP)
    result = run_in(ropedyn_exe, tmp_path, "sweep", "sweep.nml", "--jobs", "2",
                    env=shim_env(full_disk_shim, 1_000_000), timeout=300)
    assert result.returncode == 3, result.stderr
    assert "ended by" not in result.stderr and "failed (exit 4" in result.stderr
    for text in CRASH_TEXT:
        assert text not in result.stderr
    assert_none_running(tmp_path)
    logs = "".join(p.read_text() for p in (tmp_path / "out").glob("case_*.log"))
    assert "No space left on device" in logs


def test_two_runners_on_one_sweep(ropedyn_exe, tmp_path):
    """The second runner reported the first one's cases as failed. The first runner takes
    case 1 (short); the second, started then, takes cases 2 and 3 (longer); when the first
    gets to case 2 the second is at it: 'not run here: being written by ...'."""
    (tmp_path / "long.nml").write_text(LONG_SCENE)
    (tmp_path / "sweep.nml").write_text(SWEEP.replace("10, 11", "8, 40, 41"))
    first = subprocess.Popen([str(ropedyn_exe), "sweep", "sweep.nml", "--jobs", "1"],
                             cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                             text=True)
    try:
        lock = tmp_path / "out" / ".case_0001.lock"
        for _ in range(600):
            if lock.exists() or first.poll() is not None:
                break
            time.sleep(0.05)
        assert lock.exists(), "the first runner never took case 1"
        second = run_in(ropedyn_exe, tmp_path, "sweep", "sweep.nml", "--jobs", "2",
                        timeout=600)
        _, first_err = first.communicate(timeout=600)
    finally:
        if first.poll() is None:
            first.kill()
    both = first_err + second.stderr
    assert "failed (exit" not in both, both
    assert "case 0002 not run here: being written by host" in first_err, first_err
    assert "1 case(s) being written by another process, not started here" in second.stderr
    assert_none_running(tmp_path)
