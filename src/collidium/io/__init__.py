"""Files: GSD trajectories and extended XYZ (`trajectory`), checkpoints (`checkpoint`)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from collidium.errors import InputError

#: First bytes of a GSD file and of a checkpoint (a zip archive).
GSD_MAGIC = bytes.fromhex("df65df65df65df65")
ZIP_MAGIC = b"PK"


def describe_file(path: str | Path) -> dict[str, Any]:
    """What a trajectory (.gsd) or checkpoint file holds, told apart by their first bytes.

    Raises
    ------
    InputError
        If the file is missing, of another kind, or damaged.
    """
    from collidium.io.checkpoint import describe_checkpoint
    from collidium.io.trajectory import describe

    path = Path(path)
    try:
        with path.open("rb") as stream:
            head = stream.read(8)
    except OSError as exc:
        raise InputError(str(path), f"cannot read: {exc.strerror or exc}") from None
    if head == GSD_MAGIC:
        return describe(path)
    if head.startswith(ZIP_MAGIC):
        return describe_checkpoint(path)
    raise InputError(str(path), "neither a GSD trajectory nor a collidium checkpoint")
