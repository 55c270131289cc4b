"""GSD trajectories in the HOOMD schema and extended-XYZ export.

A frame holds the HOOMD schema that OVITO, MDAnalysis and freud read: a 2D box
``[Lx, Ly, 0, 0, 0, 0]`` centred on the origin (the vessel's bounding box), positions (N, 3) with
z = 0, velocities, masses, charges and diameters, a particle type per sign of the charge, and the
observables under ``log/`` (`LOG_KEYS`), among them the vessel itself, so that readers redraw
its real outline. Positions and velocities are stored in single precision, as the schema
does by default; checkpoints (`collidium.io.checkpoint`) keep the exact state.

Other tools:

- OVITO opens the GSD file and the XYZ export (`write_xyz`) as they are.
- freud: ``freud.box.Box.from_box(frame.configuration.box, dimensions=2)`` with the frame's
  positions.
- ASE: ``ase.io.read("run.xyz", index=":")``; velocities in ``atoms.arrays["velo"]``, charges
  as ``atoms.get_charges()``, a walled vessel as ``pbc = False``.
- MDAnalysis: its GSD reader takes the positions only, one time unit per frame;
  ``universe("run.gsd")`` adds the velocities and the real time between frames.
"""

from __future__ import annotations

import json
import os
import time as clock
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from collidium.errors import InputError
from collidium.io.atomic import replacing
from collidium.observers.base import Trigger, as_trigger
from collidium.state import FloatArray
from collidium.vessels import Box, Vessel, vessel_from_dict

if TYPE_CHECKING:
    import gsd.hoomd

    from collidium.simulation import Simulation

#: Free bytes a disk must have beyond a GSD file's holes for the file to be read through gsd's
#: memory map (see `_mapping_may_fault`).
MAPPING_MARGIN = 1 << 20

#: Particle types by the sign of the charge (OVITO colours by type).
TYPES = ("neutral", "positive", "negative")

#: What each frame logs, ``log/<key>``: name -> description.
LOG_KEYS = {
    "collidium/time": "simulated time, s",
    "collidium/dt": "time step, s",
    "collidium/periodic": "1 for a periodic box, 0 for reflecting walls",
    "collidium/vessel": "the vessel as UTF-8 JSON bytes: its shape and parameters",
    "energy/kinetic": "kinetic energy, J",
    "energy/potential": "potential energy, J",
    "energy/total": "total energy, J",
    "energy/total_speed": "sum of the speeds, m/s",
    "momentum": "total momentum (px, py), kg m/s",
    "temperature": "kT = KE / N, J",
    "collisions/pair": "pair collisions since the start",
    "collisions/walls": "hits on each wall since the start, in the vessel's wall order",
    "impulse/virial": "collision virial sum r_ij . dp_i since the start, kg m^2/s",
    "impulse/walls": "momentum received by each wall, in the vessel's wall order, kg m/s",
    "heat/walls": "energy each wall has given the disks (thermal, inelastic walls), J",
    "virial/forces": "pair virial of the forces now, J",
    "piston/position": "where the piston's face is along its axis, m (with a piston only)",
    "piston/velocity": "the piston's velocity along its axis, m/s (with a piston only)",
    "piston/work": "work the piston has done on the gas since the start, J (with a piston only)",
}


def gsd_box(vessel: Vessel) -> tuple[float, float]:
    """Sides ``(Lx, Ly)`` in m of the smallest box centred on the origin that holds the vessel
    (the GSD box is centred on the origin)."""
    reach = np.max(np.abs(vessel.bounds), axis=0)
    return float(2.0 * reach[0]), float(2.0 * reach[1])


def type_ids(charge: FloatArray) -> np.ndarray:
    """Index into `TYPES` for each charge: 0 neutral, 1 positive, 2 negative."""
    return np.where(charge > 0, 1, np.where(charge < 0, 2, 0)).astype(np.uint32)


def frame_of(sim: Simulation) -> gsd.hoomd.Frame:
    """The simulation's current state as a GSD frame."""
    import gsd.hoomd

    p = sim.particles
    box = sim.container
    frame = gsd.hoomd.Frame()
    frame.configuration.step = sim.steps
    frame.configuration.dimensions = 2
    width, height = gsd_box(box)
    frame.configuration.box = [width, height, 0.0, 0.0, 0.0, 0.0]
    frame.particles.N = p.n
    frame.particles.types = list(TYPES)
    frame.particles.typeid = type_ids(p.charge)
    frame.particles.position = np.column_stack([p.position, np.zeros(p.n)]).astype(np.float32)
    frame.particles.velocity = np.column_stack([p.velocity, np.zeros(p.n)]).astype(np.float32)
    frame.particles.mass = p.mass.astype(np.float32)
    frame.particles.charge = p.charge.astype(np.float32)
    frame.particles.diameter = (2.0 * p.radius).astype(np.float32)
    if box.periodic:
        frame.particles.image = np.column_stack([p.image, np.zeros(p.n)]).astype(np.int32)
    energy = sim.energy()
    counts, impulse = sim.tally.counts, sim.tally.impulse
    values: dict[str, Any] = {
        "collidium/time": sim.time,
        "collidium/dt": sim.dt,
        "collidium/periodic": int(box.periodic),
        "collidium/vessel": np.frombuffer(json.dumps(box.to_dict()).encode(), dtype=np.uint8),
        "energy/kinetic": energy.kinetic,
        "energy/potential": energy.potential,
        "energy/total": energy.total,
        "energy/total_speed": sim.total_speed(),
        "momentum": sim.momentum(),
        "temperature": sim.temperature(),
        "collisions/pair": counts[0],
        "collisions/walls": counts[1:],
        "impulse/virial": impulse[0],
        "impulse/walls": impulse[1:],
        "heat/walls": sim.tally.heat[1:],
        "virial/forces": sim.virial(),
    }
    piston = sim.piston()
    if piston is not None:
        values |= {"piston/position": piston.position, "piston/velocity": piston.velocity,
                   "piston/work": piston.work}  # fmt: skip
    frame.log = {key: np.atleast_1d(np.asarray(value)) for key, value in values.items()}
    return frame


class GSDWriter:
    """Observer that appends a frame to a GSD file whenever its trigger fires.

    Parameters
    ----------
    path : str or Path
        File to write (replaced, unless ``append``).
    trigger : callable or int, optional
        When to write (default every step). The state when the run starts is written too.
    flush_seconds : float
        Every frame reaches the disk within this many wall-clock seconds (checked after each
        step), and all of them when the writer is closed; 0 flushes each frame as it is written.
        A killed run keeps every flushed frame.
    append : bool
        Add to an existing file instead of replacing it (used when a run resumes).

    Notes
    -----
    A closed writer reopens its file (appending) at its next frame, so it can stay attached
    across runs.
    """

    def __init__(
        self,
        path: str | Path,
        trigger: Trigger | int | None = None,
        flush_seconds: float = 1.0,
        append: bool = False,
    ) -> None:
        self.path = Path(path)
        self._frames = as_trigger(trigger)
        if not flush_seconds >= 0:
            raise InputError("flush_seconds", f"must be >= 0, got {flush_seconds!r}")
        self.flush_seconds = float(flush_seconds)
        self.append = append
        self._file: gsd.hoomd.HOOMDTrajectory | None = None
        self._unflushed_since: float | None = None  # when the oldest unflushed frame was written
        self._last_step = -1
        self.frames_written = 0
        #: What the run loop calls after each step: the frame trigger, with the flush check.
        self.trigger: Trigger = self._flush_when_due_then_trigger

    def _flush_when_due_then_trigger(self, sim: Simulation) -> bool:
        """Flush frames that have waited ``flush_seconds``; then ask the frame trigger."""
        waiting = self._unflushed_since
        if waiting is not None and clock.monotonic() - waiting >= self.flush_seconds:
            self.flush()
        return self._frames(sim)

    def attach(self, sim: Simulation) -> None:
        """Open the file and write the current state as the first frame (when appending to a
        file that has frames, only the trigger's frames are added)."""
        if self._open():
            self.update(sim)

    def _open(self) -> bool:
        """Open the file if closed; False if it already holds frames to continue."""
        import gsd.hoomd

        if self._file is not None:
            return True
        if self.append and self.path.is_file() and _mapping_may_fault(self.path):
            raise InputError(str(self.path), f"cannot append: {_free_space(self.path)} on its disk")
        created = not self.path.exists()
        try:
            self._file = gsd.hoomd.open(self.path, "r+" if self.append else "w")
        except (OSError, RuntimeError) as exc:
            if created:  # leave no empty file behind
                self.path.unlink(missing_ok=True)
            reason = getattr(exc, "strerror", None) or str(exc)
            raise InputError(str(self.path), f"cannot write a GSD file: {reason}") from None
        if self.append and len(self._file):
            self._last_step = int(self._file[-1].configuration.step)
            return False
        return True

    def update(self, sim: Simulation) -> None:
        """Append the current state (once per step); flush at once if ``flush_seconds`` is 0."""
        self._open()
        if self._file is None or sim.steps == self._last_step:
            return
        with self._writing():
            self._file.append(frame_of(sim))
        self._last_step = sim.steps
        self.frames_written += 1
        if self._unflushed_since is None:
            self._unflushed_since = clock.monotonic()
        if self.flush_seconds == 0:
            self.flush()

    @property
    def last_step(self) -> int:
        """The step of the last frame in the file (-1 before any)."""
        return self._last_step

    def flush(self) -> None:
        """Write the buffered frames to disk now."""
        if self._file is not None:
            with self._writing():
                self._file.flush()
        self._unflushed_since = None

    def close(self) -> None:
        """Flush and close the file; `last_step` is then read back from it (a Ctrl-C between
        a frame's append and its bookkeeping would otherwise leave them apart)."""
        import gsd.hoomd

        file, self._file = self._file, None
        self._unflushed_since = None
        if file is not None:
            self.append = True  # reopening continues the same file
            with self._writing():
                file.close()
                with gsd.hoomd.open(self.path, "r") as written:
                    self._last_step = int(written[-1].configuration.step) if written else -1

    @contextmanager
    def _writing(self) -> Iterator[None]:
        """Turn a failed write (a full disk) into an `InputError` naming the file."""
        try:
            yield
        except OSError as exc:
            raise InputError(str(self.path), f"cannot write: {exc.strerror or exc}") from None

    def __enter__(self) -> GSDWriter:
        return self

    def __exit__(self, *_: object) -> None:
        self.close()


@dataclass
class Trajectory:
    """Frames read back from a GSD file (or recorded in memory), as float64 arrays.

    Attributes
    ----------
    vessel : Vessel
        The vessel the frames were taken in.
    step : ndarray of int64, shape (K,)
        Step of each frame.
    time : ndarray, shape (K,)
        Simulated time of each frame in s.
    position, velocity : ndarray, shape (K, N, 2)
        Centres (m) and velocities (m/s).
    mass, radius, charge : ndarray, shape (N,)
        From the first frame (kg, m, C).
    log : dict of str to ndarray
        Each ``log/`` entry (without the prefix) stacked over frames, shape (K, ...).
    """

    vessel: Vessel
    step: np.ndarray
    time: FloatArray
    position: FloatArray
    velocity: FloatArray
    mass: FloatArray
    radius: FloatArray
    charge: FloatArray
    log: dict[str, np.ndarray] = field(default_factory=dict)

    @property
    def width(self) -> float:
        """Side along x of the vessel's bounding box, m."""
        return float(self.vessel.size[0])

    @property
    def height(self) -> float:
        """Side along y of the vessel's bounding box, m."""
        return float(self.vessel.size[1])

    @property
    def periodic(self) -> bool:
        """Whether the vessel is periodic."""
        return self.vessel.periodic

    @property
    def frames(self) -> int:
        """Number of frames."""
        return int(self.step.shape[0])

    @property
    def n(self) -> int:
        """Number of particles."""
        return int(self.mass.shape[0])


def universe(path: str | Path) -> Any:
    """A GSD trajectory as an MDAnalysis ``Universe`` with its velocities and frame interval.

    MDAnalysis's own GSD reader takes only the positions, and counts one time unit per frame;
    here the topology (types, masses, charges) is MDAnalysis's reading of the file, and the
    positions and velocities (z = 0) are held in memory (``MemoryReader``) with ``dt`` the time
    between frames and the first frame's time as offset. A periodic box has its dimensions
    (``Lz`` the larger side: nothing moves along z); a walled vessel none, which MDAnalysis takes
    as not periodic. Values keep collidium's units (m, s, m/s), not MDAnalysis's Angstrom and
    ps. Needs MDAnalysis (``pip install MDAnalysis``).
    """
    import MDAnalysis
    from MDAnalysis.coordinates.memory import MemoryReader

    trajectory = read_trajectory(path)
    flat = np.zeros((trajectory.frames, trajectory.n, 3), dtype=np.float32)
    moving = flat.copy()
    flat[..., :2] = trajectory.position
    moving[..., :2] = trajectory.velocity
    interval = float(np.diff(trajectory.time[:2])[0]) if trajectory.frames > 1 else 1.0
    sides = [trajectory.width, trajectory.height]
    box = [*sides, max(sides), 90.0, 90.0, 90.0] if trajectory.periodic else None
    return MDAnalysis.Universe(
        str(path), flat, format=MemoryReader, order="fac", velocities=moving, dt=interval,
        time_offset=float(trajectory.time[0]), dimensions=box,
    )  # fmt: skip


def unwritten_bytes(path: Path) -> int:
    """Bytes of ``path`` in holes: ranges never written, which read back as zeros.

    GSD files have them: the library grows its index by extending the file. 0 where the
    filesystem does not report holes.
    """
    hole = getattr(os, "SEEK_HOLE", None)
    data = getattr(os, "SEEK_DATA", None)
    if hole is None or data is None:
        return 0
    fd = os.open(path, os.O_RDONLY)
    try:
        size, start, total = os.fstat(fd).st_size, 0, 0
        while start < size:
            end = os.lseek(fd, start, hole)
            try:
                start = os.lseek(fd, end, data)
            except OSError:  # no data after this hole
                start = size
            total += start - end
        return total
    except OSError:
        return 0
    finally:
        os.close(fd)


def _mapping_may_fault(path: Path) -> bool:
    """Whether gsd's memory map of ``path`` could stop the process with SIGBUS.

    A mapped hole is backed by a new page when it is read on some filesystems (tmpfs); on a
    disk without room for the holes, that read kills the process instead of raising.
    """
    holes = unwritten_bytes(path)
    if holes == 0:
        return False
    disk = os.statvfs(path)
    return disk.f_bavail * disk.f_frsize < holes + MAPPING_MARGIN


def _free_space(path: Path) -> str:
    """The free space on ``path``'s disk, in words."""
    disk = os.statvfs(path)
    return f"{disk.f_bavail * disk.f_frsize} bytes free"


def _open_for_reading(path: Path) -> gsd.hoomd.HOOMDTrajectory:
    import gsd.hoomd
    import gsd.pygsd

    if not path.is_file():
        raise InputError(str(path), "no such file")
    try:
        if not _mapping_may_fault(path):
            return gsd.hoomd.open(path, "r")
        # gsd's pure-Python reader reads with read(), which gives holes as zeros without room.
        return gsd.hoomd.HOOMDTrajectory(gsd.pygsd.GSDFile(path.open("rb")))
    except Exception as exc:  # gsd raises RuntimeError, OSError or ValueError on bad files
        raise InputError(str(path), f"not a readable GSD trajectory ({exc})") from None


def iter_frames(path: str | Path) -> Iterator[gsd.hoomd.Frame]:
    """Frames of a GSD file, one at a time; a damaged frame gives an `InputError`."""
    path = Path(path)
    with _open_for_reading(path) as trajectory:
        for k in range(len(trajectory)):
            try:
                frame = trajectory[k]
            except Exception as exc:
                raise InputError(str(path), f"frame {k} cannot be read ({exc})") from None
            yield frame


def read_trajectory(path: str | Path) -> Trajectory:
    """All frames of a GSD file written by collidium (or any 2D HOOMD-schema file).

    Raises
    ------
    InputError
        If the file is missing, is not GSD, is damaged, has no frames or is not 2D.
    """
    path = Path(path)
    frames = list(iter_frames(path))
    if not frames:
        raise InputError(str(path), "the trajectory has no frames")
    first = frames[0]
    if first.configuration.dimensions != 2:
        raise InputError(str(path), f"expected a 2D box, found {first.configuration.dimensions}D")
    n = int(first.particles.N)
    if any(int(f.particles.N) != n for f in frames):
        raise InputError(str(path), "the number of particles changes between frames")
    log = {
        key: np.stack([np.asarray(f.log[key]) for f in frames])
        for key in first.log
        if all(key in f.log for f in frames)
    }
    step = np.array([int(f.configuration.step) for f in frames], dtype=np.int64)
    time = log["collidium/time"][:, 0] if "collidium/time" in log else step.astype(float)
    return Trajectory(
        vessel=_vessel_of(path, first, log),
        step=step,
        time=np.asarray(time, dtype=float),
        position=np.stack([f.particles.position[:, :2] for f in frames]).astype(float),
        velocity=np.stack([f.particles.velocity[:, :2] for f in frames]).astype(float),
        mass=np.asarray(first.particles.mass, dtype=float),
        radius=0.5 * np.asarray(first.particles.diameter, dtype=float),
        charge=np.asarray(first.particles.charge, dtype=float),
        log=log,
    )


def keep_frames_through(path: str | Path, step: int) -> int:
    """Rewrite a GSD file keeping only the frames up to ``step`` (a resumed run continues from
    there); returns how many frames remain. The file is replaced atomically."""
    import gsd.hoomd

    frames = list(iter_frames(path))
    kept = [f for f in frames if int(f.configuration.step) <= step]
    if len(kept) < len(frames):
        with replacing(path) as temporary, gsd.hoomd.open(temporary, "w") as out:
            out.extend(kept)
    return len(kept)


def _vessel_of(path: Path, first: gsd.hoomd.Frame, log: dict[str, np.ndarray]) -> Vessel:
    """The vessel logged in a file, or for files without one (other programs, older versions)
    the GSD box, periodic unless logged as reflecting."""
    if "collidium/vessel" in log:
        try:
            return vessel_from_dict(json.loads(log["collidium/vessel"][0].tobytes().decode()))
        except (ValueError, TypeError, InputError) as exc:
            raise InputError(str(path), f"the logged vessel cannot be read ({exc})") from None
    periodic = bool(log["collidium/periodic"][0, 0]) if "collidium/periodic" in log else True
    width, height = (float(side) for side in first.configuration.box[:2])
    return Box(width, height, "periodic" if periodic else "reflecting")


def write_xyz(trajectory: Trajectory, path: str | Path) -> None:
    """Write an extended-XYZ file (one block per frame; OVITO and ASE read it).

    Each block: the particle count, a comment line with ``Lattice``, ``Origin``, ``Properties``,
    ``Time`` and ``pbc`` (``F F F`` for a walled vessel), then one line per particle: type, Z,
    x, y, z, vx, vy, vz, mass, radius, charge. The types (``positive``, ``negative``,
    ``neutral``) are OVITO's particle types; ``Z`` is 0, ASE's dummy atom ``X``, since ASE reads
    a type as a chemical symbol unless a ``Z`` column gives the atomic number.
    """
    (x0, y0), (w, h) = trajectory.vessel.bounds[0], trajectory.vessel.size
    pbc = "T T F" if trajectory.periodic else "F F F"
    names = np.array(TYPES)[type_ids(trajectory.charge)]
    zeros = np.zeros(trajectory.n)
    lines: list[str] = []
    for k in range(trajectory.frames):
        lines.append(str(trajectory.n))
        lines.append(
            f'Lattice="{w:.17g} 0 0 0 {h:.17g} 0 0 0 1" Origin="{x0:.17g} {y0:.17g} -0.5" '
            "Properties=species:S:1:Z:I:1:pos:R:3:velo:R:3:mass:R:1:radius:R:1:charge:R:1 "
            f'Time={trajectory.time[k]:.17g} Step={int(trajectory.step[k])} pbc="{pbc}"'
        )
        x, v = trajectory.position[k], trajectory.velocity[k]
        table = np.column_stack([x, zeros, v, zeros, trajectory.mass, trajectory.radius,
                                 trajectory.charge])  # fmt: skip
        lines.extend(
            f"{name} 0 " + " ".join(f"{value:.9g}" for value in row)
            for name, row in zip(names, table, strict=True)
        )
    with replacing(path) as temporary:
        temporary.write_text("\n".join(lines) + "\n", encoding="utf-8")


def describe(path: str | Path) -> dict[str, Any]:
    """What a GSD file holds: frames, particles, box, steps, times and log entries."""
    path = Path(path)
    trajectory = read_trajectory(path)
    return {
        "file": str(path),
        "format": "gsd",
        "bytes": path.stat().st_size,
        "frames": trajectory.frames,
        "n": trajectory.n,
        "vessel": trajectory.vessel.to_dict(),
        "box": [trajectory.width, trajectory.height],
        "steps": [int(trajectory.step[0]), int(trajectory.step[-1])],
        "time": [float(trajectory.time[0]), float(trajectory.time[-1])],
        "types": {t: int(np.sum(type_ids(trajectory.charge) == k)) for k, t in enumerate(TYPES)},
        "log": sorted(trajectory.log),
    }
