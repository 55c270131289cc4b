"""Presets: the exact parameters of each seed configuration (as each preset's docstring states
them), overrides, the registry."""

from __future__ import annotations

import math

import numpy as np
import pytest

from collidium import load, restore, theory
from collidium.errors import InputError
from collidium.loading import load_scenario
from collidium.observers import Every, TemperatureProfile, VirialRatio
from collidium.presets import PRESETS, describe_presets, parameters, preset, presets
from collidium.scenario import Scenario

SECTIONS = {
    "head-on": "3.1.1",
    "right-angle": "3.1.2",
    "gas": "3.1.3",
    "charged-like": "3.2.1",
    "charged-opposite": "3.2.1",
    "orbit": "3.2.2",
    "bohr-atom": "3.2.2",
    "charged-gas": "3.2.3",
    "pool-break": "4.1.1",
    "charged-no-collisions": "4.2.1",
    "circle-gas": "5",
    "hard-disks": "5",
    "pi-blocks": "5",
    "brownian": "5",
    "heat-flow": "5",
    "granular": "5",
    "piston": "5",
    "effusion": "5",
    "atmosphere": "5",
    "projectile": "5",
    "spectrometer": "5",
    "galaxy": "5",
    "drag": "5",
}

# name -> (positions, velocities, masses, charges, radius, Coulomb (k, softening) or None)
TWO_BODY = {
    "head-on": ([[-1, 0], [1, 0]], [[5, 0], [-5, 0]], [1, 1], [0, 0], 0.25, None),
    "right-angle": ([[0, 1], [1, 0]], [[0, -5], [-5, 0]], [1, 1], [0, 0], 0.25, None),
    "charged-like": ([[-5, 0], [5, 0]], [[2, 0], [-2, 0]], [1, 1], [1, 1], 0.25, (5, 0)),
    "charged-opposite": ([[-5, 0], [5, 0]], [[2, 0], [-2, 0]], [1, 1], [1, -1], 0.25, (5, 0)),
    "orbit": ([[-2, 0], [2, 0]], [[0, -0.6], [0, 0.6]], [1, 1], [-1, 1], 0.25, (5, 0)),
    "bohr-atom": (
        [[0, 0], [3, 0], [-5, 0]],
        [[0, 0], [0, 12.9], [0, -10]],
        [100, 0.1, 0.1],
        [10, -1, -1],
        0.25,
        (5, 0),
    ),
    "charged-no-collisions": (
        [[-5, 0], [5, 0]],
        [[2, 0], [-2, 0]],
        [1, 1],
        [1, -1],
        0.0,
        (5, 0.05),
    ),
}


def test_registry_lists_every_preset_in_report_order():
    assert presets() == list(SECTIONS)
    assert set(PRESETS) == set(SECTIONS)


def test_describe_presets_sections_descriptions_parameters():
    entries = describe_presets()
    assert [e["name"] for e in entries] == list(SECTIONS)
    for entry in entries:
        assert entry["section"] == SECTIONS[entry["name"]]
        assert entry["description"] and "\n" not in entry["description"]
        assert entry["parameters"] == parameters(entry["name"])
        assert {"seed", "dt", "time", "collisions", "radius"} <= set(entry["parameters"])


@pytest.mark.parametrize("name", list(SECTIONS))
def test_default_vessel_and_run(name):
    scenario = preset(name)
    assert isinstance(scenario, Scenario)
    assert scenario.name == name
    assert scenario.run.dt == 0.01
    assert scenario.run.collisions == "exact"
    times = {"pool-break": 60.0, "heat-flow": 60.0, "brownian": 300.0, "granular": 30.0,
             "piston": 60.0, "effusion": 200.0, "hard-disks": 50.0, "atmosphere": 120.0,
             "projectile": 5.0, "spectrometer": 14.0, "galaxy": 40.0}  # fmt: skip
    assert scenario.run.time == times.get(name, 10.0)
    if name in ("circle-gas", "galaxy"):
        radius = {"circle-gas": 11.3, "galaxy": 20.0}[name]
        assert scenario.to_dict()["vessel"] == {"shape": "circle", "radius": radius}
        return
    if name == "brownian":  # a periodic box, for a walk longer than a box
        assert scenario.to_dict()["vessel"] == {"shape": "box", "width": 40.0, "height": 40.0,
                                                "boundary": "periodic"}  # fmt: skip
        return
    if name == "granular":  # a periodic box: no walls to start clusters on
        assert scenario.to_dict()["vessel"] == {"shape": "box", "width": 60.0, "height": 60.0,
                                                "boundary": "periodic"}  # fmt: skip
        assert scenario.run.restitution == 0.9
        return
    if name == "hard-disks":  # a periodic box that a 20 x 20 hexagonal lattice fills exactly
        spacing = 0.5 * np.sqrt(2 * np.pi / (np.sqrt(3) * 0.3))
        assert scenario.vessel.boundary == "periodic"
        assert scenario.vessel.width == pytest.approx(20 * spacing, rel=1e-15)
        assert scenario.vessel.height == pytest.approx(10 * np.sqrt(3) * spacing, rel=1e-15)
        return
    assert scenario.vessel.boundary == "reflecting"
    size = {"pool-break": (40.0, 20.0), "heat-flow": (40.0, 10.0), "piston": (20.0, 40.0),
            "effusion": (40.0, 20.0), "atmosphere": (40.0, 100.0), "spectrometer": (24.0, 14.0),
            "drag": (12.0, 40.0)}  # fmt: skip
    size = size.get(name, (20.0, 20.0))
    assert (scenario.vessel.width, scenario.vessel.height) == size


@pytest.mark.parametrize("name", list(TWO_BODY))
def test_few_body_presets_exact(name):
    position, velocity, mass, charge, radius, coulomb = TWO_BODY[name]
    sim = preset(name).build()
    p = sim.particles
    np.testing.assert_array_equal(p.position, np.array(position, float))
    np.testing.assert_array_equal(p.velocity, np.array(velocity, float))
    np.testing.assert_array_equal(p.mass, mass)
    np.testing.assert_array_equal(p.charge, charge)
    assert (p.radius == radius).all()
    if coulomb is None:
        assert sim.forces == ()
    else:
        (force,) = sim.forces
        assert (force.k, force.softening, force.max_acceleration) == (*coulomb, None)


def test_circle_gas_is_the_gas_in_a_circle_and_keeps_its_angular_momentum():
    sim = preset("circle-gas", n=150, vessel_radius=9.0).build()
    p = sim.particles
    assert p.n == 150 and sim.forces == ()
    assert (np.hypot(*p.position.T) <= 9.0 - 0.25).all()
    spin = sim.angular_momentum()
    sim.run(time=10.0)
    assert sim.counters.wall_hits["rim"] > 100 and sim.escaped() == 0
    assert sim.angular_momentum() == pytest.approx(spin, rel=1e-10, abs=1e-10)


PI = "314159265"


@pytest.mark.parametrize("digits", range(8))
def test_pi_blocks_count_the_digits_of_pi(digits):
    """Galperin's billiard: with a mass ratio 100^d the collisions (pair and wall) number the
    first d + 1 digits of pi; exact counts, nothing approximate."""
    sim = preset("pi-blocks", digits=digits).build().run(time=10.0)
    counters = sim.counters
    assert counters.pair_collisions + counters.wall_collisions == int(PI[: digits + 1])
    assert counters.wall_hits["right"] == 0  # the run ends before the heavy block gets there
    velocity = sim.particles.velocity[:, 0]
    assert 0.0 <= velocity[0] <= velocity[1]  # both leave to the right, the light one slower


def test_pi_blocks_refuse_digits_beyond_double_precision():
    with pytest.raises(InputError, match="digits: must be a whole number from 0 to 8"):
        preset("pi-blocks", digits=9)


@pytest.mark.slow
def test_the_brownian_disk_takes_the_gas_temperature_and_wanders():
    """Equipartition: the heavy disk's mean kinetic energy is the gas's kT (2D, Boltzmann's
    constant 1), within 3 standard errors of block averages; and it diffuses."""
    sim = preset("brownian").build()
    (tracer,) = sim.observers
    sim.run(time=10.0)  # the small disks kick the heavy one up to their temperature
    energy = []
    for _ in range(2000):
        sim.run(steps=5)
        v = sim.particles.velocity[0]
        energy.append(0.5 * sim.particles.mass[0] * float(v @ v))
    blocks = [np.mean(b) for b in np.array_split(energy, 20)]
    error = np.std(blocks, ddof=1) / math.sqrt(20)
    assert abs(np.mean(energy) - sim.temperature()) < 3 * error
    assert tracer.diffusion_coefficient() > 0.2 and tracer.msd()[-1] > 50.0
    assert sim.particles.radius[0] == 1.0 and sim.escaped() == 0


def test_heat_flow_carries_heat_from_the_hot_wall_to_the_cold_one_down_a_temperature_slope():
    sim = preset("heat-flow", n=200).build()
    (profile,) = sim.observers
    sim.run(time=60.0)
    heat = sim.wall_heat()
    assert heat["left"] > 0 > heat["right"] and heat["top"] == heat["bottom"] == 0.0
    kT, error = profile.temperature, profile.temperature_error()
    # Hotter near the hot wall than near the cold one, by many standard errors ...
    assert kT[0] - kT[-1] > 5 * math.hypot(error[0], error[-1])
    # ... and between the two walls' temperatures, as a conducting gas must be.
    assert 5.0 < kT[-1] < kT[0] < 30.0


@pytest.mark.parametrize("name", ["gas", "charged-gas"])
def test_gas_presets(name):
    sim = preset(name).build()
    p = sim.particles
    assert p.n == 200
    assert (p.mass == 1).all() and (p.radius == 0.25).all()
    assert (np.abs(p.velocity) <= 10).all() and np.abs(p.velocity).max() > 9
    assert (np.abs(p.position) <= 10 - 0.25).all()
    distance = np.hypot(*(p.position[:, None] - p.position[None]).transpose(2, 0, 1))
    np.fill_diagonal(distance, np.inf)
    assert distance.min() >= 0.5
    if name == "gas":
        assert (p.charge == 0).all() and sim.forces == ()
    else:
        assert (p.charge == 1).sum() == 100 and (p.charge == -1).sum() == 100
        assert not (p.charge[:100] == 1).all()  # random order
        (force,) = sim.forces
        assert (force.k, force.softening) == (5.0, 0.0)


def test_pool_break():
    sim = preset("pool-break").build()
    p = sim.particles
    assert p.n == 225
    rack, cue = p.position[:224], p.position[224]
    assert tuple(cue) == (-10.0, 0.0)
    assert tuple(p.velocity[224]) == (100.0, 0.0)
    assert (p.velocity[:224] == 0).all()
    assert (p.mass == 1).all() and (p.radius == 0.25).all() and (p.charge == 0).all()
    assert tuple(rack[0]) == (3.0, 0.0) and rack[:, 0].min() == 3.0
    columns = np.unique(np.round(rack[:, 0], 9), return_counts=True)[1]
    assert list(columns) == [*range(1, 16), *range(14, 1, -1)]
    distance = np.hypot(*(rack[:, None] - rack[None]).transpose(2, 0, 1))
    np.fill_diagonal(distance, np.inf)
    assert distance.min() == pytest.approx(2 * 0.25 * 1.005, rel=1e-12)
    # the rack lies inside the 40 x 20 table
    assert (np.abs(rack[:, 0]) + 0.25 <= 20).all() and (np.abs(rack[:, 1]) + 0.25 <= 10).all()
    assert sim.forces == () and sim.escaped() == 0


def test_pool_break_rack_must_fit_the_table():
    with pytest.raises(InputError) as info:
        preset("pool-break", width=25.0).build()
    assert info.value.field == "particles.0"
    assert "outside" in info.value.reason


def test_common_overrides():
    scenario = preset(
        "charged-opposite",
        dt=0.005,
        k=2.5,
        radius=0.1,
        mass=2.0,
        time=3.0,
        collisions="step",
        seed=7,
        width=30.0,
        height=12.0,
    )
    assert (scenario.run.dt, scenario.run.time, scenario.run.collisions) == (0.005, 3.0, "step")
    assert (scenario.vessel.width, scenario.vessel.height, scenario.seed) == (30.0, 12.0, 7)
    assert scenario.forces[0].k == 2.5
    p = scenario.build().particles
    assert (p.radius == 0.1).all() and (p.mass == 2.0).all()


def test_gas_overrides_and_seed():
    a = preset("gas", n=50, speed=2.0, seed=3).build().particles
    b = preset("gas", n=50, speed=2.0, seed=3).build().particles
    c = preset("gas", n=50, speed=2.0, seed=4).build().particles
    assert a.n == 50 and (np.abs(a.velocity) <= 2).all()
    assert a.position.tobytes() == b.position.tobytes()
    assert not np.array_equal(a.position, c.position)


def test_pool_break_cue_speed_and_softening_overrides():
    assert tuple(preset("pool-break", speed=40.0).build().particles.velocity[-1]) == (40.0, 0.0)
    assert preset("charged-no-collisions", softening=0.2).forces[0].softening == 0.2


def test_unknown_preset():
    with pytest.raises(InputError) as info:
        preset("gass")
    assert info.value.field == "preset"
    assert "unknown preset 'gass'; choose from head-on" in info.value.reason


@pytest.mark.parametrize(("name", "key"), [("gas", "k"), ("head-on", "n"), ("bohr-atom", "mass")])
def test_unknown_override_is_named(name, key):
    with pytest.raises(InputError) as info:
        preset(name, **{key: 1})
    assert info.value.field == key
    assert f"not a parameter of preset '{name}'; it takes: " in info.value.reason


def test_invalid_override_value_names_the_parameter():
    with pytest.raises(InputError, match=r"^n: must be >= 0"):
        preset("gas", n=-5)
    with pytest.raises(InputError, match=r"^dt: must be > 0"):
        preset("head-on", dt=0.0)


def test_load_preset_with_keywords_and_dotted_paths():
    sim = load("gas", n=30, seed=2, **{"run.dt": 0.002, "vessel.boundary": "periodic"})
    assert sim.particles.n == 30 and sim.dt == 0.002 and sim.container.periodic


def test_load_file_with_aliases(tmp_path):
    path = tmp_path / "gas.toml"
    path.write_text(preset("gas", n=20).to_toml())
    scenario = load_scenario(
        str(path), dt=0.02, time=2.0, collisions="step", seed=5, **{"particles.0.n": 12}
    )
    assert (scenario.run.dt, scenario.run.time, scenario.run.collisions) == (0.02, 2.0, "step")
    assert scenario.seed == 5 and scenario.to_dict()["particles"][0]["n"] == 12
    with pytest.raises(InputError, match=r"^n: unknown field"):
        load_scenario(path, n=3)


def test_load_unknown_source():
    with pytest.raises(InputError, match=r"^preset: unknown preset 'nothing'"):
        load("nothing")
    with pytest.raises(InputError, match="no such file"):
        load("nothing.toml")


@pytest.mark.parametrize(("name", "key"), [("pool-break", "speed"), ("charged-gas", "charge")])
@pytest.mark.parametrize("value", ["x", True, None, [1.0]])
def test_a_number_parameter_refuses_other_values_in_one_line(name, key, value):
    with pytest.raises(InputError, match=f"^{key}: must be a number, got "):
        preset(name, **{key: value})


@pytest.mark.slow
def test_granular_gas_cools_as_haffs_law_over_the_first_cooling_time():
    """T(t) = T0 / (1 + t / tau)^2 with tau from Enskog's collision rate (`theory.haff_time`),
    within 5% for t <= tau: the homogeneous cooling state's non-Gaussian correction (a few %
    at e = 0.9) and the spread of 20,000 collisions (under 1%) stay inside it. The energy the
    collisions take is booked exactly."""
    sim = preset("granular").build()
    p = sim.particles
    n = p.n
    kT0 = float(sim.energy().kinetic) / n
    area = float(np.prod(sim.container.size))
    tau = theory.haff_time(n / area, 2 * 0.25, kT0, 1.0, 0.9)
    start = sim.energy().total
    times, temperatures = [], []
    while sim.time < tau:
        sim.run(time=tau / 20)
        times.append(sim.time)
        temperatures.append(float(sim.energy().kinetic) / n)
    expected = theory.haff_temperature(np.array(times), kT0, tau)
    assert temperatures[-1] < 0.3 * kT0  # cooled to about a quarter
    np.testing.assert_allclose(temperatures, expected, rtol=0.05)
    assert sim.counters.pair_collisions > 15_000
    assert abs(sim.energy().total - sim.collision_heat() - start) <= 1e-12 * start


def test_granular_restitution_is_checked_and_elastic_disks_take_no_heat():
    with pytest.raises(InputError, match=r"^restitution: must be <= 1, got 1.5$"):
        preset("granular", restitution=1.5)
    with pytest.raises(InputError, match=r"^restitution: must be in \(0, 1\], got 0$"):
        preset("gas").build().restitution = 0
    sim = preset("gas").build().run(time=2.0)
    assert sim.collision_heat() == 0.0 and sim.restitution == 1.0


def test_granular_resumes_bitwise_and_the_step_mode_books_its_heat(tmp_path):
    sim = preset("granular", n=500).build().run(time=2.0)
    sim.save(tmp_path / "g.ckpt")
    whole = sim.run(time=2.0).particles.velocity.copy()
    again = restore(tmp_path / "g.ckpt")
    assert again.restitution == 0.9
    assert again.run(time=2.0).particles.velocity.tobytes() == whole.tobytes()
    step = preset("granular", n=500, collisions="step").build()
    start = step.energy().total
    step.run(time=5.0)
    assert step.collision_heat() < -0.05 * start  # it cools in the seed's step mode too
    assert abs(step.energy().total - step.collision_heat() - start) <= 1e-12 * start


def test_piston_preset_settles_where_its_weight_balances_the_gas():
    """The free piston's weight over its line of contact equals the pressure the gas puts on it
    (within 3 standard errors, block averages), and every disk stays below it."""
    sim = preset("piston", time=1.0).build()
    sim.run(time=40.0)  # the first swings die down
    start, impulse = sim.tally.impulse[4], []
    for _ in range(400):
        sim.run(time=0.25)
        impulse.append(sim.tally.impulse[4])
    length = 20.0 - 2 * 0.25
    rates = np.diff([start, *impulse]) / (0.25 * length)
    blocks = np.array([part.mean() for part in np.array_split(rates, 20)])
    error = blocks.std(ddof=1) / np.sqrt(20)
    assert abs(blocks.mean() - 80.0 / length) <= 3 * error
    assert sim.escaped() == 0
    piston = sim.piston()
    assert piston is not None and -20.0 < piston.position < 20.0


def test_piston_preset_compresses_to_half_when_driven():
    sim = preset("piston", compress=0.5).build()
    kinetic = sim.energy().kinetic
    sim.run(time=45.0)
    piston = sim.piston()
    assert piston is not None and (piston.position, piston.velocity) == (-10.0, 0.0)
    assert piston.work == pytest.approx(sim.energy().kinetic - kinetic, rel=1e-12)
    assert piston.work > 0  # the gas was compressed: it gained energy


def test_effusion_starts_both_masses_in_the_left_chamber_at_one_temperature():
    sim = preset("effusion").build()
    p = sim.particles
    light, heavy = p.mass == 1.0, p.mass == 4.0
    assert light.sum() == heavy.sum() == 500
    assert (p.position[:, 0] < -0.02).all() and sim.escaped() == 0
    # Velocity components uniform in [-s, s] and [-s/2, s/2]: kT = m s^2 / 3 for both.
    assert np.abs(p.velocity[light]).max() == pytest.approx(5.0, abs=0.05)
    assert np.abs(p.velocity[heavy]).max() == pytest.approx(2.5, abs=0.03)
    ((start, end),) = sim.container.partition_lines()[:1]
    assert sim.container.partition("divider").gap == 2.0 and start[0] == end[0] == 0.0


@pytest.mark.slow
def test_effusion_follows_grahams_law_and_the_lighter_escapes_faster():
    """Graham: per-disk crossing rates in the ratio sqrt(m2/m1) = 2, within 5%; the run counts
    some 14000 and 7000 crossings, so 5% is over 3 standard errors of the ratio. Disks of
    radius 5 mm make the mean free path (some 14 m) long against the 4 m hole, the effusion
    regime; steps of 0.05 s move a disk some 0.1 m, so none crosses twice between samples.
    Each rate also matches the effusion rate <|v_x|> w / (2 A) within 3 standard errors, with
    <|v_x|> = sqrt(2 kT / (pi m)) of the Maxwell-Boltzmann gas the collisions make in the first
    few seconds (a mean free time is some 4 s)."""
    sim = preset("effusion", n=2000, radius=0.005, gap=4.0, dt=0.05).build()
    (effusion,) = sim.observers
    kT = sim.temperature()
    sim.run(time=20.0)
    early = effusion.escaped[-1]
    assert early[0] > early[1] + 0.015  # the lighter leaves its chamber faster
    sim.run(time=580.0)
    assert effusion.crossings.min() > 5000
    assert effusion.ratio == pytest.approx(effusion.graham, rel=0.05)
    assert abs(effusion.ratio - 2.0) < 3 * effusion.ratio_error
    chamber = (20.0 - 2 * 0.005) ** 2
    for k, mass in enumerate((1.0, 4.0)):
        speed = math.sqrt(2 * kT / (math.pi * mass))
        expected = theory.effusion_rate(speed, 4.0 - 2 * 0.005, chamber)
        assert abs(effusion.rates[k] - expected) < 3 * effusion.rate_errors[k]


@pytest.mark.parametrize("packing", [0.05, 0.3, 0.65, 0.9])
def test_hard_disks_start_on_a_lattice_that_fills_the_periodic_box(packing):
    """Every disk's six neighbours, across the box's seams too, sit one lattice spacing away:
    the packing is exact and no pair overlaps."""
    sim = preset("hard-disks", packing=packing).build()
    p, box = sim.particles, sim.container
    assert p.n == 400
    assert p.n * np.pi * 0.25 / (box.width * box.height) == pytest.approx(packing, rel=1e-12)
    separation = p.position[:, None, :] - p.position[None, :, :]
    separation -= np.array([box.width, box.height]) * np.round(
        separation / np.array([box.width, box.height])
    )
    distance = np.hypot(separation[..., 0], separation[..., 1]) + np.diag(np.full(p.n, np.inf))
    spacing = 0.5 * np.sqrt(2 * np.pi / (np.sqrt(3) * packing))
    nearest = np.sort(distance, axis=1)[:, :6]
    np.testing.assert_allclose(nearest, spacing, rtol=1e-9)
    assert (distance >= 1.0).all()  # touching at most, at the densest packing


def test_hard_disks_follow_hendersons_equation_of_state():
    """The lattice melts at packing 0.3; Z from the collision virial over 200 s after 20 s
    matches Henderson's formula within 3 standard errors plus Henderson's own error (its distance
    from the virial series)."""
    from collidium.observers import Thermo
    from collidium.theory import hard_disk_compressibility, hard_disk_virial_series

    sim = preset("hard-disks", packing=0.3).build().run(time=20.0)
    thermo = Thermo()
    sim.observers.append(thermo)
    sim.run(time=200.0)
    series = hard_disk_virial_series(0.3)
    henderson = hard_disk_compressibility(0.3)
    z, error = thermo.compressibility(), thermo.compressibility_error()
    assert abs(z - henderson) < 3 * error + abs(henderson - series)


def test_projectile_falls_on_the_parabola_and_lands_at_the_textbook_range():
    """q E / m = 2 m/s^2 down, a drop of 9.75 m to the floor at 4 m/s: it lands after
    sqrt(2 h m / (q E)) = 3.1225 s, 12.49 m on (`theory.projectile_range`)."""
    sim = preset("projectile").build()
    start = sim.particles.position[0].copy()
    landing = theory.projectile_range(4.0, 9.75, 2.0) / 4.0
    sim.run(time=3.12)  # just before the landing: still on the parabola, to round-off
    t = sim.time
    np.testing.assert_allclose(
        sim.particles.position[0], start + np.array([4.0 * t, -t * t]), atol=1e-12
    )
    assert sim.counters.wall_hits["bottom"] == 0 and t < landing
    sim.run(time=0.01)  # just after: one bounce on the floor
    assert sim.counters.wall_hits["bottom"] == 1 and sim.time > landing


@pytest.mark.slow
def test_spectrometer_ions_land_two_radii_from_the_slit():
    """Each ion turns on a half circle of radius m v / (q B) (2, 4 and 6 m) and lands on the
    floor at x = -10 + 2 r. It crosses the field's edge twice, each to O(omega h) in the
    direction (h the substep, omega h <= the tolerance): over the 4 m down to the floor that
    is within a few mm."""
    sim = preset("spectrometer").build()
    landed: dict[int, float] = {}
    while len(landed) < 3 and sim.time < 14.0:
        before = sim.particles.velocity[:, 1].copy()
        sim.run(steps=1)
        for i in np.flatnonzero((before < 0) & (sim.particles.velocity[:, 1] > 0)):
            landed.setdefault(int(i), float(sim.particles.position[i, 0]))
    masses = sim.particles.mass
    for i, x in landed.items():
        assert x == pytest.approx(-10 + 2 * theory.cyclotron_radius(masses[i], 2.0, 1.0, 1.0),
                                  abs=0.01)  # fmt: skip
    assert len(landed) == 3


@pytest.mark.slow
def test_drag_disks_reach_their_terminal_velocities():
    """After 10 s (at least 3.3 time constants m / gamma) each disk falls at
    m g / gamma (1 - exp(-t gamma / m)), the exact solution, to the substeps' O(h^2)."""
    sim = preset("drag").build().run(time=10.0)
    masses = sim.particles.mass
    terminal = np.array([theory.terminal_velocity(m, 1.0, 1.0) for m in masses])
    want = terminal * (1 - np.exp(-10.0 / masses))
    np.testing.assert_allclose(-sim.particles.velocity[:, 1], want, rtol=sim.tolerance**2)


@pytest.mark.slow
def test_galaxy_settles_to_virial_equilibrium():
    """A fifth of the galaxy with five times G (the same G M: the same free-fall time, 13 s, and
    speeds): after the collapse the bound cluster's 2 KE / |W| comes to 1 (the virial theorem),
    within 0.15: a 1000-disk cluster still swings by about a tenth a few free-fall times on,
    and the fixed step's energy error (1e-2 here) moves it as much."""
    sim = preset("galaxy", n=1000, G=0.05).build()
    sim.run(time=40.0)
    (virial,) = [o for o in sim.observers if isinstance(o, VirialRatio)]
    assert virial.time[0] == pytest.approx(25.0, abs=0.01)
    assert abs(virial.summary()["mean_virial_ratio"] - 1.0) < 0.15
    assert 0.8 < virial.summary()["bound_fraction"] < 1.0


@pytest.mark.slow
def test_atmosphere_follows_the_barometric_law_where_dilute():
    """A smaller atmosphere (400 disks, 20 m x 40 m, kT about 16 J, scale height kT / (m g)
    about 16 m), relaxed for 40 s and measured over 200 s in 10 slices. In the upper half
    (packing below 0.012, where the gas is ideal to a few parts in a thousand) each slice's
    density is ``A exp(-m g y / kT)`` within 3 standard errors (block averages), kT the slices'
    mean and A fitted; the error of kT adds to each slice's by how far it lies from their
    middle. The slices' kT agree with each other (one temperature at every height)."""
    sim = load("atmosphere", n=400, width=20.0, height=40.0, speed=5.0, seed=3)
    sim.observers = []
    sim.run(time=40.0)
    profile = TemperatureProfile(bins=10, axis="y", trigger=Every(10))
    sim.observers = [profile]
    sim.run(time=200.0)
    top = profile.centres > 0
    y, density, error = profile.centres[top], profile.density[top], profile.density_error()[top]
    kT_each, kT_error = profile.temperature[top], profile.temperature_error()[top]
    weights = 1 / kT_error**2
    kT = np.sum(weights * kT_each) / np.sum(weights)
    assert np.all(np.abs(kT_each - kT) <= 3 * kT_error)
    shape = theory.barometric_density(y - y.mean(), 1.0, 1.0, kT)
    slope_error = density * np.abs(y - y.mean()) / kT**2 / math.sqrt(np.sum(weights))
    sigma = np.hypot(error, slope_error)
    amplitude = np.sum(density * shape / sigma**2) / np.sum(shape**2 / sigma**2)
    assert np.all(np.abs(density - amplitude * shape) <= 3 * sigma)
