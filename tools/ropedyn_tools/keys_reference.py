"""The key reference, docs/reference/keys.md, written from the one key table.

`ropedyn keys` prints the code's table of scene keys, tab-separated: group, key, type,
unit, default, allowed values, meaning (the table that also drives reading, `--set`, each
key's check and the echo of a scene). This writes one Markdown table per group, one line
per key, between the markers `<!-- keys:begin -->` and `<!-- keys:end -->` of the page;
the text around them is kept. Longer explanations live in the user guide, which each
group's table links to (GUIDE).

    scripts/keys_reference            # write the section (builds the Release executable)
    scripts/keys_reference --check    # exit 1, naming the first difference, when the page
                                      # is not what the table gives
"""
import argparse
import functools
import subprocess
import sys

from ropedyn_tools.repo import DOCS, add_exe_argument, exe_or_build
from ropedyn_tools.studies.common import splice
from ropedyn.docstrings import summary

PAGE = DOCS / "reference" / "keys.md"
BEGIN, END = "<!-- keys:begin -->", "<!-- keys:end -->"
COLUMNS = ["group", "key", "type", "unit", "default", "allowed", "meaning"]
#: where the user guide explains each group (relative to the page); a group not listed
#: gets its table without the line
GUIDE = {
    "rope": ("the rope's material and geometry", "../guide/scenes.md#the-rope-rope"),
    "model": ("the model and its elements", "../guide/scenes.md#the-model-model"),
    "supports": ("supports, their motion and release",
                 "../guide/scenes.md#the-supports-supports"),
    "initial": ("initial states", "../guide/scenes.md#the-initial-state-initial"),
    "effects": ("the effects", "../guide/effects.md"),
    "solver": ("choosing a method", "../guide/choosing.md"),
    "output": ("the output", "../guide/output.md"),
    "fluid": ("drag in a fluid", "../guide/effects.md#drag-in-a-fluid-fluid"),
    "ground": ("ground contact", "../guide/effects.md#ground-contact-ground"),
    "attachments": ("point masses and loads",
                    "../guide/effects.md#point-masses-and-loads-attachments"),
}


def listing(text):
    """The rows of `ropedyn keys`' output as dicts of COLUMNS (header line checked)."""
    lines = text.splitlines()
    if not lines or lines[0].split("\t") != COLUMNS:
        raise SystemExit(f"keys_reference: unexpected header {lines[:1]!r} of `ropedyn keys`")
    return [dict(zip(COLUMNS, line.split("\t"))) for line in lines[1:] if line.strip()]


@functools.lru_cache(maxsize=None)
def keys_text(exe):
    """The output of `exe keys` (exe a str), read once per executable: a study checks
    several options against it (arguments.check_names)."""
    result = subprocess.run([exe, "keys"], capture_output=True, text=True)
    if result.returncode != 0:
        raise SystemExit(f"keys_reference: {exe} keys failed:\n{result.stderr}")
    return result.stdout


def table(exe):
    """The rows of `exe keys` (`listing`)."""
    return listing(keys_text(str(exe)))


def allowed(exe, group, key):
    """The values the code allows for group.key: the `allowed` column of `exe keys`, split at
    commas."""
    for row in table(exe):
        if (row["group"], row["key"]) == (group, key):
            return [value.strip() for value in row["allowed"].split(",")]
    raise SystemExit(f"keys_reference: `{exe} keys` has no key {group}.{key}")


def cell(text):
    """A table cell: '|' escaped."""
    return text.replace("|", "\\|")


def code(text):
    """A value as code (`...`), or as it is for 'not set' (with what stands for the value
    then: 'not set: ...') and the empty string."""
    if text == "" or text == "not set" or text.startswith("not set: "):
        return text or "–"
    return f"`{text}`"


def render(rows):
    """The section between the markers (markers included) for the rows of the table."""
    out = [BEGIN, "", "Written by `scripts/keys_reference` from `ropedyn keys`: do not edit "
                      "by hand.", ""]
    groups = []
    for row in rows:
        if row["group"] not in groups:
            groups.append(row["group"])
    for group in groups:
        out += [f"## `&{group}`", ""]
        if group in GUIDE:
            title, link = GUIDE[group]
            out += [f"Explained in the guide: [{title}]({link}).", ""]
        out += ["| key | type | unit | default | allowed | meaning |",
                "|---|---|---|---|---|---|"]
        for row in (r for r in rows if r["group"] == group):
            out.append(f"| `{row['key']}` | {cell(row['type'])} | {cell(row['unit'])} | "
                       f"{cell(code(row['default']))} | {cell(row['allowed'])} | "
                       f"{cell(row['meaning'])} |")
        out.append("")
    out.append(END)
    return "\n".join(out)


def section(page_text):
    """The generated section of the page (markers included); None without the markers."""
    if BEGIN not in page_text or END not in page_text:
        return None
    return page_text[page_text.index(BEGIN):page_text.index(END) + len(END)]


def main(argv=None):
    parser = argparse.ArgumentParser(description=summary(__doc__))
    add_exe_argument(parser)
    parser.add_argument("--check", action="store_true",
                        help="compare the page with the table; exit 1 when it differs")
    args = parser.parse_args(argv)
    exe = exe_or_build(args.exe)
    block = render(table(exe))
    text = PAGE.read_text()
    if args.check:
        if section(text) != block:
            print(f"{PAGE} is not current: run scripts/keys_reference", file=sys.stderr)
            return 1
        return 0
    new = splice(text, BEGIN, END, block)
    if new is None:
        raise SystemExit(f"keys_reference: {PAGE}: markers {BEGIN} ... {END} not found")
    PAGE.write_text(new)
    print(f"keys_reference: wrote {PAGE}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
