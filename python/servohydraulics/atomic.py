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
"""

from __future__ import annotations

import errno
import os
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

    def path(self, target: str | Path) -> Path:
        target = Path(target)
        if target.name in ("", ".", "..") or target.is_dir():
            raise WriteError(target, errno.EISDIR, "it is a directory")
        tmp = _temporary(target)
        self._pending.append((tmp, target))
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
                for tmp, target in self._pending:
                    if not tmp.exists():
                        raise FileNotFoundError(2, "it was not written")
                for tmp, target in self._pending:
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


def write_with(path: str | Path, writer: Callable[[Path], object]) -> Path:
    """Calls ``writer(tmp)`` and renames ``tmp`` over ``path`` (e.g. ``lambda p: fig.savefig(p)``)."""
    with atomic_path(path) as tmp:
        writer(tmp)
    return Path(path)


__all__ = ["FileSet", "WriteError", "atomic_path", "write_text", "write_with"]
