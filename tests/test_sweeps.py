"""Sweeps on Dask: one row per run, failures isolated, resumable, the same on any number of
workers."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time

import pandas
import pytest
from distributed import Client, LocalCluster

import collidium as cd
from collidium.cli import parse_grid
from collidium.errors import InputError
from collidium.sweeps import RUN_COLUMNS, plan, sweep
from collidium.theory import hard_disk_compressibility


@pytest.fixture(scope="module")
def two_workers():
    """A 2-worker LocalCluster (processes, one numba thread each), as a sweep makes its own."""
    with (
        LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0",
                     env={"NUMBA_NUM_THREADS": "1"}) as cluster,
        Client(cluster) as client,
    ):  # fmt: skip
        yield client


def collidium(*args, cwd):
    return subprocess.run([sys.executable, "-m", "collidium", *map(str, args)], cwd=cwd,
                          capture_output=True, text=True, timeout=300, check=False)  # fmt: skip


def test_one_row_per_run_in_plan_order_with_the_runs_summary(two_workers):
    table = cd.sweep("gas", {"n": [20, 40], "speed": [1.0, 2.0]}, seeds=2, time=1.0,
                     client=two_workers)  # fmt: skip
    assert list(table.columns[:8]) == ["run", "key", "seed", "n", "speed", *RUN_COLUMNS[3:]]
    assert list(table["run"]) == list(range(8))
    assert list(table["n"]) == [20] * 4 + [40] * 4
    assert list(table["speed"]) == [1.0, 1.0, 2.0, 2.0] * 2
    assert list(table["seed"]) == [1, 2] * 4
    assert (table["status"] == "ok").all()
    # Each row is the run collidium run would do: the same summary, number for number.
    single = cd.load("gas", n=40, speed=2.0, seed=2)
    single.run(time=1.0)
    row = table.iloc[7]
    assert row["energy.total"] == single.energy().total
    assert row["collisions.pair"] == single.summary()["collisions"]["pair"]
    assert row["steps"] == 100


def test_the_table_is_the_same_on_one_worker_and_on_two(two_workers):
    grid = {"packing": [0.2, 0.5]}
    on_two = sweep("hard-disks", grid, seeds=2, time=2.0, client=two_workers)
    on_one = sweep("hard-disks", grid, seeds=2, time=2.0, workers=1)
    pandas.testing.assert_frame_equal(
        on_one.drop(columns="wall_seconds"), on_two.drop(columns="wall_seconds"), check_exact=True
    )


def test_a_failing_run_is_a_row_with_its_error_and_the_others_go_on(two_workers):
    table = sweep("gas", {"n": [50, 3000, 60]}, time=0.5, client=two_workers)
    assert list(table["status"]) == ["ok", "failed", "ok"]
    assert "too dense" in table["error"][1] and table["error"][1].startswith("particles.0.n")
    assert table["energy.total"].isna().tolist() == [False, True, False]


def test_a_sweep_run_again_skips_the_runs_it_has(tmp_path, two_workers):
    out = tmp_path / "results.parquet"
    first = sweep("gas", {"n": [20]}, seeds=2, time=0.5, out=out, client=two_workers)
    assert not (tmp_path / "results.parquet.runs").exists()  # folded into the table
    again = sweep("gas", {"n": [20, 30]}, seeds=2, time=0.5, out=out, client=two_workers)
    # The runs of n = 20 were not run again: their wall times are those of the first sweep.
    assert list(again["wall_seconds"][:2]) == list(first["wall_seconds"])
    assert list(again["n"]) == [20, 20, 30, 30] and (again["status"] == "ok").all()
    pandas.testing.assert_frame_equal(pandas.read_parquet(out), again)


#: A sweep's finished runs in its runs' folder: not the hidden temporary of a write the kill cut
#: short (`collidium.io.atomic.replacing`), which may be empty.
RUN_FILES = "[!.]*.json"


def test_a_killed_sweep_keeps_its_finished_runs_and_resumes(tmp_path):
    """kill -9 of the whole sweep (its workers too) once runs have finished: they are in the
    runs' folder, and the sweep started again runs only the others."""
    # Runs of some 0.2 s each: the sweep is caught with runs both done and to do.
    command = [sys.executable, "-m", "collidium", "sweep", "gas", "--grid", "n=20,30,40,50,60,70",
               "--time", "100", "--out", "r.parquet", "--workers", "1"]  # fmt: skip
    process = subprocess.Popen(command, cwd=tmp_path, start_new_session=True,
                               stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)  # fmt: skip
    folder = tmp_path / "r.parquet.runs"
    try:
        deadline = time.monotonic() + 120
        while len(list(folder.glob(RUN_FILES))) < 2 and time.monotonic() < deadline:
            time.sleep(0.01)
    finally:
        os.killpg(process.pid, signal.SIGKILL)
        process.wait()
    kept = {json.loads(p.read_text())["key"]: json.loads(p.read_text()) for p in
            folder.glob(RUN_FILES)}  # fmt: skip
    assert len(kept) >= 2 and not (tmp_path / "r.parquet").exists()
    result = collidium(*command[3:], cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    table = pandas.read_parquet(tmp_path / "r.parquet")
    assert (table["status"] == "ok").all() and list(table["n"]) == [20, 30, 40, 50, 60, 70]
    for key, row in kept.items():  # not run again
        assert table.loc[table["key"] == key, "wall_seconds"].item() == row["wall_seconds"]


def test_the_equation_of_state_example_makes_its_figure(tmp_path):
    """The hard-disk equation of state as one command (two points, two seeds, short runs here):
    the table's Z is Henderson's within the spread of the seeds, and the figure is written."""
    result = collidium("sweep", "hard-disks", "--grid", "packing=0.1:0.4:2", "--seeds", "2",
                       "--time", "20", "--out", "eos.parquet", "--plot", "eos.png",
                       "--workers", "2", cwd=tmp_path)  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert result.stderr == ""  # not a word from the workers as the cluster shuts down
    assert result.stdout.startswith("4 runs: 4 ok, 0 failed")
    table = pandas.read_parquet(tmp_path / "eos.parquet")
    for packing, z, error in table[["packing", "compressibility", "compressibility_error"]].values:
        assert abs(z - hard_disk_compressibility(packing)) < 4 * error
    assert (tmp_path / "eos.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize(
    ("grid", "line"),
    [
        (["bogus=1,2"], "error: bogus: not a parameter of preset 'gas'"),
        (["n="], "error: grid.n: needs at least one value"),
        (["n=many"], "error: n: input should be a valid integer, got 'many'"),
        (["n=1:2"], "error: n: input should be a valid integer, got '1:2'"),  # not a range
        (["n=1:10:0"], "error: n: a range is start:stop:count with count >= 1"),
        (["seed=1,2"], "error: grid.seed: give the seeds with seeds="),
        (["n=20", "n=30"], "error: --grid: n is given twice"),
        ([], "error: --grid: give at least one KEY=V1,V2,..."),
    ],
)
def test_bad_grids_give_one_line_and_exit_2(tmp_path, grid, line):
    result = collidium("sweep", "gas", *(a for g in grid for a in ("--grid", g)), cwd=tmp_path)
    assert result.returncode == 2
    assert result.stderr.startswith(line) and result.stderr.count("\n") == 1, result.stderr
    assert list(tmp_path.iterdir()) == []


def test_grid_ranges_and_lists():
    assert parse_grid(["packing=0.05:0.65:13"])["packing"][:3] == [0.05, 0.1, 0.15]
    assert parse_grid(["n=100:400:4", "k=[1, 2],[3, 4]"]) == {
        "n": [100, 200, 300, 400], "k": [[1, 2], [3, 4]]}  # fmt: skip


def test_plan_refuses_bad_seeds_and_names_the_field():
    for seeds in (0, [], [1, 1], [1.5], True):
        with pytest.raises(InputError) as caught:
            plan("gas", {"n": [20]}, seeds)
        assert caught.value.field == "seeds"
    assert len({run.key for run in plan("gas", {"n": [20, 30]}, 3)}) == 6
    # The keys differ between runs; the same run gets the same key in another sweep.
    assert plan("gas", {"n": [20]}, 1)[0].key == plan("gas", {"n": [20, 30]}, 1)[0].key


def test_each_run_writes_its_trajectory_and_a_scheduler_address_is_used(tmp_path, two_workers):
    from collidium.io.trajectory import read_trajectory

    address = two_workers.scheduler.address
    table = sweep("gas", {"n": [20, 30]}, time=1.0, trajectories=tmp_path / "runs",
                  scheduler=address)  # fmt: skip
    assert (table["status"] == "ok").all()
    for run, n in table[["run", "n"]].values:
        trajectory = read_trajectory(tmp_path / "runs" / f"run-{run:05d}.gsd")
        assert trajectory.n == n and trajectory.frames == 11  # every 0.1 s, both ends
