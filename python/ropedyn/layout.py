"""Check that a ropedyn HDF5 output file has the documented layout (docs/reference/file-format.md).

Use from Python (the end-to-end tests do)::

    from ropedyn.layout import check_layout
    summary = check_layout("out/run.h5", n_elements=20)

or by hand::

    .venv/bin/python -m ropedyn.layout out/run.h5 20

The file's kind comes from its root attributes: a run file, or a file of `ropedyn statics`
or `ropedyn modes` (attribute `analysis`), each checked against its own layout; a sweep's
summary (attribute `sweep`) has no layout per element and is refused, saying so.
`check_layout` raises AssertionError naming the file and the dataset or attribute at fault,
and returns a small summary dict (kind, records, status, reason, modes) when the layout is
right. A run file of any status passes: 'complete', 'failed', 'interrupted' (a signal
stopped it; `ropedyn run --resume` continues it) and 'running' (its run was killed or
crashed, or is still writing it: valid up to its last record); the layout is the same, but
only a complete or interrupted file must have the solver statistics (a run writes them with
its records at each flush, so a running file and one given up after a write error have
those of their last flush, or none before the first),
and the series of a running or failed file may hold more records than /time (a block
written halfway). A statics or modes file is always 'complete'.
"""

import sys

import h5py
import numpy as np

from ropedyn.io import text as _text

#: Step-by-step datasets: path -> (record shape as h5py sees it without the time axis, units)
#: (the record shapes use "n" for n_elements, "2n" for 2 * n_elements and "n+1" for the
#: joints).
SERIES = {
    "time": ((), "s"),
    "state/q": (("n", 3), "m, m, rad"),
    "state/qdot": (("n", 3), "m/s, m/s, rad/s"),
    "rope/points": (("2n", 2), "m"),
    "energy/kinetic": ((), "J"),
    "energy/elastic": ((), "J"),
    "energy/gravity": ((), "J"),
    "energy/dissipated": ((), "J"),
    "energy/support_work": ((), "J"),
    "energy/total": ((), "J"),
    "solver/step_size": ((), "s"),
    "solver/order": ((), "1"),
    "forces/axial": (("n+1",), "N"),
    "forces/shear": (("n+1",), "N"),
    "forces/moment": (("n+1",), "N m"),
    "supports/top/reaction": ((2,), "N"),
    "supports/bottom/reaction": ((2,), "N"),
}

#: Step-by-step datasets that exist only for some scenes, checked when present: the anchor of
#: a support that has one (not of a free end).
OPTIONAL_SERIES = {
    "supports/top/position": ((2,), "m"),
    "supports/bottom/position": ((2,), "m"),
}

#: Datasets written once at create: path -> units (shape (n_elements,)).
FIXED = {
    "rope/element_length": "m",
    "rope/element_mass": "kg",
}

#: Scalar solver statistics: path -> units (int64 counters, cpu_time float).
STATS = {
    "solver/steps": "1",
    "solver/rhs_evals": "1",
    "solver/jac_evals": "1",
    "solver/lin_setups": "1",
    "solver/err_test_fails": "1",
    "solver/nonlin_iters": "1",
    "solver/nonlin_conv_fails": "1",
    "solver/cpu_time": "s",
}

#: Scalar solver statistics that files of earlier versions lack, checked as STATS when
#: present: the f evaluations spent differencing Jacobians (int64).
OPTIONAL_STATS = {
    "solver/jac_rhs_evals": "1",
}

#: Extra attributes on some datasets.
COLUMNS = {
    "state/q": "x, y, phi",
    "rope/points": "x, y",
    "supports/top/reaction": "x, y",
    "supports/bottom/reaction": "x, y",
    "supports/top/position": "x, y",
    "supports/bottom/position": "x, y",
}

ROOT_ATTRIBUTES = ("status", "version", "model", "method", "scene", "created",
                   "units_convention")

#: The kinds of file `ropedyn statics` and `ropedyn modes` write (root attribute `analysis`).
ANALYSES = ("statics", "modes")

#: Root attributes of a statics or modes file (`source` only in newer files).
ANALYSIS_ATTRIBUTES = ("status", "analysis", "version", "model", "scene", "created",
                       "units_convention")

#: The datasets of a statics or modes file that are one record of a run file's series (the
#: equilibrium; shapes and units as in SERIES, with one time).
ANALYSIS_RECORDS = ("state/q", "rope/points", "forces/axial", "forces/shear", "forces/moment",
                    "supports/top/reaction", "supports/bottom/reaction")

#: The results of a statics (and modes) file: path -> (shape, units, integer); "N" is the
#: number of generalized coordinates (the length of /statics/q), None the units of /statics/q.
STATICS = {
    "statics/q": (("N",), None, False),
    "statics/residual": ((), "N", False),
    "statics/residual_relative": ((), "1", False),
    "statics/last_step": ((), "m", False),
    "statics/weight": ((), "N", False),
    "statics/iterations": ((), "1", True),
    "statics/rejected": ((), "1", True),
    "statics/stages": ((), "1", True),
    "energy/elastic": ((), "J", False),
    "energy/gravity": ((), "J", False),
}

#: The results of a modes file beyond STATICS, as STATICS ("K": the number of modes).
MODES = {
    "modes/omega": (("K",), "rad/s", False),
    "modes/frequency_hz": (("K",), "Hz", False),
    "modes/period": (("K",), "s", False),
    "modes/damping_ratio": (("K",), "1", False),
    "modes/axial_fraction": (("K",), "1", False),
    "modes/shape": (("K", "N"), None, False),
    "modes/shape_points": (("K", "2n", 2), "m", False),
    "modes/stiffness_asymmetry": ((), "1", False),
}

UNITS_CONVENTION = "SI; x points down (gravity), y horizontal, angles from x towards y"

#: The statuses of a run file and what each means (docs/reference/file-format.md, "Status").
RUN_STATUSES = {
    "complete": "the run reached its end time",
    "failed": "the run stopped on an error (see the reason)",
    "interrupted": "a signal stopped the run at its last record (usually off the output "
                   "grid); ropedyn run --resume FILE continues it",
    "running": "the run was killed or crashed, or is still writing: the data are valid up "
               "to the last record; ropedyn run --resume FILE continues it",
}

#: Statuses whose file has the solver statistics (STATS) of every part of the run.
STATS_STATUSES = ("complete", "interrupted")

#: Statuses whose file has a reason attribute.
REASON_STATUSES = ("failed", "interrupted")


def _require(condition, message):
    if not condition:
        raise AssertionError(message)


def file_kind(f, path):
    """'run', 'statics' or 'modes', from the root attributes of the open file `f`; a sweep's
    summary, or an analysis of another name, raises AssertionError saying why."""
    _require("sweep" not in f.attrs,
             f"{path}: a sweep summary (root attribute 'sweep'), not a run, statics or modes "
             f"file: its datasets are one column per case, with no layout per element to check")
    if "analysis" not in f.attrs:
        return "run"
    kind = _text(f.attrs["analysis"])
    _require(kind in ANALYSES,
             f"{path}: root attribute analysis is '{kind}', expected one of {ANALYSES}")
    return kind


def check_layout(path, n_elements):
    """Assert the layout of output file `path` (a run, statics or modes file) of a rope of
    `n_elements` elements."""
    path = str(path)
    n_elements = int(n_elements)
    extents = {"n": n_elements, "2n": 2 * n_elements, "n+1": n_elements + 1}
    with h5py.File(path, "r") as f:
        kind = file_kind(f, path)
        if kind == "run":
            return _check_run(f, path, n_elements, extents)
        return _check_analysis(f, path, kind, n_elements, extents)


def _check_run(f, path, n_elements, extents):
    """The layout of a run file (`check_layout`)."""
    status, reason = _check_root(f, path, ROOT_ATTRIBUTES, tuple(RUN_STATUSES))
    _check_units(f, path)

    # step-by-step datasets: (times, ...) extendible along time; /time is written last, so
    # in a file whose run did not end normally (running, or failed writing) the others may
    # hold the records of a block written halfway
    _require("time" in f, f"{path}: /time is missing")
    n_times = f["time"].shape[0]
    present = {k: v for k, v in OPTIONAL_SERIES.items() if k in f}
    for name, (record, units) in {**SERIES, **present}.items():
        longer = (name != "time" and status in ("running", "failed") and name in f
                  and f[name].ndim >= 1 and f[name].shape[0] > n_times)
        _check_dataset(f, path, name, ((f[name].shape[0] if longer else n_times),) + record,
                       units, extents)
        dset = f[name]
        _require(dset.chunks is not None and dset.maxshape[0] is None,
                 f"{path}: /{name} is not chunked and extendible along time")
    # the last record of every series, and of the restart data a resume starts from,
    # reads back: a run killed in the middle of a flush can leave series whose last chunk
    # lies past the end HDF5 recorded ("addr overflow")
    restart = [name for name in ("state/y", "state/yq") if name in f]
    for name in [*SERIES, *present, *restart]:
        if n_times == 0:
            break
        try:
            f[name][n_times - 1]
        except (OSError, RuntimeError, ValueError) as exc:
            raise AssertionError(f"{path}: /{name}: record {n_times - 1} (the last of "
                                 f"/time) does not read back: {exc}") from exc
    _check_columns(f, path)
    _check_fixed(f, path, n_elements)

    # solver statistics: written with the records at each flush and when a run ends
    # (complete, failed in the integration, interrupted); a running file or one given up
    # after a write error has those of its last flush, or none before the first
    have = [name for name in STATS if name in f]
    if status in STATS_STATUSES or have:
        _check_stats(f, path)
    if status == "interrupted":
        _require("solver/t_reached" in f, f"{path}: /solver/t_reached is missing")

    # values
    time = f["time"][()]
    _require(np.all(np.isfinite(time)), f"{path}: /time has non-finite values")
    _require(np.all(np.diff(time) > 0), f"{path}: /time is not strictly increasing")
    kinetic = f["energy/kinetic"][:n_times]
    elastic = f["energy/elastic"][:n_times]
    gravity = f["energy/gravity"][:n_times]
    total = f["energy/total"][:n_times]
    expected_total = kinetic + elastic + gravity
    bad = np.abs(total - expected_total) > 1e-12 * np.abs(expected_total) + 1e-12
    _require(not np.any(bad),
             f"{path}: /energy/total differs from kinetic + elastic + gravity at records "
             f"{np.flatnonzero(bad).tolist()}")
    return {"kind": "run", "records": int(n_times), "status": status, "reason": reason,
            "modes": None}


def _check_stats(f, path):
    """The scalar solver statistics (STATS), all of them, and those of OPTIONAL_STATS the
    file has."""
    present = {k: v for k, v in OPTIONAL_STATS.items() if k in f}
    for name, units in {**STATS, **present}.items():
        _require(name in f, f"{path}: /{name} is missing")
        dset = f[name]
        _require(dset.shape == (), f"{path}: /{name} has shape {dset.shape}, expected ()")
        if name == "solver/cpu_time":
            _require(dset.dtype.kind == "f", f"{path}: /{name} has dtype {dset.dtype}")
        else:
            _require(dset.dtype == np.int64,
                     f"{path}: /{name} has dtype {dset.dtype}, expected int64")
            _require(dset[()] >= 0, f"{path}: /{name} is negative")
        got = _text(dset.attrs["units"])
        _require(got == units, f"{path}: /{name} units '{got}', expected '{units}'")


def _check_analysis(f, path, kind, n_elements, extents):
    """The layout of a statics or modes file (`check_layout`): the equilibrium as one record
    of a run file's series, its results, and for modes the modes."""
    status, reason = _check_root(f, path, ANALYSIS_ATTRIBUTES, ("complete",))
    _check_units(f, path)
    for name in ANALYSIS_RECORDS:
        record, units = SERIES[name]
        _check_dataset(f, path, name, (1,) + record, units, extents)
    for name, (record, units) in OPTIONAL_SERIES.items():
        if name in f:
            _check_dataset(f, path, name, (1,) + record, units, extents)
    _check_columns(f, path)
    _check_fixed(f, path, n_elements)

    _require("statics/q" in f and f["statics/q"].ndim == 1,
             f"{path}: /statics/q is missing or not one-dimensional")
    extents = {**extents, "N": f["statics/q"].shape[0]}
    coordinate_units = _text(f["statics/q"].attrs["units"])
    results = dict(STATICS)
    if kind == "modes":
        _require("modes/omega" in f and f["modes/omega"].ndim == 1,
                 f"{path}: /modes/omega is missing or not one-dimensional")
        extents["K"] = f["modes/omega"].shape[0]
        results.update(MODES)
    for name, (shape, units, integer) in results.items():
        _check_dataset(f, path, name, shape, units or coordinate_units, extents)
        dtype = f[name].dtype
        _require(dtype == np.int64 if integer else dtype.kind == "f",
                 f"{path}: /{name} has dtype {dtype}, expected "
                 f"{'int64' if integer else 'float'}")
    for end in ("top", "bottom"):
        name = f"statics/support_force_{end}"
        if name in f:
            _check_dataset(f, path, name, (2,), "N", extents)
            _require(np.array_equal(f[name][()], f[f"supports/{end}/reaction"][0]),
                     f"{path}: /{name} differs from /supports/{end}/reaction")
    for group, attribute in (("statics", "criterion"), ("modes", "eigensolver")):
        if group in f:
            _require(attribute in f[group].attrs,
                     f"{path}: /{group} has no '{attribute}' attribute")
    _require(kind == "modes" or "modes" not in f,
             f"{path}: a statics file (root attribute analysis) with /modes")
    return {"kind": kind, "records": 1, "status": status, "reason": reason,
            "modes": extents.get("K")}


def _check_root(f, path, names, statuses):
    """The root attributes `names`, the status (one of `statuses`; 'failed' with a reason),
    the units convention and the creation time; returns (status, reason or None)."""
    for name in names:
        _require(name in f.attrs, f"{path}: root attribute '{name}' is missing")
    status = _text(f.attrs["status"])
    _require(status in statuses,
             f"{path}: status is '{status}', expected " + " or ".join(f"'{s}'" for s in statuses))
    reason = None
    if status in REASON_STATUSES:
        _require("reason" in f.attrs, f"{path}: {status} run without a 'reason' attribute")
        reason = _text(f.attrs["reason"])
        _require(reason.strip() != "", f"{path}: {status} run with an empty reason")
    else:
        _require("reason" not in f.attrs, f"{path}: {status} file with a 'reason' attribute")
    convention = _text(f.attrs["units_convention"])
    _require(convention == UNITS_CONVENTION, f"{path}: units_convention is '{convention}'")
    created = _text(f.attrs["created"])
    _require(len(created) == 20 and created[10] == "T" and created.endswith("Z"),
             f"{path}: created '{created}' is not ISO 8601 UTC (yyyy-mm-ddThh:mm:ssZ)")
    return status, reason


def _check_units(f, path):
    """Every dataset has units."""
    missing = []

    def visit(name, obj):
        if isinstance(obj, h5py.Dataset) and "units" not in obj.attrs:
            missing.append(name)

    f.visititems(visit)
    _require(not missing, f"{path}: datasets without a 'units' attribute: {missing}")


def _check_dataset(f, path, name, shape, units, extents):
    """Dataset `name` is there with `shape` (names of extents resolved) and `units`."""
    _require(name in f, f"{path}: /{name} is missing")
    dset = f[name]
    expected = tuple(extents.get(e, e) for e in shape)
    _require(dset.shape == expected,
             f"{path}: /{name} has shape {dset.shape}, expected {expected}")
    got = _text(dset.attrs["units"])
    _require(got == units, f"{path}: /{name} units '{got}', expected '{units}'")


def _check_columns(f, path):
    """The `columns` attributes (COLUMNS) of the datasets that have them."""
    for name, columns in COLUMNS.items():
        if name in OPTIONAL_SERIES and name not in f:
            continue
        _require("columns" in f[name].attrs, f"{path}: /{name} has no 'columns' attribute")
        got = _text(f[name].attrs["columns"])
        _require(got == columns, f"{path}: /{name} columns '{got}', expected '{columns}'")


def _check_fixed(f, path, n_elements):
    """The datasets written once (FIXED): (n_elements,), positive and finite."""
    for name, units in FIXED.items():
        _check_dataset(f, path, name, (n_elements,), units, {})
        values = f[name][()]
        _require(np.all(np.isfinite(values)) and np.all(values > 0),
                 f"{path}: /{name} has non-positive or non-finite values")


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) != 2:
        print("usage: python -m ropedyn.layout FILE N_ELEMENTS", file=sys.stderr)
        return 2
    try:
        summary = check_layout(argv[0], int(argv[1]))
    except (AssertionError, OSError, KeyError, ValueError, RuntimeError) as exc:
        # (h5py raises RuntimeError for some damaged files: "Object visitation failed")
        print(f"FAIL {exc}", file=sys.stderr)
        return 1
    if summary["kind"] == "run":
        line = f"{argv[0]}: layout OK (run file, {summary['records']} records"
    else:
        line = f"{argv[0]}: layout OK ({summary['kind']} file, {argv[1]} elements"
    if summary["modes"] is not None:
        line += f", {summary['modes']} modes"
    line += f", status {summary['status']}"
    if summary["reason"]:
        line += f", reason: {summary['reason']}"
    print(line + ")")
    if summary["kind"] == "run" and summary["status"] != "complete":
        print(f"status {summary['status']}: {RUN_STATUSES[summary['status']]}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
