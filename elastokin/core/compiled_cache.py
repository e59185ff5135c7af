"""numba's on-disk cache made to follow the files a compiled function inlines, not only its own.

A function that calls another compiled function compiles it into itself, but numba checks only the
stamp of the function's own file: after a change to the callee its cache would run the old code
(on new arrays: wrong bits at best, memory corruption at worst). :func:`follow` registers, for the
functions of one file, a cache locator whose stamp also covers the files they call into.
"""

from __future__ import annotations

import os

from numba.core import caching


def follow(owner: str, *callees: str) -> None:
    """Make the cache of the compiled functions of file ``owner`` stale whenever ``owner`` or one of
    ``callees`` (file paths) changes. Call it before the functions are defined."""
    owner_path = os.path.realpath(owner)
    paths = tuple(os.path.realpath(p) for p in callees)

    class StampedLocator(caching.InTreeCacheLocator):
        @classmethod
        def from_function(cls, py_func, py_file):
            if os.path.realpath(py_file) != owner_path:
                return None  # other files keep numba's own locators
            return super().from_function(py_func, py_file)

        def get_source_stamp(self):
            stamps = [super().get_source_stamp()]
            for path in paths:
                st = os.stat(path)
                stamps.append(caching._hash_source_file(path, st.st_mtime, st.st_size))
            return tuple(stamps)

    caching.CacheImpl._locator_classes.insert(0, StampedLocator)
