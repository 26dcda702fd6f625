"""What a program's --help says first: the opening paragraph of its module's docstring."""


def summary(doc):
    """The first paragraph of `doc` on one line (a sentence may run over several lines of
    the docstring; its first line alone stopped mid-sentence)."""
    return " ".join((doc or "").strip().split("\n\n")[0].split())
