"""The shared start of the Python scripts in scripts/ that a shell may run with the
shebang's python3, which lacks the project's packages: `rerun_with_venv` starts the script
again with the project's venv (.venv, which scripts/setup makes), or ends with a message
saying how to make it. Not a command itself."""
import os
import pathlib
import sys

VENV = pathlib.Path(__file__).resolve().parents[1] / ".venv"


def rerun_with_venv(script, missing):
    """Run `script` (its __file__) again with the venv's Python and the same arguments; when
    that is the Python running now, or there is no venv, exit naming `missing`."""
    python = VENV / "bin" / "python"
    if python.exists() and pathlib.Path(sys.prefix).resolve() != VENV.resolve():
        os.execv(str(python), [str(python), script, *sys.argv[1:]])
    sys.exit(f"{pathlib.Path(script).name}: no {missing} in {sys.prefix}: run scripts/setup "
             "(it makes .venv), then this script again")
