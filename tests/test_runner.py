"""Runs as the command line does them: outputs, checkpoints, resuming from anywhere."""

from __future__ import annotations

import json
import os
import zipfile

import numpy as np
import pytest

import collidium as cd
from collidium.errors import InputError
from collidium.io.trajectory import GSDWriter, read_trajectory
from collidium.loading import load_scenario
from collidium.runner import Job, execute, prepare, record, resume
from test_cli import collidium

TRAJECTORY = '\n[[observers]]\nkind = "trajectory"\npath = "mine.gsd"\nevery = 10\n'


def run_job(tmp_path, stop, end=60, **job):
    """Run the gas to step ``stop`` with a job ending at ``end`` (an interrupted run when
    ``stop < end``), from inside ``tmp_path``."""
    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:
        spec = load_scenario("gas", n=50)
        sim = spec.build()
        execute(sim, Job(end_step=stop, **job))
        return sim
    finally:
        os.chdir(cwd)


def test_resume_from_another_folder_continues_the_files_beside_the_checkpoint(tmp_path):
    (tmp_path / "run").mkdir()
    (tmp_path / "elsewhere").mkdir()
    whole = run_job(tmp_path / "run", 60, out="whole.gsd", every=10, checkpoint="whole.ckpt")
    part = run_job(tmp_path / "run", 30, out="part.gsd", every=10, checkpoint="part.ckpt")
    assert part.steps == 30
    # The job saved says the run ends at 60: resume it from another working folder.
    checkpoint = tmp_path / "run" / "part.ckpt"
    sim, job = resume(checkpoint)
    job.end_step = 60
    cwd = os.getcwd()
    os.chdir(tmp_path / "elsewhere")
    try:
        execute(sim, job)
    finally:
        os.chdir(cwd)
    assert list((tmp_path / "elsewhere").iterdir()) == []
    np.testing.assert_array_equal(sim.particles.position, whole.particles.position)
    a, b = (
        read_trajectory(tmp_path / "run" / "whole.gsd"),
        read_trajectory(tmp_path / "run/part.gsd"),
    )
    np.testing.assert_array_equal(a.step, b.step)
    np.testing.assert_array_equal(a.position, b.position)
    assert cd.restore(checkpoint).steps == 60


def test_scenario_trajectories_are_cut_back_and_continued(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # the scenario's path is relative to the working folder
    text = load_scenario("gas", n=50).to_toml() + TRAJECTORY
    (tmp_path / "gas.toml").write_text(text)
    whole = collidium("run", "gas.toml", "--steps", "100", "--checkpoint", "w.ckpt", cwd=tmp_path)
    assert whole.returncode == 0, whole.stderr
    (tmp_path / "mine.gsd").rename(tmp_path / "whole.gsd")
    # An interrupted run: checkpoint at step 40, frames written up to step 60.
    sim = cd.load(tmp_path / "gas.toml")
    job = Job(
        end_step=100,
        checkpoint=str(tmp_path / "p.ckpt"),
        observers=[{"kind": "trajectory", "path": str(tmp_path / "mine.gsd"), "every": 10}],
    )
    sim.run(steps=40)
    from collidium.runner import save

    save(sim, job, cd.observers.EnergyDrift().compute(sim))
    sim.run(steps=20)
    sim.observers[0].close()
    assert read_trajectory(tmp_path / "mine.gsd").step[-1] == 60
    resumed = collidium("resume", "p.ckpt", "--json", cwd=tmp_path)
    assert resumed.returncode == 0, resumed.stderr
    a, b = read_trajectory(tmp_path / "whole.gsd"), read_trajectory(tmp_path / "mine.gsd")
    np.testing.assert_array_equal(b.step, 10 * np.arange(11))
    np.testing.assert_array_equal(a.position, b.position)


def test_resuming_a_finished_xyz_run_leaves_its_file_alone(tmp_path):
    args = ["run", "gas", "--steps", "100", "--every", "10", "--out", "t.xyz", "--checkpoint",
            "t.ckpt"]  # fmt: skip
    assert collidium(*args, cwd=tmp_path).returncode == 0
    before = (tmp_path / "t.xyz").read_bytes()
    assert before.count(b"Lattice=") == 11
    again = collidium("resume", "t.ckpt", "--json", cwd=tmp_path)
    assert again.returncode == 0, again.stderr
    assert json.loads(again.stdout) == {"checkpoint": "t.ckpt", "finished": True, "steps": 100,
                                        "time": 1.0}  # fmt: skip
    assert (tmp_path / "t.xyz").read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.ckpt", "t.xyz"]
    said = collidium("resume", "t.ckpt", cwd=tmp_path)  # one line: nothing left to do
    assert said.stdout == "t.ckpt: the run finished at step 100 (t = 1 s); nothing left to do\n"


@pytest.mark.parametrize(
    ("extra", "field"),
    [
        (["--out", "r.gsd", "--checkpoint", "r.gsd"], "--checkpoint"),
        (["--out", "r.xyz", "--checkpoint", ".r.xyz.gsd"], "--checkpoint"),
        (["--checkpoint", "folder"], "--checkpoint"),
        (["--out", "folder"], "--out"),
        (["--out", "folder/"], "--out"),
        (["--checkpoint", ""], "--checkpoint"),
    ],
)
def test_bad_targets_are_refused_before_the_run(tmp_path, extra, field):
    (tmp_path / "folder").mkdir()
    result = collidium("run", "gas", "--steps", "5", *extra, cwd=tmp_path)
    assert result.returncode == 2, result.stderr
    assert result.stderr.startswith(f"error: {field}: ") and result.stderr.count("\n") == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["folder"]


def test_resume_needs_a_checkpoint_with_a_run(tmp_path):
    cd.load("gas").save(tmp_path / "plain.ckpt")
    result = collidium("resume", "plain.ckpt", cwd=tmp_path)
    assert result.returncode == 2
    assert "holds no run to resume" in result.stderr
    with zipfile.ZipFile(tmp_path / "fake.ckpt", "w") as archive:
        archive.writestr("__meta__.npy", b"xx")
    for command in ("inspect", "resume"):
        result = collidium(command, "fake.ckpt", cwd=tmp_path)
        assert result.returncode == 2 and result.stderr.startswith("error: fake.ckpt: ")
        assert "Traceback" not in result.stderr


def test_energy_drift_is_the_whole_runs_after_a_resume(tmp_path):
    """The orbit's energy wobbles: a run stopped at step 1400 and resumed to 2000 reports the
    same largest drift, measured from the same starting energy, as the run never stopped."""
    whole = execute(cd.load("orbit", integrator="fixed"), Job(end_step=2000))
    checkpoint = str(tmp_path / "o.ckpt")
    execute(cd.load("orbit", integrator="fixed"), Job(end_step=1400, checkpoint=checkpoint))
    sim, job = resume(checkpoint)
    job.end_step = 2000
    resumed = execute(sim, job)
    assert resumed["energy"]["initial_total"] == whole["energy"]["initial_total"]
    assert resumed["energy"]["max_rel_drift"] == whole["energy"]["max_rel_drift"] > 1e-6
    assert resumed["energy"]["total"] == whole["energy"]["total"]


def test_writer_reopens_after_close(tmp_path):
    sim = cd.load("gas", n=20)
    writer = GSDWriter(tmp_path / "re.gsd", 10)
    sim.observers.append(writer)
    sim.run(steps=50)
    writer.close()
    sim.run(steps=50)
    writer.close()
    np.testing.assert_array_equal(read_trajectory(tmp_path / "re.gsd").step, 10 * np.arange(11))


def test_frames_reach_the_disk_within_flush_seconds_without_a_next_frame(tmp_path):
    import time

    sim = cd.load("gas", n=20)
    writer = GSDWriter(tmp_path / "slow.gsd", 1000, flush_seconds=0.05)
    sim.observers.append(writer)
    sim.run(steps=1)  # the starting frame, buffered
    time.sleep(0.1)
    sim.run(steps=1)  # no new frame; the check after the step flushes the waiting one
    assert read_trajectory(tmp_path / "slow.gsd").frames == 1
    writer.close()


def test_bad_tracer_index_in_a_scenario_is_refused_before_anything_is_written(tmp_path):
    text = load_scenario("gas", n=50).to_toml() + TRAJECTORY
    text += '\n[[observers]]\nkind = "tracer"\nparticles = [3, 50]\n'
    (tmp_path / "gas.toml").write_text(text)
    result = collidium("run", "gas.toml", "--steps", "5", cwd=tmp_path)
    assert result.returncode == 2
    assert result.stderr.startswith("error: observers.1.particles.1: no particle 50")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["gas.toml"]


def test_job_paths_are_stored_relative_to_the_checkpoint(tmp_path):
    job = Job(end_step=5, out=str(tmp_path / "a.gsd"), checkpoint=str(tmp_path / "c.ckpt"))
    meta = job.to_meta(tmp_path)
    assert meta["out"] == "a.gsd" and meta["checkpoint"] == "c.ckpt"
    assert Job.from_meta(meta, tmp_path) == job
    with pytest.raises(InputError, match="checkpoint"):
        Job(end_step=5, out="x.gsd", checkpoint="x.gsd")


def test_record_returns_the_runs_trajectory_with_some_200_frames():
    trajectory = record(load_scenario("gas", n=30), time=4.0)
    assert trajectory.frames == 201 and trajectory.n == 30  # every 2 steps, both ends
    np.testing.assert_allclose(trajectory.time[[0, -1]], [0.0, 4.0])
    sim = cd.load("gas", n=30).run(time=4.0)
    np.testing.assert_allclose(trajectory.position[-1], sim.particles.position, atol=1e-5)
    assert record(load_scenario("gas", n=30), time=1.0, every=25).frames == 5


@pytest.mark.parametrize(("dt", "every"), [(0.01, 10), (0.3, 1), (5e-324, 10**12)])
def test_frames_come_every_tenth_of_a_second_by_default(dt, every):
    """Ten frames a simulated second, at least one step apart; a subnormal dt (the fuzz test's)
    asks for more steps than a run may have, not an overflow."""
    spec = load_scenario("gas", n=10, dt=dt)
    _, job = prepare(spec, steps=1)
    assert job.every == every


def test_ctrl_c_just_after_a_frame_names_the_frames_the_file_holds(tmp_path, monkeypatch):
    """A Ctrl-C between a frame's write and the writer's note of it: the line names the last
    frame in the file, not the one before."""
    import gsd.hoomd

    from collidium.errors import Interrupted
    from collidium.runner import execute, prepare

    opened = gsd.hoomd.open

    class InterruptedAfterFifth:
        def __init__(self, file):
            self.file, self.appended = file, 0

        def append(self, frame):
            self.file.append(frame)
            self.appended += 1
            if self.appended == 5:
                raise KeyboardInterrupt

        def __getattr__(self, name):
            return getattr(self.file, name)

    def open_gsd(path, mode="r"):
        file = opened(path, mode)
        return InterruptedAfterFifth(file) if mode == "w" else file

    monkeypatch.setattr(gsd.hoomd, "open", open_gsd)
    sim, job = prepare(load_scenario("head-on"), steps=50, out=tmp_path / "r.gsd", every=2)
    with pytest.raises(Interrupted) as caught:
        execute(sim, job)
    last = int(read_trajectory(tmp_path / "r.gsd").step[-1])
    assert last == 8  # frames at steps 0, 2, 4, 6 and 8
    assert f"(frames to step {last})" in str(caught.value)
