"""Scenes in-process: a scene file or namelist text, changed as `--set` changes it.

    scene = ropedyn.Scene.from_file("input/paper.nml")
    scene.set("model.elements", 40).set("solver.rtol", 1e-8)
    scene.get("model.elements")        # 40
    scene.write("out/paper_n40.nml")   # reads in again to the same scene

A Scene holds the effective scene as the library reads it (every key, as a run file's
`scene` attribute has it): each change is read and checked by the library with the rules
of `--set`, and a bad one raises ropedyn.Error and leaves the scene as it was.
"""
import ctypes
import os
import pathlib
import re

from ropedyn._lib import c_handle, library
from ropedyn.errors import Error, message_text
from ropedyn.namelist import parse_namelist

#: how scene texts cross to the library and back: a byte that is not UTF-8 (a Latin-1
#: file's string value, which the library reads as the command line does) comes back as
#: the same byte
TEXT = ("utf-8", "surrogateescape")


def _value_text(value):
    """A Python value as the text of `--set group.key=VALUE`."""
    if isinstance(value, bool):
        return ".true." if value else ".false."
    if isinstance(value, float):
        # float(): numpy's float64 is a float whose repr is "np.float64(2.0)" (numpy 2)
        return repr(float(value))
    if isinstance(value, (list, tuple)):
        if any(isinstance(v, (list, tuple)) or getattr(v, "ndim", 0) for v in value):
            # a 2-D array's rows were joined into one list of values
            raise Error(f"set: a value is a bool, a number, a string or a pair, not "
                        f"{value!r}", 2)
        return ", ".join(_value_text(v) for v in value)
    if hasattr(value, "tolist"):   # numpy scalars and arrays
        return _value_text(value.tolist())
    return str(value)


def _path_text(what, path):
    """The text of a file's path (a str, bytes or an os.PathLike); Error for anything
    else (str() made a path "None" of None)."""
    if not isinstance(path, (str, bytes, os.PathLike)):
        raise Error(f"{what} is a file's path (a str, bytes or a pathlib.Path), not "
                    f"{path!r}", 2)
    return os.fsdecode(path)


def _unset_keys(text):
    """{group: {key, ...}}: the keys that the effective scene text shows as not set, on
    comment lines "! key = (not set: ...)"."""
    unset, group = {}, None
    for line in text.splitlines():
        start = re.match(r"\s*&(\w+)", line)
        if start:
            group = start.group(1).lower()
            continue
        key = re.match(r"\s*!\s*(\w+)\s*=\s*\(not set\b", line)
        if key and group:
            unset.setdefault(group, set()).add(key.group(1).lower())
    return unset


class _Handle:
    """An instance of the library for one call sequence; destroyed on exit."""

    def __init__(self, create, *args):
        self.lib = library()
        self.h = c_handle()
        status = create(*args, ctypes.byref(self.h))
        if status != 0:
            self.fail(status)

    def fail(self, status):
        message = message_text(self.lib.ropedyn_last_error(self.h))
        self.close()
        raise Error(message, status)

    def check(self, status):
        if status != 0:
            self.fail(status)

    def text(self, function):
        out = ctypes.c_char_p()
        self.check(function(self.h, ctypes.byref(out)))
        return out.value.decode(*TEXT)

    def close(self):
        if self.h:
            self.lib.ropedyn_destroy(self.h)
            self.h = c_handle()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def _open(text, name, settings=()):
    """A library instance of the scene `text` named `name`, with `settings` applied
    together."""
    lib = library()
    if "\0" in text or "\0" in name:
        # C strings: the library would see the text up to the NUL, and silently no more
        raise Error(f"{name}: the scene text holds a NUL character", 2)
    handle = _Handle(lib.ropedyn_create_from_text, text.encode(*TEXT), name.encode())
    if settings:
        _apply(handle, settings)
    return handle


def _apply(handle, settings):
    """`settings` ('group.key=value' each) applied to the instance of `handle` together, as
    several --set; Error (the handle closed) when one is bad."""
    if any("\n" in s for s in settings):
        handle.close()
        raise Error("set: a value holds a new line", 2)
    handle.check(handle.lib.ropedyn_set(handle.h, "\n".join(settings).encode(*TEXT)))


class Scene:
    """A scene: namelist text (a scene file's content) read and checked by the library."""

    def __init__(self, text, name="scene"):
        """The scene of namelist `text`; `name` stands for its file in messages and in the
        default output file (out/NAME.h5). Relative paths in it are relative to the
        folder of `name`, or to the current directory when `name` has none."""
        if not isinstance(text, str):
            # str() made a scene of "b'&model ...'" or of a file's path
            raise Error(f"Scene: text is namelist text (a str), not {text!r}; "
                        "Scene.from_file reads a scene file", 2)
        self.name = _path_text("Scene: name", name)
        # what the scene was made of (its text, or its file when _source is None) and the
        # settings made since, all applied again at each set, as several --set: a derived
        # default (tangential_damping from normal_damping) follows the last of them
        self._source = text
        self._settings = []
        self._read([])

    @classmethod
    def from_file(cls, path):
        """The scene of a scene file (as `ropedyn run PATH` reads it)."""
        scene = cls.__new__(cls)
        scene.name = _path_text("Scene.from_file: path", path)
        scene._source = None
        scene._settings = []
        scene._read([])
        return scene

    def _read(self, settings):
        """The effective text and warnings of the source with `settings` (checked together;
        Error, and the scene unchanged, when one is bad)."""
        if self._source is None:
            lib = library()
            handle = _Handle(lib.ropedyn_create_from_file, self.name.encode(*TEXT))
            if settings:
                _apply(handle, settings)
        else:
            handle = _open(self._source, self.name, settings)
        with handle:
            self._text = handle.text(handle.lib.ropedyn_scene_text)
            self._warnings = handle.text(handle.lib.ropedyn_warnings)
        self._settings = list(settings)

    @property
    def text(self):
        """The effective scene as namelist text (every key)."""
        return self._text

    @property
    def warnings(self):
        """Values that are legal but probably a unit slip, one text each."""
        return [line for line in self._warnings.splitlines() if line]

    def set(self, key, value=None):
        """Set "group.key" to `value` with the rules of `--set group.key=value` (a bool, a
        number, a string, a pair as a tuple); or, with a dict as `key`, several keys at once
        (checked together, as several --set are). Returns the scene."""
        items = key.items() if isinstance(key, dict) else [(key, value)]
        settings = [f"{k}={_value_text(v)}" for k, v in items]
        self._read(self._settings + settings)
        return self

    def get(self, key):
        """The value of "group.key" (a number, bool, string, or a list for a pair); None
        for a key that is not set (an optional key with no default, which the text shows as
        "! key = (not set: ...)"); a key that does not exist raises KeyError."""
        if not isinstance(key, str):
            raise KeyError(key)
        group, _, name = key.lower().partition(".")
        values = parse_namelist(self._text).get(group, {})
        if name in values:
            return values[name]
        if name in _unset_keys(self._text).get(group, ()):
            return None
        raise KeyError(key)

    def write(self, path):
        """Write the scene to `path` (a scene file: it reads in again to this scene)."""
        path = pathlib.Path(_path_text("Scene.write: path", path))
        path.write_text(self._text + "\n", encoding=TEXT[0], errors=TEXT[1])
        return path

    def copy(self):
        """An independent copy."""
        other = Scene.__new__(Scene)
        other.__dict__.update(self.__dict__)
        other._settings = list(self._settings)
        return other

    def __eq__(self, other):
        return isinstance(other, Scene) and self._text == other._text

    def __repr__(self):
        return f"<ropedyn.Scene {self.name!r}>"
