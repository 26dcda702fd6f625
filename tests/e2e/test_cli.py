"""Command line: bad input gets one clear message (file, group, key, value), exit code 2
and no output file; a failed integration exits 3 and leaves a file marked failed."""

import h5py
import pytest

MODEL = "&model kind = 'rfem', elements = 4 /\n"
GOOD = MODEL + "&solver t_end = 0.05, output_interval = 0.01 /\n"

# (name, scene text, fragments the message must contain)
BAD_SCENES = [
    ("no_model", "&rope length = 1.0 /\n", ["no &model group"]),
    ("malformed", "&model kind = 'rfem', elements = 4\n&rope length = 1.0 /\n", ["&model"]),
    ("wrong_type", GOOD + "&rope length = 'long' /\n", ["&rope", "length", "long"]),
    ("unknown_key", GOOD + "&rope lenght = 2.0 /\n", ["&rope", "lenght"]),
    ("length", GOOD + "&rope length = -1.0 /\n", ["&rope", "length", "-1", "> 0"]),
    ("diameter", GOOD + "&rope diameter = 0.0 /\n", ["&rope", "diameter", "> 0"]),
    ("density", GOOD + "&rope density = -5.0 /\n", ["&rope", "density", "-5"]),
    ("elements", "&model kind = 'rfem', elements = 1 /\n", ["&model", "elements", "1", ">= 2"]),
    ("rtol", MODEL + "&solver rtol = 0.0 /\n", ["&solver", "rtol", "> 0"]),
    ("t_end", "&model kind = 'rfem' /\n&solver t_end = -3.0 /\n", ["&solver", "t_end", "-3"]),
    ("output_interval", "&model kind = 'rfem' /\n&solver output_interval = 0.0 /\n",
     ["&solver", "output_interval"]),
    ("kind", "&model kind = 'fem', elements = 4 /\n", ["&model", "kind", "fem", "rfem"]),
    ("method", MODEL + "&solver method = 'rk4' /\n", ["&solver", "method", "rk4"]),
    ("support", GOOD + "&supports top = 'glued' /\n", ["&supports", "top", "glued", "pinned"]),
    ("shape", GOOD + "&initial shape = 'coiled' /\n", ["&initial", "shape", "coiled"]),
    ("max_order", MODEL + "&solver max_order = 9 /\n", ["&solver", "max_order", "9"]),
    ("twice", GOOD + "&solver rtol = 1e-6 /\n", ["&solver", "twice"]),
]


@pytest.mark.parametrize("name,text,fragments", BAD_SCENES, ids=[b[0] for b in BAD_SCENES])
def test_bad_scene(run, tmp_path, name, text, fragments):
    scene = tmp_path / f"{name}.nml"
    scene.write_text(text)
    result = run("run", scene.name)
    assert result.returncode == 2, result.stderr
    message = result.stderr.strip()
    assert message.startswith("ropedyn: error: "), message
    assert len(message.splitlines()) == 1, message
    assert f"{name}.nml" in message, message
    for fragment in fragments:
        assert fragment in message, f"{fragment!r} not in {message!r}"
    assert not (tmp_path / "out").exists(), "bad input must not create output"


def test_unreadable_file(run, tmp_path):
    result = run("run", "missing.nml")
    assert result.returncode == 2
    assert "missing.nml" in result.stderr and "cannot open" in result.stderr


@pytest.mark.parametrize("override,fragments", [
    ("rope.length", ["rope.length", "group.key=value"]),
    ("foo.bar=1", ["foo", "unknown group"]),
    ("rope.lenght=2", ["&rope", "lenght"]),
    ("model.elements=abc", ["&model", "elements", "abc"]),
    ("rope.length=-2", ["rope.length=-2", "length", "> 0"]),
    ("rope.length=\t", ["rope.length=", "no value after"]),
])
def test_bad_override(run, tmp_path, override, fragments):
    (tmp_path / "good.nml").write_text(GOOD)
    result = run("run", "good.nml", "--set", override)
    assert result.returncode == 2, result.stderr
    for fragment in fragments:
        assert fragment in result.stderr, f"{fragment!r} not in {result.stderr!r}"
    assert not (tmp_path / "out").exists()


def test_bad_command_line(run, tmp_path):
    assert run("frobnicate").returncode == 2
    assert run("run").returncode == 2
    (tmp_path / "good.nml").write_text(GOOD)
    result = run("run", "good.nml", "--bogus")
    assert result.returncode == 2 and "--bogus" in result.stderr


def test_version(run):
    result = run("--version")
    assert result.returncode == 0 and result.stdout.startswith("ropedyn ")


@pytest.mark.parametrize("args,fragment", [
    (("run", "good.nml", "--force=no"), 'run: --force takes no value ("--force=no")'),
    (("run", "good.nml", "--verbose=1"), "--verbose takes no value"),
    (("statics", "good.nml", "--no-continuation=yes"), "--no-continuation takes no value"),
    (("modes", "good.nml", "--force=0"), "--force takes no value"),
    (("sweep", "s.nml", "--list=3"), "--list takes no value"),
    (("testset", "hires", "--csv=1"), "--csv takes no value"),
    (("testset", "--list", "hires"), '--list lists every problem: give no problem ("hires")'),
    (("--version", "extra"), '--version takes no arguments ("extra")'),
    (("--help", "extra"), '--help takes no arguments ("extra")'),
    (("run", "--help=1"), 'run: --help takes no value ("--help=1")'),
    (("testset", "--help=yes"), "testset: --help takes no value"),
    (("run", "--resume", "x.h5", "--force"), "--force does not apply to --resume"),
])
def test_a_flag_takes_no_value_and_no_stray_arguments(run, tmp_path, args, fragment):
    """A flag given a value was taken as the flag, the value ignored: '--force=no'
    forced the replacement of another run's file. Now it is a usage error, as are
    arguments after a command that takes none."""
    (tmp_path / "good.nml").write_text(GOOD)
    result = run(*args)
    assert result.returncode == 2, (args, result.stderr)
    message = result.stderr.strip()
    assert message.startswith("ropedyn: error: ") and len(message.splitlines()) == 1, message
    assert fragment in message, message
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("options", [("--help",), ("-h", "--list"), ("--task", "1", "--help")])
def test_sweep_help_after_the_file_does_only_help(run, tmp_path, options):
    """'ropedyn sweep FILE --help' printed the help and then ran the whole sweep with 0
    workers, which never ended ('--task 1 --help' ran case 1): --help after the sweep file
    left the file set, the mark of a plain --help."""
    (tmp_path / "good.nml").write_text(GOOD)
    (tmp_path / "s.nml").write_text("&sweep base = 'good.nml', elements = 4, 6 /\n")
    result = run("sweep", "s.nml", *options, timeout=20)
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith("usage: ropedyn sweep"), result.stdout
    assert result.stderr == ""
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("args,fragment", [
    (("sweep", "s.nml", "a\nb", "--list"), 'more than one sweep file: "s.nml", "a\\x0ab"'),
    (("sweep", "\r", "x", "--list"), 'more than one sweep file: "\\x0d", "x"'),
    (("keys", "rope", "\u00a0"), 'more than one group: "rope", "<U+00A0>"'),
    (("\ufeff",), 'unknown command "<U+FEFF>"'),
])
def test_usage_error_shows_control_and_invisible_characters(run, tmp_path, args, fragment):
    """A usage error quoted its arguments raw: a newline in one split the message into two
    lines, a CR or an invisible character hid what was wrong."""
    result = run(*args)
    assert result.returncode == 2, result.stderr
    assert result.stderr.startswith("ropedyn: error: ") and result.stderr.count("\n") == 1
    assert fragment in result.stderr, result.stderr
    assert "\r" not in result.stderr


@pytest.mark.parametrize("sets", [
    ("model.elements=6", "solver.rtol=1e-7"),
    # a tab where a scene file allows white space is white space in --set too
    ("\tmodel .\telements\t=\t6\t", "solver.rtol\t= 1e-7"),
])
def test_override_applies(run, tmp_path, sets):
    (tmp_path / "good.nml").write_text(GOOD)
    result = run("run", "good.nml", *(word for s in sets for word in ("--set", s)))
    assert result.returncode == 0, result.stderr
    with h5py.File(tmp_path / "out" / "good.h5") as f:
        assert f["state/q"].shape[1] == 6
        scene = f.attrs["scene"].decode()
    rtol = [line for line in scene.splitlines() if line.strip().startswith("rtol")]
    assert len(rtol) == 1 and float(rtol[0].split("=")[1]) == 1e-7, rtol


def test_a_tolerance_below_rounding_is_warned_of_and_not_budgeted(run, tmp_path):
    """rtol 1e-20 is below what double precision resolves: a warning says so when the scene
    is read; the run's steps shrink to the rounding limit, and the hint after max_steps
    names no budget above max_steps' largest value (it named 1.8e13 steps, which --set
    then refused) but a looser tolerance."""
    (tmp_path / "good.nml").write_text(GOOD)
    result = run("run", "good.nml", "--set", "solver.rtol=1e-20", "--set", "solver.atol=1e-30",
                 "--set", "solver.max_steps=2000")
    assert result.returncode == 3, result.stderr
    assert ("--set solver.rtol=1e-20: &solver: rtol = 1.0e-20: below what double precision "
            "resolves") in result.stderr, result.stderr
    assert ("no step budget covers that (solver.max_steps is at most 2147483647): loosen "
            "solver.rtol and atol") in result.stderr, result.stderr
    assert "--set solver.max_steps=" not in result.stderr
    tight = run("run", "good.nml", "--set", "solver.rtol=1e-13", "--set", "solver.t_end=0.01",
                "--set", "output.file=tight.h5")
    assert tight.returncode == 0 and "warning" not in tight.stderr, tight.stderr


def test_failed_integration_is_marked(run, tmp_path):
    (tmp_path / "short.nml").write_text(
        "&model kind = 'rfem', elements = 8 /\n"
        "&solver t_end = 1.0, output_interval = 0.01, max_steps = 300 /\n")
    result = run("run", "short.nml")
    assert result.returncode == 3, result.stderr
    assert "max_steps" in result.stderr and "t =" in result.stderr
    with h5py.File(tmp_path / "out" / "short.h5") as f:
        assert f.attrs["status"].decode() == "failed"
        assert "max_steps" in f.attrs["reason"].decode()
        t = f["time"][:]
        assert len(t) >= 2 and 0.0 < t[-1] < 1.0, "keeps the data before the failure"
        assert f["solver/steps"][()] >= 300


def test_unwritable_output(run, tmp_path):
    """An output file that cannot be created: exit code 4, a message naming the path."""
    blocker = tmp_path / "blocker"
    blocker.write_text("a file where a directory is needed")
    (tmp_path / "w.nml").write_text(GOOD + "&output file = 'blocker/run.h5' /\n")
    result = run("run", "w.nml")
    assert result.returncode == 4, result.stderr
    assert "blocker/run.h5" in result.stderr


def test_a_near_miss_of_a_command_or_group_gets_a_suggestion(run):
    near = run("runn", "x.nml")
    assert near.returncode == 2
    assert 'unknown command "runn"; did you mean "run"?' in near.stderr
    far = run("frobnicate")
    assert far.returncode == 2 and "commands: run, sweep, statics" in far.stderr
    group = run("keys", "rop")
    assert group.returncode == 2 and 'no group "rop"; did you mean "rope"?' in group.stderr


def test_keys_of_one_group(run):
    whole = run("keys").stdout.splitlines()
    rope = run("keys", "rope")
    assert rope.returncode == 0, rope.stderr
    lines = rope.stdout.splitlines()
    assert lines[0] == whole[0]
    assert lines[1:] == [x for x in whole[1:] if x.split("\t")[0] == "rope"]
    assert len(lines) > 5
    # a group name in any case, as in a scene file
    assert run("keys", "ROPE").stdout.splitlines() == lines
