"""Polygon: its geometry and its refusals, and disks in convex and non-convex polygons through
every engine: energy conserved, nobody escapes past an edge or a reflex corner, the event sequence
equals the brute-force twin's, the wall and virial pressures agree, checkpoints resume bitwise."""

from __future__ import annotations

import math

import numpy as np
import pytest

import collidium as cd
from collidium import InputError, Particles, Polygon, Simulation
from collidium.initial import random_positions
from collidium.kernels import reference
from collidium.observers import Thermo
from collidium.scenario import Scenario
from collidium.vessels import regular_polygon, vessel_from_dict

#: An L: six corners, one of them reflex (at (4, 4)).
L_SHAPE = [[0.0, 0.0], [10.0, 0.0], [10.0, 4.0], [4.0, 4.0], [4.0, 10.0], [0.0, 10.0]]
#: A five-pointed star: five reflex corners.
STAR = [
    [r * math.cos(math.pi / 2 + k * math.pi / 5), r * math.sin(math.pi / 2 + k * math.pi / 5)]
    for k, r in zip(range(10), [12.0, 5.5] * 5, strict=True)
]


def gas(vertices, n: int = 150, speed: float = 10.0, seed: int = 1, **run) -> Scenario:
    return Scenario.from_dict(
        {
            "seed": seed,
            "vessel": {"shape": "polygon", "vertices": vertices},
            "run": run,
            "particles": [{"kind": "random", "n": n, "speed": speed, "radius": 0.2}],
        }
    )


def test_an_l_answers_the_geometry_every_layer_asks_for():
    shape = Polygon(L_SHAPE)
    assert shape.wall_names == tuple(f"edge{i}" for i in range(6)) and not shape.periodic
    assert shape.reflex.tolist() == [False, False, False, True, False, False]
    assert shape.area == 64.0
    np.testing.assert_array_equal(shape.bounds, [[0, 0], [10, 10]])
    np.testing.assert_array_equal(shape.extent, [20, 20])  # the grids are centred on the origin
    # Centres of disks of radius 1/2: two rectangles (9 x 3 and 3 x 6) and, at the reflex
    # corner, the square of side 1/2 less the quarter disk around the corner.
    assert shape.available_area(0.5) == pytest.approx(27 + 18 + 0.25 * (1 - math.pi / 4), 1e-14)
    # Edge 2 ends at the reflex corner: its contact line runs to it, then round it.
    np.testing.assert_allclose(shape.contact_lengths(0.5), [9, 3, 5.5 + math.pi / 4, 5.5, 3, 9])
    # Inside; outside; past the reflex corner; within 1/2 of it alone; touching two edges.
    inside = np.array([[1.0, 1.0], [5.0, 5.0], [4.3, 4.3], [3.7, 3.7], [0.5, 9.5]])
    np.testing.assert_array_equal(shape.outside(inside, np.full(5, 0.5)), [1, 2, 3])
    assert vessel_from_dict(shape.to_dict()).to_dict() == {"shape": "polygon", "vertices": L_SHAPE}


def test_clockwise_corners_make_the_same_vessel_with_edges_named_in_their_order():
    clockwise = Polygon(L_SHAPE[::-1])
    assert clockwise.area == 64.0 and clockwise.reflex.sum() == 1
    assert clockwise.available_area(0.5) == pytest.approx(Polygon(L_SHAPE).available_area(0.5))
    outline = clockwise.outline()  # drawn counter-clockwise whatever the order given
    assert 0.5 * np.sum(outline[:, 0] * np.roll(outline[:, 1], -1)
                        - np.roll(outline[:, 0], -1) * outline[:, 1]) == 64.0  # fmt: skip


@pytest.mark.parametrize("corners", [3, 12, 40])
def test_a_regular_polygon_leaves_a_similar_one_to_the_centres(corners):
    shape = regular_polygon(corners, 10.0)
    apothem = 10.0 * math.cos(math.pi / corners)
    assert shape.available_area(1.0) == pytest.approx(shape.area * (1 - 1.0 / apothem) ** 2)
    assert shape.area == pytest.approx(0.5 * corners * 100 * math.sin(2 * math.pi / corners))


@pytest.mark.parametrize(
    ("vertices", "reason"),
    [
        ([[0, 0], [4, 4], [4, 0], [0, 4]], "must be a simple polygon: edges 0 and 2 cross"),
        ([[0, 0], [4, 0], [4, 4], [2, 0]], "must be a simple polygon"),  # a corner on an edge
        ([[0, 0], [4, 0], [2, 0]], "must be a simple polygon"),  # folds back on itself
        ([[0, 0], [4, 0]], "must be at least 3 [x, y] points"),
        ([[0, 0], [4, 0], [4, 0], [0, 4]], "has two equal consecutive points"),
        ([[0, 0], [4, 0], [math.nan, 4]], "must be finite numbers"),
        ([[0, 0], [2e12, 0], [0, 1]], "must span at most 1e+12 m"),
        ("square", "must be"),
    ],
)
def test_a_bad_polygon_names_the_field(vertices, reason):
    with pytest.raises(InputError) as info:
        Polygon(vertices)
    assert info.value.field == "vessel.vertices" and reason in info.value.reason


def test_disks_outside_the_polygon_are_refused_with_the_particle_named():
    data = gas(L_SHAPE).to_dict()
    data["particles"] = [{"kind": "explicit", "position": [[1.0, 1.0], [7.0, 7.0]]}]
    with pytest.raises(InputError) as info:
        Scenario.from_dict(data).build()
    assert info.value.field == "particles.0.position.1"
    assert "outside the polygon of 6 corners" in info.value.reason


def test_a_self_intersecting_polygon_in_a_scenario_names_the_field():
    text = '[vessel]\nshape = "polygon"\nvertices = [[0, 0], [4, 4], [4, 0], [0, 4]]\n'
    text += '[[particles]]\nkind = "random"\nn = 2\n'
    with pytest.raises(InputError) as info:
        Scenario.from_toml_string(text).build()
    assert info.value.field == "vessel.vertices"


@pytest.mark.parametrize("vertices", [L_SHAPE, STAR], ids=["L", "star"])
def test_the_exact_engine_keeps_energy_and_every_disk(vertices):
    sim = gas(vertices).build()
    energy = sim.energy().total
    sim.run(time=40.0)
    assert sim.counters.pair_collisions > 5_000 and sim.counters.wall_collisions > 5_000
    # Each collision or bounce rounds the energy by ~1e-16 relative: a random walk.
    assert abs(sim.energy().total - energy) <= 1e-12 * energy
    assert sim.escaped() == 0


def test_the_engine_matches_the_brute_force_twin_in_a_star(rng):
    """Every pair collision and every hit on an edge or a reflex corner (one disk is aimed at
    one), in the same order: the same counts, momentum given to each wall and final state. A
    short run (~50 events) keeps the chaotic growth of round-off far below the tolerance."""
    shape = Polygon(STAR)
    corner = np.array(STAR[1])  # a reflex corner, 5.5 m out
    aimed = np.array([[0.0, 0.0]])
    n = 15
    radius = np.full(n + 1, 0.4)
    position = np.vstack([aimed, random_positions(n, 0.4, shape, rng, existing=aimed,
                                                  existing_radius=0.4)])  # fmt: skip
    velocity = np.vstack([[corner * 2.0], rng.uniform(-10, 10, (n, 2))])
    mass = rng.uniform(0.5, 2.0, n + 1)
    sim = Simulation(shape, Particles(position.copy(), velocity.copy(), mass=mass, radius=radius),
                     dt=0.375)  # fmt: skip
    sim.run(steps=4)
    twin_position, twin_velocity = position.copy(), velocity.copy()
    pairs, walls, virial, impulse = reference.event_drift(
        twin_position, twin_velocity, mass, radius, 0.5 * shape.extent, 1.5,
        table=shape.segments(), box_walls=False,
    )  # fmt: skip
    assert pairs > 5 and walls > 15
    assert (sim.counters.pair_collisions, sim.counters.wall_collisions) == (pairs, walls)
    assert impulse[len(STAR) :].sum() > 0  # a reflex corner was met
    # The tally books a corner's hits on the edge that ends there.
    ending = shape.segments()[len(STAR) :, 7].astype(int)
    by_wall = impulse[: len(STAR)].copy()
    np.add.at(by_wall, ending, impulse[len(STAR) :])
    np.testing.assert_allclose(sim.tally.impulse, [virial, *by_wall], rtol=1e-9)
    np.testing.assert_allclose(sim.particles.position, twin_position, atol=1e-9)
    np.testing.assert_allclose(sim.particles.velocity, twin_velocity, atol=1e-9)


def test_the_engine_matches_the_twin_in_a_star_under_gravity(rng):
    """Parabolic flights in the star: edges met at roots of quadratics, reflex corners at the
    first crossings of quartics; the same events and final state as the all-pairs twin."""
    shape = Polygon(STAR)
    g = np.array([-1.5, -9.0])
    n = 16
    radius = np.full(n, 0.4)
    position = random_positions(n, 0.4, shape, rng)
    velocity = rng.uniform(-8, 8, (n, 2))
    mass = rng.uniform(0.5, 2.0, n)
    sim = Simulation(shape, Particles(position.copy(), velocity.copy(), mass=mass, radius=radius),
                     forces=[cd.Gravity(g=g)], dt=0.375)  # fmt: skip
    sim.run(steps=4)
    twin_position, twin_velocity = position.copy(), velocity.copy()
    pairs, walls, *_ = reference.event_drift(
        twin_position, twin_velocity, mass, radius, 0.5 * shape.extent, 1.5,
        table=shape.segments(), box_walls=False, fall=g,
    )  # fmt: skip
    assert pairs > 3 and walls > 15
    assert sim._drift.rebuilds == 1
    assert (sim.counters.pair_collisions, sim.counters.wall_collisions) == (pairs, walls)
    np.testing.assert_allclose(sim.particles.position, twin_position, atol=1e-9)
    np.testing.assert_allclose(sim.particles.velocity, twin_velocity, atol=1e-9)
    energy = sim.energy()
    assert energy.kinetic + energy.potential == pytest.approx(
        0.5 * float(mass @ (velocity**2).sum(axis=1)) - float(mass @ (position @ g)), rel=1e-12
    )


def test_a_disk_at_1000_m_per_s_stays_inside_the_star():
    data = gas(STAR, n=150).to_dict()
    data["particles"].append({"kind": "explicit", "position": [[0.0, 0.0]],
                              "velocity": [[1000.0, 377.0]], "radius": 0.1})  # fmt: skip
    sim = Scenario.from_dict(data).build().run(time=3.0)
    assert sim.escaped() == 0 and sim.counters.wall_collisions > 200


@pytest.mark.parametrize("collisions", ["step", "off"])
def test_the_step_and_off_modes_meet_edges_and_corners(collisions):
    sim = gas(STAR, collisions=collisions).build()
    energy = sim.energy().total
    sim.run(time=10.0)
    assert sim.counters.wall_collisions > 500 and sim.escaped() == 0
    assert abs(sim.energy().total - energy) <= 1e-12 * energy


def test_wall_pressure_in_an_l_equals_the_virial_pressure():
    """Impulse per time over the whole contact line (edges and the arc round the reflex corner)
    equals the virial pressure over the area open to the centres."""
    sim = gas(L_SHAPE, n=120, seed=3).build()
    sim.run(time=5.0)
    thermo = Thermo(trigger=10)
    sim.observers.append(thermo)
    sim.run(time=60.0)
    lengths = sim.container.contact_lengths(0.2)
    pressures = thermo.wall_pressure()
    weights = dict(zip(sim.container.wall_names, lengths, strict=True))
    wall = sum(pressures[name] * length for name, length in weights.items()) / lengths.sum()
    virial = thermo.virial_pressure()
    spread = 3 * math.hypot(thermo.wall_pressure_error(), thermo.virial_pressure_error())
    assert abs(wall - virial) < spread


def test_checkpoints_in_a_polygon_resume_bitwise(tmp_path):
    sim = gas(STAR, n=80).build().run(time=2.0)
    sim.save(tmp_path / "p.ckpt")
    whole = sim.run(time=2.0).particles.position.copy()
    again = cd.restore(tmp_path / "p.ckpt")
    assert (
        isinstance(again.container, Polygon)
        and again.container.to_dict() == sim.container.to_dict()
    )
    assert again.run(time=2.0).particles.position.tobytes() == whole.tobytes()


@pytest.mark.slow
def test_a_charged_gas_in_an_l_holds_its_energy():
    """Contacts of forced disks with edges and corners have their kick timing corrected too
    (`collidium.kernels.kick_timing`: the segment's normal at the contact)."""
    data = gas(L_SHAPE, n=40, speed=5.0).to_dict()
    data["particles"][0] |= {"charge": 1.0, "charges": "balanced"}
    data["forces"] = [{"type": "coulomb", "k": 5.0}]
    sim = Scenario.from_dict(data).build()
    energy = sim.energy().total
    sim.run(time=5.0)
    assert sim.counters.wall_collisions > 50 and sim.escaped() == 0
    assert abs(sim.energy().total - energy) <= 1e-5 * abs(energy)
