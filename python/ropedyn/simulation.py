"""Simulations in-process: run a scene, or drive one step by step.

    run = ropedyn.run(ropedyn.Scene.from_file("input/paper.nml"))   # a Run, no file
    run.energy["total"], run.points[-1]

    with ropedyn.Simulation(scene) as sim:           # top_motion = 'coupled'
        for k in range(1, 1001):
            t = k * 1e-3
            sim.set_support("top", position=(0.0, 0.05 * sin(t)), velocity=(0.0, 0.05 * cos(t)))
            sim.advance(t)
            tension = sim.reaction("top")            # (2,) N: the support's force on the rope

The frame: x down (gravity), y horizontal; SI units. What applies of a command-line run,
and the coupling rule: the API page of the manual (docs/reference/api.md).
"""
import ctypes
import io
import numbers
import os
import pathlib

import numpy as np

from ropedyn._lib import c_handle, library
from ropedyn.errors import Error, message_text
from ropedyn.scene import TEXT, Scene, _path_text

SUPPORTS = {"top": 0, "bottom": 1}
ENERGY_NAMES = ("kinetic", "elastic", "gravity", "dissipated", "support_work", "total")


def _scene_of(scene):
    """A Scene from a Scene, or from the path of a scene file."""
    if isinstance(scene, Scene):
        return scene
    if not isinstance(scene, (str, bytes, os.PathLike)):
        raise Error(f"the scene is a Scene or a scene file's path, not {scene!r}", 2)
    return Scene.from_file(scene)


def _support(end):
    if not isinstance(end, str) or end not in SUPPORTS:
        raise Error(f"unknown support {end!r} (top or bottom)", 2)
    return SUPPORTS[end]


def _real(value):
    """`value` as a float when it is one real number: an int or float (numpy's too) or a
    0-d array of one, not a bool; else None."""
    if isinstance(value, (bool, np.bool_)):
        return None
    if isinstance(value, numbers.Real) or (isinstance(value, np.ndarray) and value.shape == ()
                                           and value.dtype.kind in "iuf"):
        try:
            return float(value)
        except OverflowError:   # an int past the range of a float: the library refuses it
            return float("inf") if value > 0 else float("-inf")
    return None


def _pair(value):
    """`value` as two floats when it is a pair of real numbers (a tuple, list or 1-D
    array of two); else None. A dict or set, whose iteration gave two keys, is none."""
    if type(value) is tuple and len(value) == 2 and type(value[0]) is type(value[1]) is float:
        return value   # the common case, checked at little cost
    if isinstance(value, np.ndarray):
        if value.shape != (2,) or value.dtype.kind not in "iuf":
            return None
    elif not isinstance(value, (tuple, list)) or len(value) != 2:
        return None
    x, y = _real(value[0]), _real(value[1])
    return None if x is None or y is None else (x, y)


def run(scene, output=None):
    """Run `scene` (a Scene, or a scene file's path) from its start to t_end as `ropedyn run`
    does (the same records, order safety and statuses; no signals caught) and return it as
    the Run that ropedyn.load_run reads. No file is written unless `output` names one (it is
    then guarded as the command line's output: a lock, FILE.part until the end)."""
    from ropedyn.io import load_run
    scene = _scene_of(scene)
    if output is not None:
        # str() wrote output=True to a file "True" (and then failed to read it back)
        output = _path_text("run: output", output) or None
    lib = library()
    h = c_handle()
    image, size = ctypes.c_void_p(), ctypes.c_size_t()
    try:
        status = lib.ropedyn_create_from_text(scene.text.encode(*TEXT), scene.name.encode(),
                                              ctypes.byref(h))
        if status == 0:
            status = lib.ropedyn_run(h, output.encode(*TEXT) if output else None,
                                     ctypes.byref(image), ctypes.byref(size))
        message = message_text(lib.ropedyn_last_error(h))
        data = ctypes.string_at(image, size.value) if image.value and size.value else b""
    finally:
        lib.ropedyn_destroy(h)
    if status == 0:
        return _loaded(load_run, scene, output, data)
    error = Error(message, status)
    if status == 3 and (data or (output and pathlib.Path(output).is_file())):
        # a failed integration: the records up to the failure, as the file has them
        error.run = _loaded(load_run, scene, output, data)
    raise error


def _loaded(load_run, scene, output, data):
    """The Run of a file, or of a file's bytes in memory."""
    if output:
        return load_run(output)
    result = load_run(io.BytesIO(data))
    result.path = f"{scene.name} (in memory)"
    return result


class Snapshot:
    """A state of a Simulation kept in memory (Simulation.save); restore it with
    Simulation.restore."""

    def __init__(self, lib, handle, t):
        self._lib = lib
        self._h = handle
        self._t = t

    @property
    def t(self):
        """The time of the state kept, s."""
        if not self._h:
            raise Error("the snapshot is closed", 2)
        return self._t

    def close(self):
        if self._h:
            self._lib.ropedyn_snapshot_destroy(self._h)
            self._h = c_handle()

    def __del__(self):
        self.close()


class Simulation:
    """A scene's simulation, moved on by `advance`; no file is written.

    `statics=True` starts at the static equilibrium (at rest) instead of the scene's
    initial state. The scene's t_end does not stop it, and nothing is recorded; the step
    budget (solver.max_steps) counts every step of the simulation, and the order safety's
    second look does not run (docs/reference/api.md says why)."""

    def __init__(self, scene, statics=False):
        if not isinstance(statics, (bool, np.bool_)):
            # any truthy object ("no", 0.0 that was meant as a time) would start at rest
            raise Error(f"Simulation: statics is True or False, not {statics!r}", 2)
        # a copy: a later set on the Scene given changed sim.scene, not what it simulates
        self._scene = _scene_of(scene).copy()
        self._lib = library()
        self._h = c_handle()
        status = self._lib.ropedyn_create_from_text(
            self._scene.text.encode(*TEXT), self._scene.name.encode(), ctypes.byref(self._h))
        if status == 0:
            status = self._lib.ropedyn_init(self._h, 1 if statics else 0)
        self._check(status)
        n, size = ctypes.c_int(), ctypes.c_int()
        self._check(self._lib.ropedyn_size(self._h, ctypes.byref(n), ctypes.byref(size)))
        self._n, self._state_size = n.value, size.value
        self._t = ctypes.c_double()
        self._p = (ctypes.c_double * 2)()
        self._v = (ctypes.c_double * 2)()
        self._f = (ctypes.c_double * 2)()
        # buffers of the reads made every exchange of a coupling, with their pointers made
        # once (a numpy array from a ctypes array, or a pointer made per call, costs more
        # than the call into the library)
        self._force = np.empty(2)
        self._force_ptr = self._force.ctypes.data_as(ctypes.POINTER(ctypes.c_double))
        self._xy = np.empty((2 * self._n, 2))
        self._xy_ptr = self._xy.ctypes.data_as(ctypes.POINTER(ctypes.c_double))
        self._advance = self._lib.ropedyn_advance
        self._set_support = self._lib.ropedyn_set_support
        self._reaction = self._lib.ropedyn_reaction
        self._points = self._lib.ropedyn_points

    def _check(self, status):
        if status != 0:
            message = message_text(self._lib.ropedyn_last_error(self._h))
            if not self._alive():
                self.close()
            raise Error(message, status)

    def _alive(self):
        return bool(self._h) and hasattr(self, "_n")

    def _handle(self):
        if not self._h:
            raise Error("the simulation is closed", 2)
        return self._h

    # ---- what it is (every property of a closed simulation raises, as its methods do) ---

    @property
    def scene(self):
        """The scene simulated (a copy of the Scene given: later changes to that do not
        reach it)."""
        self._handle()
        return self._scene

    @property
    def n(self):
        """The number of elements."""
        self._handle()
        return self._n

    @property
    def state_size(self):
        """The number of unknowns: the length of `state`."""
        self._handle()
        return self._state_size

    # ---- moving on -------------------------------------------------------------------

    def advance(self, t):
        """Integrate to time `t` (s, not before the time reached). A failed integration
        raises ropedyn.Error, keeps the last good state and ends the simulation: later
        `advance`, `set_support`, `save` and assignments to `state` raise the same error
        until `restore`; the reads give the last good state."""
        if type(t) is not float:   # the common case, checked at no cost
            number = _real(t)
            if number is None:
                # a bool or an array of one number was taken, a text refused by ctypes
                raise Error(f"advance: t is a time in s (a number), not {t!r}", 2)
            t = number
        status = self._advance(self._handle(), t)
        if status != 0:
            self._check(status)

    def set_support(self, end, position, velocity=(0.0, 0.0)):
        """Prescribe the coupled support `end` ('top' or 'bottom'; its &supports motion
        'coupled') at the time of the next `advance`: position (x, y) in m, velocity in m/s
        ((0, 0) when left out: at rest there, not on with its velocity now). In between it
        moves on the cubic Hermite curve from its position and velocity now (as a motion
        table's segment)."""
        p, v = self._p, self._v
        position_xy, velocity_xy = _pair(position), _pair(velocity)
        if position_xy is None or velocity_xy is None:
            # bools were taken as 0 and 1, a dict's or set's two keys as (x, y)
            raise Error(f"set_support: position and velocity are two numbers each, (x, y) "
                        f"in m and m/s, not {position!r} and {velocity!r}", 2)
        p[0], p[1] = position_xy
        v[0], v[1] = velocity_xy
        status = self._set_support(self._handle(), _support(end), p, v)
        if status != 0:
            self._check(status)

    # ---- the state now ---------------------------------------------------------------

    @property
    def t(self):
        """The time reached, s."""
        self._check(self._lib.ropedyn_time(self._handle(), ctypes.byref(self._t)))
        return self._t.value

    @property
    def points(self):
        """The polyline (2n, 2), m: element end points A_1, B_1, A_2, ... (x, y), as a
        record of /rope/points."""
        status = self._points(self._handle(), self._xy_ptr, 2 * self._n)
        if status != 0:
            self._check(status)
        return self._xy.copy()

    @property
    def forces(self):
        """The internal forces at the joints 0 (top end) .. n: 'axial' (tension > 0, N),
        'shear' (N), 'moment' (N m), each (n + 1,)."""
        handle = self._handle()
        out = {k: np.empty(self._n + 1) for k in ("axial", "shear", "moment")}
        ptr = ctypes.POINTER(ctypes.c_double)
        self._check(self._lib.ropedyn_forces(
            handle, *(out[k].ctypes.data_as(ptr) for k in ("axial", "shear", "moment")),
            self._n + 1))
        return out

    def reaction(self, end):
        """The force (x, y) of support `end` on the rope, N (zero for a free end)."""
        status = self._reaction(self._handle(), _support(end), self._force_ptr)
        if status != 0:
            self._check(status)
        return self._force.copy()

    def anchor(self, end):
        """Where support `end` holds the rope now (x, y), m (NaN for a free end)."""
        self._check(self._lib.ropedyn_support_position(self._handle(), _support(end),
                                                       self._f))
        return np.array(self._f[:])

    @property
    def energy(self):
        """The energies now, J: kinetic, elastic, gravity, dissipated, support_work (the
        external work so far), total (kinetic + elastic + gravity)."""
        out = (ctypes.c_double * 6)()
        self._check(self._lib.ropedyn_energy(self._handle(), out))
        return dict(zip(ENERGY_NAMES, out[:]))

    @property
    def state(self):
        """The ODE state (as /state/y of a record)."""
        handle = self._handle()
        out = np.empty(self._state_size)
        self._check(self._lib.ropedyn_get_state(
            handle, out.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), self._state_size))
        return out

    @state.setter
    def state(self, y):
        handle, size = self._handle(), self._state_size
        try:
            given = np.asarray(y)
        except (TypeError, ValueError):   # a ragged list
            given = np.asarray(None)
        if given.dtype.kind not in "iuf":
            # strings ("1.0" is no number here), bools, objects
            raise Error(f"state: {size} numbers, not {y!r}", 2)
        if given.shape != (size,):
            # a (2, size/2) array was flattened and taken
            raise Error(f"state: a 1-D sequence of {size} numbers (shape ({size},)), not "
                        f"one of shape {given.shape}", 2)
        y = np.ascontiguousarray(given, dtype=float)
        self._check(self._lib.ropedyn_set_state(
            handle, y.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), y.size))

    # ---- keeping states --------------------------------------------------------------

    def save(self):
        """Keep the state now (a Snapshot). The simulation goes on from here exactly as it
        will after `restore` of it."""
        snap = c_handle()
        self._check(self._lib.ropedyn_save(self._handle(), ctypes.byref(snap)))
        return Snapshot(self._lib, snap, self.t)

    def restore(self, snapshot):
        """Go back to a state kept by `save` (also after a failed advance)."""
        if not isinstance(snapshot, Snapshot):
            raise Error(f"restore: a Snapshot of Simulation.save, not {snapshot!r}", 2)
        if not snapshot._h:
            raise Error("restore: the snapshot is closed", 2)
        self._check(self._lib.ropedyn_restore(self._handle(), snapshot._h))

    # ---- the end ---------------------------------------------------------------------

    def close(self):
        """Free the simulation (further calls, and reads of its properties, raise
        ropedyn.Error)."""
        if getattr(self, "_h", None):
            self._lib.ropedyn_destroy(self._h)
            self._h = c_handle()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        self.close()

    def __repr__(self):
        state = f"t = {self.t:g} s" if self._h else "closed"
        return (f"<ropedyn.Simulation {self._scene.name!r}, n = {getattr(self, '_n', '?')}, "
                f"{state}>")
