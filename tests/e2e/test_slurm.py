"""A sweep on a real single-node Slurm cluster: scripts/slurm/submit queues the job array and
the dependent summary job; the summary must equal the local runner's (same cases, same
results up to floating-point reproducibility; times differ).

The test starts its own cluster on localhost, as root: munged (own key, socket and files in
a temporary directory), slurmctld and slurmd in the foreground (-D) as child processes,
with a slurm.conf for one node with 2 CPUs (select/cons_tres, proctrack/linuxproc,
task/none, no cgroups, no accounting) on free ports; clients find it through SLURM_CONF.
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
AuthInfo=socket={socket_path}
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
MpiDefault=none
ReturnToService=2
SlurmdParameters=config_overrides
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
MaxArraySize=1001
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


def test_slurm_array_summary_equals_local(slurm, ropedyn_exe, tmp_path):
    (tmp_path / "base.nml").write_text(BASE)
    (tmp_path / "sw.nml").write_text(SWEEP)
    n = int(subprocess.run([str(ropedyn_exe), "sweep", "sw.nml", "--count"], cwd=tmp_path,
                           capture_output=True, text=True, check=True).stdout)
    assert n == 16

    start = time.monotonic()
    result = subprocess.run([str(SUBMIT), "sw.nml", "--exe", str(ropedyn_exe), "--output-dir",
                             "out/slurm", "--throttle", "2", "--wait"], cwd=tmp_path,
                            env=slurm.env, capture_output=True, text=True, timeout=300)
    elapsed = time.monotonic() - start
    # 8 cases fail on purpose (max_steps = 20): the summary job exits 3
    assert result.returncode == 3, result.stderr + slurm.log_tail()
    array_id, summary_id = result.stdout.split()
    out = tmp_path / "out" / "slurm"
    assert (out / "summary.csv").exists(), result.stderr + slurm.log_tail()
    summary_log = (out / "slurm" / "summary.out").read_text()
    assert "8 of 16 cases complete" in summary_log, summary_log
    assert len(list((out / "slurm").glob("case_*.out"))) == n
    # nothing left in the queue
    queue = subprocess.run(["squeue", "-h"], env=slurm.env, capture_output=True, text=True)
    assert queue.stdout.strip() == ""
    print(f"slurm: array {array_id} + summary {summary_id}: {elapsed:.1f} s")

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
            if key == "reason":
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
