"""docs/reference/scene-file.md against the key table: `ropedyn keys` lists every key of a scene file with
its default (from the table in src/io/ropedyn_scene_keys.f90); every key must have a row in
the table of its group in docs/reference/scene-file.md whose default cell holds that default, and every key
the docs list must exist."""
import pathlib
import re

import pytest

DOCS = pathlib.Path(__file__).resolve().parents[2] / "docs" / "reference" / "scene-file.md"


def listing(run):
    result = run("keys")
    assert result.returncode == 0, result.stderr
    lines = result.stdout.splitlines()
    assert lines[0].split("\t") == ["group", "key", "type", "unit", "default", "allowed",
                                    "meaning"]
    return [dict(zip(lines[0].split("\t"), line.split("\t"))) for line in lines[1:]]


def doc_rows():
    """{(group, key): default cell} from the key tables under the '## `&group`' headings."""
    rows, group, header = {}, None, None
    for line in DOCS.read_text().splitlines():
        heading = re.match(r"^## `&(\w+)`", line)
        if heading or line.startswith("## "):
            group, header = (heading.group(1) if heading else None), None
            continue
        if group is None or not line.startswith("|"):
            continue
        cells = [c.strip() for c in re.split(r"(?<!\\)\|", line.strip())[1:-1]]
        if cells and cells[0] == "key":
            header = cells
        elif header and cells[0].startswith("`"):
            for key in re.findall(r"`(\w+)`", cells[0]):
                rows[(group, key)] = cells[header.index("default")]
    return rows


def values(text):
    """A default as a tuple of values: numbers (also a/b), logicals, strings."""
    parts = re.findall(r"'[^']*'|[^,]+", text)
    out = []
    for part in (p.strip() for p in parts):
        if part.lower() in (".true.", ".false."):
            out.append(part.lower() == ".true.")
        elif part.startswith("'"):
            out.append(part[1:-1])
        elif re.fullmatch(r"[0-9.]+/[0-9.]+", part):
            a, b = part.split("/")
            out.append(float(a) / float(b))
        else:
            out.append(float(part))
    return tuple(out)


def documented(cell, default):
    if default == "not set":
        return "not set" in cell
    want = values(default)
    for token in re.findall(r"`([^`]*)`", cell):
        try:
            if values(token) == want:
                return True
        except ValueError:
            continue
    return False


def test_every_key_documented_with_its_default(run):
    keys = listing(run)
    assert len(keys) == 89
    rows = doc_rows()
    missing, wrong = [], []
    for k in keys:
        cell = rows.get((k["group"], k["key"]))
        if cell is not None and "as for the top" in cell:
            cell = rows.get((k["group"], k["key"].replace("bottom_", "top_", 1)))
        if cell is None:
            missing.append(f"&{k['group']} {k['key']}")
        elif not documented(cell, k["default"]):
            wrong.append(f"&{k['group']} {k['key']}: docs {cell!r}, table {k['default']!r}")
    assert not missing, "keys without a row in docs/reference/scene-file.md: " + ", ".join(missing)
    assert not wrong, "defaults that differ:\n" + "\n".join(wrong)


def test_docs_list_no_other_keys(run):
    table = {(k["group"], k["key"]) for k in listing(run)}
    extra = sorted(f"&{g} {k}" for g, k in doc_rows() if (g, k) not in table)
    assert not extra, "docs/reference/scene-file.md lists keys the table does not have: " + ", ".join(extra)


@pytest.mark.parametrize("default,cell,ok", [
    ("1.1111111111111112", "`10/9` (1.1111…)", True),
    ("3.5e7", "`35e6`", True),
    ("'rfem'", "`'rfem'`", True),
    ("0.0, 0.0", "`0.0, 0.0`", True),
    ("not set", "not set", True),
    ("1.0", "`2.0`", False),
])
def test_default_comparison(default, cell, ok):
    assert documented(cell, default) is ok
