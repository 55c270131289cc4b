"""Circle: its geometry, and disks in it through every engine: energy and angular momentum
conserved, nobody escapes, the wall and virial pressures agree, checkpoints resume bitwise."""

from __future__ import annotations

import math

import numpy as np
import pytest

import collidium as cd
from collidium import Circle, InputError
from collidium.observers import Thermo
from collidium.scenario import Scenario
from collidium.vessels import vessel_from_dict


def gas(n: int = 200, rim: float = 10.0, speed: float = 10.0, seed: int = 1, **run) -> Scenario:
    return Scenario.from_dict(
        {
            "seed": seed,
            "vessel": {"shape": "circle", "radius": rim},
            "run": run,
            "particles": [{"kind": "random", "n": n, "speed": speed}],
        }
    )


def test_a_circle_answers_the_geometry_every_layer_asks_for():
    circle = Circle(10.0)
    assert circle.kind == "circle" and circle.wall_names == ("rim",) and not circle.periodic
    np.testing.assert_array_equal(circle.bounds, [[-10, -10], [10, 10]])
    corners = circle.outline()
    x, y = corners[:, 0], corners[:, 1]
    k = len(corners)  # a regular k-gon inscribed in the rim, counter-clockwise
    shoelace = 0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y)
    assert shoelace == pytest.approx(0.5 * k * 100 * math.sin(2 * math.pi / k), rel=1e-12)
    np.testing.assert_allclose(np.hypot(x, y), 10.0)
    assert circle.available_area(0.5) == pytest.approx(math.pi * 9.5**2)
    np.testing.assert_allclose(circle.contact_lengths(0.5), [2 * math.pi * 9.5])
    np.testing.assert_array_equal(circle.outside(np.array([[9.6, 0.0], [7.0, 7.0], [6.0, 7.0]]),
                                                 np.array([0.5, 0.5, 0.5])), [0, 1])  # fmt: skip
    assert vessel_from_dict(circle.to_dict()).to_dict() == {"shape": "circle", "radius": 10.0}


@pytest.mark.parametrize("radius", [0.0, -1.0, math.nan, math.inf, 2e12])
def test_a_bad_radius_names_the_field(radius):
    with pytest.raises(InputError, match=r"vessel\.radius: must be a finite number > 0"):
        Circle(radius)


def test_disks_outside_the_circle_are_refused_with_the_particle_named():
    data = gas().to_dict()
    data["particles"] = [{"kind": "explicit", "position": [[0.0, 0.0], [7.5, 7.5]]}]
    with pytest.raises(InputError) as info:
        Scenario.from_dict(data).build()
    assert info.value.field == "particles.0.position.1"
    assert "outside the circle of radius 10 m" in info.value.reason


def test_random_disks_fill_the_circle_uniformly(rng):
    sim = gas(n=2000, speed=0.0, rim=20.0).build()
    distance = np.hypot(*sim.particles.position.T)
    assert distance.max() <= 20.0 - 0.25
    # Uniform over the disk of radius R - r: the fraction within half of it is a quarter,
    # within 3 binomial standard errors.
    inner = np.mean(distance <= 0.5 * 19.75)
    assert abs(inner - 0.25) < 3 * math.sqrt(0.25 * 0.75 / 2000)


def test_the_exact_engine_keeps_energy_and_angular_momentum_and_every_disk():
    sim = gas().build()
    energy, spin = sim.energy().total, sim.angular_momentum()
    sim.run(time=60.0)
    assert sim.counters.pair_collisions > 40_000 and sim.counters.wall_hits["rim"] > 5_000
    # Each collision or bounce rounds the energy by ~1e-16 relative: a random walk.
    assert abs(sim.energy().total - energy) <= 1e-12 * energy
    assert abs(sim.angular_momentum() - spin) <= 1e-10 * sum(
        np.hypot(*sim.particles.position.T) * np.hypot(*sim.particles.velocity.T)
    )
    assert sim.escaped() == 0


def test_a_disk_at_1000_m_per_s_stays_inside():
    data = gas(n=300).to_dict()
    data["particles"].append({"kind": "explicit", "position": [[0.0, 0.0]],
                              "velocity": [[1000.0, 377.0]], "radius": 0.1})  # fmt: skip
    sim = Scenario.from_dict(data).build().run(time=5.0)
    assert sim.escaped() == 0 and sim.counters.wall_hits["rim"] > 200


@pytest.mark.parametrize("collisions", ["step", "off"])
def test_the_step_and_off_modes_reflect_off_the_rim(collisions):
    sim = gas(collisions=collisions).build()
    energy, spin = sim.energy().total, sim.angular_momentum()
    sim.run(time=10.0)
    assert sim.counters.wall_hits["rim"] > 500 and sim.escaped() == 0
    assert abs(sim.energy().total - energy) <= 1e-12 * energy
    if collisions == "off":  # a bounce off the rim keeps each disk's angular momentum
        assert sim.angular_momentum() == pytest.approx(spin, rel=1e-10, abs=1e-9)


def test_wall_pressure_on_the_rim_equals_the_virial_pressure():
    """The rim's pressure is impulse per time per contact length 2 pi (R - r); in equilibrium it
    equals the virial pressure over the area pi (R - r)^2 the centres move in."""
    sim = gas(n=300, seed=3).build()
    sim.run(time=5.0)
    thermo = Thermo(trigger=10)
    sim.observers.append(thermo)
    sim.run(time=60.0)
    wall, virial = thermo.wall_pressure()["rim"], thermo.virial_pressure()
    spread = 3 * math.hypot(thermo.wall_pressure_error(), thermo.virial_pressure_error())
    assert abs(wall - virial) < spread
    assert thermo.summary()["pressure"]["walls"] == {"rim": wall}


def test_checkpoints_in_a_circle_resume_bitwise(tmp_path):
    sim = gas(n=100).build().run(time=2.0)
    sim.save(tmp_path / "c.ckpt")
    whole = sim.run(time=2.0).particles.position.copy()
    again = cd.restore(tmp_path / "c.ckpt")
    assert isinstance(again.container, Circle)
    assert again.run(time=2.0).particles.position.tobytes() == whole.tobytes()


@pytest.mark.slow
def test_a_charged_gas_in_a_circle_holds_its_energy():
    """Contacts of forced disks with the rim have their kick timing corrected too
    (`collidium.kernels.kick_timing`: the rim's outward normal)."""
    data = gas(n=60, speed=5.0).to_dict()
    data["particles"][0] |= {"charge": 1.0, "charges": "balanced"}
    data["forces"] = [{"type": "coulomb", "k": 5.0}]
    sim = Scenario.from_dict(data).build()
    energy = sim.energy().total
    sim.run(time=5.0)
    assert sim.counters.wall_hits["rim"] > 50 and sim.escaped() == 0
    assert abs(sim.energy().total - energy) <= 1e-5 * abs(energy)
