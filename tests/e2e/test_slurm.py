"""Sweeps on a real single-node Slurm cluster, started once for this module:
scripts/slurm/submit queues the job arrays (several cases per task; split at the cluster's
MaxArraySize, 6 here) and the dependent summary job; the summary must equal the local
runner's (same cases, same results up to floating-point reproducibility; times differ).
Also: two submissions of one sweep at once (one writer per case; the second is warned, the
task that finds its case taken fails and its summary job says so), `submit --missing`
(queues only the cases not complete, keeps the earlier logs), a cancelled task (its case is
`interrupted`, the summary job names the CANCELLED task).

The test starts its own cluster on localhost, as root: munged (own key, socket and files in
a temporary directory), slurmctld and slurmd in the foreground (-D) as child processes,
with a slurm.conf for one node with 2 CPUs (select/cons_tres, proctrack/linuxproc,
task/none, no cgroups, no accounting) on free ports; clients find it through SLURM_CONF.
A requeued task may start again after cred_expire (Slurm's default 120 s), and pending
tasks are looked at by the main scheduling loop (every 60 s by default): here 10 s and 2 s,
so that the requeue test waits seconds, not three minutes.
It stops exactly the processes it started. It skips (saying why) when not root or when
Slurm or munge are not installed: scripts/setup installs slurm-wlm and munge.
"""
import csv
import os
import pathlib
import shutil
import socket
import subprocess
import tempfile
import time

import h5py
import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
SUBMIT = ROOT / "scripts" / "slurm" / "submit"
DAEMONS = ("munged", "mungekey", "slurmctld", "slurmd", "sbatch", "sinfo", "squeue")

BASE = """&model kind = 'rfem', elements = 4 /
&solver t_end = 0.2, output_interval = 0.01 /
"""
SWEEP = """&sweep
    base = 'base.nml'
    elements = 4, 6
    methods = 'cvode', 'mebdf'
    rtols = 1e-4, 1e-6
    vary = 'solver.max_steps = 100000; 20'
/
"""

# columns that hold timings (differ between runs) or the case file name (differs by dir)
VOLATILE = {"wall_time", "cpu_time", "file"}

# one case of a few seconds (Debug build), to be caught while it runs
# cases that run for seconds (MEBDF, the slowest method: with the default method they ended
# before a second array could find them being written)
LONG = """&sweep
    base = 'base.nml'
    set = 'solver.t_end={t_end}', 'model.elements=20', 'solver.method="mebdf"'
    rtols = {rtols}
/
"""


def _missing_tools():
    return [t for t in DAEMONS if shutil.which(t) is None
            and not pathlib.Path("/usr/sbin", t).exists()]


def _tool(name):
    return shutil.which(name) or str(pathlib.Path("/usr/sbin", name))


def _free_ports(count):
    socks = []
    for _ in range(count):
        s = socket.socket()
        s.bind(("127.0.0.1", 0))
        socks.append(s)
    ports = [s.getsockname()[1] for s in socks]
    for s in socks:
        s.close()
    return ports


class LocalSlurm:
    """munged + slurmctld + slurmd for one node named localhost, all files in `root`."""

    def __init__(self, root):
        self.root = pathlib.Path(root)
        self.procs = []
        self.munged_pid = None
        self.env = dict(os.environ, SLURM_CONF=str(self.root / "slurm.conf"))

    def log_tail(self):
        text = []
        for name in ("munged.log", "slurmctld.log", "slurmd.log"):
            path = self.root / name
            if path.exists():
                text.append(f"--- {name}\n" + "\n".join(path.read_text().splitlines()[-25:]))
        return "\n".join(text)

    def start(self, timeout=60):
        r = self.root
        for d in ("state", "spool", "munge"):
            (r / d).mkdir(mode=0o700)
        key = r / "munge" / "munge.key"
        subprocess.run([_tool("mungekey"), "--create", f"--keyfile={key}"], check=True,
                       capture_output=True)
        key.chmod(0o400)
        socket_path = r / "munge" / "munge.socket"
        subprocess.run([_tool("munged"), "--force", f"--key-file={key}",
                        f"--socket={socket_path}", f"--pid-file={r / 'munge' / 'munged.pid'}",
                        f"--log-file={r / 'munged.log'}", f"--seed-file={r / 'munge' / 'seed'}"],
                       check=True, capture_output=True)
        self.munged_pid = int((r / "munge" / "munged.pid").read_text())
        ctld_port, slurmd_port = _free_ports(2)
        (r / "slurm.conf").write_text(f"""\
ClusterName=ropedyntest
SlurmctldHost=localhost
SlurmctldPort={ctld_port}
SlurmdPort={slurmd_port}
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket={socket_path},cred_expire=10
CredType=cred/munge
StateSaveLocation={r / 'state'}
SlurmdSpoolDir={r / 'spool'}
SlurmctldPidFile={r / 'slurmctld.pid'}
SlurmdPidFile={r / 'slurmd.pid'}
SlurmctldLogFile={r / 'slurmctld.log'}
SlurmdLogFile={r / 'slurmd.log'}
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/builtin
SchedulerParameters=sched_interval=2
MpiDefault=none
ReturnToService=2
SlurmdParameters=config_overrides
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
MaxArraySize=6
MinJobAge=600
NodeName=localhost NodeAddr=127.0.0.1 CPUs=2 State=UNKNOWN
PartitionName=test Nodes=localhost Default=YES MaxTime=INFINITE State=UP
""")
        conf = str(r / "slurm.conf")
        self.procs.append(subprocess.Popen([_tool("slurmctld"), "-D", "-i", "-f", conf],
                                           env=self.env, stdout=subprocess.DEVNULL,
                                           stderr=open(r / "slurmctld.err", "w")))
        self.procs.append(subprocess.Popen([_tool("slurmd"), "-D", "-N", "localhost", "-f", conf],
                                           env=self.env, stdout=subprocess.DEVNULL,
                                           stderr=open(r / "slurmd.err", "w")))
        deadline = time.monotonic() + timeout
        state = ""
        while time.monotonic() < deadline:
            for p in self.procs:
                if p.poll() is not None:
                    raise RuntimeError(f"{p.args[0]} exited with {p.returncode}\n"
                                       + self.log_tail())
            out = subprocess.run(["sinfo", "-h", "-N", "-o", "%T"], env=self.env,
                                 capture_output=True, text=True)
            state = out.stdout.strip()
            if out.returncode == 0 and state.startswith("idle"):
                return
            time.sleep(0.5)
        raise RuntimeError(f"node not idle after {timeout} s (state {state!r})\n"
                           + self.log_tail())

    def stop(self):
        for p in reversed(self.procs):
            if p.poll() is None:
                p.terminate()
        for p in reversed(self.procs):
            try:
                p.wait(timeout=20)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()
        if self.munged_pid:
            try:
                os.kill(self.munged_pid, 15)
            except ProcessLookupError:
                pass


@pytest.fixture(scope="module")
def slurm():
    if os.geteuid() != 0:
        pytest.skip("the Slurm test starts munged, slurmctld and slurmd: it needs root")
    missing = _missing_tools()
    if missing:
        pytest.skip(f"Slurm/munge not installed (missing: {', '.join(missing)}); "
                    "scripts/setup installs slurm-wlm and munge")
    root = tempfile.mkdtemp(prefix="ropedyn-slurm-")
    cluster = LocalSlurm(root)
    try:
        cluster.start()
        yield cluster
    finally:
        cluster.stop()
        shutil.rmtree(root, ignore_errors=True)


def read_rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def submit(slurm, cwd, exe, *args, timeout=300):
    return subprocess.run([str(SUBMIT), *args, "--exe", str(exe)], cwd=cwd, env=slurm.env,
                          capture_output=True, text=True, timeout=timeout)


def sweep_status(exe, cwd, sweep):
    return subprocess.run([str(exe), "sweep", sweep, "--status"], cwd=cwd, capture_output=True,
                          text=True)


def wait_for(predicate, timeout=60, what="condition"):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return
        time.sleep(0.05)
    raise AssertionError(f"timed out waiting for {what}")


def test_slurm_array_summary_equals_local(slurm, ropedyn_exe, tmp_path):
    (tmp_path / "base.nml").write_text(BASE)
    (tmp_path / "sw.nml").write_text(SWEEP)
    n = int(subprocess.run([str(ropedyn_exe), "sweep", "sw.nml", "--count"], cwd=tmp_path,
                           capture_output=True, text=True, check=True).stdout)
    assert n == 16

    start = time.monotonic()
    result = submit(slurm, tmp_path, ropedyn_exe, "sw.nml", "--output-dir", "out/slurm",
                    "--throttle", "2", "--wait")
    elapsed = time.monotonic() - start
    # 8 cases fail on purpose (max_steps = 20): the summary job exits 3
    assert result.returncode == 3, result.stderr + slurm.log_tail()
    arrays, summary_id = result.stdout.split()
    arrays = arrays.split(",")
    # --throttle 2: 4 tasks per slot, 8 tasks of 2 cases; MaxArraySize 6: arrays of 5 and 3
    assert "16 case(s) in 8 task(s) of up to 2 (auto" in result.stderr
    assert "8 tasks > MaxArraySize - 1 = 5: 2 arrays" in result.stderr
    assert len(arrays) == 2
    out = tmp_path / "out" / "slurm"
    assert (out / "summary.csv").exists(), result.stderr + slurm.log_tail()
    [task_file] = (out / "slurm").glob("tasks_*.txt")
    assert task_file.read_text().split() == ["1-2", "3-4", "5-6", "7-8", "9-10", "11-12",
                                             "13-14", "15-16"]
    logs = sorted(p.name for p in (out / "slurm").glob("task_*.out"))
    assert logs == sorted([f"task_{arrays[0]}_{k}.out" for k in range(1, 6)]
                          + [f"task_{arrays[1]}_{k}.out" for k in range(1, 4)])
    summary_log = (out / "slurm" / f"summary_{summary_id}.out").read_text()
    assert "8 of 16 cases complete" in summary_log, summary_log
    # the tasks of the failing cases 5-8 and 13-16 are named with their cases
    assert f"summary: task {arrays[0]}_3 (cases 5-6) ended FAILED, exit code 3:0" in summary_log
    assert f"summary: task {arrays[1]}_3 (cases 15-16) ended FAILED" in summary_log
    assert "summary: 4 array task(s) did not end COMPLETED" in summary_log
    # nothing left in the queue
    queue = subprocess.run(["squeue", "-h"], env=slurm.env, capture_output=True, text=True)
    assert queue.stdout.strip() == ""
    print(f"slurm: arrays {arrays} + summary {summary_id}: {elapsed:.1f} s")

    local = subprocess.run([str(ropedyn_exe), "sweep", "sw.nml", "--output-dir", "out/local",
                            "--jobs", "2"], cwd=tmp_path, capture_output=True, text=True)
    assert local.returncode == 3, local.stderr
    slurm_rows = read_rows(out / "summary.csv")
    local_rows = read_rows(tmp_path / "out" / "local" / "summary.csv")
    assert [r["case"] for r in slurm_rows] == [r["case"] for r in local_rows]
    assert [r["status"] for r in slurm_rows].count("failed") == 8
    for a, b in zip(slurm_rows, local_rows):
        assert a.keys() == b.keys()
        for key in a:
            if key in VOLATILE:
                continue
            if key in ("reason", "reference_kind", "warning"):
                assert a[key] == b[key], (a["case"], key)
            elif a[key] and b[key] and key not in ("status", "model", "method", "reference"):
                np.testing.assert_allclose(float(a[key]), float(b[key]), rtol=1e-12,
                                           err_msg=f"case {a['case']}: {key}")
            else:
                assert a[key] == b[key], (a["case"], key)
    with h5py.File(out / "summary.h5") as fa, \
            h5py.File(tmp_path / "out" / "local" / "summary.h5") as fb:
        assert sorted(fa) == sorted(fb)
        np.testing.assert_array_equal(fa["steps"][:], fb["steps"][:])
        np.testing.assert_allclose(fa["tip_error_max"][:], fb["tip_error_max"][:], rtol=1e-12)


def test_double_submission_one_writer_per_case(slurm, ropedyn_exe, tmp_path):
    """The same sweep submitted twice while the first array runs: each case is written by
    one task; a task that finds its case being written fails (exit 4) and its summary job
    says so; every case ends complete and readable."""
    (tmp_path / "base.nml").write_text(BASE)
    (tmp_path / "dbl.nml").write_text(LONG.format(t_end=7, rtols="1e-8, 1e-9"))
    args = ("dbl.nml", "--throttle", "1", "--cases-per-task", "1", "--wait")
    first = subprocess.Popen([str(SUBMIT), *args, "--exe", str(ropedyn_exe)], cwd=tmp_path,
                             env=slurm.env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                             text=True)
    out = tmp_path / "out" / "sweep_dbl"
    try:
        wait_for(lambda: (out / ".case_0001.lock").exists(), what="the first array's case 1")
        second = submit(slurm, tmp_path, ropedyn_exe, *args)
    finally:
        stdout, stderr = first.communicate(timeout=300)
    assert "submit: warning: jobs for out/sweep_dbl are still queued or running:" \
        in second.stderr
    assert {first.returncode, second.returncode} <= {0, 3}, stderr + second.stderr
    logs = {p.name: p.read_text() for p in (out / "slurm").glob("task_*.out")}
    assert len(logs) == 4, logs.keys()
    # refused at a lock: by its host's name, or, caught between the lock's creation and
    # its owner writing its name there, as 'a writer that has not said who it is yet'
    taken = [name for name, text in logs.items() if "not run: being written by " in text]
    assert taken, logs
    for name, text in logs.items():
        assert ": complete:" in text or "complete already" in text or name in taken, text
    # the summary job of an array with a taken task fails and names it
    summaries = [p.read_text() for p in (out / "slurm").glob("summary_*.out")]
    assert any("ended FAILED, exit code 4:0" in text for text in summaries), summaries
    assert 3 in (first.returncode, second.returncode)
    status = sweep_status(ropedyn_exe, tmp_path, "dbl.nml")
    assert status.returncode == 0, status.stdout
    for k in (1, 2):
        with h5py.File(out / f"case_000{k}.h5") as f:
            assert f.attrs["status"] == b"complete"
            assert f["rope/points"].shape[0] == f["time"].shape[0] == 701
    assert not list(out.glob(".case_*"))


def test_missing_queues_only_what_is_not_complete(slurm, ropedyn_exe, tmp_path):
    (tmp_path / "base.nml").write_text(BASE)
    (tmp_path / "m.nml").write_text("&sweep base = 'base.nml'\n"
                                    "  vary = 'solver.max_steps = 100000; 20'\n"
                                    "  methods = 'cvode', 'mebdf'\n/\n")
    first = submit(slurm, tmp_path, ropedyn_exe, "m.nml", "--wait")
    assert first.returncode == 3, first.stderr
    out = tmp_path / "out" / "sweep_m"
    mtime = (out / "case_0002.h5").stat().st_mtime_ns
    (out / "case_0001.h5").unlink()
    dry = submit(slurm, tmp_path, ropedyn_exe, "m.nml", "--missing", "--dry-run")
    assert dry.returncode == 0 and dry.stdout.split() == ["1", "3", "4"]
    second = submit(slurm, tmp_path, ropedyn_exe, "m.nml", "--missing", "--wait")
    assert second.returncode == 3, second.stderr
    assert "submit: --missing: 3 of 4 cases not complete: 1 (missing); 3 4 (failed)" \
        in second.stderr
    assert "3 case(s) in 3 task(s) of up to 1" in second.stderr
    task_files = sorted((out / "slurm").glob("tasks_*.txt"))
    assert [f.read_text().split() for f in task_files] == [["1", "2", "3", "4"],
                                                           ["1", "3", "4"]]
    # both attempts' logs are kept
    arrays = {p.name.split("_")[1] for p in (out / "slurm").glob("task_*.out")}
    assert len(arrays) == 2 and len(list((out / "slurm").glob("task_*.out"))) == 7
    assert (out / "case_0002.h5").stat().st_mtime_ns == mtime
    status = sweep_status(ropedyn_exe, tmp_path, "m.nml")
    assert "  complete         2" in status.stdout and "  failed           2" in status.stdout
    # every case complete: nothing to queue
    (tmp_path / "ok.nml").write_text("&sweep base = 'base.nml'\n  methods = 'cvode'\n/\n")
    assert submit(slurm, tmp_path, ropedyn_exe, "ok.nml", "--wait").returncode == 0
    none = submit(slurm, tmp_path, ropedyn_exe, "ok.nml", "--missing")
    assert none.returncode == 0 and "submit: nothing to queue" in none.stderr


def test_cancelled_task_is_interrupted(slurm, ropedyn_exe, tmp_path):
    (tmp_path / "base.nml").write_text(BASE)
    (tmp_path / "c.nml").write_text(LONG.format(t_end=30, rtols="1e-8"))
    job = subprocess.Popen([str(SUBMIT), "c.nml", "--wait", "--exe", str(ropedyn_exe)],
                           cwd=tmp_path, env=slurm.env, stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE, text=True)
    out = tmp_path / "out" / "sweep_c"
    try:
        wait_for(lambda: (out / ".case_0001.lock").exists(), what="the case to start")
        [task_file] = (out / "slurm").glob("tasks_*.txt")
        array = next((out / "slurm").glob("task_*_1.out")).name.split("_")[1]
        subprocess.run(["scancel", f"{array}_1"], env=slurm.env, check=True)
    finally:
        stdout, stderr = job.communicate(timeout=120)
    assert job.returncode == 3, stderr
    summary = next((out / "slurm").glob("summary_*.out")).read_text()
    assert f"summary: task {array}_1 (cases 1) ended CANCELLED" in summary, summary
    # the run stopped itself at a step boundary and wrote status interrupted with the reason
    assert "sweep: case 0001: interrupted: " in summary and "interrupted by SIGTERM at t = " \
        in summary, summary
    status = sweep_status(ropedyn_exe, tmp_path, "c.nml")
    assert status.returncode == 3
    assert "0001 interrupted: " in status.stdout
    assert "interrupted by SIGTERM at t = " in status.stdout
    assert f"Slurm job {array}_1" in status.stdout


def test_time_limit_warning_requeues_and_resumes(slurm, ropedyn_exe, tmp_path):
    """The warning signal ahead of the time limit (USR1 to the batch shell, as
    `--signal=B:USR1@120` sends it; here by scancel) stops the case at a step boundary and
    requeues the task, which continues the case from its last record."""
    (tmp_path / "base.nml").write_text(BASE)
    (tmp_path / "r.nml").write_text(LONG.format(t_end=6, rtols="1e-8"))
    job = subprocess.Popen([str(SUBMIT), "r.nml", "--wait", "--exe", str(ropedyn_exe)],
                           cwd=tmp_path, env=slurm.env, stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE, text=True)
    out = tmp_path / "out" / "sweep_r"
    try:
        wait_for(lambda: (out / ".case_0001.lock").exists(), what="the case to start")
        time.sleep(0.5)
        array = next((out / "slurm").glob("task_*_1.out")).name.split("_")[1]
        subprocess.run(["scancel", "--batch", "--signal=USR1", f"{array}_1"], env=slurm.env,
                       check=True)
        stdout, stderr = job.communicate(timeout=300)
    finally:
        if job.poll() is None:
            job.kill()
    logs = "".join(p.read_text() for p in (out / "slurm").glob("task_*_1.out"))
    # both attempts in the log (--open-mode=append)
    assert "sweep.sbatch: warning signal: stopping the case and requeueing" in logs, logs
    assert "interrupted before: continuing it from its last record" in logs, logs
    assert job.returncode == 0, stderr + logs
    with h5py.File(out / "case_0001.h5") as f:
        assert f.attrs["status"] == b"complete"
        assert f["solver/restarts/time"].shape == (1,)


def no_controller(tmp_path, sbatch_says):
    """The environment of a machine with Slurm's clients but no controller: squeue, sinfo
    and scontrol fail, sbatch fails with `sbatch_says` (fakes first on PATH)."""
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    for tool, text in (("squeue", "squeue: error: no controller"), ("sinfo", ""),
                       ("scontrol", ""), ("sbatch", sbatch_says), ("scancel", "")):
        (bin_dir / tool).write_text(f"#!/bin/sh\necho '{text}' >&2\nexit 1\n")
        (bin_dir / tool).chmod(0o755)
    (tmp_path / "base.nml").write_text(BASE)
    (tmp_path / "s.nml").write_text(SWEEP)
    return {**os.environ, "PATH": f"{bin_dir}:{os.environ['PATH']}"}


def test_dry_run_without_a_controller(ropedyn_exe, tmp_path):
    """Before, `submit --dry-run` stopped with exit 1 and no word where squeue reached no
    controller (pipefail on squeue's pipeline): now it warns that earlier jobs were not
    checked and prints the task file it would queue (16 cases, one slot: 4 tasks of 4)."""
    env = no_controller(tmp_path, "sbatch: fatal: no controller")
    result = subprocess.run([str(SUBMIT), "s.nml", "--dry-run", "--exe", str(ropedyn_exe)],
                            cwd=tmp_path, env=env, capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr
    assert "squeue failed" in result.stderr and "nothing queued" in result.stderr
    assert result.stdout.split() == ["1-4", "5-8", "9-12", "13-16"], result.stdout
    assert not list((tmp_path / "out").rglob("tasks_*.txt"))


def test_failed_sbatch_queues_nothing_and_says_so(ropedyn_exe, tmp_path):
    """sbatch's own message, then submit's: nothing queued (exit 4), no task file left."""
    env = no_controller(tmp_path, "sbatch: fatal: Could not establish a configuration source")
    result = subprocess.run([str(SUBMIT), "s.nml", "--exe", str(ropedyn_exe)], cwd=tmp_path,
                            env=env, capture_output=True, text=True, timeout=60)
    assert result.returncode == 4, result.stderr
    assert "Could not establish" in result.stderr
    assert "submit: sbatch failed (its message above): nothing queued" in result.stderr
    assert not list((tmp_path / "out").rglob("tasks_*.txt"))
