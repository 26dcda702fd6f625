"""The hostile corpus (tests/hostile/manifest.txt): bad scene files, sweep files, --set
arguments and command lines. Each must end with its exit code and one message line naming
the culprit, without crash text, and leave no file behind (nothing runs: every case fails
while its input is read)."""
import pathlib
import shlex
import shutil
import subprocess

import pytest

HOSTILE = pathlib.Path(__file__).resolve().parents[1] / "hostile"
CRASH_TEXT = ("Fortran runtime", "Backtrace", "Segmentation", "Error termination", "ERROR STOP",
              "Program received signal", "SIGSEGV", "SIGABRT", "malloc")


def manifest():
    cases = []
    text = (HOSTILE / "manifest.txt").read_text(encoding="utf-8")
    for number, line in enumerate(text.splitlines(), 1):
        if not line.strip() or line.startswith("#"):
            continue
        args, code, fragment = line.split(" | ", 2)
        cases.append(pytest.param(shlex.split(args), int(code), fragment,
                                  id=f"{number}:{args[:60]}"))
    return cases


def files_below(root):
    return {p.relative_to(root) for p in root.rglob("*")}


def test_corpus_size():
    assert len(manifest()) >= 100


@pytest.mark.parametrize("args,code,fragment", manifest())
def test_hostile_input(ropedyn_exe, tmp_path, args, code, fragment):
    work = tmp_path / "hostile"
    shutil.copytree(HOSTILE, work)
    before = files_below(work)
    result = subprocess.run([str(ropedyn_exe), *args], cwd=work, capture_output=True,
                            text=True, encoding="utf-8", errors="replace", timeout=20)
    assert result.returncode == code, result.stderr
    assert fragment in result.stderr, f"{fragment!r} not in {result.stderr!r}"
    error_lines = [line for line in result.stderr.splitlines()
                   if line.startswith("ropedyn: error: ")]
    assert len(error_lines) == 1, result.stderr
    for text in CRASH_TEXT:
        assert text not in result.stderr + result.stdout, result.stderr
    assert files_below(work) == before, "bad input must not leave files"
