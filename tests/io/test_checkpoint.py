"""Checkpoints: a restored simulation continues bit for bit; damaged files give one clear error."""

from __future__ import annotations

import numpy as np
import pytest

import collidium as cd
from collidium.errors import InputError
from collidium.io.checkpoint import describe_checkpoint, read_checkpoint, write_checkpoint


def state(sim):
    p = sim.particles
    return (p.position, p.velocity, p.image, sim.tally.counts, sim.tally.impulse)


def assert_same_run(a, b):
    for x, y in zip(state(a), state(b), strict=True):
        np.testing.assert_array_equal(x, y)
    assert (a.time, a.steps) == (b.time, b.steps)
    assert a.counters == b.counters


@pytest.mark.parametrize(
    ("preset", "collisions"),
    [
        ("gas", "exact"),
        pytest.param("gas", "step", marks=pytest.mark.slow),
        pytest.param("charged-gas", "exact", marks=pytest.mark.slow),
        pytest.param("charged-gas", "step", marks=pytest.mark.slow),
        ("pool-break", "exact"),
        ("pool-break", "step"),
    ],
)
def test_resumed_run_is_bitwise_the_uninterrupted_one(tmp_path, preset, collisions):
    """Exact and step collisions, with and without Coulomb forces, and the exact engine's
    persistent event queue (force-free presets) saved mid-run."""
    whole = cd.load(preset, collisions=collisions).run(steps=300)
    first = cd.load(preset, collisions=collisions).run(steps=170)
    first.save(tmp_path / "run.ckpt")
    resumed = cd.restore(tmp_path / "run.ckpt").run(steps=130)
    assert_same_run(whole, resumed)
    assert resumed.name == preset and resumed.collisions == collisions


def test_values_all_particles_share_are_saved_once_and_restored_shared(tmp_path):
    sim = cd.load("charged-gas", n=40, seed=2)  # one mass and radius, charges +q and -q
    sim.save(tmp_path / "run.ckpt")
    arrays, _ = read_checkpoint(tmp_path / "run.ckpt")
    assert arrays["mass"].shape == arrays["radius"].shape == () and arrays["charge"].shape == (40,)
    restored = cd.restore(tmp_path / "run.ckpt").particles
    assert restored.mass.strides == restored.radius.strides == (0,)
    np.testing.assert_array_equal(restored.charge, sim.particles.charge)
    assert describe_checkpoint(tmp_path / "run.ckpt")["n"] == 40


def test_resumed_run_of_disks_of_two_masses_is_bitwise_the_uninterrupted_one(tmp_path):
    """The exact engine's full rows (each disk's own radius and mass) saved mid-run."""

    def mixed() -> cd.Simulation:
        sim = cd.load("gas")
        sim.particles.mass = np.where(np.arange(sim.particles.n) % 2 == 0, 3.0, 1.0)
        return sim

    whole = mixed().run(steps=300)
    first = mixed().run(steps=170)
    first.save(tmp_path / "run.ckpt")
    resumed = cd.restore(tmp_path / "run.ckpt").run(steps=130)
    assert_same_run(whole, resumed)
    assert resumed._drift.rebuilds == whole._drift.rebuilds == 1  # the saved queue went on


def test_restore_keeps_dt_changes_the_random_generator_and_periodic_images(tmp_path):
    whole = cd.load("gas", **{"vessel.boundary": "periodic"})
    whole.run(steps=50)
    whole.dt = 0.003  # the time origin moves: time stays exact across the change
    whole.run(steps=50)
    whole.save(tmp_path / "a.ckpt")
    expected_draw = whole.rng.random(3)
    resumed = cd.restore(tmp_path / "a.ckpt")
    assert resumed.dt == 0.003 and resumed.time == whole.time
    np.testing.assert_array_equal(resumed.rng.random(3), expected_draw)
    assert np.abs(resumed.particles.image).max() > 0
    whole.run(steps=200)
    assert_same_run(whole, resumed.run(steps=200))


def test_save_writes_nothing_partial_and_replaces_atomically(tmp_path, monkeypatch):
    sim = cd.load("head-on")
    target = tmp_path / "x.ckpt"
    sim.save(target)
    before = target.read_bytes()

    def fail(*args, **kwargs):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(np.lib.format, "write_array", fail)
    with pytest.raises(InputError, match="cannot write: No space left on device") as caught:
        sim.run(steps=3).save(target)
    assert caught.value.field == str(target)
    assert target.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["x.ckpt"]


def test_describe(tmp_path):
    sim = cd.load("orbit").run(steps=25)
    sim.save(tmp_path / "o.ckpt")
    facts = describe_checkpoint(tmp_path / "o.ckpt")
    assert facts["scenario"] == "orbit" and facts["n"] == 2 and facts["step"] == 25
    assert facts["time"] == sim.time
    assert facts["forces"][0]["type"] == "coulomb"


@pytest.mark.parametrize(
    ("damage", "reason"),
    [
        (lambda data: data[: len(data) // 2], "not a readable"),
        (lambda data: data[:200] + bytes(b ^ 0xFF for b in data[200:400]) + data[400:], ""),
        (lambda data: b"", "not a readable"),
        (lambda data: b"PK\x03\x04 garbage", "not a readable"),
    ],
)
def test_damaged_checkpoint_gives_one_clear_error(tmp_path, damage, reason):
    path = tmp_path / "run.ckpt"
    cd.load("gas").run(steps=10).save(path)
    path.write_bytes(damage(path.read_bytes()))
    with pytest.raises(InputError) as caught:
        cd.restore(path)
    assert caught.value.field == str(path)
    assert reason in caught.value.reason and "\n" not in str(caught.value)


def test_other_npz_files_and_incomplete_checkpoints_are_refused(tmp_path):
    other = tmp_path / "other.npz"
    np.savez(other, position=np.zeros((2, 2)))
    with pytest.raises(InputError, match="not a readable collidium checkpoint"):
        cd.restore(other)
    incomplete = tmp_path / "incomplete.ckpt"
    write_checkpoint(incomplete, {"position": np.zeros((2, 2))}, {"simulation": {"dt": 0.1}})
    with pytest.raises(InputError, match="incomplete or damaged"):
        cd.restore(incomplete)
    bad_value = tmp_path / "bad.ckpt"
    sim = cd.load("head-on")
    sim.save(bad_value)
    arrays, meta = read_checkpoint(bad_value)
    arrays["mass"] = -arrays["mass"]
    write_checkpoint(bad_value, arrays, {k: v for k, v in meta.items() if k != "format"})
    with pytest.raises(InputError, match="invalid mass"):
        cd.restore(bad_value)


def test_the_vessel_is_saved_and_checkpoints_that_name_a_box_still_restore(tmp_path):
    path = tmp_path / "run.ckpt"
    sim = cd.load("gas", n=50, **{"vessel.boundary": "periodic"}).run(steps=5)
    sim.save(path)
    arrays, meta = read_checkpoint(path)
    assert meta["simulation"]["vessel"] == {"shape": "box", **sim.container.parameters()}
    assert describe_checkpoint(path)["vessel"] == sim.container.to_dict()
    # Before vessels had shapes, checkpoints held the box's parameters under "box".
    state = dict(meta["simulation"])
    state["box"] = sim.container.parameters()
    del state["vessel"]
    write_checkpoint(path, arrays, {k: v for k, v in meta.items() if k != "format"}
                     | {"simulation": state})  # fmt: skip
    again = cd.restore(path)
    assert again.container.to_dict() == sim.container.to_dict()
    np.testing.assert_array_equal(again.run(steps=5).particles.position,
                                  sim.run(steps=5).particles.position)  # fmt: skip


def test_arrays_of_objects_are_refused_not_pickled_and_nothing_is_left(tmp_path):
    path = tmp_path / "objects.ckpt"
    with pytest.raises(ValueError, match="allow_pickle=False"):
        write_checkpoint(path, {"bad": np.array([{"a": 1}], dtype=object)}, {})
    assert list(tmp_path.iterdir()) == []
    write_checkpoint(path, {"good": np.arange(3.0)}, {"note": "x"})
    arrays, meta = read_checkpoint(path)
    np.testing.assert_array_equal(arrays["good"], np.arange(3.0))
    assert meta["note"] == "x"


def test_a_run_saved_just_after_a_contact_under_forces_resumes_bitwise(tmp_path):
    """charged-opposite under the seed's collision step, whose contacts the compiled substeps
    leave to Python, saved at the end of its first interval with a collision: the adaptive
    integrator takes the next interval in Python rather than trying it whole, and so does the
    resumed run, which ends bit for bit as the uninterrupted one."""
    first = cd.load("charged-opposite", collisions="step")
    while not first._integrator.next_in_python:
        first.run(steps=1)
    first.save(tmp_path / "run.ckpt")
    whole = cd.load("charged-opposite", collisions="step").run(steps=first.steps + 100)
    resumed = cd.restore(tmp_path / "run.ckpt")
    assert resumed._integrator.next_in_python
    assert_same_run(whole, resumed.run(steps=100))
