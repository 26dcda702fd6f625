"""argparse types that the studies share: a number above 0, and lists of such numbers. A bad
value is then one usage error that names the option, the list and the bad item (exit 2),
before anything is built or run, for example
    argument --elements: 'ten', a list separated by blanks: not a whole number: 'ten'
Without a type the study would trace back where it first converts the list.

`listing` returns the list; `list_text` checks the list and returns the text as given, for
the studies that quote the option's text in their Command line. Names are checked too: a
study's own labels by `choice`, the code's methods and models by `check_names` (methods with
a max order, `name:K`, by `method_specs` and `check_methods`), which asks the executable for
its list (`ropedyn keys`) once the study knows it, before anything runs."""
import argparse

#: how a list's items are separated: blanks, commas, or either
SEPARATORS = {None: "blanks", ",": "commas", ", ": "commas or blanks", "+": "plus signs"}


def positive(kind):
    """An argparse type: a number of `kind` (int or float) above 0."""
    def parse(text):
        try:
            value = kind(text)
        except ValueError:
            what = "a whole number" if kind is int else "a number"
            raise argparse.ArgumentTypeError(f"not {what}: {text!r}") from None
        if not value > 0:
            raise argparse.ArgumentTypeError(f"must be above 0: {text!r}")
        return value
    parse.__name__ = kind.__name__
    return parse


def choice(allowed):
    """An argparse type: one of the names `allowed`, as given."""
    def parse(text):
        if text not in allowed:
            raise argparse.ArgumentTypeError(f"unknown: {text!r} (allowed: {', '.join(allowed)})")
        return text
    return parse


def check_names(parser, exe, option, names, group, key, extra=()):
    """A usage error (exit 2) naming `option` unless `names` is not empty and each is a value
    the code allows for group.key (the `allowed` column of `ropedyn keys`: the code's one
    list) or one of `extra`. Call it once the executable is known, before anything runs."""
    from ropedyn_tools.keys_reference import allowed   # it imports repo, which imports this
    known = [*allowed(exe, group, key), *extra]
    bad = [name for name in names if name not in known]
    if bad or not names:
        what = f"unknown: {', '.join(map(repr, bad))}" if bad else "an empty list"
        parser.error(f"argument {option}: {what} (allowed: {', '.join(known)}; "
                     f"the {group}.{key} of `ropedyn keys`)")


def method_specs(sep=None):
    """An argparse type: methods given as `name` or `name:max_order` (the studies' --methods,
    which studies.common.method_sets turns into scene settings), max_order a whole number
    above 0, separated as `items` reads them; the text as given. Their names are checked
    by check_methods once the executable is known."""
    def parse(text):
        for item in items(text, sep):
            _, colon, order = item.partition(":")
            if colon:
                positive(int)(order)
        return text
    parse.__name__ = "method_specs"
    return parse


def check_methods(parser, exe, option, specs):
    """check_names for the methods of `specs` (each `name` or `name:max_order`)."""
    check_names(parser, exe, option, [spec.partition(":")[0] for spec in specs], "solver",
                "method")


def items(text, sep=None):
    """The items of a list: split at blanks (sep None), at commas (","), at either (", "),
    or at plus signs ("+")."""
    if sep not in SEPARATORS:
        raise ValueError(f"unknown separator {sep!r}")
    if sep == ", ":
        return text.replace(",", " ").split()
    return text.split(sep)


def listing(item, sep=None, length=None):
    """An argparse type: a non-empty list of `item` (an argparse type such as positive(int)),
    separated as `items` reads them; with `length`, exactly that many."""
    def parse(text):
        try:
            values = [item(x) for x in items(text, sep)]
        except argparse.ArgumentTypeError as e:
            raise argparse.ArgumentTypeError(
                f"{text!r}, a list separated by {SEPARATORS[sep]}: {e}") from None
        if not values:
            raise argparse.ArgumentTypeError("an empty list")
        if length is not None and len(values) != length:
            raise argparse.ArgumentTypeError(
                f"{text!r}: {length} values separated by {SEPARATORS[sep]}, not {len(values)}")
        return values
    return parse


def list_text(item, sep=None, length=None):
    """An argparse type: the text of a list that `listing(item, sep, length)` accepts, as
    given."""
    check = listing(item, sep, length)

    def parse(text):
        check(text)
        return text
    return parse


def named_lists(item, sep, entries=None):
    """An argparse type: NAME=LIST, LIST as `listing(item, sep)` reads it ('mpp=10,30,70'),
    or with `entries` a separator of several such ('cvode=2+5,mebdf=4+7'); returns the text
    as given."""
    check = listing(item, sep)

    def parse(text):
        for entry in (text.split(entries) if entries else [text]):
            name, equals, values = entry.partition("=")
            if not equals or not name.strip():
                raise argparse.ArgumentTypeError(f"{entry!r}: not NAME=VALUES")
            try:
                check(values)
            except argparse.ArgumentTypeError as e:
                raise argparse.ArgumentTypeError(f"{entry!r}: {e}") from None
        return text
    return parse
