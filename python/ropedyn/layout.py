"""Check that a ropedyn HDF5 output file has the documented layout (docs/reference/file-format.md).

Use from Python (the end-to-end tests do)::

    from ropedyn.layout import check_layout
    summary = check_layout("out/run.h5", n_elements=20)

or by hand::

    .venv/bin/python -m ropedyn.layout out/run.h5 20

`check_layout` raises AssertionError naming the file and the dataset or attribute at fault,
and returns a small summary dict (records, status, reason) when the layout is right.
Only finished runs pass: status must be 'complete' or 'failed' ('running' means the run
crashed or is still going).
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

UNITS_CONVENTION = "SI; x points down (gravity), y horizontal, angles from x towards y"


def _require(condition, message):
    if not condition:
        raise AssertionError(message)


def check_layout(path, n_elements):
    """Assert the layout of output file `path` of a rope of `n_elements` elements."""
    path = str(path)
    n_elements = int(n_elements)
    extents = {"n": n_elements, "2n": 2 * n_elements, "n+1": n_elements + 1}
    with h5py.File(path, "r") as f:
        # root attributes
        for name in ROOT_ATTRIBUTES:
            _require(name in f.attrs, f"{path}: root attribute '{name}' is missing")
        status = _text(f.attrs["status"])
        _require(status in ("complete", "failed"),
                 f"{path}: status is '{status}', expected 'complete' or 'failed'")
        reason = None
        if status == "failed":
            _require("reason" in f.attrs, f"{path}: failed run without a 'reason' attribute")
            reason = _text(f.attrs["reason"])
            _require(reason.strip() != "", f"{path}: failed run with an empty reason")
        else:
            _require("reason" not in f.attrs, f"{path}: complete run with a 'reason' attribute")
        convention = _text(f.attrs["units_convention"])
        _require(convention == UNITS_CONVENTION,
                 f"{path}: units_convention is '{convention}'")
        created = _text(f.attrs["created"])
        _require(len(created) == 20 and created[10] == "T" and created.endswith("Z"),
                 f"{path}: created '{created}' is not ISO 8601 UTC (yyyy-mm-ddThh:mm:ssZ)")

        # every dataset has units
        missing = []

        def visit(name, obj):
            if isinstance(obj, h5py.Dataset) and "units" not in obj.attrs:
                missing.append(name)

        f.visititems(visit)
        _require(not missing, f"{path}: datasets without a 'units' attribute: {missing}")

        # step-by-step datasets: (times, ...) extendible along time
        _require("time" in f, f"{path}: /time is missing")
        n_times = f["time"].shape[0]
        present = {k: v for k, v in OPTIONAL_SERIES.items() if k in f}
        for name, (record, units) in {**SERIES, **present}.items():
            _require(name in f, f"{path}: /{name} is missing")
            dset = f[name]
            expected = (n_times,) + tuple(extents.get(e, e) for e in record)
            _require(dset.shape == expected,
                     f"{path}: /{name} has shape {dset.shape}, expected {expected}")
            _require(dset.chunks is not None and dset.maxshape[0] is None,
                     f"{path}: /{name} is not chunked and extendible along time")
            got = _text(dset.attrs["units"])
            _require(got == units, f"{path}: /{name} units '{got}', expected '{units}'")
        for name, columns in COLUMNS.items():
            if name in OPTIONAL_SERIES and name not in f:
                continue
            _require("columns" in f[name].attrs, f"{path}: /{name} has no 'columns' attribute")
            got = _text(f[name].attrs["columns"])
            _require(got == columns, f"{path}: /{name} columns '{got}', expected '{columns}'")

        # fixed datasets
        for name, units in FIXED.items():
            _require(name in f, f"{path}: /{name} is missing")
            dset = f[name]
            _require(dset.shape == (n_elements,),
                     f"{path}: /{name} has shape {dset.shape}, expected ({n_elements},)")
            got = _text(dset.attrs["units"])
            _require(got == units, f"{path}: /{name} units '{got}', expected '{units}'")
            _require(np.all(np.isfinite(dset[()])) and np.all(dset[()] > 0),
                     f"{path}: /{name} has non-positive or non-finite values")

        # solver statistics (written at the end of complete and failed runs)
        for name, units in STATS.items():
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

        # values
        time = f["time"][()]
        _require(np.all(np.isfinite(time)), f"{path}: /time has non-finite values")
        _require(np.all(np.diff(time) > 0), f"{path}: /time is not strictly increasing")
        kinetic = f["energy/kinetic"][()]
        elastic = f["energy/elastic"][()]
        gravity = f["energy/gravity"][()]
        total = f["energy/total"][()]
        expected_total = kinetic + elastic + gravity
        bad = np.abs(total - expected_total) > 1e-12 * np.abs(expected_total) + 1e-12
        _require(not np.any(bad),
                 f"{path}: /energy/total differs from kinetic + elastic + gravity at records "
                 f"{np.flatnonzero(bad).tolist()}")

        return {"records": int(n_times), "status": status, "reason": reason}


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) != 2:
        print("usage: python -m ropedyn.layout FILE N_ELEMENTS", file=sys.stderr)
        return 2
    try:
        summary = check_layout(argv[0], int(argv[1]))
    except (AssertionError, OSError, KeyError, ValueError) as exc:
        print(f"FAIL {exc}", file=sys.stderr)
        return 1
    line = f"{argv[0]}: layout OK ({summary['records']} records, status {summary['status']}"
    if summary["reason"]:
        line += f", reason: {summary['reason']}"
    print(line + ")")
    return 0


if __name__ == "__main__":
    sys.exit(main())
