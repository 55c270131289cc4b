"""Sweeps: one scenario over a grid of parameters and seeds, each run a Dask task, one table.

`sweep` plans every combination of the grid's values, each with every seed, runs each as its own
task on Dask distributed (a ``LocalCluster`` of single-threaded workers, one per core, unless a
client or a scheduler's address is given) and gathers one row per run: the run's number and key,
the grid's values, the seed, its status and error, its wall time and its summary (the object
``collidium run --json`` prints, flattened: ``energy.max_rel_drift``, ``pressure.virial``,
``compressibility``, ``compressibility_error``...).

Each finished run is written at once, atomically, as one small JSON file in a folder beside the
output (``results.parquet.runs/``), so a sweep killed part-way loses no finished run; the table
is written when the sweep ends, and the folder then removed. A sweep started again with the
same output skips every run it finds there, in the table or the folder, under the same key: a
hash of the scenario the run builds and its number of steps. A run that failed is a row with
its error (status ``"failed"``); it is run again when the sweep is.

Every run depends only on its scenario and seed, and the workers run one numba thread each, so
the table is the same, bit for bit, whatever the number of workers, but for the wall times.
"""

from __future__ import annotations

import hashlib
import itertools
import json
import logging
import math
import os
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from collidium.errors import InputError, SimulationError
from collidium.io.atomic import replacing
from collidium.loading import load_scenario
from collidium.runner import execute, prepare, steps_of
from collidium.scenario import Scenario
from collidium.theory import hard_disk_compressibility

if TYPE_CHECKING:
    import pandas
    from matplotlib.axes import Axes

#: Output formats by file suffix.
TABLE_SUFFIXES = (".parquet", ".csv")

#: The columns every row has, before the grid's values and the summary.
RUN_COLUMNS = ("run", "key", "seed", "status", "error", "wall_seconds")

#: Curves a sweep's plot draws beside its points, by (grid key, quantity): a label and the
#: function of the grid value.
THEORY: dict[tuple[str, str], tuple[str, Callable[[float], float]]] = {
    ("packing", "compressibility"): ("Henderson", hard_disk_compressibility),
}


#: Axis labels of the plot, by column.
LABELS = {
    "packing": "packing fraction eta",
    "compressibility": "Z = P A / (N kT)",
    "temperature": "kT (J)",
    "pressure.virial": "virial pressure (N/m)",
    "pressure.wall": "wall pressure (N/m)",
}


@dataclass(frozen=True)
class Run:
    """One run of a sweep: its place, the grid's values and seed, and what it builds.

    Attributes
    ----------
    index : int
        Its place in the sweep (grid order, then seeds).
    parameters : dict
        The grid's values for this run, by key.
    seed : int
        The random seed.
    scenario : dict
        The scenario it runs, as plain data (`Scenario.to_dict`).
    steps : int
        Its number of steps.
    key : str
        A hash of ``scenario`` and ``steps``: the same key, the same run.
    """

    index: int
    parameters: dict[str, Any]
    seed: int
    scenario: dict[str, Any]
    steps: int
    key: str


def plan(
    scenario: str | Path,
    grid: Mapping[str, Sequence[Any]],
    seeds: int | Sequence[int] = 1,
    time: float | None = None,
) -> list[Run]:
    """The runs of a sweep, every grid point with every seed, each scenario checked.

    Raises
    ------
    InputError
        Naming the grid's key for an empty list, an unknown key or a value of the wrong type,
        and ``seeds`` for bad seeds.
    """
    seed_list = _seeds(seeds)
    values = _grid(grid)
    runs: list[Run] = []
    for point in itertools.product(*values.values()):
        parameters = dict(zip(values, point, strict=True))
        for seed in seed_list:
            spec = load_scenario(scenario, **parameters, seed=seed)
            steps = steps_of(spec, time)
            data = spec.to_dict()
            text = json.dumps([data, steps], sort_keys=True, default=str)
            key = hashlib.sha256(text.encode()).hexdigest()[:16]
            runs.append(Run(len(runs), parameters, seed, data, steps, key))
    return runs


def _seeds(seeds: int | Sequence[int]) -> list[int]:
    """``N`` -> seeds 1..N; a list of seeds as given (each a whole number >= 0, no repeats)."""
    if isinstance(seeds, bool):
        raise InputError("seeds", f"must be a count or a list of seeds, got {seeds!r}")
    if isinstance(seeds, int):
        if seeds < 1:
            raise InputError("seeds", f"must be at least 1, got {seeds}")
        return list(range(1, seeds + 1))
    listed = list(seeds)
    if not listed or any(isinstance(s, bool) or not isinstance(s, int) or s < 0 for s in listed):
        raise InputError("seeds", f"must be whole numbers >= 0, at least one, got {seeds!r}")
    if len(set(listed)) < len(listed):
        raise InputError("seeds", f"repeats a seed: {listed}")
    return listed


def _grid(grid: Mapping[str, Sequence[Any]]) -> dict[str, list[Any]]:
    """The grid as lists of values, each key checked for the obvious mistakes."""
    if not isinstance(grid, Mapping):
        raise InputError("grid", f"must map keys to lists of values, got {type(grid).__name__}")
    values: dict[str, list[Any]] = {}
    for key, listed in grid.items():
        if key == "seed":
            raise InputError("grid.seed", "give the seeds with seeds=, not in the grid")
        if isinstance(listed, (str, bytes)) or not isinstance(listed, Sequence):
            raise InputError(f"grid.{key}", f"must be a list of values, got {listed!r}")
        if not listed:
            raise InputError(f"grid.{key}", "needs at least one value")
        values[key] = list(listed)
    return values


def run_one(run: Run, trajectories: str | None = None) -> dict[str, Any]:
    """Do one run (on a worker) and return its row: a failure is a row with its error."""
    import time as clock

    start = clock.perf_counter()
    row: dict[str, Any] = {"run": run.index, "key": run.key, **run.parameters, "seed": run.seed}
    out = None if trajectories is None else str(Path(trajectories) / f"run-{run.index:05d}.gsd")
    try:
        sim, job = prepare(Scenario.from_dict(run.scenario), steps=run.steps, out=out)
        summary = execute(sim, job)
    except (InputError, SimulationError) as exc:
        return row | {"status": "failed", "error": str(exc),
                      "wall_seconds": clock.perf_counter() - start}  # fmt: skip
    except Exception as exc:  # a bug: the row says so, the sweep goes on
        return row | {"status": "failed", "error": f"{type(exc).__name__}: {exc}",
                      "wall_seconds": clock.perf_counter() - start}  # fmt: skip
    summary.pop("scenario", None)
    wall = summary.pop("wall_seconds")
    # The grid's values win over a summary quantity of the same name (n, dt).
    return row | {"status": "ok", "error": "", "wall_seconds": wall} | flatten(summary) | row


def flatten(summary: Mapping[str, Any], prefix: str = "") -> dict[str, Any]:
    """``{"energy": {"total": 1.0}, "momentum": [1, 2]}`` -> ``{"energy.total": 1.0,
    "momentum.0": 1, "momentum.1": 2}``; a list of tables (observers) is left out."""
    flat: dict[str, Any] = {}
    for name, value in summary.items():
        column = f"{prefix}{name}"
        if isinstance(value, Mapping):
            flat |= flatten(value, f"{column}.")
        elif isinstance(value, (list, tuple)):
            if all(not isinstance(v, (Mapping, list, tuple)) for v in value):
                flat |= {f"{column}.{k}": v for k, v in enumerate(value)}
        else:
            flat[column] = math.nan if value is None else value
    return flat


def sweep(
    scenario: str | Path,
    grid: Mapping[str, Sequence[Any]],
    *,
    seeds: int | Sequence[int] = 1,
    time: float | None = None,
    measure: Sequence[str] | None = None,
    out: str | Path | None = None,
    trajectories: str | Path | None = None,
    client: Any = None,
    scheduler: str | None = None,
    workers: int | None = None,
    progress: bool = False,
) -> pandas.DataFrame:
    """Run ``scenario`` at every point of ``grid`` with every seed, on Dask; one row per run.

    Parameters
    ----------
    scenario : str or Path
        A preset's name or a scenario file.
    grid : mapping of str to list
        Keys as ``collidium run --set`` takes them (a preset's parameters, ``run.dt``,
        ``vessel.width``...), each with its values.
    seeds : int or list of int
        ``N`` runs every point with seeds 1..N; or the seeds themselves.
    time : float, optional
        Simulated seconds of each run (the scenario's ``run.time`` by default).
    measure : list of str, optional
        The summary's quantities to keep (``"temperature"``, ``"pressure"`` keeps every
        ``pressure.*`` column); all by default.
    out : str or Path, optional
        Where to write the table (.parquet or .csv); finished runs stream to a folder beside it,
        and a sweep started again skips the runs found there.
    trajectories : str or Path, optional
        A folder for each run's GSD trajectory, ``run-00000.gsd``...
    client : distributed.Client, optional
        Run on this client's cluster.
    scheduler : str, optional
        Or on the cluster of the scheduler at this address.
    workers : int, optional
        Or on a LocalCluster of this many single-threaded workers (the number of cores).
    progress : bool
        Show a progress bar: runs done, running and failed.

    Returns
    -------
    pandas.DataFrame
        One row per run in plan order: `RUN_COLUMNS`, the grid's keys, then the summary.

    Raises
    ------
    InputError
        For a bad grid, seeds, output or measure, naming the field.
    """
    _require_extra()
    runs = plan(scenario, grid, seeds, time)
    table_path = None if out is None else _table_path(out)
    folder = None if trajectories is None else _folder(trajectories)
    store = _Store(table_path)
    rows = store.finished()
    pending = [run for run in runs if run.key not in rows]
    if pending:
        with _cluster(client, scheduler, workers) as dask:
            for row in _run_all(dask, pending, folder, progress):
                store.keep(row)
                rows[row["key"]] = row
    table = _table(runs, rows, list(grid), measure)
    store.finish(table)
    return table


def _require_extra() -> None:
    """Refuse in one line when the ``sweep`` extra (Dask, pandas, pyarrow) is missing."""
    import importlib.util

    missing = [
        m for m in ("distributed", "pandas", "pyarrow") if importlib.util.find_spec(m) is None
    ]
    if missing:
        raise InputError("sweep", f"needs {', '.join(missing)}: pip install 'collidium[sweep]'")


def _table_path(out: str | Path) -> Path:
    path = Path(out)
    if path.suffix not in TABLE_SUFFIXES:
        raise InputError("--out", f"must end in {' or '.join(TABLE_SUFFIXES)}, got {path}")
    if not path.parent.is_dir():
        raise InputError("--out", f"cannot write {path}: no folder {path.parent}")
    return path


def _folder(path: str | Path) -> str:
    folder = Path(path)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError("--trajectories", f"cannot create {folder} ({exc.strerror})") from None
    return str(folder.resolve())


@contextmanager
def _cluster(client: Any, scheduler: str | None, workers: int | None) -> Iterator[Any]:
    """A Dask client: the one given, one for ``scheduler``, or one on a new LocalCluster."""
    if client is not None:
        yield client
        return
    from distributed import Client, LocalCluster

    if scheduler is not None:
        try:
            remote = Client(scheduler, timeout="10s")
        except (OSError, TimeoutError) as exc:
            raise InputError("--scheduler", f"cannot reach {scheduler} ({exc})") from None
        with remote:
            yield remote
        return
    count = (os.cpu_count() or 1) if workers is None else workers
    if count < 1:
        raise InputError("--workers", f"must be at least 1, got {count}")
    # One numba thread a worker: the cores are shared between workers, not within a run. The
    # dashboard takes a free port (8787 may be another cluster's).
    # Workers log to stderr; a run's failure comes back as its row, and what they would say
    # as the cluster shuts down (a heartbeat to a closed scheduler) is noise.
    cluster = LocalCluster(
        n_workers=count, threads_per_worker=1, processes=True, dashboard_address=":0",
        env={"NUMBA_NUM_THREADS": "1"}, silence_logs=logging.CRITICAL,
    )  # fmt: skip
    with cluster, Client(cluster) as local:
        yield local


def _run_all(dask: Any, runs: list[Run], folder: str | None, progress: bool) -> Iterator[dict]:
    """Submit every run; yield each row as its run finishes (a lost worker fails its run)."""
    from distributed import as_completed

    futures = {dask.submit(run_one, run, folder, key=f"collidium-run-{run.key}", pure=False): run
               for run in runs}  # fmt: skip
    done = failed = 0
    with _progress_bar(progress, len(runs)) as advance:
        for future in as_completed(futures):
            run = futures[future]
            try:
                row = future.result()
            except Exception as exc:  # the worker died (killed, out of memory)
                row = {"run": run.index, "key": run.key, **run.parameters, "seed": run.seed,
                       "status": "failed", "error": f"worker lost: {exc}",
                       "wall_seconds": math.nan}  # fmt: skip
            done += 1
            failed += row["status"] != "ok"
            advance(done, len(runs) - done, failed)
            yield row


@contextmanager
def _progress_bar(show: bool, total: int) -> Iterator[Callable[[int, int, int], None]]:
    """``advance(done, running, failed)``: a rich progress bar, or nothing."""
    if not show:
        yield lambda done, running, failed: None
        return
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn

    columns = (TextColumn("runs"), BarColumn(), MofNCompleteColumn(),
               TextColumn("{task.description}"))  # fmt: skip
    with Progress(*columns, transient=True) as bar:
        task = bar.add_task(f"{total} running or queued, 0 failed", total=total)

        def advance(done: int, running: int, failed: int) -> None:
            bar.update(task, completed=done,
                       description=f"{running} running or queued, {failed} failed")  # fmt: skip

        yield advance


def _table(
    runs: list[Run], rows: dict[str, dict], keys: list[str], measure: Sequence[str] | None
) -> pandas.DataFrame:
    """The rows of ``runs`` in plan order (a row found under a run's key is that run's, renumbered
    to its place in this sweep), columns in a fixed order."""
    import pandas

    ordered = [rows[run.key] | {"run": run.index} for run in runs]
    table = pandas.DataFrame.from_records(ordered)
    summary = [c for c in table.columns if c not in RUN_COLUMNS and c not in keys]
    if measure is not None:
        summary = [c for c in summary if any(c == m or c.startswith(f"{m}.") for m in measure)]
        missing = [m for m in measure if not any(c == m or c.startswith(f"{m}.") for c in summary)]
        if missing and (table["status"] == "ok").any():
            raise InputError("measure", f"no quantity {missing[0]!r} in the runs' summaries")
    return table[[*RUN_COLUMNS[:3], *keys, *RUN_COLUMNS[3:], *summary]]


class _Store:
    """Where a sweep's rows go: one JSON file per finished run in ``<out>.runs/``, then the table
    at ``out``. Without ``out``, nothing is written."""

    def __init__(self, table: Path | None) -> None:
        self.table = table
        self.folder = None if table is None else table.with_name(f"{table.name}.runs")

    def finished(self) -> dict[str, dict]:
        """Rows of runs already done, by key: the table's, then the folder's (failed runs are
        left out, to be run again)."""
        rows: dict[str, dict] = {}
        if self.table is not None and self.table.is_file():
            for row in _read_table(self.table).to_dict("records"):
                rows[str(row["key"])] = row
        if self.folder is not None and self.folder.is_dir():
            # Not the hidden temporaries of a write cut short (`replacing`): half a row.
            for path in sorted(self.folder.glob("[!.]*.json")):
                try:
                    row = json.loads(path.read_text(encoding="utf-8"))
                except (OSError, ValueError):  # cut short by a kill: run again
                    continue
                rows[str(row["key"])] = row
        return {key: row for key, row in rows.items() if row.get("status") == "ok"}

    def keep(self, row: dict[str, Any]) -> None:
        """Write a finished run's row at once (atomically)."""
        if self.folder is None:
            return
        self.folder.mkdir(exist_ok=True)
        with replacing(self.folder / f"{row['key']}.json") as temporary:
            temporary.write_text(json.dumps(row, default=_plain), encoding="utf-8")

    def finish(self, table: pandas.DataFrame) -> None:
        """Write the table, then drop the rows' folder."""
        if self.table is None or self.folder is None:
            return
        with replacing(self.table) as temporary:
            if self.table.suffix == ".csv":
                table.to_csv(temporary, index=False)
            else:
                table.to_parquet(temporary, index=False)
        if self.folder.is_dir():
            for path in self.folder.glob("*.json"):
                path.unlink()
            self.folder.rmdir()


def _read_table(path: Path) -> pandas.DataFrame:
    import pandas

    try:
        return pandas.read_csv(path) if path.suffix == ".csv" else pandas.read_parquet(path)
    except Exception as exc:  # pyarrow and pandas raise many kinds on a damaged file
        raise InputError(str(path), f"not a sweep's table ({exc})") from None


def _plain(value: Any) -> Any:
    """JSON for NumPy scalars."""
    return value.item() if hasattr(value, "item") else str(value)


def plot(table: pandas.DataFrame, x: str, y: str, ax: Axes | None = None) -> Axes:
    """``y`` against the grid key ``x``: the mean over seeds of each point, with the standard error
    of that mean as error bars (the run's own error when a point has one seed), and the theory
    beside it where `THEORY` has one.

    Parameters
    ----------
    table : pandas.DataFrame
        A sweep's table.
    x : str
        A grid key (a column of numbers).
    y : str
        A summary quantity, e.g. ``"compressibility"`` or ``"pressure.virial"``.
    """
    import numpy as np

    from collidium.observers.base import new_axes

    for name in (x, y):
        if name not in table.columns:
            raise InputError("--plot", f"the table has no column {name!r}")
    done = table[table["status"] == "ok"]
    groups = done.groupby(x)[y]
    mean, count = groups.mean(), groups.count()
    error = groups.std(ddof=1) / np.sqrt(count)
    if f"{y}_error" in done.columns:  # one seed: the run's own error
        own = done.groupby(x)[f"{y}_error"].mean()
        error = error.where(count > 1, own)
    ax = new_axes(ax)
    ax.errorbar(mean.index, mean.to_numpy(), yerr=error.to_numpy(), fmt="o", capsize=3,
                label=f"collidium ({int(count.max())} seeds a point)")  # fmt: skip
    if (x, y) in THEORY:
        label, function = THEORY[(x, y)]
        grid = np.linspace(float(mean.index.min()), float(mean.index.max()), 200)
        ax.plot(grid, [function(float(v)) for v in grid], "-", label=label)
    ax.set_xlabel(LABELS.get(x, x))
    ax.set_ylabel(LABELS.get(y, y))
    ax.legend()
    return ax
