"""Collision modes: the exact engine's persistent queue, and agreement between modes."""

from __future__ import annotations

import numba
import numpy as np
import pytest

import collidium as cd
from collidium.collisions import ExactCollisions, Tally, _free_flight, make_drift
from collidium.kernels import cells, event_queue, events


def _engine(sim: cd.Simulation) -> ExactCollisions:
    drift = sim._drift
    assert isinstance(drift, ExactCollisions)
    return drift


def test_force_free_queue_survives_across_steps():
    sim = cd.load("gas", n=300, seed=2)
    sim.run(steps=100)
    assert _engine(sim).rebuilds == 1


def contacts(sim: cd.Simulation) -> int:
    """Pair collisions and wall hits so far."""
    return sim.counters.pair_collisions + sum(sim.counters.wall_hits.values())


def test_force_kick_refreshes_the_queue_every_step():
    """Each step's kicks change every charged disk's velocity: the queue is kept, its disks all
    predicted again (`events.refresh`)."""
    sim = cd.load("charged-gas", n=50, seed=2, integrator="fixed")
    sim.run(steps=20)
    engine = _engine(sim)
    assert (engine.rebuilds, engine.refreshes, engine.repredicted) == (1, 19, 19 * 50)
    # The adaptive substeps that meet no contact fly compiled, without the queue, and move the
    # disks; a substep that may meet contacts takes them in one drift, which builds it again.
    sim.integrator = "adaptive"
    before = contacts(sim)
    sim.run(steps=20)
    rebuilds = _engine(sim).rebuilds - 1
    assert contacts(sim) > before
    assert 0 < rebuilds < 20 * sim._integrator.substeps


@pytest.mark.parametrize("share", [0.02, 1.0])
def test_a_queue_refreshed_after_kicks_meets_the_contacts_of_one_built_again(share):
    """After a kick of a few velocities (each kicked disk put in its place in the heap) or of all
    (the heap ordered again as a whole), the engine predicts the kicked disks again and keeps the
    other events (`events.refresh`). The run meets the contacts of one whose queue is built
    afresh after each kick, and ends where it does to within the round-off that every velocity
    changed in its last bit grows to over the same run (each disk kept from its own time, not the
    kick's, rounds differently)."""
    runs = []
    for fresh, nudged in ((False, False), (True, False), (True, True)):
        sim = cd.load("gas", n=400, seed=5, dt=0.05).run(steps=1)
        if nudged:
            velocity = sim.particles.velocity
            velocity[...] = np.nextafter(velocity, np.where(velocity > 0, np.inf, -np.inf))
        kicks, kicked = np.random.default_rng(6), 0
        for _ in range(10):
            chosen = kicks.random(sim.particles.n) < share
            sim.particles.velocity[chosen] *= 1.0 + kicks.uniform(-0.05, 0.05, (chosen.sum(), 1))
            kicked += chosen.sum()
            if fresh:
                sim._drift.forget()
            sim.run(steps=1)
        runs.append(sim)
    kept, built, nudged_run = runs
    engine = _engine(kept)
    assert (engine.rebuilds, engine.refreshes, engine.repredicted) == (1, 10, kicked)
    assert _engine(built).rebuilds == 11
    assert kept.counters == built.counters
    assert kept.counters.pair_collisions > 500
    growth = np.abs(nudged_run.particles.position - built.particles.position).max()
    assert 0.0 < np.abs(kept.particles.position - built.particles.position).max() < 100 * growth


def test_user_edit_between_runs_is_seen():
    sim = cd.load("head-on")
    sim.run(time=0.05)
    sim.particles.velocity[:] = 0.0  # stop both: no collision may happen any more
    sim.run(time=1.0)
    assert sim.counters.pair_collisions == 0
    assert (_engine(sim).rebuilds, _engine(sim).refreshes) == (1, 1)


def test_report_interval_does_not_change_an_exact_force_free_run():
    """Without forces dt is only how often positions are reported: the event sequence, and so
    the state at a common time, is the same bit for bit."""
    fine = cd.load("gas", n=300, seed=9, dt=0.01).run(time=2.0)
    coarse = cd.load("gas", n=300, seed=9, dt=0.5).run(time=2.0)
    assert fine.counters == coarse.counters
    np.testing.assert_array_equal(fine.particles.velocity, coarse.particles.velocity)
    np.testing.assert_allclose(fine.particles.position, coarse.particles.position, atol=1e-12)


def test_step_mode_matches_exact_mode_for_slow_dilute_gas_over_a_short_time():
    """With v dt much smaller than the disk size, the seed's method detects the same collisions
    as the exact engine, a little late (within one step)."""
    exact = cd.load("gas", n=40, seed=3, speed=1.0, dt=1e-3).run(time=2.0)
    step = cd.load("gas", n=40, seed=3, speed=1.0, dt=1e-3, collisions="step").run(time=2.0)
    assert exact.counters.pair_collisions == step.counters.pair_collisions
    assert exact.counters.wall_collisions == step.counters.wall_collisions
    # Each collision is resolved at most one step late: positions differ by O(v dt) per collision.
    assert np.abs(exact.particles.position - step.particles.position).max() < 0.05


def test_exact_wall_hit_mirrors_the_normal_component():
    box = cd.Box(20, 20)
    sim = cd.Simulation(box, cd.Particles([[9.0, 0.0]], [[4.0, 3.0]], radius=0.5), dt=0.25)
    sim.run(steps=1)
    # Contact at x = 9.5 after 0.125 s, then 0.125 s back to x = 9.0; y moves on undisturbed.
    np.testing.assert_array_equal(sim.particles.velocity, [[-4.0, 3.0]])
    np.testing.assert_allclose(sim.particles.position, [[9.0, 0.75]], rtol=0, atol=1e-15)
    assert sim.counters.wall_hits == {"left": 0, "right": 1, "bottom": 0, "top": 0}


def test_engine_follows_a_radius_change_between_runs():
    sim = cd.load("head-on")
    sim.run(time=0.1)  # centres 1 m apart, closing at 10 m/s: contact at t = 0.15 s
    sim.particles.radius = 0.4  # contact now 0.2 m sooner
    sim.run(time=0.03)
    assert sim.counters.pair_collisions == 1


def test_engine_rows_drop_radius_and_mass_only_while_all_disks_share_them():
    sim = cd.load("gas", n=200, seed=4).run(steps=5)
    assert _engine(sim)._state["body"].shape[1] == events.SHARED_BODY_COLUMNS
    mass = sim.particles.mass.copy()
    mass[0] = 2.0  # one heavier disk: every row carries its radius and mass again
    sim.particles.mass = mass
    sim.run(steps=5)
    assert _engine(sim).rebuilds == 2
    assert _engine(sim)._state["body"].shape[1] == events.BODY_COLUMNS


@pytest.mark.parametrize(
    ("preset", "most"),
    [("gas", cells.SMALL_SCENE_CELLS_PER_PARTICLE), ("atmosphere", cells.EVENT_CELLS_PER_PARTICLE),
     ("effusion", cells.EVENT_CELLS_PER_PARTICLE)],
)  # fmt: skip
def test_engine_grid_takes_small_cells_in_a_small_scene_without_gravity_or_segments(preset, most):
    """The engine lays out its grid by `cells.event_grid_shape`, told of the gravity it carries
    (atmosphere) and of the vessel's segments (effusion's partition): more than 3 cells a disk
    in the dilute gas, at most 3 in those two."""
    sim = cd.load(preset).run(steps=2)
    grid = _engine(sim)._state["grid"]
    per_disk = grid[0] * grid[1] / sim.particles.n
    assert cells.EVENT_CELLS_PER_PARTICLE * (most > 3) < per_disk <= most


def test_engine_takes_68_bytes_per_disk_of_one_radius_and_mass_its_queue_and_4_per_cell():
    """The layout that lets a million disks run in 300 MB (`kernels/events.py`): body rows of
    40 bytes, 24 bytes of integers, cell lists 4 per disk and per cell, and the event queue
    (`kernels/event_queue.py`), under 9 bytes a disk; four arrays get up to 64 bytes more to
    start on a cache line."""
    sim = cd.load("gas", n=1000, radius=0.1, seed=3).run(steps=2)
    s = _engine(sim)._state
    assert s is not None
    owners = {id(a): a for a in (x if x.base is None else x.base for x in s.values())}
    allocated = sum(a.nbytes for a in owners.values())
    queue = s["keys"].nbytes + s["items"].nbytes
    expected = 68 * sim.particles.n + queue + 4 * s["head"].size
    assert expected + s["geometry"].nbytes + s["grid"].nbytes <= allocated
    assert allocated <= expected + s["geometry"].nbytes + s["grid"].nbytes + 4 * 64
    times, slots = event_queue.sizes(10**6)
    assert 8 * times + 4 * slots < 9 * 10**6


def test_queue_saved_in_an_earlier_layout_is_rebuilt_not_misread():
    sim = cd.load("gas", n=100, seed=1).run(steps=3)
    saved = _engine(sim).state()
    saved["queue/geometry"] = saved["queue/geometry"][:4]  # before the shared radius and mass
    engine = ExactCollisions()
    engine.load_state(saved)
    assert engine._state is None


def test_event_engine_stops_when_time_no_longer_advances():
    """At t = 1e17 s a float cannot resolve the next wall hit (about 1 s away): events would
    repeat at one instant for ever. The engine notices and raises instead of hanging."""
    box = cd.Box(2, 2)
    particles = cd.Particles([[0.0, 0.0]], [[3.0, 0.0]], radius=0.5)
    with pytest.raises(cd.SimulationError, match="time stopped advancing"):
        make_drift("exact").drift(particles, box, 1e17, 100.0, Tally.for_walls(4))


def _packed_step_gas(n: int, seed: int, boundary: str = "reflecting") -> cd.Simulation:
    """Disks of radius 0.25 m at packing fraction 0.3, seed's step mode, dt = 0.02 s."""
    from collidium.initial import random_positions

    side = float(np.sqrt(n * np.pi * 0.25**2 / 0.3))
    rng = np.random.default_rng(seed)
    radius = np.full(n, 0.25)
    radius[::50] = 0.15  # unequal radii are carried through the cell sort
    position = random_positions(n, radius, cd.Box(side, side), rng)
    particles = cd.Particles(position, rng.normal(0, 2, (n, 2)), radius=radius)
    return cd.Simulation(cd.Box(side, side, boundary), particles, dt=0.02, collisions="step")


@pytest.mark.parametrize("boundary", ["reflecting", "periodic"])
def test_step_mode_does_not_depend_on_threads_or_history(boundary):
    """The step mode sorts cells and searches pairs in parallel, and keeps the cell order from
    one step to the next: neither the thread count nor a fresh start of its grid (as after
    restoring a checkpoint) may change a bit of the result."""
    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("needs two threads")
    before = numba.get_num_threads()
    runs = []
    try:
        for threads, restart in ((1, False), (2, False), (2, True)):
            numba.set_num_threads(threads)
            sim = _packed_step_gas(20000, seed=5, boundary=boundary)
            for _ in range(6):
                sim.run(steps=2)
                if restart:
                    sim._drift = make_drift("step")
            runs.append(sim)
    finally:
        numba.set_num_threads(before)
    assert runs[0].counters.pair_collisions > 1000
    for other in runs[1:]:
        np.testing.assert_array_equal(other.particles.velocity, runs[0].particles.velocity)
        np.testing.assert_array_equal(other.particles.position, runs[0].particles.position)
        np.testing.assert_array_equal(other.tally.counts, runs[0].tally.counts)
        np.testing.assert_array_equal(other.tally.impulse, runs[0].tally.impulse)


@pytest.mark.parametrize(("shared", "regrid"), [(False, True), (True, True), (True, False)])
def test_step_mode_follows_disks_that_grow(shared, regrid):
    """After the radii grow every overlap is still found, also for a radius all disks share:
    2.5 times larger, the cells are made again; back to 0.25 m after running at 0.2 m, the cells
    made for 0.25 m are kept, and only the radii change."""
    from collidium.kernels import reference

    sim = _packed_step_gas(400, seed=6)
    p = sim.particles
    if shared:
        p.radius = 0.25
    sim.run(steps=2)
    if regrid:
        p.radius = p.radius * 2.5
    else:
        p.radius = 0.2
        sim.run(steps=20)
        p.radius = 0.25
    # Disks now across a wall are folded back first.
    _free_flight(p, sim.container, 0.0, Tally.for_walls(4))
    velocity = p.velocity.copy()
    before = sim.tally.counts[0]
    sim._drift.drift(p, sim.container, sim.time, 0.0, sim.tally)  # no flight: pairs only
    done, _ = reference.step_collisions(p.position, velocity, p.mass, p.radius)
    assert sim.tally.counts[0] - before == done > 10
    np.testing.assert_allclose(p.velocity, velocity, rtol=1e-13, atol=1e-13)


def test_slots_are_sorted_more_often_in_a_gas_that_outgrows_the_caches():
    """The engine re-sorts its slots every `events.SORT_INTERVAL` events a particle, every
    `events.SORT_INTERVAL_LARGE` from `events.SORT_OFTEN_FROM` particles, unless told."""
    drift = ExactCollisions()
    below, at = events.SORT_OFTEN_FROM - 1, events.SORT_OFTEN_FROM
    assert drift._sort_every(below) == events.SORT_INTERVAL * below
    assert drift._sort_every(at) == events.SORT_INTERVAL_LARGE * at
    assert events.SORT_INTERVAL_LARGE < events.SORT_INTERVAL
    drift.sort_interval = 0  # every event
    assert drift._sort_every(at) == 1
