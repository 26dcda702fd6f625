"""Read a ropedyn run file (HDF5, layout: docs/reference/file-format.md) into numpy arrays with units.

    run = load_run("out/paper.h5")
    run.time, run.q, run.qdot, run.points, run.energy["total"], run.stats["steps"]
    run.forces["axial"], run.reactions["top"], run.anchors["top"]
    run.units["state/q"]  # 'm, m, rad', from the file's own "units" attributes

The one reader of run files for the plots, the animation, the XDMF sidecar and the
studies. Records beyond len(/time) (a half-written last record) are dropped.
"""
import dataclasses
import os

import h5py
import numpy as np

from ropedyn.namelist import parse_namelist

ENERGY_NAMES = ("kinetic", "elastic", "gravity", "dissipated", "support_work", "total")
#: Internal forces at the joints (/forces/NAME, (T, n+1)), stored by the model with each record.
FORCE_NAMES = ("axial", "shear", "moment")
#: The supports (/supports/END/reaction and /position, (T, 2)).
SUPPORT_ENDS = ("top", "bottom")
#: Scalar solver statistics written at the end of a run (/solver/NAME; jac_rhs_evals, the f
#: evaluations of differenced Jacobians, not in files of earlier versions).
SOLVER_STATS = ("steps", "rhs_evals", "jac_rhs_evals", "jac_evals", "lin_setups",
                "err_test_fails", "nonlin_iters", "nonlin_conv_fails", "cpu_time", "time_advance",
                "time_rhs", "time_jacobian", "time_factor", "time_solve", "reduced_newton")


def text(value):
    """An HDF5 string attribute as str, whether h5py gives bytes, str or a 0-d array."""
    if isinstance(value, np.ndarray) and value.shape == ():
        value = value[()]
    if isinstance(value, (bytes, np.bytes_)):
        return bytes(value).decode("utf-8", "surrogateescape")
    return str(value)


@dataclasses.dataclass
class Run:
    """One ropedyn output file, read into memory (records: len(/time))."""

    path: str
    time: np.ndarray            # (T,) s
    points: np.ndarray          # (T, 2n, 2) m: A_1, B_1, A_2, ... (x down, y horizontal)
    q: np.ndarray               # (T, n, 3) element centre x, y (m), angle phi (rad)
    qdot: np.ndarray            # (T, n, 3)
    element_length: np.ndarray  # (n,) m
    element_mass: np.ndarray    # (n,) kg
    energy: dict                # name -> (T,) J
    step_size: np.ndarray       # (T,) s
    order: np.ndarray           # (T,)
    model: str                  # lower case: 'rfem', 'mpp'
    method: str
    status: str
    scene: dict                 # parse_namelist of the scene attribute
    stats: dict = dataclasses.field(default_factory=dict)  # /solver/steps, ...: int; cpu_time: s
    attrs: dict = dataclasses.field(default_factory=dict)  # root attributes as str, unchanged
    units: dict = dataclasses.field(default_factory=dict)  # dataset path -> its "units"
    # the model's internal forces at joints 0 (top end) .. n: name -> (T, n+1) N, N m;
    # empty for a file written before ropedyn stored them
    forces: dict = dataclasses.field(default_factory=dict)
    # force of each support on the rope, 'top'/'bottom' -> (T, 2) N (x, y); may be empty
    reactions: dict = dataclasses.field(default_factory=dict)
    # each support's anchor at every record, 'top'/'bottom' -> (T, 2) m (none for a free end)
    anchors: dict = dataclasses.field(default_factory=dict)
    # what the run warned of (/solver/warnings), one line each: the scene's warnings, a held
    # end started far from its anchor, a loss of a tenth of the energy the motion took in
    warnings: list = dataclasses.field(default_factory=list)

    @property
    def n(self):
        """Number of elements (members)."""
        return self.q.shape[1]

    @property
    def balance(self):
        """B = T + V + dissipated - support work at every record, J (T + V: energy/total):
        the energy balance, which stays at its start value E0 up to the integration error."""
        e = self.energy
        none = np.zeros_like(e["total"])
        return e["total"] + e.get("dissipated", none) - e.get("support_work", none)

    @property
    def e0(self):
        """E0, the balance's start value, J: B at the first record, the E0 `ropedyn run`
        prints. For a run started from a record of another (&initial shape = 'state'), the
        energy dissipated and the work done before count in it (they carry over), so it is
        not T + V at the first record. A resumed run's file keeps its first record: its E0
        is that of the first part."""
        return float(self.balance[0])

    def group(self, name):
        """A scene group as a dict ({} when absent)."""
        return self.scene.get(name, {})


#: What every run file holds (docs/reference/file-format.md); a file without one of them is
#: not a run file.
RUN_DATASETS = ("time", "rope/points", "state/q", "state/qdot", "rope/element_length",
                "rope/element_mass", "energy/total")


def what_file(f):
    """What an open HDF5 file that is not a run file is, as far as it can tell."""
    if "modes" in f:
        return "the file of `ropedyn modes`"
    if "statics" in f:
        return "the file of `ropedyn statics`"
    if "case" in f and "reference" in f.attrs:
        return "a sweep's summary"
    return "not written by ropedyn"


def _open_run(path):
    """h5py.File of the run file at path (a name or a file object); ValueError saying what
    the file is when it is not a run file, FileNotFoundError when there is none, OSError
    saying so when a run holds it open for writing (HDF5's file lock)."""
    if isinstance(path, (str, os.PathLike)):
        if not os.path.exists(path):
            raise FileNotFoundError(f"{path}: no such file")
        if not os.path.isfile(path):
            raise ValueError(f"{path}: not a file")
        if not h5py.is_hdf5(path):
            raise ValueError(f"{path}: not an HDF5 file, so not a run file of ropedyn")
    try:
        f = h5py.File(path, "r")
    except OSError as exc:
        if "unable to lock file" not in str(exc):
            raise
        raise OSError(f"{path}: held open for writing (a run is writing it; to "
                      "read it as of its last flush, set HDF5_USE_FILE_LOCKING=FALSE)") from exc
    missing = [name for name in RUN_DATASETS if name not in f]
    if missing:
        why = f"{path}: not a run file of ropedyn (no /{missing[0]}): {what_file(f)}"
        f.close()
        raise ValueError(why)
    return f


def load_run(path):
    """Read a run file; records beyond len(/time) (a half-written record) are dropped.
    ValueError (saying what the file is) for a file that is not a run file: not HDF5, a
    statics or modes file, a sweep's summary; FileNotFoundError for a missing one."""
    with _open_run(path) as f:
        records = f["time"].shape[0]

        def series(name):
            return f[name][:records] if name in f else None

        energy = {k: series(f"energy/{k}") for k in ENERGY_NAMES if f"energy/{k}" in f}
        forces = {k: series(f"forces/{k}") for k in FORCE_NAMES if f"forces/{k}" in f}
        reactions = {k: series(f"supports/{k}/reaction") for k in SUPPORT_ENDS
                     if f"supports/{k}/reaction" in f}
        anchors = {k: series(f"supports/{k}/position") for k in SUPPORT_ENDS
                   if f"supports/{k}/position" in f}
        stats = {k: f[f"solver/{k}"][()].item() for k in SOLVER_STATS if f"solver/{k}" in f}
        warnings = [text(w) for w in f["solver/warnings"][()]] if "solver/warnings" in f else []
        attrs = {k: text(v) for k, v in f.attrs.items()}
        units = {}

        def note_units(name, obj):
            if isinstance(obj, h5py.Dataset) and "units" in obj.attrs:
                units[name] = text(obj.attrs["units"])

        f.visititems(note_units)
        return Run(path=str(path), time=f["time"][:], points=series("rope/points"),
                   q=series("state/q"), qdot=series("state/qdot"),
                   element_length=f["rope/element_length"][:],
                   element_mass=f["rope/element_mass"][:], energy=energy,
                   step_size=series("solver/step_size"), order=series("solver/order"),
                   model=attrs.get("model", "unknown").strip().lower(),
                   method=attrs.get("method", "").strip(),
                   status=attrs.get("status", "").strip(),
                   scene=parse_namelist(attrs.get("scene", "")), stats=stats, attrs=attrs,
                   units=units, forces=forces, reactions=reactions, anchors=anchors,
                   warnings=warnings)


def title(run):
    """A one-line description: model, n, method, status."""
    return f"{run.model.upper()}, n = {run.n}, {run.method} ({run.status})"
