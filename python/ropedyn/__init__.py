"""Reading, plotting and animating what the ropedyn executable writes.

Modules (each command-line module has `main(argv=None)` and runs with `python -m`):

- `ropedyn.io`: read a run file into numpy arrays with units (`load_run` -> `Run`);
- `ropedyn.namelist`: the scene text (Fortran namelist) as a dict;
- `ropedyn.fields`: derived fields: supports, axial force, curvature, speed;
- `ropedyn.layout`: check a run file against the documented layout (docs/reference/file-format.md);
- `ropedyn.plot`: drawing helpers; `ropedyn.plot.overview` (scripts/plot),
  `ropedyn.plot.energy` (scripts/plot_energy.py);
- `ropedyn.animate` (scripts/animate), `ropedyn.xdmf` (scripts/xdmf).

The studies that write docs/ and the maintenance tools of the repository are not part of
this package: they are `ropedyn_tools` in tools/ of the source tree, run by scripts/.

`import ropedyn` is light; `ropedyn.load_run` and `ropedyn.Run` are loaded on first use.
"""

__version__ = "0.1.0"
__all__ = ["Run", "load_run", "__version__"]


def __getattr__(name):
    if name in ("Run", "load_run"):
        from ropedyn import io
        return getattr(io, name)
    raise AttributeError(f"module 'ropedyn' has no attribute {name!r}")
