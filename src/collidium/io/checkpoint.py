"""Checkpoint files: named float/int arrays plus JSON metadata in one ``.npz`` (zip) file.

Arrays are stored bit for bit, so a simulation restored from a checkpoint continues exactly as the
uninterrupted one would. Files are written to a temporary name and renamed, so a crash never
leaves a half-written checkpoint; a damaged file (every zip member carries a CRC) is refused with
one clear message.
"""

from __future__ import annotations

import json
import os
import zipfile
from pathlib import Path
from typing import Any

import numpy as np

from collidium.errors import InputError
from collidium.io.atomic import replacing
from collidium.vessels import vessel_from_dict

FORMAT = "collidium-checkpoint"
VERSION = 1
_META = "__meta__"


def write_checkpoint(path: str | Path, arrays: dict[str, np.ndarray], meta: dict[str, Any]) -> None:
    """Write ``arrays`` and JSON-serialisable ``meta`` to ``path`` atomically.

    Raises
    ------
    InputError
        If the folder cannot be written.
    """
    header = {"format": FORMAT, "version": VERSION} | meta
    encoded = np.frombuffer(json.dumps(header).encode("utf-8"), dtype=np.uint8)
    with replacing(path) as temporary, temporary.open("wb") as stream:
        # np.savez's layout, written here so that a write that fails closes the archive (NumPy 1
        # leaves that to the garbage collector, which then writes to the closed file and prints
        # a traceback) and arrays of objects are refused, never pickled.
        with zipfile.ZipFile(stream, mode="w", allowZip64=True) as archive:
            for name, array in ({_META: encoded} | arrays).items():
                with archive.open(f"{name}.npy", mode="w", force_zip64=True) as member:
                    np.lib.format.write_array(member, np.asanyarray(array), allow_pickle=False)
        stream.flush()
        os.fsync(stream.fileno())


def read_checkpoint(path: str | Path) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
    """Arrays and metadata of a checkpoint written by `write_checkpoint`.

    Raises
    ------
    InputError
        If the file is missing, truncated, corrupt or not a collidium checkpoint.
    """
    path = Path(path)
    if not path.is_file():
        raise InputError(str(path), "no such checkpoint file")
    try:
        with np.load(path, allow_pickle=False) as archive:
            arrays = {name: archive[name] for name in archive.files}
        header = arrays.pop(_META)
        if not isinstance(header, np.ndarray):
            raise ValueError("its header is not an array")
        meta = json.loads(header.tobytes().decode("utf-8"))
    except (zipfile.BadZipFile, KeyError, ValueError, OSError, EOFError, UnicodeError) as exc:
        raise InputError(str(path), f"not a readable collidium checkpoint ({exc})") from None
    if not isinstance(meta, dict) or meta.get("format") != FORMAT:
        raise InputError(str(path), "not a collidium checkpoint")
    if meta.get("version") != VERSION:
        raise InputError(str(path), f"checkpoint version {meta.get('version')!r} is not {VERSION}")
    return arrays, meta


def saved_vessel(state: dict[str, Any]) -> dict[str, Any]:
    """The vessel's `Vessel.to_dict` in a checkpoint's simulation state; checkpoints from before
    vessels had shapes hold a ``box``."""
    return state["vessel"] if "vessel" in state else {"shape": "box", **state["box"]}


def describe_checkpoint(path: str | Path) -> dict[str, Any]:
    """What a checkpoint holds: the simulation's name, size, vessel (and its bounding box), step,
    time and saved run."""
    path = Path(path)
    arrays, meta = read_checkpoint(path)
    try:
        state = meta["simulation"]
        vessel = vessel_from_dict(saved_vessel(state))
        t0, k0 = state["time_origin"]
        return {
            "file": str(path),
            "format": "checkpoint",
            "bytes": path.stat().st_size,
            "scenario": state["name"],
            "n": int(arrays["position"].shape[0]),
            "vessel": vessel.to_dict(),
            "box": [float(side) for side in vessel.size],
            "collisions": state["collisions"],
            "forces": state["forces"],
            "step": state["steps"],
            "time": t0 + (state["steps"] - k0) * state["dt"],
            "dt": state["dt"],
            "run": meta.get("extra", {}).get("job"),
        }
    except (KeyError, TypeError, ValueError) as exc:
        raise InputError(str(path), f"checkpoint is incomplete or damaged ({exc!r})") from None
