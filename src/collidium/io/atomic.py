"""Writing a file so that readers see the old content or the new, never a half-written one."""

from __future__ import annotations

import os
import secrets
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from collidium.errors import InputError


@contextmanager
def replacing(path: str | Path) -> Iterator[Path]:
    """Give a temporary file beside ``path`` to write; move it onto ``path`` when the block ends.

    The temporary keeps ``path``'s suffix (for writers that go by it) and is created under the
    usual umask. If the block fails or is interrupted, the temporary is removed and ``path`` is
    left as it was.

    Raises
    ------
    InputError
        If ``path`` names a folder, its folder does not exist or cannot be written, or writing
        fails (a full disk).
    """
    path = Path(path)
    if not path.name or path.is_dir():
        raise InputError(str(path), "is a folder; give a file name")
    temporary = path.with_name(f".{path.stem}.{secrets.token_hex(4)}.part{path.suffix}")
    try:
        with temporary.open("xb"):
            pass
    except OSError as exc:
        raise InputError(str(path), f"cannot write: {exc.strerror or exc}") from None
    try:
        yield temporary
        os.replace(temporary, path)
    except OSError as exc:  # a full or read-only disk, most often
        temporary.unlink(missing_ok=True)
        raise InputError(str(path), f"cannot write: {exc.strerror or exc}") from None
    except BaseException:
        temporary.unlink(missing_ok=True)
        raise
