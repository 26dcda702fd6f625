"""What the studies share when they write their results into docs/: the machine line, the
time stamp and the generated section between two markers of a Markdown page; a number read
from a scene file's text; git's answers about the checkout (`git`, `baseline_revision`)."""
import datetime
import os
import pathlib
import platform
import re
import subprocess


def git(*args, root=None):
    """stdout (bytes) of `git -C root ARGS` (root: this checkout); CalledProcessError when
    git fails."""
    from ropedyn_tools.repo import ROOT
    return subprocess.run(["git", "-C", str(root or ROOT), *args], capture_output=True,
                          check=True).stdout


def baseline_revision(parser, rev):
    """The short hash of the commit `rev` names (a --baseline argument; None when it is not
    given), or a usage error naming the option and the value (exit 2) when git knows no
    such commit."""
    if not rev:
        return None
    try:
        return git("rev-parse", "--verify", "--quiet", "--short",
                   f"{rev}^{{commit}}").decode().strip()
    except subprocess.CalledProcessError:
        from ropedyn_tools.repo import ROOT
        parser.error(f"--baseline {rev}: not a commit of {ROOT}")


def machine():
    """'CPU model, N cores, OS release' of this machine."""
    cpu = "unknown CPU"
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return f"{cpu}, {os.cpu_count()} cores, {platform.system()} {platform.release()}"


def utc_stamp():
    """The time now, 'YYYY-MM-DD HH:MM UTC'."""
    return datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")


#: what a study's numbers come from (as scripts/docs_status counts it), besides docs/
RUN_PATHS = ("src", "solvers", "CMakeLists.txt", "input", "tools", "python")


def run_commit(root=None, paths=RUN_PATHS):
    """Which code a study ran on: ', commit `abc1234`' (HEAD) when `paths` have no
    uncommitted changes, else ', on `abc1234` with uncommitted changes' (scripts/docs_status
    then judges the section by the commit that writes its stamp, which should be the one
    that commits those changes); '' outside a git checkout."""
    try:
        rev = git("rev-parse", "--short", "HEAD", root=root).decode().strip()
        dirty = git("status", "--porcelain", "--", *paths, root=root).decode().strip()
    except (subprocess.CalledProcessError, OSError):
        return ""
    return f", on `{rev}` with uncommitted changes" if dirty else f", commit `{rev}`"


def shown_arguments(argv):
    """A study's arguments as its page's Command line shows them: as given, but for
    `--exe PATH` (a path of this machine, not part of the command)."""
    shown, skip = [], False
    for a in argv:
        if skip:
            skip = False
        elif a == "--exe":
            skip = True
        elif not a.startswith("--exe="):
            shown.append(a)
    return shown


def run_stamp(root=None):
    """The stamp of a study's run: 'YYYY-MM-DD HH:MM UTC, commit `abc1234`' (see run_commit).
    Every generated section of docs/ names it, so that its page says when and on which code
    its numbers were made."""
    return utc_stamp() + run_commit(root)


def splice(text, begin, end, block):
    """text with everything from the marker `begin` to the marker `end` (both included)
    replaced by block (which carries the markers again); None when a marker is missing."""
    if begin in text and end in text:
        return text[:text.index(begin)] + block + text[text.index(end) + len(end):]
    return None


def scene_number(path, key, default=None):
    """A real key's value from a scene file's text (Fortran d exponents read too), the first
    line that sets it outside a comment; `default` when no line does (None: ValueError
    naming the file and key)."""
    m = re.search(rf"^[^!\n]*\b{key}\s*=\s*([0-9.eEdD+-]+)", pathlib.Path(path).read_text(),
                  re.MULTILINE)
    if m:
        return float(m.group(1).lower().replace("d", "e"))
    if default is None:
        raise ValueError(f"{path}: no {key} = <number>")
    return default


def update_doc(path, begin, end, block, heading="", strip=None, default=None):
    """Write block between the markers of the page at path; the rest of the page is kept.

    A page without the markers gets the block at its end, after a blank line and heading
    (trailing characters in strip removed first; None: white space). default: the text of
    a page that does not exist yet (None: the page must exist)."""
    text = default if default is not None and not path.exists() else path.read_text()
    new = splice(text, begin, end, block)
    if new is None:
        new = text.rstrip(strip) + "\n\n" + heading + block + "\n"
    path.write_text(new)


#: The parts of the time split of a run (&solver profile = .true.; /solver/time_*).
SPLIT_PARTS = ("time_rhs", "time_jacobian", "time_factor", "time_solve")
SPLIT_HEADER = "split RHS / Jacobian / factor / solve / rest (%)"


def time_split(stats):
    """'a / b / c / d / e' percentages of the time in the integrator (/solver/time_advance)
    spent in the right-hand side, Jacobians, factorizations, solves and the rest (the
    integrator's own work); all measured inside the run with the monotonic clock. '' when
    the run was not profiled."""
    total = stats.get("time_advance", 0.0)
    parts = [stats.get(k) for k in SPLIT_PARTS]
    if not total or any(p is None for p in parts):
        return ""
    rest = max(total - sum(parts), 0.0)
    return " / ".join(f"{100 * p / total:.0f}" for p in [*parts, rest])


def least_cpu(run, repeat, complete=lambda r: True):
    """The result of `run()` with the least r["cpu"] of `repeat` calls (at least one); a
    result that is not `complete` is returned at once. Timings on a shared VM drift by
    10-20 % from run to run; the minimum is the one least disturbed."""
    best = None
    for _ in range(max(1, repeat)):
        r = run()
        if not complete(r):
            return r
        if best is None or r["cpu"] < best["cpu"]:
            best = r
    return best


def method_sets(method):
    """The scene settings of a method given as `name` or `name:max_order` (the studies'
    --methods): {'solver.method': "'name'", 'solver.max_order': order}."""
    name, _, order = method.partition(":")
    sets = {"solver.method": f"'{name}'"}
    if order:
        sets["solver.max_order"] = order
    return sets


def method_label(method, order):
    """A switch's method as the tables name it: erk with its pair's order ('erk 4',
    'erk 5': auto runs both pairs), any other by its name."""
    return f"{method} {order}" if method == "erk" else method


def distinct_runs(items, key=lambda x: x):
    """The items without those whose `key` equals the one before them."""
    items = list(items)
    return [x for i, x in enumerate(items) if i == 0 or key(x) != key(items[i - 1])]


def method_chain(methods, most=5):
    """'a -> b -> c' of a run's methods in switch order; with more than `most`, the first
    three and how many switches there were in all. An event that keeps the method (the
    symplectic method's change of step, a note) is not a switch."""
    methods = distinct_runs(methods)
    if len(methods) > most:
        return " -> ".join(methods[:3]) + f" -> ... ({len(methods) - 1} switches)"
    return " -> ".join(methods)
