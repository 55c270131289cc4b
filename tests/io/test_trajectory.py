"""GSD trajectories: the HOOMD schema other tools read, flushing, damage, XYZ export."""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import time

import gsd.hoomd
import numpy as np
import pytest

import collidium as cd
from collidium.errors import InputError
from collidium.io import describe_file
from collidium.io import trajectory as trajectory_module
from collidium.io.trajectory import (
    TYPES,
    GSDWriter,
    keep_frames_through,
    read_trajectory,
    unwritten_bytes,
    write_xyz,
)


def record(tmp_path, preset="charged-gas", every=10, steps=50, **overrides):
    sim = cd.load(preset, **overrides)
    path = tmp_path / "run.gsd"
    with GSDWriter(path, every) as writer:
        sim.observers.append(writer)
        sim.run(steps=steps)
    return sim, path


def test_frames_follow_the_hoomd_schema(tmp_path):
    sim, path = record(tmp_path)
    with gsd.hoomd.open(path) as trajectory:
        assert len(trajectory) == 6  # the start, then every 10 of 50 steps
        frame = trajectory[-1]
    assert frame.configuration.step == 50
    assert frame.configuration.dimensions == 2
    np.testing.assert_array_equal(frame.configuration.box, [20, 20, 0, 0, 0, 0])
    p = sim.particles
    assert p.n == frame.particles.N
    np.testing.assert_array_equal(frame.particles.position[:, :2], p.position.astype(np.float32))
    np.testing.assert_array_equal(frame.particles.position[:, 2], 0.0)
    np.testing.assert_array_equal(frame.particles.velocity[:, :2], p.velocity.astype(np.float32))
    np.testing.assert_array_equal(frame.particles.diameter, 0.5)
    np.testing.assert_array_equal(frame.particles.mass, 1.0)
    np.testing.assert_array_equal(frame.particles.charge, p.charge.astype(np.float32))
    assert frame.particles.types == list(TYPES)
    named = np.array(TYPES)[frame.particles.typeid]
    assert set(named[p.charge > 0]) == {"positive"} and set(named[p.charge < 0]) == {"negative"}
    log = gsd.hoomd.read_log(path)
    np.testing.assert_array_equal(log["configuration/step"], [0, 10, 20, 30, 40, 50])
    assert log["log/energy/total"][-1] == pytest.approx(sim.energy().total, rel=1e-15)
    assert log["log/collisions/pair"][-1] == sim.counters.pair_collisions
    np.testing.assert_array_equal(log["log/impulse/walls"][-1], sim.tally.impulse[1:])
    np.testing.assert_allclose(log["log/collidium/time"], np.arange(6) * 0.1, rtol=1e-15)


def test_freud_reads_the_file(tmp_path):
    """freud builds its 2D box from the GSD box and finds each disk's contacts in the frame."""
    freud = pytest.importorskip("freud")
    _, path = record(tmp_path, "pool-break", every=100, steps=100)
    with gsd.hoomd.open(path) as trajectory:
        frame = trajectory[0]  # the rack: 224 balls in hexagonal packing, tiny gaps
    box = freud.box.Box.from_box(frame.configuration.box, dimensions=frame.configuration.dimensions)
    assert box.is2D and (box.Lx, box.Ly) == (40.0, 20.0)
    query = freud.locality.AABBQuery(box, frame.particles.position)
    pairs = query.query(frame.particles.position, {"r_max": 0.51, "exclude_ii": True})
    neighbours = np.bincount(
        pairs.toNeighborList().query_point_indices, minlength=frame.particles.N
    )
    # Interior balls of a hexagonal rack touch six others; the cue ball touches none.
    assert neighbours.max() == 6
    assert neighbours[np.argmin(frame.particles.position[:, 0])] == 0


def test_periodic_images_and_flag(tmp_path):
    sim, path = record(tmp_path, "gas", every=100, steps=400, **{"vessel.boundary": "periodic"})
    trajectory = read_trajectory(path)
    assert trajectory.periodic
    with gsd.hoomd.open(path) as frames:
        np.testing.assert_array_equal(frames[-1].particles.image[:, :2], sim.particles.image)


def test_read_back_into_arrays(tmp_path):
    sim, path = record(tmp_path)
    trajectory = read_trajectory(path)
    assert (trajectory.frames, trajectory.n) == (6, 200)
    assert trajectory.position.shape == (6, 200, 2) and trajectory.position.dtype == np.float64
    np.testing.assert_allclose(trajectory.position[-1], sim.particles.position, atol=1e-5)
    np.testing.assert_array_equal(trajectory.radius, sim.particles.radius)
    assert not trajectory.periodic
    assert describe_file(path)["frames"] == 6


def test_appending_continues_and_trimming_cuts_back(tmp_path):
    sim, path = record(tmp_path, steps=30)
    sim.run(steps=5)  # not recorded
    with GSDWriter(path, 10, append=True) as writer:
        sim.observers.append(writer)
        sim.run(steps=25)
    np.testing.assert_array_equal(read_trajectory(path).step, [0, 10, 20, 30, 40, 50, 60])
    assert keep_frames_through(path, 40) == 5
    np.testing.assert_array_equal(read_trajectory(path).step, [0, 10, 20, 30, 40])


def test_xyz_export(tmp_path):
    _, path = record(tmp_path)
    trajectory = read_trajectory(path)
    target = tmp_path / "run.xyz"
    write_xyz(trajectory, target)
    lines = target.read_text().splitlines()
    assert len(lines) == 6 * (2 + 200)
    assert lines[0] == "200"
    header = lines[1]
    assert 'Lattice="20 0 0 0 20 0 0 0 1"' in header and 'pbc="F F F"' in header
    properties = "species:S:1:Z:I:1:pos:R:3:velo:R:3:mass:R:1:radius:R:1:charge:R:1"
    assert f"Properties={properties}" in header
    last = np.array([line.split()[2:] for line in lines[-200:]], dtype=float)
    # Nine significant digits give back the stored single-precision values exactly.
    f32 = np.float32
    np.testing.assert_array_equal(last[:, :2].astype(f32), trajectory.position[-1].astype(f32))
    np.testing.assert_array_equal(last[:, 3:5].astype(f32), trajectory.velocity[-1].astype(f32))
    np.testing.assert_array_equal(last[:, 8], trajectory.charge)


def test_ase_reads_the_xyz_export(tmp_path):
    """ASE reads every frame: positions, charges, the walled box as not periodic, the time, and
    the velocities by their column's name (it takes the types as chemical symbols unless a Z
    column is there)."""
    import ase.io as ase_io  # a test dependency, like freud and MDAnalysis

    _, path = record(tmp_path)
    trajectory = read_trajectory(path)
    write_xyz(trajectory, tmp_path / "run.xyz")
    frames = ase_io.read(tmp_path / "run.xyz", index=":")
    assert len(frames) == trajectory.frames
    last = frames[-1]
    assert not last.pbc.any()
    assert last.info["Time"] == pytest.approx(trajectory.time[-1])
    np.testing.assert_allclose(last.positions[:, :2], trajectory.position[-1], rtol=1e-7)
    np.testing.assert_allclose(last.arrays["velo"][:, :2], trajectory.velocity[-1], rtol=1e-7)
    np.testing.assert_array_equal(last.get_charges(), trajectory.charge)  # as computed charges


@pytest.mark.parametrize("boundary", ["reflecting", "periodic"])
def test_mdanalysis_gets_time_step_and_velocities(tmp_path, boundary):
    """`universe` gives MDAnalysis the real time between frames, the velocities and, for a
    periodic box only, the box."""
    _, path = record(tmp_path, "gas", every=10, steps=50, **{"vessel.boundary": boundary})
    trajectory = read_trajectory(path)
    universe = trajectory_module.universe(path)
    assert universe.trajectory.n_frames == trajectory.frames == 6
    assert universe.trajectory.dt == pytest.approx(10 * 0.01)
    universe.trajectory[-1]
    assert universe.trajectory.ts.time == pytest.approx(trajectory.time[-1])
    np.testing.assert_allclose(universe.atoms.velocities[:, :2], trajectory.velocity[-1],
                               rtol=1e-6)  # fmt: skip
    np.testing.assert_allclose(universe.atoms.positions[:, :2], trajectory.position[-1],
                               rtol=1e-6)  # fmt: skip
    np.testing.assert_array_equal(universe.atoms.masses, trajectory.mass)
    if boundary == "periodic":
        np.testing.assert_allclose(universe.dimensions[:2], [trajectory.width, trajectory.height])
    else:
        assert universe.dimensions is None


def test_killed_writer_leaves_every_flushed_frame(tmp_path):
    """SIGKILL a long run once frames are on disk: the file still opens, with every frame that
    was flushed before the kill, each complete."""
    path = tmp_path / "killed.gsd"
    command = [sys.executable, "-m", "collidium", "run", "gas", "--set", "n=800",
               "--time", "100000", "--out", str(path), "--every", "5"]  # fmt: skip
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    seen = 0
    try:
        deadline = time.monotonic() + 120
        while seen < 3 and time.monotonic() < deadline and process.poll() is None:
            time.sleep(0.2)
            with contextlib.suppress(InputError):  # not created yet, or caught mid-write
                seen = read_trajectory(path).frames
    finally:
        process.send_signal(signal.SIGKILL)
        process.wait()
    assert process.returncode == -signal.SIGKILL, process.stderr.read() if process.stderr else ""
    assert seen >= 3
    trajectory = read_trajectory(path)
    assert trajectory.frames >= seen
    np.testing.assert_array_equal(trajectory.step, 5 * np.arange(trajectory.frames))
    assert np.isfinite(trajectory.position).all()
    assert (np.abs(trajectory.position) <= 10.0).all()
    energy = trajectory.log["energy/total"][:, 0]
    np.testing.assert_allclose(energy, energy[0], rtol=1e-12)


@pytest.mark.parametrize(
    "damage",
    [
        lambda data: data[: len(data) // 2],  # truncated
        lambda data: data[:100] + b"\x00" * 200 + data[300:],  # header and index overwritten
        lambda data: b"not a gsd file at all",
        lambda data: b"",
    ],
)
@pytest.mark.parametrize("reader", ["mapped", "pure Python"])
def test_damaged_file_gives_one_clear_error(tmp_path, monkeypatch, damage, reader):
    _, path = record(tmp_path)
    if reader == "pure Python":  # the reader for files on a full disk
        monkeypatch.setattr(trajectory_module, "_mapping_may_fault", lambda _: True)
    path.write_bytes(damage(path.read_bytes()))
    with pytest.raises(InputError) as caught:
        read_trajectory(path)
    assert caught.value.field == str(path)
    assert "\n" not in str(caught.value)


def test_missing_file():
    with pytest.raises(InputError, match="no such file"):
        read_trajectory("does-not-exist.gsd")


def test_the_vessel_is_logged_and_read_back_and_files_without_it_get_their_box(tmp_path):
    sim, path = record(tmp_path, "gas", every=100, steps=100, width=30.0, height=20.0)
    trajectory = read_trajectory(path)
    assert trajectory.vessel.to_dict() == sim.container.to_dict()
    assert describe_file(path)["vessel"] == {"shape": "box", "width": 30.0, "height": 20.0,
                                             "boundary": "reflecting"}  # fmt: skip
    # A file from another program has only the GSD box (periodic, as HOOMD's boxes are).
    plain = tmp_path / "plain.gsd"
    with gsd.hoomd.open(path) as frames, gsd.hoomd.open(plain, "w") as out:
        frame = frames[0]
        frame.log = {}
        out.append(frame)
    assert read_trajectory(plain).vessel.to_dict() == cd.Box(30.0, 20.0, "periodic").to_dict()


def test_the_piston_is_logged_and_drawn_where_it_was(tmp_path):
    sim, path = record(tmp_path, "piston", every=50, steps=200)
    trajectory = read_trajectory(path)
    assert trajectory.vessel.to_dict() == sim.container.to_dict()
    position = trajectory.log["piston/position"][:, 0]
    assert position.shape == (5,) and np.ptp(position) > 0  # the first frame, then 4; it moved
    piston = sim.piston()
    assert piston is not None
    assert (position[-1], trajectory.log["piston/work"][-1, 0]) == (piston.position, piston.work)
    line = trajectory.vessel.piston_line(float(position[-1]))
    np.testing.assert_array_equal(line, [[-10.0, position[-1]], [10.0, position[-1]]])


def full_disk(monkeypatch):
    """Make every disk report no free space."""
    disk = os.statvfs(os.curdir)
    full = os.statvfs_result((*disk[:4], 0, *disk[5:]))  # f_bavail = 0
    monkeypatch.setattr(trajectory_module.os, "statvfs", lambda _: full)


def test_holes_are_counted_as_unwritten_bytes(tmp_path):
    path = tmp_path / "sparse"
    with path.open("wb") as stream:
        stream.write(b"x" * 4096)
        stream.truncate(1 << 22)  # 4 MiB, all but the first block never written
    holes = unwritten_bytes(path)
    assert (1 << 22) - (1 << 20) <= holes <= (1 << 22) - 4096
    path.write_bytes(b"x" * 8192)
    assert unwritten_bytes(path) == 0


def with_a_hole(path) -> None:
    """Make sure ``path`` ends in a hole, as gsd 4 and later leave when they grow a file's index
    by extending the file (gsd 3 writes its index out)."""
    if unwritten_bytes(path) == 0:
        with path.open("r+b") as stream:
            stream.truncate(path.stat().st_size + (1 << 20))
    assert unwritten_bytes(path) > 0


def test_a_full_disk_reads_without_the_memory_map(tmp_path, monkeypatch):
    """gsd maps a file's index, which it grows by extending the file (a hole); on a full tmpfs,
    reading a mapped hole kills the process (SIGBUS). With no room for the holes, the file is
    read through gsd's pure-Python reader instead, to the same arrays."""
    _, path = record(tmp_path, preset="gas", every=1, steps=150, n=20)
    with_a_hole(path)
    mapped = read_trajectory(path)

    def refuse_to_map(*_args, **_kwargs):
        raise AssertionError("gsd's memory-mapped reader was used on a full disk")

    full_disk(monkeypatch)
    monkeypatch.setattr(gsd.hoomd, "open", refuse_to_map)
    read = read_trajectory(path)
    for name in ("step", "time", "position", "velocity", "mass", "radius", "charge"):
        np.testing.assert_array_equal(getattr(read, name), getattr(mapped, name))
    assert read.log.keys() == mapped.log.keys()
    np.testing.assert_array_equal(read.log["energy/total"], mapped.log["energy/total"])


def test_appending_on_a_full_disk_is_refused_and_leaves_the_file(tmp_path, monkeypatch):
    sim, path = record(tmp_path, preset="gas", every=1, steps=150, n=20)
    with_a_hole(path)
    before = path.read_bytes()
    full_disk(monkeypatch)
    with pytest.raises(InputError, match="cannot append: 0 bytes free") as caught:
        GSDWriter(path, 10, append=True).attach(sim)
    assert caught.value.field == str(path)
    assert path.read_bytes() == before


def test_a_write_that_fails_names_the_file(tmp_path, monkeypatch):
    """A full disk (ENOSPC) while frames are flushed: one `InputError` naming the file."""
    sim = cd.load("gas")
    path = tmp_path / "run.gsd"
    writer = GSDWriter(path, 1)
    writer.attach(sim)

    def no_space():
        raise OSError(28, "No space left on device", str(path))

    monkeypatch.setattr(writer._file, "flush", no_space)
    with pytest.raises(InputError, match="cannot write: No space left on device") as caught:
        writer.flush()
    assert caught.value.field == str(path)
