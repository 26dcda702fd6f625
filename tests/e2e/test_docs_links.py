"""The manual (docs/ and README.md) holds together: every relative link and picture points
at a file that exists and, with an anchor, at a heading (or an `<a id>`) of that page."""
import pathlib
import re

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
PAGES = sorted(DOCS.rglob("*.md")) + [ROOT / "README.md"]
LINK = re.compile(r"\]\(([^)\s]+)\)")
FENCE = re.compile(r"^(```|~~~).*?^\1", re.MULTILINE | re.DOTALL)


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


def test_slug():
    assert slug("`&rope`") == "rope"
    assert slug("Overrides: `--set group.key=value`") == "overrides---set-groupkeyvalue"
    assert slug("Anchors: expected values from outside the model") == \
        "anchors-expected-values-from-outside-the-model"
