"""The project's own exception family.

Every problem a user can cause (a bad file, a bad option, impossible geometry) raises a
:class:`RoastlabError` whose message names the file, line, column or parameter and the
allowed range. The command line turns it into one line on stderr and exit code 2.
"""

from __future__ import annotations

from pathlib import Path


class RoastlabError(Exception):
    """Base class of every error roastlab raises on purpose."""


class InputError(RoastlabError, ValueError):
    """A user-supplied file or value is unusable.

    Parameters
    ----------
    problem : str
        What is wrong, in one short sentence fragment.
    source : str or Path, optional
        The file (or option) the problem is in; prefixed to the message.
    where : str, optional
        Line, column or key inside ``source`` (e.g. ``"line 4, column Gg_kg_s"``).
    """

    def __init__(self, problem: str, source: str | Path | None = None, where: str | None = None):
        self.problem = problem
        self.source = None if source is None else str(source)
        self.where = where
        parts = [p for p in (self.source, where) if p]
        prefix = ": ".join(parts)
        super().__init__(f"{prefix}: {problem}" if prefix else problem)


class ParameterError(InputError):
    """A model parameter, bound or geometry value is outside its allowed range."""
