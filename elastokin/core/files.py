"""Reading a user's file as text; writing files and folders atomically, so that a reader sees the old
version or the new one, never half of it."""

from __future__ import annotations

import contextlib
import fcntl
import os
import shutil
import tempfile
from pathlib import Path
from typing import Iterator

from elastokin.core.errors import InputError


def read_text(path: str | Path) -> str:
    """The text of a user's file; InputError naming it when it cannot be read or is not UTF-8."""
    try:
        return Path(path).read_text(encoding="utf-8")
    except UnicodeDecodeError as exc:
        raise InputError(f"not UTF-8 text ({exc.reason} at byte {exc.start})", source=str(path)) from None
    except OSError as exc:
        raise InputError(f"cannot read: {exc.strerror}", source=str(path)) from exc


def is_file(path: str | os.PathLike[str]) -> bool:
    """Whether ``path`` names a file; False, not an OSError, for a name the system cannot even look
    up (too long, a null byte): a user's file names are input like any other."""
    try:
        return Path(path).is_file()
    except (OSError, ValueError):
        return False


def check_output(path: str | os.PathLike[str], *, folder: bool = False) -> Path:
    """``path`` as a Path if an output can be written there (a file, or a ``folder``), else an
    InputError naming it: a folder where a file is expected or the reverse, an ancestor that is a
    file, a folder that cannot be written into. For commands to call before any work starts."""
    path = Path(path)
    if path.exists() and path.is_dir() != folder:
        raise InputError(f"is a {'file' if folder else 'folder'}; expected a {'folder' if folder else 'file'} to write",
                         source=str(path))
    ancestor = path.parent
    while not ancestor.exists() and ancestor != ancestor.parent:
        ancestor = ancestor.parent
    if not ancestor.is_dir():
        raise InputError(f"is a file; it cannot hold {path}", source=str(ancestor))
    if not os.access(ancestor, os.W_OK | os.X_OK):
        raise InputError(f"cannot write here (permission denied), so not {path}", source=str(ancestor))
    # permissions do not tell it all (/proc, /sys, a read-only mount, a full disk): make a file there
    try:
        fd, probe = tempfile.mkstemp(prefix=".vsim-probe.", dir=ancestor)
    except OSError as exc:
        raise InputError(f"no file can be made here ({exc.strerror or exc}), so not {path}", source=str(ancestor)) from None
    os.close(fd)
    os.unlink(probe)
    return path


def _usual_permissions(path: str | Path, mode: int) -> None:
    """mkstemp and mkdtemp create private files (0600, 0700): give ``path`` the umask's permissions."""
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(path, mode & ~umask)


#: The file a process holds to write a folder alone (:func:`exclusive_folder`).
LOCK_NAME = ".lock"


@contextlib.contextmanager
def exclusive_folder(folder: Path, writer: str) -> Iterator[None]:
    """Hold ``folder`` for this process's writing during the block: an advisory lock on
    ``folder/.lock``, which the system drops if the process dies. InputError naming the folder if
    another process (a ``writer``: "vsim sweep") holds it."""
    folder.mkdir(parents=True, exist_ok=True)
    with open(folder / LOCK_NAME, "a") as lock:
        try:
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise InputError(f"another {writer} is writing this folder: wait for it to end, or choose another folder",
                             source=str(folder)) from None
        try:
            yield
        finally:
            fcntl.flock(lock, fcntl.LOCK_UN)


@contextlib.contextmanager
def atomic_output(path: Path) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; rename it to ``path`` only if the block succeeds,
    so that a reader never sees a half-written file."""
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=path.suffix, dir=path.parent)
    except OSError as exc:
        raise InputError(f"cannot be written ({exc.strerror or exc})", source=str(path)) from None
    os.close(fd)
    _usual_permissions(tmp, 0o666)
    try:
        yield Path(tmp)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


@contextlib.contextmanager
def atomic_directory(root: Path, *, overwrite: bool = False) -> Iterator[Path]:
    """A temporary folder next to ``root`` to write a whole dataset into, renamed to ``root`` when the
    block ends without error (replacing it only if ``overwrite``) and removed otherwise.

    Raises InputError if ``root`` exists and not ``overwrite``."""
    if root.exists() and not overwrite:
        raise InputError("exists; pass --overwrite to replace it", source=str(root))
    root.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{root.name}.", dir=root.parent))
    _usual_permissions(tmp, 0o777)
    try:
        yield tmp
        if root.exists():
            shutil.rmtree(root)
        os.replace(tmp, root)
    finally:
        if tmp.exists():
            shutil.rmtree(tmp)
