"""Compare a ropedyn output with a reference output, quantity by quantity.

usage: python -m ropedyn_tools.compare REFERENCE.h5 NEW.h5

Works for the files of `ropedyn run`, `ropedyn statics` and `ropedyn modes`: the quantities
of TOLERANCES that the reference holds are compared (a quantity missing from the new file
fails). Each has an explicit absolute tolerance in its own units. The references are
converged: scripts/update_references refuses one that differs from its own run at a ten
times tighter solver tolerance by more than these tolerances (docs/development/testing.md), so a more
accurate run of a reference scene passes; the tolerances also allow for the differences
between compilers, optimization levels and LAPACK builds (measured: ~1e-9 m between the
Debug and Release builds), and are far below what a change in the physics produces (a 1 %
change of Young's modulus fails). Statics and modes are solved to the rounding level, so
their tolerances are tight. Prints one line per quantity and exits 1 when any exceeds its
tolerance.
"""
import sys

import h5py
import numpy as np

#: dataset -> (absolute tolerance, units)
TOLERANCES = {
    "time": (1e-12, "s"),
    "state/q": (5e-6, "m, rad"),
    "state/qdot": (5e-4, "m/s, rad/s"),
    "rope/points": (1e-6, "m"),
    "energy/kinetic": (1e-7, "J"),
    "energy/elastic": (1e-7, "J"),
    "energy/gravity": (1e-7, "J"),
    "energy/dissipated": (1e-7, "J"),
    "energy/support_work": (1e-7, "J"),
    "energy/total": (1e-7, "J"),
    # ropedyn statics and ropedyn modes (the equilibrium's state/q, rope/points and
    # energy/elastic, energy/gravity are compared with the entries above)
    "statics/q": (1e-9, "m, rad"),
    "statics/support_force_top": (1e-9, "N"),
    "statics/support_force_bottom": (1e-9, "N"),
    "modes/omega": (1e-6, "rad/s"),
    "modes/damping_ratio": (1e-9, "1"),
    "modes/shape": (1e-6, "m, rad (largest entry 1)"),
}


def compare(reference, new, out=sys.stdout):
    """Return the list of failing quantities; print a readable table."""
    failures = []
    with h5py.File(reference, "r") as ref, h5py.File(new, "r") as cur:
        for attr in ("model", "method", "analysis", "status"):
            if attr not in ref.attrs:
                continue
            a, b = ref.attrs[attr], cur.attrs.get(attr)
            if a != b:
                failures.append(attr)
                print(f"  {attr:22s} differs: reference {a!r}, new {b!r}", file=out)
        for name, (tol, units) in TOLERANCES.items():
            if name not in ref:
                continue
            if name not in cur:
                failures.append(name)
                print(f"  FAIL {name:22s} missing from the new file", file=out)
                continue
            a, b = ref[name][()], cur[name][()]
            if a.shape != b.shape:
                failures.append(name)
                print(f"  {name:22s} shape {b.shape} != reference {a.shape}", file=out)
                continue
            diff = np.abs(a - b)
            worst = float(diff.max()) if diff.size else 0.0
            where = np.unravel_index(int(diff.argmax()), diff.shape) if diff.size else ()
            ok = worst <= tol
            if not ok:
                failures.append(name)
            when = f", t = {ref['time'][where[0]]:.3f} s" if where and "time" in ref else ""
            print(f"  {'ok  ' if ok else 'FAIL'} {name:22s} max |diff| {worst:9.2e} "
                  f"(tolerance {tol:.0e} {units}) at index {tuple(int(i) for i in where)}"
                  f"{when}", file=out)
    return failures


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    failures = compare(argv[0], argv[1])
    if failures:
        print(f"compare: {len(failures)} quantities differ: {', '.join(failures)}")
        return 1
    print("compare: all quantities within tolerance")
    return 0


if __name__ == "__main__":
    sys.exit(main())
