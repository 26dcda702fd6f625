"""Numbers in a study page's own words that its generated sections no longer hold.

A study page (docs/validation/, docs/performance/) holds generated sections, each between
`<!-- NAME:begin -->` and `<!-- NAME:end -->` and written by the script it names, and the
words around them, written by hand: the reading of a table, the set-up of a study. When the
words quote a measured number (a ratio, a count, an error), rerunning the script changes the
table but not the quote. This lists the numbers of three or more significant digits in the
hand-written words of a page that appear neither in that page's generated sections nor in the
scene files (input/: the study's inputs, one definition each), so that such a quote is caught
the run after it went stale. Two-digit readings (\"about 2.8 times\") are left alone: they are
the page's rounding, and a quote that precise is where staleness shows.

Not read: code (spans and fenced blocks: commands, keys, paths, a program's output shown as
an example), link targets, DOIs, dates, pages that are generated whole (no sections of their
own: scripts/validation writes such pages entire), and lines that say of themselves that
their numbers are no measurement (an HTML comment `<!-- not measured -->`: a value worked out
from the inputs, such as a damping coefficient from a damping ratio).

    scripts/docs_status --prose   # every such number, page and line
"""
import pathlib
import re

from ropedyn_tools.repo import ROOT

#: the folders of the study pages
STUDY_FOLDERS = ("docs/validation", "docs/performance")
#: a generated section, its name and its text
_SECTION = re.compile(r"<!-- (?P<name>[^:>]+):begin -->(?P<body>.*?)<!-- (?P=name):end -->",
                      re.S)
#: a number as the words write it: thousands separated by commas, a decimal point, an
#: exponent, a minus sign as U+2212; not part of a word, a path, a version or a date
_NUMBER = re.compile(r"(?<![\w.`/#-])[-\u2212+]?(?:\d{1,3}(?:,\d{3})+|\d+)(?:\.\d+)?"
                     r"(?:[eE][-\u2212+]?\d+)?(?![\w.]*\d)(?![-:/])")
#: any number in a generated section or a scene file (a table cell, a key's value)
_ANY_NUMBER = re.compile(r"[-+]?\d[\d,]*(?:\.\d+)?(?:[eE][-+]?\d+)?")
#: a line's own word that its numbers are worked out, not measured (see above)
NOT_MEASURED = "<!-- not measured -->"
#: a fenced code block
_FENCE = re.compile(r"^\s*(```|~~~)")
#: what the words quote without measuring it
_NOT_PROSE = (re.compile(r"`[^`]*`"),                  # code: a command, a key, a path
              re.compile(r"\]\([^)]*\)"),              # a link's target
              re.compile(r"doi \S+", re.I),            # a citation
              re.compile(r"\d{4}-\d\d-\d\d"))          # a date


def significant_digits(text):
    """How many significant digits `text` (a number as written) has: a whole number's
    trailing zeros are not (1200 has two)."""
    mantissa = re.split(r"[eE]", text)[0]
    digits = re.sub(r"\D", "", mantissa).lstrip("0")
    return len(digits if "." in mantissa else digits.rstrip("0"))


def value(text):
    """The number `text` (commas, U+2212) as a float, or None."""
    try:
        return float(text.replace(",", "").replace("\u2212", "-"))
    except ValueError:
        return None


def values_in(text):
    """Every number in `text`, as floats, with their negatives."""
    found = set()
    for match in _ANY_NUMBER.finditer(text):
        number = value(match.group(0))
        if number is not None:
            found.update((number, -number))
    return found


def scene_values(root):
    """Every number of the scene files under input/ (the studies' inputs)."""
    found = set()
    for scene in sorted((root / "input").rglob("*.nml")):
        found |= values_in(scene.read_text(encoding="utf-8"))
    return found


def unquoted(text, known=frozenset()):
    """The numbers of three or more significant digits in the words of a page's `text` that
    its generated sections, and `known`, do not hold: (line number, number) pairs. A page
    with no sections of its own is generated whole: none."""
    sections = [m.group("body") for m in _SECTION.finditer(text)]
    if not sections:
        return []
    held = set(known)
    for body in sections:
        held |= values_in(body)
    words = _SECTION.sub(lambda m: "\n" * m.group(0).count("\n"), text)
    found = []
    fenced = False
    for number, line in enumerate(words.splitlines(), start=1):
        if _FENCE.match(line):
            fenced = not fenced
        if fenced or _FENCE.match(line) or NOT_MEASURED in line:
            continue
        for pattern in _NOT_PROSE:
            line = pattern.sub(" ", line)
        for match in _NUMBER.finditer(line):
            quoted = match.group(0)
            if significant_digits(quoted) < 3:
                continue
            if value(quoted) not in held:
                found.append((number, quoted))
    return found


def study_pages(root=ROOT):
    """The study pages, in order."""
    pages = []
    for folder in STUDY_FOLDERS:
        pages += sorted((pathlib.Path(root) / folder).glob("*.md"))
    return pages


def report(root=ROOT):
    """Every unquoted number of every study page: (page relative to root, line, number)."""
    root = pathlib.Path(root)
    known = scene_values(root)
    rows = []
    for page in study_pages(root):
        for line, number in unquoted(page.read_text(encoding="utf-8"), known):
            rows.append((page.relative_to(root).as_posix(), line, number))
    return rows
