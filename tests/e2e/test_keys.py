"""docs/reference/keys.md against the key table: `ropedyn keys` lists every key of a scene
file (the table in src/io/ropedyn_scene_keys.f90); the page's generated section must be
exactly what scripts/keys_reference makes of that listing, so a key added to the table, or
a default or rule changed, fails here until the page is written again."""
import re

import pytest

from ropedyn_tools import keys_reference


def listing(run):
    result = run("keys")
    assert result.returncode == 0, result.stderr
    return keys_reference.listing(result.stdout)


def page_rows():
    """{(group, key): row cells} of the tables in the page's generated section."""
    section = keys_reference.section(keys_reference.PAGE.read_text())
    assert section is not None, f"{keys_reference.PAGE}: no keys markers"
    rows, group = {}, None
    for line in section.splitlines():
        heading = re.match(r"^## `&(\w+)`", line)
        if heading:
            group = heading.group(1)
        elif group and line.startswith("| `"):
            cells = [c.strip() for c in re.split(r"(?<!\\)\|", line.strip())[1:-1]]
            rows[(group, cells[0].strip("`"))] = cells
    return rows


def test_reference_is_written_from_the_current_table(run):
    rows = listing(run)
    written = keys_reference.section(keys_reference.PAGE.read_text())
    assert written == keys_reference.render(rows), (
        "docs/reference/keys.md is not what the key table gives: run scripts/keys_reference")


def test_every_key_has_one_row_with_its_default(run):
    rows = listing(run)
    documented = page_rows()
    assert set(documented) == {(r["group"], r["key"]) for r in rows}
    for r in rows:
        default = documented[(r["group"], r["key"])][3]
        assert default == keys_reference.code(r["default"]), (r, default)


def test_a_key_added_to_the_table_changes_the_section(run):
    """What the first test relies on: the section depends on every row."""
    rows = listing(run)
    written = keys_reference.section(keys_reference.PAGE.read_text())
    added = rows + [dict(group="rope", key="new_key", type="real", unit="m", default="1.0",
                         allowed="> 0", meaning="a key not yet on the page")]
    assert keys_reference.render(added) != written
    changed = [dict(r, default="2.0") if r["key"] == "length" else r for r in rows]
    assert keys_reference.render(changed) != written


@pytest.mark.parametrize("default,cell", [("1.0", "`1.0`"), ("not set", "not set"),
                                          ("", "–"), ("'rfem'", "`'rfem'`")])
def test_default_cells(default, cell):
    assert keys_reference.code(default) == cell
