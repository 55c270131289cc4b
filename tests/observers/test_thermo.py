"""Temperature and pressure: ideal gas, wall against virial, the hard-disk equation of state."""

from __future__ import annotations

import numpy as np
import pytest
from matplotlib.figure import Figure

import collidium as cd
from collidium.observers import Thermo
from collidium.theory import hard_disk_compressibility, hard_disk_virial_series
from lattices import jittered_lattice


def hard_disk_fluid(packing, boundary="periodic", n_side=30, radius=0.5, seed=1):
    """n_side^2 disks at the given packing fraction, velocities normal with kT = 1, zero momentum,
    equilibrated for 50 mean free times."""
    rng = np.random.default_rng(seed)
    n = n_side**2
    side = np.sqrt(n * np.pi * radius**2 / packing)
    if boundary == "reflecting":  # the centres' area A_c = (L - 2r)^2 carries the packing
        side += 2 * radius
    position = jittered_lattice(n_side, side, radius, rng)
    velocity = rng.normal(0.0, 1.0, (n, 2))
    velocity -= velocity.mean(axis=0)
    box = cd.Box(side, side, boundary)
    sim = cd.Simulation(box, cd.Particles(position, velocity, radius=radius), dt=0.1, seed=seed)
    return sim.run(time=50.0)


def measure(sim, time):
    thermo = Thermo()
    sim.observers.append(thermo)
    sim.run(time=time)
    return thermo


def test_temperature_is_kinetic_energy_per_particle():
    sim = cd.load("gas")
    assert sim.temperature() == pytest.approx(sim.energy().kinetic / 200, rel=1e-15)
    thermo = measure(sim, 1.0)
    assert thermo.temperature == pytest.approx(sim.temperature(), rel=1e-12)  # no forces


def test_ideal_gas_of_points_obeys_pa_equals_nkt():
    """Points never collide with each other; in a square box each keeps its speed components, and
    the walls receive exactly N kT / A on average."""
    rng = np.random.default_rng(7)
    n = 500
    particles = cd.Particles(rng.uniform(-5, 5, (n, 2)), rng.normal(0, 1, (n, 2)), radius=0.0)
    sim = cd.Simulation(cd.Box(10.0, 10.0), particles, dt=0.1)
    thermo = measure(sim, 2000.0)
    assert thermo.area == 100.0
    ideal = n * thermo.temperature / thermo.area
    pressure = thermo.wall_pressure()["total"]
    assert abs(pressure - ideal) < 3 * thermo.wall_pressure_error()
    assert thermo.wall_pressure_error() < 2e-3 * ideal
    assert thermo.virial_pressure() == pytest.approx(ideal, rel=1e-12)  # no collisions, no forces


@pytest.mark.slow
def test_dilute_disk_gas_approaches_the_ideal_gas_with_the_second_virial_correction():
    """At packing 0.05 P A_c / (N kT) = 1.108: the ideal gas plus 2 eta + 3.13 eta^2 + ...; the
    wall pressure resolves that 10% excess."""
    thermo = measure(hard_disk_fluid(0.05, "reflecting"), 4000.0)
    z = thermo.wall_pressure()["total"] * thermo.area / (thermo.n * thermo.temperature)
    error = thermo.wall_pressure_error() * thermo.area / (thermo.n * thermo.temperature)
    assert error < 0.004
    assert abs(z - 1.0) > 20 * error  # not an ideal gas: the disks' own area counts
    # Henderson's Z equals the virial series to 1e-4 here; walls add a surface term of order
    # (r / L) (Z - 1), 0.2% of the excess, well below the error.
    assert abs(z - hard_disk_compressibility(0.05)) < 3 * error


def test_wall_and_virial_pressure_agree_in_a_dense_fluid():
    thermo = measure(hard_disk_fluid(0.3, "reflecting"), 500.0)
    wall = thermo.wall_pressure()
    both = np.hypot(thermo.wall_pressure_error(), thermo.virial_pressure_error())
    assert abs(wall["total"] - thermo.virial_pressure()) < 3 * both
    assert both < 0.01 * wall["total"]
    # Every wall feels the same pressure, within the statistical spread of one wall (about
    # twice that of the four together).
    for name in ("left", "right", "bottom", "top"):
        assert abs(wall[name] - wall["total"]) < 4 * 2 * thermo.wall_pressure_error()


@pytest.mark.slow
def test_wall_and_virial_pressure_agree_with_coulomb_forces():
    sim = cd.load("charged-gas", seed=3).run(time=5.0)
    thermo = measure(sim, 25.0)
    both = np.hypot(thermo.wall_pressure_error(), thermo.virial_pressure_error())
    assert sim.virial() != 0.0
    assert abs(thermo.wall_pressure()["total"] - thermo.virial_pressure()) < 3 * both


@pytest.mark.parametrize("packing", [0.05, 0.3])
def test_hard_disk_equation_of_state(packing):
    """Periodic fluid, no walls: Z from the collision virial matches Henderson's equation of state,
    within the statistical error plus Henderson's own error (its distance from the virial
    series, whose omitted terms are smaller still here)."""
    thermo = measure(hard_disk_fluid(packing), 500.0)
    assert thermo.area == pytest.approx(900 * np.pi * 0.25 / packing)
    z = thermo.compressibility()
    error = thermo.virial_pressure_error() * thermo.area / (thermo.n * thermo.temperature)
    assert error < 1e-3 * z
    henderson = hard_disk_compressibility(packing)
    series = hard_disk_virial_series(packing)
    assert abs(z - henderson) < 3 * error + abs(henderson - series)
    assert np.isnan(thermo.wall_pressure()["total"])


def test_plot_and_summary():
    thermo = measure(cd.load("gas"), 10.0)
    ax = thermo.plot(Figure().add_subplot())
    assert {line.get_label() for line in ax.get_lines()} >= {"wall", "virial"}
    summary = thermo.summary()
    assert summary["pressure"]["wall"] == thermo.wall_pressure()["total"]
    assert set(summary["pressure"]["walls"]) == {"left", "right", "bottom", "top"}


def test_compressibility_is_nan_for_disks_at_rest():
    """N kT = 0: no ideal-gas pressure to divide by (the fuzz test found the division)."""
    thermo = measure(cd.load("gas", speed=0.0), 1.0)
    assert np.isnan(thermo.compressibility()) and np.isnan(thermo.compressibility_error())
