"""The shared library libropedyn (include/ropedyn.h), loaded with ctypes.

Where it is looked for, in order:

1. the file named by the environment variable ROPEDYN_LIBRARY (set, it must exist: the
   others are not looked at);
2. beside this package (``pip install`` of the package builds it there);
3. the build folders build/release and build/debug of the source tree this package sits
   in, when it sits in one: a clone's package, used in place by the clone's venv, loads
   that clone's library.

Calls release the GIL (ctypes.CDLL), so that other Python threads run meanwhile; the
library itself runs one call at a time (docs/reference/api.md, "Threads"), so simulations
in two threads do not integrate at once.
"""
import ctypes
import os
import pathlib
import threading

_HERE = pathlib.Path(__file__).resolve().parent
_NAME = "libropedyn.so"

c_double_p = ctypes.POINTER(ctypes.c_double)
c_handle = ctypes.c_void_p

# name: (result, argument types), as in include/ropedyn.h
_SIGNATURES = {
    "ropedyn_version": (ctypes.c_char_p, []),
    "ropedyn_create_from_file": (ctypes.c_int, [ctypes.c_char_p, ctypes.POINTER(c_handle)]),
    "ropedyn_create_from_text": (ctypes.c_int, [ctypes.c_char_p, ctypes.c_char_p,
                                                ctypes.POINTER(c_handle)]),
    "ropedyn_set": (ctypes.c_int, [c_handle, ctypes.c_char_p]),
    "ropedyn_scene_text": (ctypes.c_int, [c_handle, ctypes.POINTER(ctypes.c_char_p)]),
    "ropedyn_warnings": (ctypes.c_int, [c_handle, ctypes.POINTER(ctypes.c_char_p)]),
    "ropedyn_init": (ctypes.c_int, [c_handle, ctypes.c_int]),
    "ropedyn_advance": (ctypes.c_int, [c_handle, ctypes.c_double]),
    "ropedyn_time": (ctypes.c_int, [c_handle, c_double_p]),
    "ropedyn_size": (ctypes.c_int, [c_handle, ctypes.POINTER(ctypes.c_int),
                                    ctypes.POINTER(ctypes.c_int)]),
    "ropedyn_get_state": (ctypes.c_int, [c_handle, c_double_p, ctypes.c_int]),
    "ropedyn_set_state": (ctypes.c_int, [c_handle, c_double_p, ctypes.c_int]),
    "ropedyn_points": (ctypes.c_int, [c_handle, c_double_p, ctypes.c_int]),
    "ropedyn_forces": (ctypes.c_int, [c_handle, c_double_p, c_double_p, c_double_p,
                                      ctypes.c_int]),
    "ropedyn_reaction": (ctypes.c_int, [c_handle, ctypes.c_int, c_double_p]),
    "ropedyn_support_position": (ctypes.c_int, [c_handle, ctypes.c_int, c_double_p]),
    "ropedyn_energy": (ctypes.c_int, [c_handle, c_double_p]),
    "ropedyn_set_support": (ctypes.c_int, [c_handle, ctypes.c_int, c_double_p, c_double_p]),
    "ropedyn_save": (ctypes.c_int, [c_handle, ctypes.POINTER(c_handle)]),
    "ropedyn_restore": (ctypes.c_int, [c_handle, c_handle]),
    "ropedyn_snapshot_destroy": (None, [c_handle]),
    "ropedyn_run": (ctypes.c_int, [c_handle, ctypes.c_char_p, ctypes.POINTER(ctypes.c_void_p),
                                   ctypes.POINTER(ctypes.c_size_t)]),
    "ropedyn_last_error": (ctypes.c_char_p, [c_handle]),
    "ropedyn_destroy": (None, [c_handle]),
}

_lock = threading.Lock()
_loaded = None


def candidates():
    """The places the library is looked for, in order (see the module's docstring)."""
    found = []
    if os.environ.get("ROPEDYN_LIBRARY"):
        found.append(pathlib.Path(os.environ["ROPEDYN_LIBRARY"]))
    found.append(_HERE / _NAME)
    root = _HERE.parents[1]
    if (root / "CMakeLists.txt").is_file() and (root / "include" / "ropedyn.h").is_file():
        found += [root / "build" / kind / _NAME for kind in ("release", "debug")]
    return found


def library():
    """The loaded library (loaded once per process)."""
    global _loaded
    with _lock:
        if _loaded is None:
            _loaded = _load()
        return _loaded


def _load():
    from ropedyn.errors import Error
    chosen = os.environ.get("ROPEDYN_LIBRARY")
    if chosen and not pathlib.Path(chosen).is_file():
        raise Error(f"ROPEDYN_LIBRARY={chosen}: no such file (unset it to load the "
                    "package's own library)", 2)
    tried = candidates()
    for path in tried:
        if path.is_file():
            lib = ctypes.CDLL(str(path))
            for name, (result, arguments) in _SIGNATURES.items():
                function = getattr(lib, name)
                function.restype = result
                function.argtypes = arguments
            lib.path = path
            return lib
    raise Error("libropedyn not found (looked for " + ", ".join(map(str, tried)) +
                "): build the library of this source tree (build/release), install the package "
                "with pip, or set "
                "ROPEDYN_LIBRARY to the file", 2)
