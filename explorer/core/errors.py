"""User-facing errors.

Every mistake a user can make (a bad scene file, an unknown preset, a missing mesh, a bad array
given to the library) raises an :class:`ExplorerError`, a :class:`ValueError`; an argument of the
wrong type raises an :class:`ExplorerTypeError`, also a :class:`TypeError`. Library callers can
catch them as ``ValueError`` / ``TypeError`` (or all of them as ``ExplorerError``). The CLI prints
the message of any of them as one line and exits non-zero without a traceback. A validation pass
collects every :class:`Problem` in a document before raising one :class:`ValidationError`, so the
user sees all of them at once.

Things the user should know that are not errors (a preset hiding another, a key's old name)
are :class:`Notice` warnings; the CLI prints each as one ``notice: ...`` line.
"""

from __future__ import annotations

from dataclasses import dataclass

from explorer.core.text import printable


class ExplorerError(ValueError):
    """Base class of every error caused by user input (never by a bug): a bad value."""


class ExplorerTypeError(ExplorerError, TypeError):
    """An argument of the wrong type (a number where a list of lights goes, say); the message
    names the argument."""


@dataclass(frozen=True)
class Problem:
    """One thing wrong with a document.

    message : what is wrong and what is allowed, e.g. ``"must be in [0, 1], got 1.5"``
    file : the file it came from, or None for in-memory mappings
    line : 1-based line in ``file`` or None
    key : the key path inside the document, e.g. ``lights[1].attenuation``
    """

    message: str
    file: str | None = None
    line: int | None = None
    key: str | None = None

    def __str__(self) -> str:
        """One line per problem: the file name, key and message come from files, so what a
        terminal would act on is shown escaped (:func:`explorer.core.text.printable`)."""
        key = f"{self.key}: " if self.key else ""
        return printable(f"{self.where}{key}") + printable(self.message, keep="\n")

    @property
    def where(self) -> str:
        """``"file:line: "``, ``"file: "``, ``"line N: "`` or ``""``."""
        if self.file:
            return f"{self.file}:{self.line}: " if self.line else f"{self.file}: "
        if self.line:
            return f"line {self.line}: "
        return ""


class ValidationError(ExplorerError):
    """One or more :class:`Problem` found in a document; ``str()`` gives one line each."""

    def __init__(self, problems: list[Problem]):
        self.problems = list(problems)
        super().__init__("\n".join(str(p) for p in self.problems))


class Notice(UserWarning):
    """Something the user should know that is not an error (printed as ``notice: ...``)."""


class DeprecatedName(Notice):
    """A key, keyword or flag was given by its old name; it still works."""


class Cancelled(Exception):
    """Long work (ray casting in chunks) was stopped because its ``cancelled`` callable returned
    True. Not a user mistake, so not an :class:`ExplorerError`: a caller that cancelled the
    work catches it (the CLI prints one line)."""
