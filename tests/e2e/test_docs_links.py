"""The manual (docs/ and README.md) holds together: every relative link and picture points
at a file that exists and, with an anchor, at a heading (or an `<a id>`) of that page; the
user pages (getting started, the user guide, the reference) name no source file, test or
issue; and no page grows into a lab notebook (at most MAX_LINES lines)."""
import pathlib
import re
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
PAGES = sorted(DOCS.rglob("*.md")) + [ROOT / "README.md"]
#: the pages a user reads: no source paths, tests or issue numbers there
USER_PAGES = ([DOCS / "README.md", DOCS / "getting-started.md"]
              + sorted((DOCS / "guide").glob("*.md")) + sorted((DOCS / "reference").glob("*.md")))
#: "no page over about 400 lines" (the generated tables included)
MAX_LINES = 450

LINK = re.compile(r"\]\(([^)\s]+)\)")
FENCE = re.compile(r"^(```|~~~).*?^\1", re.MULTILINE | re.DOTALL)
#: what a user page must not name: source and test files, the tools' code, issues
DEVELOPER = re.compile(r"(?<![\w./-])(src|solvers|tests|tools|python)/[\w./-]+"
                       r"|\b\w+\.(f90|c)\b|\btest_\w+|\b[Ii]ssues? #?\d+|(?<![\w&])#\d+\b")


def prose(page):
    """The page's text without fenced code blocks."""
    return FENCE.sub("", page.read_text())


def slug(heading):
    """GitHub's anchor of a heading: lower case, no punctuation but - and _, blanks -> -."""
    text = re.sub(r"<[^>]+>", "", heading.strip().lower())
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def anchors(page):
    """Every anchor of a page: its headings' slugs (repeats numbered) and <a id>s."""
    seen, found = {}, set()
    for line in prose(page).splitlines():
        m = re.match(r"^#{1,6} (.*)", line)
        if m:
            base = slug(m.group(1))
            n = seen.get(base, 0)
            found.add(base if n == 0 else f"{base}-{n}")
            seen[base] = n + 1
    found.update(re.findall(r"<a id=\"([^\"]+)\"", page.read_text()))
    return found


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(ROOT)))
def test_links_resolve(page):
    broken = []
    for target in LINK.findall(prose(page)):
        if re.match(r"^[a-z]+:", target):
            continue
        path, _, anchor = target.partition("#")
        file = (page.parent / path).resolve() if path else page
        if not file.exists():
            broken.append(f"{target}: no such file")
        elif anchor and file.suffix == ".md" and anchor not in anchors(file):
            broken.append(f"{target}: no such heading")
    assert not broken, f"{page.relative_to(ROOT)}: " + "; ".join(broken)


@pytest.mark.parametrize("page", USER_PAGES, ids=lambda p: str(p.relative_to(ROOT)))
def test_user_pages_name_no_source_test_or_issue(page):
    named = sorted({m.group(0) for m in DEVELOPER.finditer(prose(page))})
    assert not named, f"{page.relative_to(ROOT)} names {named}"


@pytest.mark.parametrize("page", sorted(DOCS.rglob("*.md")), ids=lambda p: str(p.relative_to(ROOT)))
def test_pages_stay_short(page):
    lines = len(page.read_text().splitlines())
    assert lines <= MAX_LINES, f"{page.relative_to(ROOT)}: {lines} lines"


def test_slug():
    assert slug("`&rope`") == "rope"
    assert slug("Overrides: `--set group.key=value`") == "overrides---set-groupkeyvalue"
    assert slug("Anchors: expected values from outside the model") == \
        "anchors-expected-values-from-outside-the-model"


#: where the code, tests, tools and scenes may name pages of the manual
SOURCES = ["src", "solvers", "tests", "tools", "scripts", "python", "input", "CMakeLists.txt"]
DOC_PATH = re.compile(r"(?<![\w/.-])docs/[\w./-]+\.md\b")
OUTSIDE = re.compile(r"\.\./shared|shared/docs|\bsolvers\.md|\bphysics\.md|\bintegrators\.md"
                     r"|\bperformance\.md")
#: names of pages that no longer exist, still printed by messages of the program (Fortran
#: strings, not comments); each entry goes when its message names the new page
STALE_IN_MESSAGES = set()
#: ... and the one message that names notes outside the project
OUTSIDE_IN_MESSAGES = set()
#: files that name docs/ pages of scratch repositories or quote the old names on purpose
NOT_SOURCES = {"tests/e2e/test_docs_links.py", "tests/e2e/test_docs_status.py",
               "tests/e2e/test_prose_numbers.py", "tests/e2e/test_python_package.py"}


def source_files():
    for name in SOURCES:
        path = ROOT / name
        for file in ([path] if path.is_file() else sorted(path.rglob("*"))):
            if file.is_file() and file.suffix not in (".h5", ".png", ".dat", ".pyc"):
                yield file


def test_sources_cite_only_pages_of_the_project():
    """Every docs/... page a source file, test, tool or scene names exists, and none cites
    notes outside the project."""
    missing, outside = set(), []
    for file in source_files():
        rel = file.relative_to(ROOT).as_posix()
        if rel in NOT_SOURCES:
            continue
        text = file.read_text(errors="replace")
        for page in DOC_PATH.findall(text):
            if not (ROOT / page).exists():
                missing.add((rel, page))
        outside += [f"{rel}: {m.group(0)}" for m in OUTSIDE.finditer(text)]
    assert missing == STALE_IN_MESSAGES, sorted(missing ^ STALE_IN_MESSAGES)
    assert set(outside) == OUTSIDE_IN_MESSAGES, sorted(set(outside) ^ OUTSIDE_IN_MESSAGES)


def test_the_index_links_every_page():
    """docs/README.md, the manual's index, links every page of the manual."""
    index = DOCS / "README.md"
    linked = {(DOCS / target.partition("#")[0]).resolve()
              for target in LINK.findall(prose(index)) if not re.match(r"^[a-z]+:", target)}
    pages = {p.resolve() for p in DOCS.rglob("*.md")} - {index.resolve()}
    assert not pages - linked, sorted(str(p.relative_to(DOCS)) for p in pages - linked)


def test_readme_layout_names_the_tree():
    """The README's layout table: every folder it names exists, and every top-level folder of
    the repository with code, scenes, scripts or pages is named (its `python/` row once still
    listed the studies after they moved to tools/, which the table did not name)."""
    text = (ROOT / "README.md").read_text()
    table = text[text.index("| folder | contents |"):]
    table = table[:table.index("\n\n")]
    named = {m.group(1).rstrip("/") for m in re.finditer(r"^\| `([^`]+)` \|", table, re.M)}
    assert all((ROOT / name).is_dir() for name in named), named
    tracked = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True,
                             check=True).stdout.split()
    tops = {path.split("/")[0] for path in tracked if "/" in path} - {".ci"}
    assert tops <= {name.split("/")[0] for name in named}, tops - named
