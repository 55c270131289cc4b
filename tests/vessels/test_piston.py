"""Pistons: a box wall of mass M that moves along its normal, met by disks as exact events.

The engine against the all-pairs twin, energy and momentum balance, mechanical equilibrium under
a weight, the adiabat of a slow compression, resuming bit for bit, no escapes, and bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest

from collidium.errors import InputError
from collidium.forces import Coulomb, Gravity
from collidium.initial import random_positions
from collidium.kernels import reference
from collidium.simulation import Simulation, restore
from collidium.state import Particles
from collidium.theory import hard_disk_compressibility
from collidium.vessels import Box, Circle, Piston


def _gas(box: Box, n: int, radius: float, speed: float, seed: int) -> Particles:
    rng = np.random.default_rng(seed)
    position = random_positions(n, radius, box, rng)
    return Particles(position, rng.uniform(-speed, speed, (n, 2)), mass=1.0, radius=radius)


def _block_mean(values: np.ndarray, blocks: int = 20) -> tuple[float, float]:
    """Mean and its standard error from block averages."""
    means = np.array([part.mean() for part in np.array_split(values, blocks)])
    return float(means.mean()), float(means.std(ddof=1) / math.sqrt(blocks))


@pytest.mark.parametrize(
    ("wall", "piston", "twin"),
    [
        ("top", Piston(position=2.0, mass=3.0, force=15.0),
         {"height": 2.0, "speed": 0.0, "pull": -5.0, "mass": 3.0}),
        ("left", Piston(position=-3.0, mass=2.0, velocity=4.0, restitution=0.8),
         {"height": 3.0, "speed": -4.0, "pull": 0.0, "mass": 2.0, "restitution": 0.8}),
        ("right", Piston(position=4.0, velocity=-3.0, driven=True, stop=1.5),
         {"height": 4.0, "speed": -3.0, "pull": 0.0, "mass": math.inf, "driven": 1.0,
          "low": 1.5}),
    ],
)  # fmt: skip
def test_engine_matches_the_all_pairs_twin(wall, piston, twin):
    """Same collisions and hits, final state, wall impulses and piston, to the round-off growth
    of a chaotic gas over some 50 collisions."""
    box = Box(10.0, 10.0, walls={wall: piston})
    particles = _gas(box, 30, 0.3, 5.0, seed=4)
    position, velocity = particles.position.copy(), particles.velocity.copy()
    sim = Simulation(box, particles, dt=0.25)
    sim.run(steps=4)
    index = box.wall_names.index(wall)
    state = {"restitution": 1.0, "low": -5.0, "high": 5.0, "driven": 0.0} | twin
    pairs, hits, impulse, work = reference.piston_drift(
        position, velocity, particles.mass, particles.radius, np.array([5.0, 5.0]), 1.0, index,
        state,
    )  # fmt: skip
    assert pairs > 20 and sim.counters.wall_hits[wall] > 3, (pairs, sim.counters)
    assert (sim.counters.pair_collisions, sim.counters.wall_collisions) == (pairs, hits)
    np.testing.assert_allclose(sim.tally.impulse[1:], impulse, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(sim.particles.position, position, atol=1e-9)
    np.testing.assert_allclose(sim.particles.velocity, velocity, atol=1e-8)
    sign = 1.0 if index % 2 == 1 else -1.0
    moved = sim.piston()
    assert moved is not None and moved.wall == wall
    assert moved.position == pytest.approx(sign * state["height"], abs=1e-9)
    assert moved.velocity == pytest.approx(sign * state["speed"], abs=1e-8)
    assert moved.work == pytest.approx(work, rel=1e-9, abs=1e-12)


def test_free_piston_conserves_the_energy_of_gas_piston_and_weight():
    """KE of the gas + M U^2 / 2 + F h is constant to round-off (1e-12 relative over some 1e5
    events); the piston's work is the gas's gain of kinetic energy."""
    force, mass = 60.0, 8.0
    box = Box(20.0, 30.0, walls={"top": Piston(position=0.0, mass=mass, force=force)})
    sim = Simulation(box, _gas(box, 300, 0.2, 5.0, seed=1), dt=0.5)

    def total() -> float:
        state = sim.piston()
        assert state is not None
        return sim.energy().kinetic + 0.5 * mass * state.velocity**2 + force * state.position

    start, kinetic = total(), sim.energy().kinetic
    sim.run(time=100.0)
    assert sim._drift.events > 100_000  # type: ignore[attr-defined]
    assert sim.counters.wall_hits["top"] > 1000
    assert abs(total() - start) <= 1e-12 * start
    state = sim.piston()
    assert state is not None
    assert state.work == pytest.approx(sim.energy().kinetic - kinetic, rel=1e-12, abs=1e-9)
    assert sim.escaped() == 0


def test_a_gas_under_gravity_below_a_free_piston_keeps_every_energy_to_round_off():
    """Disks on parabolas meet a piston on its own parabola at roots of one quadratic: the
    energy of gas (kinetic and potential), piston and weight holds to round-off, and the
    piston's work is the gas's gain of energy."""
    force, mass, g = 60.0, 8.0, 2.0
    box = Box(20.0, 30.0, walls={"top": Piston(position=0.0, mass=mass, force=force)})
    sim = Simulation(box, _gas(box, 200, 0.2, 5.0, seed=3), forces=[Gravity(g=(0.0, -g))],
                     dt=0.5)  # fmt: skip

    def gas() -> float:
        return sim.energy().kinetic + sim.energy().potential

    def total() -> float:
        state = sim.piston()
        assert state is not None
        return gas() + 0.5 * mass * state.velocity**2 + force * state.position

    start, gas_start = total(), gas()
    sim.run(time=50.0)
    assert sim.counters.wall_hits["top"] > 200
    assert sim._drift.rebuilds == 1  # type: ignore[attr-defined]
    # Round-off of the terms, not of their sum (the potential's zero is the box's centre).
    state = sim.piston()
    assert state is not None
    scale = sim.energy().kinetic + abs(sim.energy().potential) + abs(force * state.position)
    assert abs(total() - start) <= 1e-12 * scale
    assert state.work == pytest.approx(gas() - gas_start, rel=1e-12, abs=1e-9)
    assert sim.escaped() == 0


def test_free_piston_settles_where_the_gas_pressure_equals_its_weight():
    """Mechanical equilibrium: the momentum the gas gives the piston per unit time and length
    of contact is F / L, and the hard-disk equation of state at the piston's height, averaged
    over time, gives the same pressure, each within 3 standard errors (block averages over
    200 s, well beyond the piston's oscillation)."""
    width, height, force, radius, n = 20.0, 40.0, 80.0, 0.05, 200
    box = Box(width, height, walls={"top": Piston(position=0.0, mass=20.0, force=force)})
    sim = Simulation(box, _gas(box, n, radius, 5.0, seed=2), dt=0.1)
    sim.run(time=100.0)  # the piston's oscillation dies down into thermal motion
    length = width - 2 * radius  # the line of contact of the piston
    impulse, heights, temperatures = [sim.tally.impulse[4]], [], []
    for _ in range(2000):
        sim.run(steps=1)
        state = sim.piston()
        assert state is not None
        impulse.append(sim.tally.impulse[4])
        heights.append(state.position)
        temperatures.append(sim.temperature())
    pushed, error = _block_mean(np.diff(impulse) / (sim.dt * length))
    assert abs(pushed - force / length) <= 3 * error
    area = length * (np.array(heights) + 0.5 * height - 2 * radius)
    packing = n * math.pi * radius**2 / area
    z = np.array([hard_disk_compressibility(eta) for eta in packing])
    state_equation, error = _block_mean(z * n * np.array(temperatures) / area)
    assert abs(state_equation - force / length) <= 3 * error


@pytest.mark.slow
def test_slow_compression_follows_the_2d_adiabat():
    """A piston driven at 0.02 m/s, about 1% of the thermal speed, halves a dilute gas's
    chamber in 1000 s: P A^2 stays constant within 2% (gamma = 2 in 2D). The gas is dilute
    (packing below 0.01: Z grows by 0.7% as it halves) and collides every ~3 s, so it stays in
    equilibrium; each window's pressure has a statistical error under 1%."""
    width, radius = 40.0, 0.03
    piston = Piston(position=20.0, velocity=-0.02, driven=True, stop=0.0)
    box = Box(width, 40.0, walls={"top": piston})
    sim = Simulation(box, _gas(box, 2000, radius, 3.0, seed=3), dt=0.5)
    window = 200.0
    constants = []
    for _ in range(5):
        start, before = sim.tally.impulse[4], sim.piston()
        sim.run(time=window)
        after = sim.piston()
        assert before is not None and after is not None
        pressure = (sim.tally.impulse[4] - start) / (window * (width - 2 * radius))
        # The open area A(t) shrinks linearly: if P A^2 = C, the mean of P over the window is
        # C / (A_before A_after).
        ends = [(width - 2 * radius) * (s.position + 20.0 - 2 * radius) for s in (before, after)]
        constants.append(pressure * ends[0] * ends[1])
    assert after.position == 0.0 and after.velocity == 0.0  # it stopped where asked
    assert np.all(np.abs(np.array(constants) / constants[0] - 1.0) <= 0.02), constants


def test_a_piston_run_resumes_bit_for_bit(tmp_path):
    box = Box(12.0, 12.0, walls={"right": Piston(position=2.0, mass=4.0, force=10.0)})
    sim = Simulation(box, _gas(box, 60, 0.25, 4.0, seed=5), dt=0.1)
    sim.run(time=3.0)
    sim.save(tmp_path / "piston.ckpt")
    sim.run(time=3.0)
    again = restore(tmp_path / "piston.ckpt").run(time=3.0)
    np.testing.assert_array_equal(again.particles.position, sim.particles.position)
    np.testing.assert_array_equal(again.tally.piston, sim.tally.piston)
    assert again.piston() == sim.piston()


def test_a_fast_piston_into_a_dense_gas_lets_nothing_out():
    """Driven at 50 m/s into a gas at packing 0.3 until the chamber is 60% as wide: every disk
    stays on the gas's side of its face."""
    box = Box(10.0, 10.0, walls={"right": Piston(position=5.0, velocity=-50.0, driven=True,
                                                  stop=1.0)})  # fmt: skip
    particles = _gas(box, 230, 0.2, 2.0, seed=6)
    sim = Simulation(box, particles, dt=0.01)
    sim.run(time=0.5)
    state = sim.piston()
    assert state is not None and state.position == 1.0
    assert sim.escaped() == 0
    assert (sim.particles.position[:, 0] + 0.2 <= 1.0 + 1e-12).all()
    assert sim.energy().kinetic > 10 * 230 * 4.0 / 3  # the piston heated the gas


@pytest.mark.parametrize(
    ("make", "field"),
    [
        (lambda: Box(10, 10, walls={"top": Piston(position=6.0)}), "vessel.walls.top.position"),
        (lambda: Box(10, 10, walls={"left": Piston(position=5.0)}), "vessel.walls.left.position"),
        (lambda: Piston(position=0.0, mass=0.0), "mass"),
        (lambda: Piston(position=0.0, force=-1.0), "force"),
        (lambda: Piston(position=0.0, restitution=1.5), "restitution"),
        (lambda: Piston(position=0.0, driven=True, force=2.0), "force"),
        (lambda: Piston(position=0.0, stop=1.0), "stop"),
        (lambda: Box(10, 10, walls={"top": Piston(position=0.0, velocity=-1.0, driven=True,
                                                  stop=2.0)}), "vessel.walls.top.stop"),
        (lambda: Circle(5.0, walls={"rim": Piston(position=0.0)}), "vessel.walls.rim"),
        (lambda: Box(10, 10, walls={"top": Piston(position=0.0), "left": Piston(position=0.0)}),
         "vessel.walls.left"),
    ],
)  # fmt: skip
def test_bad_pistons_are_refused_naming_the_field(make, field):
    with pytest.raises(InputError) as caught:
        make()
    assert caught.value.field == field


def test_a_piston_needs_exact_collisions_no_forces_but_gravity_and_the_gas_behind_it():
    box = Box(10.0, 10.0, walls={"top": Piston(position=0.0, mass=1.0)})
    below = Particles(np.array([[0.0, -2.0]]), np.zeros((1, 2)), radius=0.5)
    with pytest.raises(InputError, match="exact") as caught:
        Simulation(box, below, collisions="step")
    assert caught.value.field == "collisions"
    with pytest.raises(InputError) as caught:
        Simulation(box, below, forces=[Gravity(), Coulomb(1.0)])
    assert caught.value.field == "forces"
    Simulation(box, below, forces=[Gravity()])  # the engine flies gravity's parabolas
    above = Particles(np.array([[0.0, 2.0]]), np.zeros((1, 2)), radius=0.5)
    with pytest.raises(InputError, match="outside") as caught:
        Simulation(box, above)
    assert caught.value.field == "position"


def test_a_wall_becomes_a_driven_piston_between_runs_and_its_work_is_counted():
    """Simulation.container replaced by the same box whose right wall is a piston driven in: it
    starts where it is given, stops where asked, and the gas's energy gain is its work."""
    box = Box(10.0, 10.0)
    sim = Simulation(box, _gas(box, 80, 0.2, 3.0, seed=8), dt=0.05)
    sim.run(time=1.0)
    energy = sim.energy().kinetic
    sim.container = box.with_walls(
        {"right": Piston(position=5.0, velocity=-2.0, driven=True, stop=2.0)}
    )
    sim.run(time=3.0)
    state = sim.piston()
    assert state is not None and (state.position, state.velocity) == (2.0, 0.0)
    assert sim.escaped() == 0 and (sim.particles.position[:, 0] + 0.2 <= 2.0 + 1e-12).all()
    assert sim.energy().kinetic - energy == pytest.approx(state.work, rel=1e-12)
    assert state.work > 0  # compressing heats


def test_a_piston_kept_on_its_wall_keeps_where_it_is_unless_driven():
    box = Box(12.0, 12.0, walls={"top": Piston(position=2.0, mass=2.0, force=15.0)})
    sim = Simulation(box, _gas(box, 40, 0.2, 3.0, seed=9), dt=0.05)
    sim.run(time=2.0)
    position, velocity = sim.tally.piston
    sim.container = box.with_walls({})  # the same box: the piston goes on as it was
    assert list(sim.tally.piston) == [position, velocity]
    with pytest.raises(InputError, match="behind the piston's face") as caught:
        sim.container = box.with_walls(
            {"top": Piston(position=position - 1.0, velocity=1.0, driven=True, stop=position - 0.5)}
        )
    assert caught.value.field == "walls.top.stop"
    driven = Piston(position=position, velocity=1.0, driven=True, stop=position + 0.5)
    sim.container = box.with_walls({"top": driven})
    assert list(sim.tally.piston) == [position, 1.0]  # a driven piston moves at its velocity
    sim.run(time=5.0)
    assert sim.piston().position == position + 0.5


def test_a_replaced_vessel_must_have_the_same_walls_and_hold_the_gas():
    box = Box(10.0, 10.0)
    sim = Simulation(box, _gas(box, 30, 0.2, 3.0, seed=10), dt=0.05)
    before = sim.container
    with pytest.raises(InputError, match="must have the walls of the 10 x 10 box") as caught:
        sim.container = Circle(6.0)
    assert caught.value.field == "container"
    with pytest.raises(InputError, match="outside") as caught:
        sim.container = box.with_walls({"right": Piston(position=-4.9, driven=True)})
    assert caught.value.field == "position"
    assert sim.container is before and sim.tally.piston.size == 0  # nothing changed
