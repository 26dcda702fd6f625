"""The one exception of the in-process interface."""

#: exit code of the command line -> the kind of error
KINDS = {2: "input", 3: "solver", 4: "io", 5: "internal", 130: "interrupted"}


class Error(Exception):
    """Any failure of ropedyn in-process: `message` is what the command line prints after
    "ropedyn: error: ", `code` the exit code it gives (2 bad input or call, 3 integration
    failed, 4 output, 5 internal), `kind` its name ('input', 'solver', 'io', 'internal')."""

    def __init__(self, message, code):
        super().__init__(message)
        self.message = message
        self.code = code

    @property
    def kind(self):
        return KINDS.get(self.code, "internal")


def message_text(raw):
    """A message of the library (bytes) as text. A message quotes at most so many bytes of
    a value, which may cut a character of several bytes in two: that part shows as U+FFFD
    instead of failing with UnicodeDecodeError."""
    return raw.decode("utf-8", "replace")
