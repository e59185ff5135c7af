"""The one exception type for bad user input: it names the file (and line), the key, the value and
what was expected."""

from __future__ import annotations


class ElastokinWarning(UserWarning):
    """A warning a user can act on, about their data or their run (``vsim`` shows it as one line of its own)."""


class InputError(ValueError):
    """Bad input from a file or the command line, with a message a user can act on."""

    def __init__(self, message: str, *, source: str | None = None, key: str | None = None):
        where = ": ".join(part for part in (source, key) if part)
        super().__init__(f"{where}: {message}" if where else message)
        self.source = source
        self.key = key

    @property
    def bare(self) -> str:
        """The message without its ``source: key:`` prefix."""
        where = ": ".join(part for part in (self.source, self.key) if part)
        return str(self).removeprefix(f"{where}: ") if where else str(self)
