"""Drag and sliding friction: exact decay, terminal velocities, stopping distances, and the
energy they take kept as heat."""

from __future__ import annotations

import math

import numpy as np
import pytest

import collidium as cd
from collidium import Box, Friction, Gravity, InputError, LinearDrag, Particles, QuadraticDrag
from collidium.observers.energy import conserved_energy


def _falling(*forces, mass: float = 1.0, **options) -> cd.Simulation:
    particles = Particles([[0.0, 90.0]], velocity=[[0.0, 0.0]], mass=mass, radius=0.5)
    return cd.Simulation(Box(10, 200), particles, forces=[Gravity(g=(0.0, -1.0)), *forces],
                         **options)  # fmt: skip


def test_linear_drag_alone_decays_the_speed_exactly():
    particles = Particles([[0.0, 0.0]], velocity=[[3.0, 4.0]], mass=2.0)
    sim = cd.Simulation(Box(100, 100), particles, forces=[LinearDrag(gamma=0.5)], dt=0.01)
    sim.run(time=3.0)
    speed = np.hypot(*sim.particles.velocity[0])
    assert speed == pytest.approx(5.0 * math.exp(-0.5 * 3.0 / 2.0), rel=1e-13)
    assert sim.force_heat() == pytest.approx(0.5 * 2.0 * (speed**2 - 25.0), rel=1e-13)


@pytest.mark.slow
def test_terminal_velocity_is_m_g_over_gamma_to_second_order():
    """Each fixed step is ``v -> exp(-lambda h) v + g h exp(-lambda h / 2)`` (lambda = gamma/m):
    its fixed point, reached after 40 time constants, is ``g h / (2 sinh(lambda h / 2))``,
    ``m g / gamma`` to (lambda h)^2 / 24; the adaptive substeps take it within tolerance^2 / 24."""
    rate = 6.0 / 3.0
    for dt in (0.02, 0.01):
        sim = _falling(LinearDrag(gamma=6.0), mass=3.0, dt=dt, integrator="fixed").run(time=20.0)
        assert -sim.particles.velocity[0, 1] == pytest.approx(
            dt / (2 * math.sinh(rate * dt / 2)), rel=1e-12
        )
    sim = _falling(LinearDrag(gamma=6.0), mass=3.0, dt=0.01).run(time=20.0)
    terminal = 3.0 * 1.0 / 6.0
    assert -sim.particles.velocity[0, 1] == pytest.approx(terminal, rel=sim.tolerance**2 / 24)


@pytest.mark.slow
def test_quadratic_drag_reaches_sqrt_m_g_over_c():
    sim = _falling(QuadraticDrag(c=0.5), mass=2.0, dt=0.01).run(time=30.0)
    assert -sim.particles.velocity[0, 1] == pytest.approx(math.sqrt(2.0 * 1.0 / 0.5), rel=1e-6)


def test_quadratic_drag_alone_follows_its_exact_decay():
    particles = Particles([[0.0, 0.0]], velocity=[[0.0, 6.0]], mass=2.0)
    sim = cd.Simulation(Box(100, 100), particles, forces=[QuadraticDrag(c=0.1)], dt=0.01)
    sim.run(time=2.0)
    assert sim.particles.velocity[0, 1] == pytest.approx(6.0 / (1 + 0.1 * 6.0 * 2.0 / 2.0),
                                                         rel=1e-13)  # fmt: skip


def test_friction_stops_a_sliding_disk_after_s2_over_2_mu_g():
    """Speeds fall by mu g per second until 0; the distance errs only in the last step, by at
    most mu g dt^2 / 2."""
    mu, g, speed, dt = 0.2, 9.81, 3.0, 0.01
    particles = Particles([[-40.0, 0.0]], velocity=[[speed, 0.0]])
    sim = cd.Simulation(Box(100, 10), particles, forces=[Friction(mu=mu, g=g)], dt=dt)
    sim.run(time=1.0)
    assert sim.particles.velocity[0, 0] == pytest.approx(speed - mu * g * 1.0, rel=1e-13)
    sim.run(time=1.0)
    assert sim.particles.velocity[0, 0] == 0.0
    travelled = sim.particles.position[0, 0] + 40.0
    assert travelled == pytest.approx(speed**2 / (2 * mu * g), abs=mu * g * dt**2 / 2)
    assert sim.force_heat() == pytest.approx(-0.5 * speed**2, rel=1e-12)


def test_heat_is_what_the_energy_lost():
    """A gas falling under gravity with drag and friction, bouncing and colliding: the total
    energy less the heat the forces took holds to round-off (leapfrog is exact under uniform
    gravity, the drag flows are exact and booked)."""
    rng = np.random.default_rng(7)
    n = 30
    position = np.column_stack([np.linspace(-8, 8, n), rng.uniform(-8, 8, n)])
    particles = Particles(position, velocity=rng.normal(0, 3, (n, 2)), radius=0.2,
                          mass=rng.uniform(0.5, 2.0, n))  # fmt: skip
    forces = [Gravity(g=(0.0, -2.0)), LinearDrag(gamma=0.1), QuadraticDrag(c=0.02),
              Friction(mu=0.01)]  # fmt: skip
    sim = cd.Simulation(Box(20, 20), particles, forces=forces, dt=0.01)
    start = conserved_energy(sim)
    sim.run(time=5.0)
    assert sim.counters.pair_collisions > 0
    assert sim.force_heat() < -0.1 * abs(start)
    assert conserved_energy(sim) == pytest.approx(start, rel=1e-12)


@pytest.mark.parametrize(
    ("make", "field"),
    [
        (lambda: LinearDrag(gamma=-1.0), "forces.linear_drag.gamma"),
        (lambda: QuadraticDrag(c=float("nan")), "forces.quadratic_drag.c"),
        (lambda: Friction(mu=-0.1), "forces.friction.mu"),
        (lambda: Friction(mu=0.1, g=-9.81), "forces.friction.g"),
    ],
)
def test_bad_coefficients_are_refused(make, field):
    with pytest.raises(InputError) as info:
        make()
    assert info.value.field == field
