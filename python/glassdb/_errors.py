"""glassdb's error classes, one per ``glassdb_io::ErrorKind``.

Every exception glassdb raises is a ``GlassdbError`` whose message is what the ``glassdb``
command prints after ``error:`` for the same failure, with its ``hint:`` lines in ``hints``.
"""


class GlassdbError(Exception):
    """A glassdb error: ``str(e)`` is the command's message, ``e.hints`` its hints."""

    kind = "error"

    def __init__(self, message, hints=()):
        super().__init__(message)
        self.hints = list(hints)


class InvalidInput(GlassdbError, ValueError):
    """The input is wrong: a malformed file, a bad value, an unknown id, mismatched images."""

    kind = "invalid"


class Unsupported(GlassdbError):
    """The input is valid but uses something glassdb does not support."""

    kind = "unsupported"


class LimitExceeded(GlassdbError):
    """The input is over a limit (pixels, memory, file size)."""

    kind = "limits"


class IoError(GlassdbError, OSError):
    """A file could not be read or written."""

    kind = "io"


class InternalError(GlassdbError):
    """A bug of glassdb's (a caught panic), not a problem of the input."""

    kind = "internal"
