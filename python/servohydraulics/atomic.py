"""Files written whole or not at all.

Every writer of the package (``Response.to_csv``, ``save_rig``, the diagnosis
and reproduction reports, figures) writes to a temporary file in the target's
directory and renames it over the target (``os.replace``, atomic on POSIX), so
a full disk, a missing directory or an interrupt leaves the old file (or none),
never a truncated one.  A failure is an ``OSError`` whose message names the
file in one line::

    cannot write out/record.csv: [Errno 28] No space left on device

:class:`FileSet` does the same for several files that belong together (a
diagnosis: JSON, rig file, report, plots): they are renamed into place only
after all of them were written.

Targets that are not regular files are not replaced (a rename would swap a
device node or a link for a regular file, e.g. as root ``--out /dev/null``
would replace the system's ``/dev/null``):

* a **symbolic link is followed**: the file it points to is replaced, the
  link stays (it is usually there to name where results go, e.g.
  ``latest.csv -> runs/7/record.csv``; replacing it would silently detach it);
  a dangling link creates the file it names;
* a **character device** (``/dev/null``, a terminal) is **written through**:
  the finished file's bytes are copied into it (no atomicity to keep there);
* a FIFO, a socket or a block device is **refused** (``WriteError`` naming it):
  writing a FIFO blocks until some reader opens it, and a disk is never an
  output file.
"""

from __future__ import annotations

import errno
import os
import shutil
import stat
import tempfile
import uuid
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path


def _temporary(path: Path) -> Path:
    # Same directory (rename stays on one file system), same suffix (savefig and
    # savetxt infer the format from it), hidden and unique.
    return path.with_name(f".{path.name}.{os.getpid()}.{uuid.uuid4().hex[:8]}.tmp{path.suffix}")


class WriteError(OSError):
    """A file could not be written; ``str()`` is one line naming it."""

    def __init__(self, path: Path, errno_: int | None, reason: str):
        super().__init__(errno_, reason)
        self.filename = str(path)
        self.text = f"cannot write {path}: {reason}"

    def __str__(self) -> str:
        return self.text


def _failure(path: Path, e: OSError) -> WriteError:
    if isinstance(e, WriteError):
        return e
    reason = f"[Errno {e.errno}] {e.strerror}" if e.errno and e.strerror else str(e) or type(e).__name__
    return WriteError(path, e.errno, reason)


def _special(path: Path) -> str | None:
    """What ``path`` is when it exists and is neither a regular file nor a directory, else None."""
    try:
        mode = os.stat(path).st_mode
    except OSError:
        return None
    for test, kind in ((stat.S_ISCHR, "character device"), (stat.S_ISFIFO, "FIFO"), (stat.S_ISSOCK, "socket"),
                       (stat.S_ISBLK, "block device")):
        if test(mode):
            return kind
    return None


def _followed(link: Path) -> Path:
    """The file a symbolic link leads to (it may not exist yet); WriteError for a loop."""
    try:
        return Path(os.path.realpath(link, strict=True))
    except FileNotFoundError:  # dangling: the write creates the file it names
        return Path(os.path.realpath(link))
    except OSError as e:
        raise _failure(link, e) from None


def _copy_into(tmp: Path, device: Path) -> None:
    """Writes the finished temporary's bytes into a character device and removes the temporary."""
    with open(tmp, "rb") as src, open(device, "wb") as dst:
        shutil.copyfileobj(src, dst)
    _remove(tmp)


def check_folder(folder: str | Path) -> Path:
    """Creates ``folder`` (and its parents) and proves a file can be written in it, so a
    command fails before its computation, not after; WriteError naming the folder otherwise."""
    folder = Path(folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=folder, prefix=".write_check."):
            pass
    except OSError as e:
        raise _failure(folder, e) from None
    return folder


def _remove(p: Path) -> None:
    try:
        p.unlink()
    except OSError:
        pass


class FileSet:
    """Temporary paths for a group of files, renamed over their targets together.

    ``path(target)`` gives the temporary path to write ``target`` to; on a
    clean exit of the ``with`` block every temporary is renamed over its
    target; on any exception all temporaries are removed and no target is
    touched (an ``OSError`` is re-raised naming the file).
    """

    def __init__(self) -> None:
        self._pending: list[tuple[Path, Path]] = []
        self._through: set[Path] = set()  # temporaries copied into a character device, not renamed

    def path(self, target: str | Path) -> Path:
        target = Path(target)
        if target.name in ("", ".", "..") or target.is_dir():
            raise WriteError(target, errno.EISDIR, "it is a directory")
        real = _followed(target) if target.is_symlink() else target  # followed, never replaced
        kind = _special(real)
        if kind is not None and kind != "character device":
            raise WriteError(target, errno.EINVAL, f"it is a {kind}, not a regular file (refusing to replace it)")
        tmp = _temporary(real)
        if kind is not None:
            self._through.add(tmp)
        self._pending.append((tmp, real))
        return tmp

    def write_text(self, target: str | Path, text: str) -> Path:
        tmp = self.path(target)
        try:
            tmp.write_text(text, encoding="utf-8")
        except OSError as e:
            raise _failure(Path(target), e) from None
        return Path(target)

    def __enter__(self) -> FileSet:
        return self

    def __exit__(self, exc_type, exc, tb) -> bool:
        target = self._pending[-1][1] if self._pending else Path("?")
        try:
            if exc_type is None:
                for tmp, target in self._pending:  # noqa: B007 - target names the failing file below
                    if not tmp.exists():
                        raise FileNotFoundError(2, "it was not written")
                for tmp, target in self._pending:
                    if tmp in self._through:
                        _copy_into(tmp, target)
                    else:
                        os.replace(tmp, target)
                return False
        except OSError as e:
            exc = e
        for tmp, _ in self._pending:
            _remove(tmp)
        if isinstance(exc, OSError) and not isinstance(exc, WriteError):
            raise _failure(target, exc) from None
        if exc_type is None:
            raise exc
        return False


@contextmanager
def atomic_path(target: str | Path) -> Iterator[Path]:
    """Yields a temporary path to write ``target`` to; renames it into place on success."""
    with FileSet() as files:
        yield files.path(target)


def write_text(path: str | Path, text: str) -> Path:
    """Writes ``text`` (UTF-8) to ``path`` atomically."""
    with FileSet() as files:
        files.write_text(path, text)
    return Path(path)


def replace_marked(path: str | Path, name: str, text: str) -> Path:
    """Replaces the section of a text file (a page of ``docs/``) between the lines ``<!-- name -->`` and
    ``<!-- /name -->`` with ``text``, the rest as it is, atomically; ValueError if the markers are absent."""
    import re

    path = Path(path)
    pat = re.compile(rf"(<!-- {re.escape(name)} -->\n)(.*?)(<!-- /{re.escape(name)} -->)", re.S)
    old = path.read_text(encoding="utf-8")
    if not pat.search(old):
        raise ValueError(f"marker <!-- {name} --> ... <!-- /{name} --> not found in {path}")
    return write_text(path, pat.sub(lambda m: m.group(1) + text.rstrip("\n") + "\n" + m.group(3), old))


def write_with(path: str | Path, writer: Callable[[Path], object]) -> Path:
    """Calls ``writer(tmp)`` and renames ``tmp`` over ``path`` (e.g. ``lambda p: fig.savefig(p)``)."""
    with atomic_path(path) as tmp:
        writer(tmp)
    return Path(path)


__all__ = ["FileSet", "WriteError", "atomic_path", "check_folder", "replace_marked", "write_text", "write_with"]
