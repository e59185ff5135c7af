"""What software made a file: the installed version and the source tree's commit, each asked once
per process (a process runs the code it imported, whatever the tree becomes; a diagnosis records
hundreds of runs, and asking git cost 7 ms each)."""

from __future__ import annotations

import functools
import importlib.metadata
import subprocess

from elastokin.core.shipped import SOURCE_TREE


@functools.cache
def software_version() -> str:
    """The installed elastokin version, or ``unknown``."""
    try:
        return importlib.metadata.version("elastokin")
    except importlib.metadata.PackageNotFoundError:
        return "unknown"


@functools.cache
def git_revision() -> str:
    """The source tree's commit (``-dirty`` if tracked files changed), or ``unknown`` (an installed
    wheel has no source tree: asking git there could name an unrelated repository around it)."""
    if SOURCE_TREE is None:
        return "unknown"
    try:
        rev = subprocess.run(["git", "rev-parse", "HEAD"], cwd=SOURCE_TREE, capture_output=True, text=True, check=True)
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=SOURCE_TREE,
                               capture_output=True, text=True, check=True)
    except (OSError, subprocess.CalledProcessError):
        return "unknown"
    return rev.stdout.strip() + ("-dirty" if dirty.stdout.strip() else "")
