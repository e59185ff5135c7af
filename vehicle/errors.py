"""The one exception type for bad user input (files, keys, values)."""

from bushings.errors import InputError

__all__ = ["InputError"]
