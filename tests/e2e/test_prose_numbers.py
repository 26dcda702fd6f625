"""scripts/docs_status --prose: no study page quotes, in its own words, a measured number that
its generated sections no longer hold (tools/ropedyn_tools/prose_numbers.py)."""
from ropedyn_tools import docs_status, prose_numbers

#: a page as a study writes it: a generated section between the words around it
PAGE = """# A study

Words before the table.

<!-- study:begin -->
Command: `scripts/study` ... Run: 2026-12-01 14:59 UTC, commit `c28958a`.

| n | ratio | steps |
|---|---|---|
| 30 | 3.32 | 25022 |
<!-- study:end -->

Reading: {reading}
"""


def quotes(reading, known=frozenset()):
    """The numbers prose_numbers flags in PAGE with `reading` as its words."""
    return [number for _, number in prose_numbers.unquoted(PAGE.format(reading=reading), known)]


def test_the_study_pages_quote_only_what_their_sections_hold():
    rows = prose_numbers.report()
    assert rows == [], "\n".join(f"{page}:{line}: {number}" for page, line, number in rows)


def test_a_quote_of_the_section_passes_and_a_stale_one_is_caught():
    assert quotes("3.32 times faster in 25,022 steps.") == []
    assert quotes("3.41 times faster in 25,022 steps.") == ["3.41"]
    assert quotes("3.32 times faster in 25,023 steps.") == ["25,023"]
    # its line on the page
    page = PAGE.format(reading="3.41 times.")
    assert prose_numbers.unquoted(page) == [(page.splitlines().index("Reading: 3.41 times.") + 1,
                                             "3.41")]


def test_what_is_not_a_measured_quote():
    # two significant digits are the page's own rounding; a whole number's zeros do not count
    assert quotes("about 3.3 times, 2.8 ms, 1200 steps.") == []
    # code, links, dates, DOIs and a line that says it is worked out from the inputs
    assert quotes("`--set solver.rtol=0.0312` [x](a/3.456.md) on 2026-12-01, doi 10.3390/x") == []
    assert quotes("0.1217 kg/m <!-- not measured -->") == []
    assert quotes("an example:\n```\n  cpu time 7.200E-04 s\n```") == []
    # the scene files' values (`known`) are inputs, one definition each
    assert quotes("anchored 32.554 m away") == ["32.554"]
    assert quotes("anchored 32.554 m away", known={32.554}) == []
    # a page generated whole has no words of its own
    assert prose_numbers.unquoted("# A page\n\nOrder 2.07, 1.98.\n") == []


def test_docs_status_prose_exits_1_on_a_stale_quote(tmp_path, capsys):
    (tmp_path / "input").mkdir()
    (tmp_path / "docs" / "performance").mkdir(parents=True)
    (tmp_path / "docs" / "performance" / "study.md").write_text(PAGE.format(reading="3.41."))
    assert docs_status.main(["--prose", "--root", str(tmp_path)]) == 1
    assert "docs/performance/study.md:13: 3.41" in capsys.readouterr().out
    (tmp_path / "docs" / "performance" / "study.md").write_text(PAGE.format(reading="3.32."))
    assert docs_status.main(["--prose", "--root", str(tmp_path)]) == 0
