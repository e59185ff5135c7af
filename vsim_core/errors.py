"""Errors raised on bad user input: they name the file, the key, the value and what was expected;
and reading a user's YAML file with such errors."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml


class InputError(ValueError):
    """Bad input from a file or the command line, with a message a user can act on."""

    def __init__(self, message: str, *, source: str | None = None, key: str | None = None):
        where = ": ".join(part for part in (source, key) if part)
        super().__init__(f"{where}: {message}" if where else message)
        self.source = source
        self.key = key


def read_yaml(path: Path, missing: str) -> Any:
    """The parsed content of a user's YAML file; InputError naming the file when it does not exist
    (with the message ``missing``) or is not valid YAML."""
    if not path.is_file():
        raise InputError(missing, source=str(path))
    return parse_yaml(path.read_text(), str(path))


def parse_yaml(text: str, source: str) -> Any:
    """The parsed YAML ``text``; InputError naming ``source`` when it is not valid YAML."""
    try:
        return yaml.safe_load(text)
    except yaml.YAMLError as exc:
        raise InputError(f"not valid YAML: {exc}", source=source) from exc
