"""The Langevin thermostat: a hard-disk gas settles at its kT with Maxwell-Boltzmann speeds,
collisions still exact, the energy it exchanges kept as heat."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

import collidium as cd
from collidium import InputError, Langevin
from collidium.observers.energy import conserved_energy

KT = 2.0


def _bathed_gas(**options) -> cd.Simulation:
    """400 disks of unit mass (packing 0.03) starting cold, in a bath at kT = 2 J with
    gamma = 1 kg/s: time constant m / gamma = 1 s."""
    sim = cd.load("gas", n=400, radius=0.2, speed=0.5, seed=11, **options)
    sim.forces = [Langevin(temperature=KT, gamma=1.0)]
    return sim


def test_the_gas_settles_at_the_bath_temperature():
    """After 10 time constants, kT from snapshots 4 s apart (velocities correlated by e^-4,
    independent enough): in 2D each disk's kinetic energy is exponential with mean kT, so the
    mean of M samples has the standard error kT / sqrt(M); within 3 of them. The speeds pass a
    Kolmogorov-Smirnov test against Maxwell-Boltzmann (Rayleigh, scale sqrt(kT / m))."""
    sim = _bathed_gas()
    sim.integrator = "fixed"  # the bath samples exactly whatever the step
    sim.dt = 0.05
    sim.run(time=10.0)
    energies, speeds = [], []
    for _ in range(12):
        sim.run(time=4.0)
        v = sim.particles.velocity
        energies.append(0.5 * np.einsum("ij,ij->i", v, v))
        speeds.append(np.hypot(v[:, 0], v[:, 1]))
    assert sim.counters.pair_collisions > 1000
    sample = np.concatenate(energies)
    assert abs(sample.mean() - KT) <= 3 * KT / math.sqrt(sample.size)
    assert (
        stats.kstest(np.concatenate(speeds), stats.rayleigh(scale=math.sqrt(KT)).cdf).pvalue > 0.01
    )


def test_the_bath_heats_a_cold_gas_and_books_it():
    sim = _bathed_gas()
    start = conserved_energy(sim)
    sim.run(time=3.0)
    assert sim.force_heat() > 0.5 * sim.particles.n * KT
    assert conserved_energy(sim) == pytest.approx(start, rel=1e-12)


def test_runs_repeat_and_resume_bit_for_bit(tmp_path):
    one, two = _bathed_gas(), _bathed_gas()
    one.run(time=0.5)
    one.save(tmp_path / "bath.npz")
    resumed = cd.restore(tmp_path / "bath.npz")
    for sim in (one, resumed):
        sim.run(time=0.5)
    two.run(time=1.0)
    np.testing.assert_array_equal(one.particles.velocity, two.particles.velocity)
    np.testing.assert_array_equal(resumed.particles.velocity, two.particles.velocity)
    assert resumed.force_heat() == two.force_heat()


@pytest.mark.parametrize(
    ("parameters", "field"),
    [
        ({"temperature": 0.0}, "forces.langevin.temperature"),
        ({"temperature": -1.0}, "forces.langevin.temperature"),
        ({"temperature": float("nan")}, "forces.langevin.temperature"),
        ({"temperature": 1.0, "gamma": -2.0}, "forces.langevin.gamma"),
    ],
)
def test_bad_bath_parameters_are_refused(parameters, field):
    with pytest.raises(InputError) as info:
        Langevin(**parameters)
    assert info.value.field == field
