"""A run as the command line does it: a simulation taken to an end step with its trajectory,
checkpoints and measurements, and resumable from any checkpoint.

The job (end step, output file, checkpoint file and periods) is stored in each checkpoint, so
``collidium resume run.ckpt`` finishes the interrupted run: the trajectory is cut back to the
checkpoint's step and continued, and the final state is bitwise the uninterrupted run's.
"""

from __future__ import annotations

import math
import time as clock
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from collidium.errors import InputError
from collidium.io.trajectory import GSDWriter, keep_frames_through, read_trajectory, write_xyz
from collidium.observers import CollisionRate, EnergyDrift, Every, SpeedHistogram, Thermo, Trigger
from collidium.simulation import Simulation, restore_with_meta

#: Trajectory formats by file suffix.
OUTPUT_SUFFIXES = (".gsd", ".xyz")

#: How many samples the run's own measurements take at most (their collision parts are exact).
SAMPLES = 500


@dataclass
class Job:
    """What a run was asked to do.

    Attributes
    ----------
    end_step : int
        The step at which the run ends.
    out : str or None
        Trajectory file (.gsd, or .xyz converted from a .gsd beside it at the end).
    every : int
        Steps between trajectory frames.
    checkpoint : str or None
        Checkpoint file, rewritten every ``checkpoint_every`` steps and at the end.
    checkpoint_every : int or None
        Steps between checkpoints.
    initial_total : float or None
        Total energy at the start of the whole run (kept across resumes), J.
    max_rel_drift : float
        Largest relative energy drift seen before the last checkpoint.
    """

    end_step: int
    out: str | None = None
    every: int = 10
    checkpoint: str | None = None
    checkpoint_every: int | None = None
    initial_total: float | None = None
    max_rel_drift: float = 0.0

    def __post_init__(self) -> None:
        if self.every < 1:
            raise InputError("--every", f"must be >= 1 step, got {self.every}")
        if self.checkpoint_every is not None and self.checkpoint_every < 1:
            raise InputError(
                "--checkpoint-every", f"must be >= 1 step, got {self.checkpoint_every}"
            )
        if self.checkpoint_every is not None and self.checkpoint is None:
            raise InputError("--checkpoint-every", "needs --checkpoint FILE")
        if self.out is not None and Path(self.out).suffix not in OUTPUT_SUFFIXES:
            raise InputError("--out", f"must end in {' or '.join(OUTPUT_SUFFIXES)}, got {self.out}")
        for name in (self.out, self.checkpoint):
            if name is not None and not Path(name).parent.is_dir():
                raise InputError(name, f"cannot write: no folder {Path(name).parent}")

    def record_drift(self, drift: EnergyDrift) -> None:
        """Fold a segment's energy drift into the whole run's, measured against the energy at
        the start of the whole run."""
        assert self.initial_total is not None
        scale = max(abs(self.initial_total), 1e-300)
        offset = abs(drift.initial_total - self.initial_total)
        worst = (offset + drift.max_rel_drift * abs(drift.initial_total)) / scale
        self.max_rel_drift = max(self.max_rel_drift, worst)

    @property
    def trajectory(self) -> Path | None:
        """The GSD file frames go to (a hidden one beside ``out`` for .xyz output)."""
        if self.out is None:
            return None
        out = Path(self.out)
        return out if out.suffix == ".gsd" else out.with_name(f".{out.name}.gsd")


class CheckpointWriter:
    """Observer that saves the simulation and its job every ``period`` steps.

    Trajectory writers attached to the simulation are flushed first, so the file holds every
    frame up to the checkpoint.
    """

    def __init__(self, path: str | Path, period: int, job: Job, drift: EnergyDrift) -> None:
        self.path = Path(path)
        self.trigger: Trigger = Every(period)
        self.job = job
        self.drift = drift

    def attach(self, sim: Simulation) -> None:
        """Nothing to do before the run."""

    def update(self, sim: Simulation) -> None:
        """Flush the trajectories, then write the checkpoint."""
        for observer in sim.observers:
            if isinstance(observer, GSDWriter):
                observer.flush()
        self.job.record_drift(self.drift)
        sim.save(self.path, job=asdict(self.job))


def resume(path: str | Path) -> tuple[Simulation, Job]:
    """The simulation and job saved in a checkpoint, its trajectory cut back to the saved step.

    Raises
    ------
    InputError
        If the checkpoint is damaged or holds no job, or its trajectory cannot be read.
    """
    sim, meta = restore_with_meta(path)
    if not isinstance(meta.get("job"), dict):
        raise InputError(str(path), "the checkpoint holds no run to resume (saved by sim.save?)")
    try:
        job = Job(**meta["job"])
    except TypeError as exc:
        raise InputError(str(path), f"the checkpoint's job is damaged ({exc})") from None
    if job.trajectory is not None and job.trajectory.exists():
        keep_frames_through(job.trajectory, sim.steps)
    return sim, job


def execute(sim: Simulation, job: Job, progress: bool = False) -> dict[str, Any]:
    """Run ``sim`` to ``job.end_step`` with its outputs; returns the summary (`summarise`)."""
    remaining = job.end_step - sim.steps
    if remaining < 0:
        raise InputError("steps", f"the run is already past step {job.end_step}")
    if job.initial_total is None:
        job.initial_total = sim.energy().total
    period = max(1, remaining // SAMPLES)
    drift, thermo, rate = EnergyDrift(), Thermo(period), CollisionRate(period)
    sim.observers += [drift, thermo, rate]
    if job.trajectory is not None:
        append = sim.steps > 0 and job.trajectory.exists()
        sim.observers.append(GSDWriter(job.trajectory, Every(job.every), append=append))
    if job.checkpoint is not None and job.checkpoint_every is not None:
        sim.observers.append(CheckpointWriter(job.checkpoint, job.checkpoint_every, job, drift))
    start = clock.perf_counter()
    try:
        sim.run(steps=remaining, progress=progress)
    finally:  # this run's trajectory and any a scenario file asked for
        for observer in sim.observers:
            if isinstance(observer, GSDWriter):
                observer.close()
    wall = clock.perf_counter() - start
    job.record_drift(drift)
    if job.checkpoint is not None:
        sim.save(job.checkpoint, job=asdict(job))
    if job.out is not None and job.trajectory is not None and Path(job.out).suffix == ".xyz":
        write_xyz(read_trajectory(job.trajectory), job.out)
        job.trajectory.unlink()
    return summarise(sim, job, thermo, rate, wall)


def summarise(
    sim: Simulation, job: Job, thermo: Thermo, rate: CollisionRate, wall_seconds: float
) -> dict[str, Any]:
    """Plain numbers describing a finished run (the ``--json`` object).

    The state quantities are the final ones; temperature, pressures and collision rate are
    averaged over the run (since the resume, for a resumed run); the KS p-value tests the final
    speeds against Maxwell-Boltzmann at the final temperature.
    """
    summary: dict[str, Any] = sim.summary()
    summary["dt"] = float(sim.dt)
    summary["wall_seconds"] = wall_seconds
    summary["energy"]["initial_total"] = job.initial_total
    summary["energy"]["max_rel_drift"] = job.max_rel_drift
    summary |= thermo.summary()
    summary["collisions"]["rate"] = rate.rate
    summary["collisions"]["mean_free_time"] = rate.mean_free_time
    speeds = SpeedHistogram().compute(sim).summary()
    summary["ks_statistic"] = speeds["ks_statistic"]
    summary["ks_pvalue"] = speeds["ks_pvalue"]
    return finite(summary)


def finite(value: Any) -> Any:
    """``value`` with every NaN or infinity replaced by None, recursively (JSON has neither)."""
    if isinstance(value, dict):
        return {key: finite(item) for key, item in value.items()}
    if isinstance(value, list | tuple):
        return [finite(item) for item in value]
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value
