"""ropedyn in Python: scenes and simulations in-process, and what the executable writes.

In-process (the shared library libropedyn through ctypes; docs/reference/api.md):

- `ropedyn.Scene.from_file(path)`, `ropedyn.Scene(text)`: a scene, changed with
  `scene.set("group.key", value)` (the rules of `--set`), written with `scene.write(path)`;
- `ropedyn.run(scene)`: the whole run as `ropedyn run` makes it, as the `Run` that
  `ropedyn.load_run` reads (no file unless `output=` names one);
- `ropedyn.Simulation(scene)`: a simulation moved on with `advance(t)`, read with `t`,
  `points`, `forces`, `reaction(end)`, driven with `set_support(end, position, velocity)`;
- `ropedyn.Error`: every failure, with the command line's message and exit code.

Modules (each command-line module has `main(argv=None)` and runs with `python -m`):

- `ropedyn.io`: read a run file into numpy arrays with units (`load_run` -> `Run`);
- `ropedyn.namelist`: the scene text (Fortran namelist) as a dict;
- `ropedyn.fields`: derived fields: supports, axial force, curvature, speed;
- `ropedyn.layout`: check a run, statics or modes file against the documented layout
  (docs/reference/file-format.md);
- `ropedyn.plot`: drawing helpers; `ropedyn.plot.overview` (scripts/plot),
  `ropedyn.plot.energy` (scripts/plot_energy.py);
- `ropedyn.animate` (scripts/animate), `ropedyn.xdmf` (scripts/xdmf).

The studies that write docs/ and the maintenance tools of the repository are not part of
this package: they are `ropedyn_tools` in tools/ of the source tree, run by scripts/.

`import ropedyn` is light; everything above is loaded on first use.
"""

__version__ = "0.1.0"
__all__ = ["Run", "load_run", "Scene", "Simulation", "Snapshot", "run", "Error",
           "__version__"]

_LAZY = {"Run": "ropedyn.io", "load_run": "ropedyn.io", "Scene": "ropedyn.scene",
         "Simulation": "ropedyn.simulation", "Snapshot": "ropedyn.simulation",
         "run": "ropedyn.simulation", "Error": "ropedyn.errors"}


def __getattr__(name):
    if name in _LAZY:
        import importlib
        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'ropedyn' has no attribute {name!r}")


def __dir__():
    # the lazy names too: dir(ropedyn), help() and a notebook's completion list them
    return sorted(set(globals()) | set(_LAZY))
