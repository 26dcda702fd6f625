"""Which generated sections of docs/ were written before the code under them last changed.

Every table or figure in docs/ stands between two markers, `<!-- NAME:begin -->` and
`<!-- NAME:end -->`, and opens with the command that wrote it, when, and on which commit (a
"Run: YYYY-MM-DD HH:MM UTC, commit `abc1234`" stamp, a "(... min, YYYY-MM-DD HH:MM UTC)" or
a "YYYY-MM-DD, commit `abc1234`" line; the studies write the commit when the code they ran
had no uncommitted changes: studies.common.run_stamp). For each section
this lists the commits that changed the code its numbers come from after the commit that
first wrote that stamp into docs/ (after the run's time while it is not committed): the
Fortran (src/, solvers/, CMakeLists.txt), the scenes (input/) and the study's own module
(the module scripts/SCRIPT runs for the section's command, SCRIPT and its first word read
from the command: a wrapper that branches on its first argument, as `scripts/validation
bergdahl` does, runs another module for that word; with the modules of the studies that
module imports, whose code makes its numbers too; each in tools/ropedyn_tools/studies/,
tools/ropedyn_tools/ or, for the runs before they moved, python/ropedyn/studies/; NARROWER
lists the studies that read less than the Fortran and the scenes). A commit there does not
mean the numbers changed; it means the study has not been run on the code as it is, and its
page should say why not or be rerun by its script. A commit that changes code but, checked, none of the results (a refactoring, a
comment) says so with a line `Numbers-unchanged: how it was checked` in its message, or,
once committed, with a line `HASH  how it was checked` in docs/numbers-unchanged.txt; it is
not counted. A line `HASH  sections=NAME,NAME  how it was checked` there keeps it from
counting against those sections only (a change that alters some studies' runs, checked
not to reach the others'); a NAME also stands for the sections named NAME and a variant
after a space (`profile_step` for `profile_step erk` too), whose names a word cannot hold.
A section made from other sections' data (DERIVED: the choosing guide) counts the commits
that count against any of them.

    scripts/docs_status            # every section, oldest first
    scripts/docs_status --stale    # only those with code commits since their run
    scripts/docs_status --check    # as --stale, exit status 1 when any is listed
    scripts/docs_status --prose    # numbers in the pages' words that no section holds
                                   # (ropedyn_tools.prose_numbers)
"""
import argparse
import ast
import datetime
import pathlib
import re
import subprocess
import sys

from ropedyn_tools import prose_numbers
from ropedyn_tools.repo import ROOT
from ropedyn_tools.studies.common import git
from ropedyn.docstrings import summary

#: where a study's own module is, and (for the runs before it moved) was
STUDY_FOLDERS = ("tools/ropedyn_tools/studies", "tools/ropedyn_tools", "python/ropedyn/studies")
#: what a study's numbers come from besides its own module
CODE_PATHS = ("src", "solvers", "CMakeLists.txt", "input")
#: studies whose numbers come from less than CODE_PATHS
NARROWER = {
    # the stiff test set: the integrators and their driver, no rope, no scene
    "work_precision_testset": ("solvers", "CMakeLists.txt"),
    # the MEBDF and BDF stability tables: the formulas' coefficients, solved by the study
    # itself in exact arithmetic; no run of the program
    "mebdf_stability": (),
}
#: sections made from other sections' data, not from runs of their own: as current as those
#: (the commits listed against any of them), whatever their own stamp says
DERIVED = {
    # scripts/accuracy choosing: the guide's tables from the four accuracy studies' CSVs
    "choosing": ("accuracy-windows", "accuracy-discretization", "accuracy-fig4",
                 "accuracy-chaos"),
}
#: sections whose currency a test checks instead (their script regenerates them exactly from
#: the program: no run to date); not listed
CHECKED_BY_TESTS = {
    "keys_reference": "tests/e2e/test_keys.py",
}
#: the line of a commit message that keeps a code commit from counting (see above)
UNCHANGED = "Numbers-unchanged:"
#: commits that changed code but, checked, no result (one `HASH  how checked` a line)
UNCHANGED_FILE = "docs/numbers-unchanged.txt"
#: how many lines after the begin marker are searched for the command and the stamp
HEAD_LINES = 6

#: a begin marker stands alone on its line (one quoted in a sentence, as in the contributing
#: guide's `<!-- name:begin -->`, is no section)
_BEGIN = re.compile(r"^\s*<!-- (?P<name>[^:>]+):begin -->\s*$")
#: the section's script and the first word after it (a wrapper may branch on that word)
_SCRIPT = re.compile(r"scripts/(?P<script>[a-z0-9_]+)(?: (?P<word>[a-z][a-z0-9_]*))?")
_STAMP = re.compile(r"(?P<date>20\d\d-\d\d-\d\d)(?:[ T](?P<time>\d\d:\d\d)(?: ?UTC)?)?")
_COMMIT = re.compile(r"commit `(?P<rev>[0-9a-f]{7,40})`")
#: a wrapper's branch on its first argument: `if [ "${1:-}" = "WORD" ]; then ... fi`
_BRANCH = re.compile(r'^if \[ "\$\{1:-\}" = "(?P<word>[^"]+)" \]; then\n(?P<body>.*?)^fi$',
                     re.S | re.M)
#: the Python module a wrapper runs
_RUNS = re.compile(r"-m ropedyn_tools\.(?:studies\.)?(?P<module>[a-z0-9_]+)")


def heads(page):
    """[(name, head)] of the generated sections of the Markdown page at `page`, in page
    order: head is the section's first HEAD_LINES non-blank lines, joined (where its
    command and stamp are)."""
    lines = pathlib.Path(page).read_text().splitlines()
    found = []
    for i, line in enumerate(lines):
        m = _BEGIN.search(line)
        if not m:
            continue
        name = m.group("name")
        head = []
        for text in lines[i + 1:]:
            if f"<!-- {name}:end -->" in text or len(head) == HEAD_LINES:
                break
            if text.strip():
                head.append(text)
        found.append((name, "\n".join(head)))
    return found


def sections(page):
    """[(name, script or None, stamp text or None, commit or None)] of the generated
    sections of the Markdown page at `page`, in page order."""
    return [found[:4] for found in _sections(page)]


def _sections(page):
    """sections(), each with the first word after its script (or None) last."""
    found = []
    for name, head in heads(page):
        script = _SCRIPT.search(head)
        stamp = _STAMP.search(head)
        commit = _COMMIT.search(head)
        found.append((name, script and script.group("script"),
                      stamp and stamp.group(0), commit and commit.group("rev"),
                      script and script.group("word")))
    return found


def wrapper_module(root, script, word=None):
    """The module root/scripts/SCRIPT runs when its first argument is `word`: the one its
    branch on that word runs (`if [ "${1:-}" = "WORD" ]; then ... fi`), else the last one it
    runs outside such branches; SCRIPT itself when there is no such file or it names no
    module (a study run before its wrapper was renamed or removed)."""
    path = pathlib.Path(root) / "scripts" / script
    if not path.is_file():
        return script
    text = path.read_text()
    outside = text
    for branch in _BRANCH.finditer(text):
        runs = _RUNS.search(branch.group("body"))
        if runs and branch.group("word") == word:
            return runs.group("module")
        outside = outside.replace(branch.group(0), "")
    found = _RUNS.findall(outside)
    return found[-1] if found else script


def _imported_studies(path):
    """The modules of ropedyn_tools.studies that the Python file at `path` imports."""
    found = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            if node.module == "ropedyn_tools.studies":
                found += [alias.name for alias in node.names]
            elif node.module.startswith("ropedyn_tools.studies."):
                found.append(node.module.split(".")[2])
        elif isinstance(node, ast.Import):
            found += [alias.name.split(".")[2] for alias in node.names
                      if alias.name.startswith("ropedyn_tools.studies.")]
    return found


def study_modules(root, module):
    """`module` and the study modules it imports, directly or through others (sorted
    names): their code makes the numbers of its sections as much as its own does."""
    seen, todo = set(), [module]
    while todo:
        name = todo.pop()
        if name in seen:
            continue
        seen.add(name)
        for folder in STUDY_FOLDERS:
            path = pathlib.Path(root) / folder / f"{name}.py"
            if path.is_file():
                todo += _imported_studies(path)
                break
    return sorted(seen)


def run_time(stamp):
    """The UTC time of a stamp 'YYYY-MM-DD[ HH:MM[ UTC]]' (a date alone: the end of that
    day, so that only the next days' commits count against it)."""
    m = _STAMP.fullmatch(stamp.strip())
    day = datetime.datetime.strptime(m.group("date"), "%Y-%m-%d")
    if m.group("time"):
        hours, minutes = map(int, m.group("time").split(":"))
        when = day.replace(hour=hours, minute=minutes)
    else:
        when = day.replace(hour=23, minute=59)
    return when.replace(tzinfo=datetime.timezone.utc)


def _git_text(root, *args):
    return git(*args, root=root).decode().strip()


def unchanged_commits(root, known=None):
    """{full hash: the sections it does not count against (None: every one)} of the commits
    listed in root/UNCHANGED_FILE (comments: #; a second word `sections=A,B` names them); a
    line whose first word git knows as no commit, or (given `known`, the section names of
    docs/) that names a section not among them, is an error naming the file, line and
    word."""
    path = pathlib.Path(root) / UNCHANGED_FILE
    if not path.exists():
        return {}
    full = {}
    for number, line in enumerate(path.read_text().splitlines(), start=1):
        words = line.split("#", 1)[0].split()
        if not words:
            continue
        rev = words[0]
        try:
            key = _git_text(root, "rev-parse", "--verify", "--quiet", rev + "^{commit}")
        except subprocess.CalledProcessError:
            raise SystemExit(f"docs_status: {path}: line {number}: '{rev}' is not a commit")
        names = None
        if len(words) > 1 and words[1].startswith("sections="):
            names = set(words[1][len("sections="):].split(","))
            unknown = sorted(n for n in names if not any(covers(n, k) for k in known)) \
                if known is not None else []
            if unknown:
                raise SystemExit(f"docs_status: {path}: line {number}: section "
                                 f"'{unknown[0]}' is in no page of docs/")
        # a commit listed again: the union of its sections (every one if either line says so)
        before = full.get(key, set())
        full[key] = None if names is None or before is None else before | names
    return full


def covers(name, section):
    """Whether a `sections=` word's `name` stands for `section`: the same name, or the
    name and a variant after a space."""
    return section == name or section.startswith(name + " ")


def code_commits(root, since, paths, commit=None, skip=None, section=None, until="HEAD"):
    """[(short hash, ISO date, subject)] of the commits that changed `paths` after the time
    `since` (or, given `commit`, after that commit, up to `until`), newest first; not those
    whose message has a line starting with UNCHANGED, nor those `skip` (unchanged_commits)
    lists for every section or for `section`."""
    skip = skip or {}
    cmd = ["log", "-z", "--format=%H%x09%h%x09%cI%x09%s%x09%b"]
    if commit:
        cmd.append(f"{commit}..{until}")
    else:
        cmd.append(f"--since={since.isoformat()}")
    if not any((pathlib.Path(root) / p).exists() for p in paths):
        return []    # (a bare `git log --` would list every commit)
    commits = []
    # every path, also those gone (a module's earlier place), for the commits to them
    for record in git(*cmd, "--", *paths, root=root).decode().split("\0"):
        if not record.strip():
            continue
        full, rev, date, subject, body = record.strip("\n").split("\t", 4)
        if full in skip and (skip[full] is None or
                             any(covers(n, section) for n in skip[full])):
            continue
        if any(line.startswith(UNCHANGED) for line in body.splitlines()):
            continue
        commits.append((rev, date, subject))
    return commits


def version_commit(version):
    """The commit a `ropedyn --version` text names ('0.1.0+g48c82d8' -> '48c82d8', also after
    a tag: '0.1.0+gv1.0-3-g48c82d8'); None for a tree with uncommitted changes ('-dirty...')
    or a build without git."""
    _, plus, described = version.partition("+g")
    if not plus or "-dirty" in described:
        return None
    found = re.fullmatch(r".*-g([0-9a-f]{7,40})", described)
    return found.group(1) if found else described


def same_code(version, reference, section, root=ROOT):
    """Whether a file that the build `version` wrote (its /@version) holds what the build
    `reference` writes, as the numbers of docs/ `section` go: the same text (one commit, or
    one set of edits to it), or two commits one after the other with no commit between
    that counts against the section (the code paths, less those marked numbers-unchanged
    for it)."""
    if version == reference:
        return True
    a, b = version_commit(version), version_commit(reference)
    if a is None or b is None:
        return False
    def before(x, y):
        return subprocess.run(["git", "-C", str(root), "merge-base", "--is-ancestor", x, y],
                              capture_output=True).returncode == 0

    try:
        a, b = (_git_text(root, "rev-parse", "--verify", "--quiet", r + "^{commit}")
                for r in (a, b))
    except subprocess.CalledProcessError:
        return False                                      # a commit this clone does not know
    if not before(a, b):
        a, b = b, a                                       # the reference may be the older
        if not before(a, b):
            return False
    return not code_commits(root, None, CODE_PATHS, commit=a, skip=unchanged_commits(root),
                            section=section, until=b)


def status(root=ROOT):
    """One row per generated section of root/docs/**/*.md: dict(page, name, script, stamp,
    commits); commits None when the section names no run time."""
    root = pathlib.Path(root)
    pages = {page: _sections(page) for page in sorted((root / "docs").rglob("*.md"))}
    skip = unchanged_commits(root, {s[0] for found in pages.values() for s in found})
    modules = {}                 # (script, word): the study modules, read once per command
    rows = []
    for page, found in pages.items():
        for name, script, stamp, commit, word in found:
            if script in CHECKED_BY_TESTS:
                continue
            paths = list(NARROWER.get(script, CODE_PATHS))
            if script:
                if (script, word) not in modules:
                    modules[script, word] = study_modules(
                        root, wrapper_module(root, script, word))
                paths += [f"{folder}/{module}.py" for folder in STUDY_FOLDERS
                          for module in modules[script, word]]
            commits = None
            if stamp and not commit:
                # the commit that first wrote this stamp into docs/: the code it ran is
                # that commit's (a study is run on the working tree and committed with the
                # code it measured); the first, since a page may have moved or been split
                # since (which writes the stamp again); a stamp not committed yet is
                # judged by its time
                written = _git_text(root, "log", "--format=%h", "-S", stamp, "--",
                                    "docs").split()
                commit = written[-1] if written else None
            if stamp or commit:
                when = run_time(stamp) if stamp else None
                commits = code_commits(root, when, paths, commit, skip, name)
            rows.append({"page": str(page.relative_to(root)), "name": name, "script": script,
                         "stamp": stamp, "commits": commits})
    by_name = {r["name"]: r for r in rows}
    for row in rows:
        inputs = [by_name[n] for n in DERIVED.get(row["name"], ()) if n in by_name]
        if inputs:
            if any(r["commits"] is None for r in inputs):
                row["commits"] = None
            else:
                union = {c[0]: c for r in inputs for c in r["commits"]}
                row["commits"] = sorted(union.values(), key=lambda c: c[1], reverse=True)
    return rows


def main(argv=None):
    parser = argparse.ArgumentParser(description=summary(__doc__))
    parser.add_argument("--stale", action="store_true",
                        help="list only the sections with code commits since their run")
    parser.add_argument("--check", action="store_true",
                        help="as --stale; exit status 1 when any section is listed")
    parser.add_argument("--prose", action="store_true",
                        help="list instead the numbers in the study pages' own words that "
                             "their generated sections do not hold (exit status 1 if any)")
    parser.add_argument("--root", type=pathlib.Path, default=ROOT,
                        help="the checkout whose docs/ to read (default: this one)")
    args = parser.parse_args(argv)
    if args.prose:
        return prose_main(args.root)
    rows = status(args.root)
    rows.sort(key=lambda r: (r["stamp"] is not None, r["stamp"] or ""))
    listed = [r for r in rows if not (args.stale or args.check) or r["commits"] is None
              or r["commits"]]
    print("| page | section | written by | run | code commits since | newest |")
    print("|---|---|---|---|---|---|")
    for r in listed:
        commits = r["commits"]
        count = "no run time" if commits is None else str(len(commits))
        newest = f"{commits[0][0]} {commits[0][2][:60]}" if commits else ""
        script = f"scripts/{r['script']}" if r["script"] else "?"
        print(f"| {r['page']} | {r['name']} | {script} | {r['stamp'] or '?'} | {count} | "
              f"{newest} |")
    print(f"\n{len(listed)} of {len(rows)} sections listed", file=sys.stderr)
    return 1 if args.check and listed else 0


def prose_main(root):
    """--prose: the quotes of prose_numbers, a line each; 1 when there are any."""
    rows = prose_numbers.report(root)
    for page, line, number in rows:
        print(f"{page}:{line}: {number}")
    print(f"{len(rows)} numbers in the study pages' words that no generated section or "
          "scene holds", file=sys.stderr)
    return 1 if rows else 0


if __name__ == "__main__":
    sys.exit(main())
