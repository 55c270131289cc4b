"""A run as the command line does it: a simulation taken to an end step with its trajectory,
checkpoints and measurements, and resumable from any checkpoint.

The job (end step, output files, checkpoint file and periods, the scenario file's observers) is
stored in each checkpoint, with its paths relative to the checkpoint's folder, so
``collidium resume run.ckpt`` finishes the interrupted run from anywhere: trajectories are cut back
to the checkpoint's step and continued, and the final state and trajectories are bitwise those of
the run that was never stopped.
"""

from __future__ import annotations

import math
import os
import tempfile
import time as clock
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from collidium.errors import InputError, Interrupted
from collidium.io.trajectory import (
    GSDWriter,
    Trajectory,
    keep_frames_through,
    read_trajectory,
    write_xyz,
)
from collidium.observers import (
    CollisionRate,
    EnergyDrift,
    Every,
    Measurement,
    SpeedHistogram,
    Thermo,
    Trigger,
)
from collidium.observers.energy import DRIFT_WARNING, conserved_energy
from collidium.observers.energy import drift_warning as drift_warning_line
from collidium.scenario import Scenario, build_observers
from collidium.simulation import MAX_STEPS, Simulation, restore_with_meta, step_count

#: Trajectory formats by file suffix.
OUTPUT_SUFFIXES = (".gsd", ".xyz")

#: Fewest particles for which the summary tests the speeds against Maxwell-Boltzmann and the
#: table shows a temperature: with fewer, neither describes a gas.
STATISTICS_FROM = 20

#: How many samples the run's own measurements take at most (their collision parts are exact).
SAMPLES = 500


@dataclass
class Job:
    """What a run was asked to do. Paths are made absolute when the job is created.

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
    observers : list of dict
        The scenario file's observer tables, rebuilt when the run resumes.
    initial_total : float or None
        Total energy at the start of the whole run (kept across resumes), J.
    max_rel_drift : float
        Largest relative energy drift from ``initial_total`` so far.
    max_drift : float or None
        The drift past which the run fails (``--max-drift``); None warns past `DRIFT_WARNING`.
    """

    end_step: int
    out: str | None = None
    every: int = 10
    checkpoint: str | None = None
    checkpoint_every: int | None = None
    observers: list[dict[str, Any]] = field(default_factory=list)
    initial_total: float | None = None
    max_rel_drift: float = 0.0
    max_drift: float | None = None

    def __post_init__(self) -> None:
        if self.max_drift is not None and not (
            isinstance(self.max_drift, int | float) and self.max_drift > 0  # also refuses NaN
        ):
            raise InputError("--max-drift", f"must be a number > 0, got {self.max_drift!r}")
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
        self.out = _writable("--out", self.out)
        self.checkpoint = _writable("--checkpoint", self.checkpoint)
        self.observers = [dict(spec) for spec in self.observers]
        for k, spec in enumerate(self.observers):
            if "path" in spec:
                spec["path"] = _writable(f"observers.{k}.path", spec["path"])
        targets = [str(path) for path in self.files()]
        if self.staged:
            targets.append(str(self.out))  # .xyz output beside its staging .gsd
        if self.checkpoint is not None:
            targets.append(self.checkpoint)
        if len(set(targets)) < len(targets):
            raise InputError("--checkpoint", "the trajectory and checkpoint files must differ")

    @property
    def drift_limit(self) -> float:
        """The relative energy drift past which the run warns, or fails with ``max_drift``."""
        return DRIFT_WARNING if self.max_drift is None else self.max_drift

    @property
    def trajectory(self) -> Path | None:
        """The GSD file frames go to (a hidden one beside ``out`` for .xyz output)."""
        if self.out is None:
            return None
        out = Path(self.out)
        return out if out.suffix == ".gsd" else out.with_name(f".{out.name}.gsd")

    @property
    def staged(self) -> bool:
        """Whether frames go to a hidden GSD file first (.xyz output, converted at the end)."""
        return self.out is not None and self.trajectory != Path(self.out)

    def files(self) -> list[Path]:
        """Every trajectory the run writes (its own and the scenario file's)."""
        paths = [Path(spec["path"]) for spec in self.observers if "path" in spec]
        return paths if self.trajectory is None else [self.trajectory, *paths]

    def to_meta(self, folder: Path) -> dict[str, Any]:
        """The job as JSON data, paths relative to ``folder`` (the checkpoint's)."""

        def relative(path: str | None) -> str | None:
            return None if path is None else os.path.relpath(path, folder.absolute())

        observers = [spec | ({"path": relative(spec["path"])} if "path" in spec else {})
                     for spec in self.observers]  # fmt: skip
        return asdict(self) | {"out": relative(self.out), "checkpoint": relative(self.checkpoint),
                               "observers": observers}  # fmt: skip

    @classmethod
    def from_meta(cls, meta: dict[str, Any], folder: Path) -> Job:
        """The job stored by `to_meta`, paths taken relative to ``folder``."""

        def absolute(path: str | None) -> str | None:
            return None if path is None else str(folder / path)

        observers = [spec | ({"path": absolute(spec["path"])} if "path" in spec else {})
                     for spec in meta.get("observers", [])]  # fmt: skip
        return cls(**meta | {"out": absolute(meta.get("out")),
                             "checkpoint": absolute(meta.get("checkpoint")),
                             "observers": observers})  # fmt: skip


def _writable(name: str, target: str | None) -> str | None:
    """``target`` made absolute, after checking a file can be written there."""
    if target is None:
        return None
    if not str(target).strip():
        raise InputError(name, "needs a file name")
    path = Path(target).absolute()
    if path.is_dir():
        raise InputError(name, f"{target} is a folder; give a file name")
    if not path.parent.is_dir():
        raise InputError(name, f"cannot write {target}: no folder {path.parent}")
    if not os.access(path.parent, os.W_OK):
        raise InputError(name, f"cannot write {target}: folder {path.parent} is read-only")
    return str(path)


class CheckpointWriter:
    """Observer that saves the simulation and its job every ``period`` steps.

    Trajectory writers attached to the simulation are flushed first, so the files hold every
    frame up to the checkpoint.
    """

    def __init__(self, path: str | Path, period: int, job: Job, drift: EnergyDrift) -> None:
        self.path = Path(path)
        self.trigger: Trigger = Every(period)
        self.job = job
        self.drift = drift
        #: The step of the last checkpoint this writer saved (None before the first).
        self.saved_step: int | None = None

    def attach(self, sim: Simulation) -> None:
        """Nothing to do before the run."""

    def update(self, sim: Simulation) -> None:
        """Flush the trajectories, then write the checkpoint."""
        for observer in sim.observers:
            if isinstance(observer, GSDWriter):
                observer.flush()
        save(sim, self.job, self.drift)
        self.saved_step = sim.steps


def save(sim: Simulation, job: Job, drift: EnergyDrift) -> None:
    """Write ``job.checkpoint`` with the drift seen so far folded into the job."""
    assert job.checkpoint is not None
    job.max_rel_drift = max(job.max_rel_drift, drift.max_rel_drift)
    checkpoint = Path(job.checkpoint)
    sim.save(checkpoint, job=job.to_meta(checkpoint.parent))


def resume(path: str | Path) -> tuple[Simulation, Job]:
    """The simulation and job saved in a checkpoint, with the scenario file's observers attached
    again and every trajectory cut back to the saved step.

    Raises
    ------
    InputError
        If the checkpoint is damaged or holds no job, or a trajectory cannot be read.
    """
    path = Path(path)
    sim, meta = restore_with_meta(path)
    if not isinstance(meta.get("job"), dict):
        raise InputError(str(path), "the checkpoint holds no run to resume (saved by sim.save?)")
    try:
        job = Job.from_meta(meta["job"], path.parent)
        observers = build_observers(job.observers)
    except (TypeError, AttributeError) as exc:
        raise InputError(str(path), f"the checkpoint's run is damaged ({exc})") from None
    for file in job.files():
        if file.exists():
            keep_frames_through(file, sim.steps)
    for observer in observers:
        if isinstance(observer, GSDWriter):
            observer.append = True
    sim.observers += observers
    return sim, job


def steps_of(spec: Scenario, time: float | None = None, steps: int | None = None) -> int:
    """The steps a run of the scenario takes: ``time`` s, or ``steps``, or its ``run.time``."""
    if time is not None and steps is not None:
        raise InputError("--time", "give --time or --steps, not both")
    duration = spec.run.time if time is None and steps is None else time
    return step_count(duration, steps, spec.run.dt)


def prepare(
    spec: Scenario,
    time: float | None = None,
    steps: int | None = None,
    out: str | Path | None = None,
    every: int | None = None,
    checkpoint: str | Path | None = None,
    checkpoint_every: int | None = None,
    max_drift: float | None = None,
) -> tuple[Simulation, Job]:
    """The simulation a scenario builds and the job of running it, as `collidium run` does.

    The run lasts ``time`` s or ``steps`` steps (the scenario's ``run.time`` if neither); frames
    go to ``out`` every ``every`` steps (0.1 s by default).
    """
    job = Job(
        end_step=steps_of(spec, time, steps), out=None if out is None else str(out),
        every=every if every is not None else _steps_in_a_tenth_of_a_second(spec.run.dt),
        checkpoint=None if checkpoint is None else str(checkpoint),
        checkpoint_every=checkpoint_every, observers=spec.to_dict().get("observers", []),
        max_drift=max_drift,
    )  # fmt: skip
    return spec.build(), job


def _steps_in_a_tenth_of_a_second(dt: float) -> int:
    """The default frame interval, in steps of ``dt`` (s): 0.1 s, at least a step (at most
    `MAX_STEPS`: a subnormal dt would overflow the count)."""
    return max(1, round(min(0.1 / dt, MAX_STEPS)))


def record(
    spec: Scenario, time: float | None = None, every: int | None = None, progress: bool = False
) -> Trajectory:
    """Run a scenario for ``time`` s (its own ``run.time`` by default) and return its trajectory,
    a frame every ``every`` steps (some 200 frames by default), recorded through a temporary
    GSD file: what `collidium render` draws, and the notebooks' figures."""
    with tempfile.TemporaryDirectory() as folder:
        recording = Path(folder) / "run.gsd"
        sim, job = prepare(spec, time, out=recording, every=every)
        if every is None:
            job.every = max(1, job.end_step // 200)
        execute(sim, job, progress=progress)
        return read_trajectory(recording)


def execute(sim: Simulation, job: Job, progress: bool = False) -> dict[str, Any]:
    """Run ``sim`` to ``job.end_step`` with its outputs; returns the summary (`summarise`).

    Observers already attached (a scenario file's) run along and are reported in the summary.
    """
    remaining = job.end_step - sim.steps
    if remaining < 0:
        raise InputError("steps", f"the run is already past step {job.end_step}")
    if job.initial_total is None:
        job.initial_total = conserved_energy(sim)
    reported = [o for o in sim.observers if isinstance(o, Measurement)]
    period = max(1, remaining // SAMPLES)
    drift = EnergyDrift(reference=job.initial_total)
    thermo, rate = Thermo(period), CollisionRate(period)
    sim.observers += [drift, thermo, rate]
    if remaining > 0:  # a finished run resumed again leaves its files alone
        if job.trajectory is not None:
            append = sim.steps > 0 and job.trajectory.exists()
            sim.observers.append(GSDWriter(job.trajectory, Every(job.every), append=append))
        if job.checkpoint is not None and job.checkpoint_every is not None:
            sim.observers.append(CheckpointWriter(job.checkpoint, job.checkpoint_every, job, drift))
    start = clock.perf_counter()
    with _staging_named_as_out(job):
        try:
            sim.run(steps=remaining, progress=progress)
        except KeyboardInterrupt:
            _close_trajectories(sim)  # first: the line names the frames the files hold
            raise Interrupted(_where_stopped(sim, job)) from None
        finally:
            _close_trajectories(sim)
    wall = clock.perf_counter() - start
    if job.checkpoint is not None and remaining > 0:
        save(sim, job, drift)
    job.max_rel_drift = max(job.max_rel_drift, drift.max_rel_drift)
    trajectory = job.trajectory
    if job.staged and trajectory is not None and trajectory.exists():
        write_xyz(read_trajectory(trajectory), str(job.out))
        trajectory.unlink()
    return summarise(sim, job, thermo, rate, wall, reported)


def _close_trajectories(sim: Simulation) -> None:
    """Close this run's trajectory and any a scenario file asked for."""
    for observer in sim.observers:
        if isinstance(observer, GSDWriter):
            observer.close()


def _where_stopped(sim: Simulation, job: Job) -> str:
    """One line for Ctrl-C: the step and time the run stopped at, and the files kept."""
    kept = []
    for observer in sim.observers:
        if isinstance(observer, GSDWriter) and observer.last_step >= 0:
            name = job.out if job.staged and observer.path == job.trajectory else observer.path
            kept.append(f"{name} (frames to step {observer.last_step})")
        if isinstance(observer, CheckpointWriter) and observer.saved_step is not None:
            kept.append(f"{observer.path} (step {observer.saved_step}; `collidium resume "
                        f"{observer.path}` finishes the run)")  # fmt: skip
    return (f"interrupted at step {sim.steps} of {job.end_step} (t = {sim.time:g} s); kept: "
            + (", ".join(kept) if kept else "nothing"))  # fmt: skip


@contextmanager
def _staging_named_as_out(job: Job) -> Iterator[None]:
    """Name ``--out`` in a failed write of the GSD file that stages .xyz output (a full disk),
    and remove that file unless a checkpoint may resume it."""
    try:
        yield
    except InputError as exc:
        trajectory = job.trajectory
        if not job.staged or trajectory is None or exc.field != str(trajectory):
            raise
        if job.checkpoint is None:
            trajectory.unlink(missing_ok=True)
        raise InputError(str(job.out), exc.reason) from None


def summarise(
    sim: Simulation,
    job: Job,
    thermo: Thermo,
    rate: CollisionRate,
    wall_seconds: float,
    reported: Sequence[Measurement] = (),
) -> dict[str, Any]:
    """Plain numbers describing a finished run (the ``--json`` object).

    The state quantities are the final ones and the energy drift is the whole run's; temperature,
    pressures and collision rate are averaged over this run (since the resume, for a resumed
    run); the KS p-value tests the final speeds against Maxwell-Boltzmann at the final
    temperature. ``reported`` measurements (a scenario file's) add their summaries under
    ``observers``.
    """
    summary: dict[str, Any] = sim.summary()
    summary["dt"] = float(sim.dt)
    summary["wall_seconds"] = wall_seconds
    summary["energy"]["initial_total"] = job.initial_total
    summary["energy"]["max_rel_drift"] = job.max_rel_drift
    summary["energy"]["warning"] = drift_warning(job)
    summary |= thermo.summary()
    summary["collisions"]["rate"] = rate.rate
    summary["collisions"]["mean_free_time"] = rate.mean_free_time
    if sim.particles.n >= STATISTICS_FROM:
        speeds = SpeedHistogram().compute(sim).summary()
        summary["ks_statistic"] = speeds["ks_statistic"]
        summary["ks_pvalue"] = speeds["ks_pvalue"]
    else:  # a few bodies have no speed distribution to test
        summary["ks_statistic"] = summary["ks_pvalue"] = None
    if reported:
        summary["observers"] = [
            {"observer": type(o).__name__} | o.summary() for o in reported if o.sampled
        ]
    return finite(summary)


def drift_exceeded(job: Job) -> bool:
    """Whether the run's energy drifted past its limit (``max_drift``, else `DRIFT_WARNING`).
    A drift that cannot be measured (a zero initial energy) never counts."""
    return math.isfinite(job.max_rel_drift) and job.max_rel_drift > job.drift_limit


def drift_warning(job: Job) -> str | None:
    """One line saying that the energy drifted past the run's limit, or None."""
    return drift_warning_line(job.max_rel_drift, job.drift_limit)


def finite(value: Any) -> Any:
    """``value`` with every NaN or infinity replaced by None, recursively (JSON has neither)."""
    if isinstance(value, dict):
        return {key: finite(item) for key, item in value.items()}
    if isinstance(value, list | tuple):
        return [finite(item) for item in value]
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value
