"""Bring every stale section of docs/ up to date: the commands that wrote them, run again.

scripts/docs_status lists the generated sections written before the code under them last
changed. Each section names the command that wrote it (the first `scripts/...` in its
head). This plans those commands and runs them:

- once each (several sections share a command);
- one after the other, never two at once, since most of them time what they run;
- in an order that respects what some of them read:
  - some read what another command writes (BEFORE): the stability report reads the long
    suite's cache (`scripts/test --only-long` runs before the first report), fig5 the
    damping factors `scripts/calibrate` fits;
  - a command with `--analyse-only` reads the case files of the same command without
    it, so that one runs first and the analysis after every other command (the Bergdahl
    page reads MoorDyn-C's cases, which `scripts/bench_peers bergdahl` writes);
  - a section made from other sections (docs_status.DERIVED) is written last.

A section without a run time (docs_status says "no run time") or without a command is
named and left alone. A command that fails stops the rerun; its log names what went wrong,
and running again starts from the sections still stale.

    scripts/docs_rerun --dry-run   # the plan
    scripts/docs_rerun             # run it (logs in out/docs_rerun/)
"""
import argparse
import pathlib
import re
import shlex
import subprocess
import sys
import time

from ropedyn_tools import docs_status
from ropedyn_tools.repo import ROOT
from ropedyn.docstrings import summary

#: what a study reads that another command writes: {study: that command}, run once before
#: the first command of the study. The stability report's long-horizon matrix comes from
#: the long suite's cache (build/long, by the code's content); fig5 reads the factors of
#: docs/data/mpp_damping_fit.csv
BEFORE = {"scripts/stability_report": "scripts/test --only-long",
          "scripts/fig5": "scripts/calibrate"}
ANALYSE_ONLY = "--analyse-only"
_COMMAND = re.compile(r"`(scripts/[^`]+)`")


def section_command(page, name):
    """The command that wrote section `name` of the Markdown page at `page`: the first
    backquoted `scripts/...` in its head (docs_status.heads); None if none."""
    for found, head in docs_status.heads(page):
        if found == name:
            m = _COMMAND.search(head)
            return m.group(1) if m else None
    return None


def without_flag(command, flag):
    """command with the word `flag` taken out."""
    return shlex.join(w for w in shlex.split(command) if w != flag)


def plan(items, derived=docs_status.DERIVED, before=None):
    """The commands to run, in order, for the stale sections `items` [(name, command)]
    (docs_status's order): each once; a `--analyse-only` command after its variant without
    the flag (which goes first) and after every other command; the derived sections'
    commands last; BEFORE's command before the first command of its study."""
    before = BEFORE if before is None else before
    first, middle, analyses, last = [], [], [], []
    for name, command in items:
        if command is None:
            continue
        if name in derived:
            target = last
        elif ANALYSE_ONLY in shlex.split(command):
            target = analyses
            runs = without_flag(command, ANALYSE_ONLY)
            if runs not in first:
                first.append(runs)
        else:
            target = middle
        if command not in target:
            target.append(command)
    ordered = []
    for command in first + middle + analyses + last:
        needs = before.get(shlex.split(command)[0])
        if needs and needs not in ordered:
            ordered.append(needs)
        if command not in ordered:
            ordered.append(command)
    return ordered


def stale_items(root=ROOT):
    """([(name, command)] of the stale sections with a run time, oldest first;
    [(page, name, why)] of those left alone)."""
    rows = docs_status.status(root)
    rows.sort(key=lambda r: (r["stamp"] is not None, r["stamp"] or ""))
    items, left = [], []
    for r in rows:
        if r["commits"] is None:
            left.append((r["page"], r["name"], "no run time"))
        elif r["commits"]:
            command = section_command(pathlib.Path(root) / r["page"], r["name"])
            if command is None:
                left.append((r["page"], r["name"], "no command in its head"))
            else:
                items.append((r["name"], command))
    return items, left


def run(commands, root, logs):
    """Each command in turn from `root`, its output into `logs`/NN-SCRIPT.log; the index of
    the first that fails, or None."""
    logs.mkdir(parents=True, exist_ok=True)
    for k, command in enumerate(commands, start=1):
        words = shlex.split(command)
        log = logs / f"{k:02d}-{pathlib.Path(words[0]).name}.log"
        print(f"[{k}/{len(commands)}] {command}  (log: {log})", flush=True)
        start = time.monotonic()
        with open(log, "w") as out:
            code = subprocess.run(words, cwd=root, stdout=out,
                                  stderr=subprocess.STDOUT).returncode
        print(f"      exit {code}, {time.monotonic() - start:.0f} s", flush=True)
        if code != 0:
            print(f"docs_rerun: `{command}` failed with exit {code}; see {log}; running "
                  "scripts/docs_rerun again starts from the sections still stale",
                  file=sys.stderr)
            return k
    return None


def main(argv=None):
    parser = argparse.ArgumentParser(description=summary(__doc__))
    parser.add_argument("--dry-run", action="store_true", help="print the plan only")
    parser.add_argument("--root", type=pathlib.Path, default=ROOT,
                        help="the checkout whose docs/ to bring up to date (default: this one)")
    parser.add_argument("--logs", type=pathlib.Path, default=None,
                        help="where the commands' logs go (default: ROOT/out/docs_rerun)")
    args = parser.parse_args(argv)
    items, left = stale_items(args.root)
    for page, name, why in left:
        print(f"left alone: {page} {name} ({why})")
    commands = plan(items)
    if not commands:
        print("docs_rerun: no stale section has a command to run")
        return 0
    print("\n".join(["plan:", *(f"  {c}" for c in commands)]), flush=True)
    if args.dry_run:
        return 0
    failed = run(commands, args.root, args.logs or args.root / "out" / "docs_rerun")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
