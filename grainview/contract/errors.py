"""The project's exception and warning types.

Every error that grainview or the solver raises on purpose is a :class:`GrainviewError`, so a
caller can catch them all at once; each also derives from the matching built-in type
(``ValueError``, ``OSError``) so that generic handlers keep working.
"""

from __future__ import annotations


class GrainviewError(Exception):
    """Base class of every error raised on purpose by grainview and the solver."""


class SchemaError(GrainviewError, ValueError):
    """A dataset or file does not follow the grainview data contract (docs/schema.md).

    ``problems`` holds one line per problem found; the message lists them all, so a user
    sees everything wrong with a file at once rather than one problem per attempt.
    """

    def __init__(self, problems, source: str | None = None):
        if isinstance(problems, str):
            problems = [problems]
        self.problems = list(problems)
        self.source = source
        where = f" in {source}" if source else ""
        head = f"{len(self.problems)} problem(s) with the grainview data contract{where}:"
        super().__init__("\n  - ".join([head, *self.problems]))

    def summary(self) -> str:
        """The error in one line: ``<source>: <problem>`` for a single problem, else how many
        there are, the first, and the command that lists them all (the command line's
        message; the exception's own message lists every problem)."""
        where = f"{self.source}: " if self.source else ""
        if len(self.problems) == 1:
            return f"{where}{self.problems[0]}"
        listing = f"'grainview info --check {self.source}'" if self.source else "grainview.validate"
        return (f"{where}{len(self.problems)} problems with the grainview data contract, first: {self.problems[0]}; "
                f"{listing} lists them")


class FileFormatError(GrainviewError, OSError):
    """A path cannot be read as a grainview netCDF file (missing, not netCDF, truncated)."""


class OutputError(GrainviewError, OSError):
    """A snapshot could not be written (a full disk, a lost network mount); the file keeps
    every snapshot completed before it."""


class ParameterError(GrainviewError, ValueError):
    """A parameter passed by the user is out of range or of the wrong form."""


class ConvergenceWarning(UserWarning):
    """The contact solver stopped before reaching its tolerance: at its sweep cap, or because
    its sweeps stalled (``stall_sweeps``)."""
