"""Collision modes: the exact engine's persistent queue, and agreement between modes."""

from __future__ import annotations

import numpy as np

import collidium as cd
from collidium.collisions import ExactCollisions


def _engine(sim: cd.Simulation) -> ExactCollisions:
    drift = sim._drift
    assert isinstance(drift, ExactCollisions)
    return drift


def test_force_free_queue_survives_across_steps():
    sim = cd.load("gas", n=300, seed=2)
    sim.run(steps=100)
    assert _engine(sim).rebuilds == 1


def test_force_kick_rebuilds_the_queue_every_step():
    sim = cd.load("charged-gas", n=50, seed=2)
    sim.run(steps=20)
    assert _engine(sim).rebuilds == 20


def test_user_edit_between_runs_is_seen():
    sim = cd.load("head-on")
    sim.run(time=0.05)
    sim.particles.velocity[:] = 0.0  # stop both: no collision may happen any more
    sim.run(time=1.0)
    assert sim.counters.pair_collisions == 0
    assert _engine(sim).rebuilds == 2


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
