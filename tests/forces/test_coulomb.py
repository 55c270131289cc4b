"""Coulomb's force: parameters, the seed's acceleration limiter, direct and tree sums."""

from __future__ import annotations

import numpy as np
import pytest

from collidium import Box, Coulomb, InputError, Particles, Simulation
from collidium.forces import TREE_CROSSOVER, ForceField
from collidium.forces.pair import uses_tree


def test_limiter_caps_smoothly_and_leaves_small_accelerations_alone():
    """Pairs at 0.01 m, 1 m and 30 m: accelerations of order 1e5, 5 and 5e-3 m/s^2 against a
    cap of 10; each capped as ``a / sqrt(1 + (|a| / cap)^2)``, direction kept."""
    cap = 10.0
    position = [[-1e3, 0.0], [-1e3 + 0.01, 0.0], [0.0, 0.0], [0.6, 0.8], [400.0, 0.0], [430, 0.0]]
    particles = Particles(position, charge=[1.0, -1.0] * 3)
    box = Box(2000, 2000)
    free = ForceField((Coulomb(k=5.0, method="direct"),)).evaluate(particles, box).copy()
    limited = ForceField((Coulomb(k=5.0, method="direct", max_acceleration=cap),))
    capped = limited.evaluate(particles, box)
    pull = np.linalg.norm(free, axis=1)
    np.testing.assert_allclose(capped, free / np.sqrt(1 + (pull / cap) ** 2)[:, None], rtol=1e-14)
    magnitude = np.linalg.norm(capped, axis=1)
    assert (magnitude < cap).all()
    assert magnitude[0] == pytest.approx(cap, rel=1e-7)  # |a| = 5e4: cap (1 - (cap / a)^2 / 2)
    assert magnitude[4] == pytest.approx(pull[4], rel=1e-6)  # |a| << cap: unchanged


def test_field_gives_acceleration_and_potential_of_a_pair():
    particles = Particles([[-2.0, 0.0], [2.0, 0.0]], mass=[1.0, 2.0], charge=[1.0, -1.0])
    field = ForceField((Coulomb(k=5.0),))
    acceleration = field.evaluate(particles, Box(20, 20))
    # |F| = k / r^2 = 5 / 16 N, towards each other; a = F / m.
    np.testing.assert_allclose(acceleration, [[5 / 16, 0.0], [-5 / 32, 0.0]], rtol=1e-15)
    assert field.potential(particles, Box(20, 20)) == pytest.approx(-5 / 4, rel=1e-15)


def test_potential_follows_moved_particles():
    particles = Particles([[-2.0, 0.0], [2.0, 0.0]], charge=[1.0, 1.0])
    box = Box(20, 20)
    field = ForceField((Coulomb(k=5.0),))
    field.evaluate(particles, box)
    particles.position[1, 0] = 3.0
    assert field.potential(particles, box) == pytest.approx(1.0, rel=1e-15)


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"k": float("nan")}, "forces.coulomb.k"),
        ({"softening": -1.0}, "forces.coulomb.softening"),
        ({"softening": 1e300}, "forces.coulomb.softening"),  # its square overflows
        ({"max_acceleration": 0.0}, "forces.coulomb.max_acceleration"),
        ({"method": "fmm"}, "forces.coulomb.method"),
        ({"theta": 1.5}, "forces.coulomb.theta"),
        ({"theta": 0.0}, "forces.coulomb.theta"),
    ],
)
def test_bad_parameters_name_the_field(kwargs, field):
    with pytest.raises(InputError) as info:
        Coulomb(**kwargs)
    assert info.value.field == field


def _plasma(n: int, seed: int = 3) -> Particles:
    rng = np.random.default_rng(seed)
    side = np.sqrt(n / 0.25)
    charge = np.where(np.arange(n) % 2 == 0, 1.0, -1.0)
    return Particles(rng.uniform(-side / 2, side / 2, (n, 2)), charge=charge)


def test_auto_sums_by_tree_from_the_crossover_and_never_in_a_periodic_box():
    assert not uses_tree("auto", _plasma(TREE_CROSSOVER - 1), Box(10, 10))
    assert uses_tree("auto", _plasma(TREE_CROSSOVER), Box(10, 10))
    assert not uses_tree("auto", _plasma(TREE_CROSSOVER), Box(10, 10, "periodic"))
    assert uses_tree("tree", _plasma(10), Box(10, 10))
    assert not uses_tree("direct", _plasma(TREE_CROSSOVER), Box(10, 10))


def test_tree_in_a_periodic_box_is_refused_with_the_field():
    with pytest.raises(InputError) as info:
        Simulation(Box(40, 40, "periodic"), _plasma(100), forces=[Coulomb(method="tree")])
    assert info.value.field == "forces.coulomb.method"


def test_tree_and_direct_fields_agree_to_the_tree_error():
    """The same ForceField with either method: accelerations within the tree's 1e-3 RMS error,
    the potential far closer (errors of both signs cancel in the sum)."""
    particles = _plasma(3000)
    box = Box(200, 200)
    direct = ForceField((Coulomb(method="direct", softening=0.05),))
    by_tree = ForceField((Coulomb(method="tree", softening=0.05),))
    a = direct.evaluate(particles, box).copy()
    b = by_tree.evaluate(particles, box)
    error = np.linalg.norm(b - a, axis=1) / np.linalg.norm(a, axis=1)
    assert np.sqrt(np.mean(error**2)) < 1e-3
    assert by_tree.potential(particles, box) == pytest.approx(
        direct.potential(particles, box), rel=1e-4
    )


@pytest.mark.slow
def test_tree_driven_run_conserves_energy():
    """A softened plasma (no collisions) run by tree: leapfrog keeps the total energy to
    O(dt^2), and the tree's small force error must not add a drift of its own. The same run by
    direct summation sets the scale of the leapfrog error (measured 1.15e-3 of the kinetic
    energy); the tree's run must end within 1e-4 of it (measured 7e-6)."""
    drifts = []
    for method in ("direct", "tree"):
        particles = _plasma(1500, seed=5)
        particles.velocity[...] = np.random.default_rng(6).normal(0, 0.5, (1500, 2))
        sim = Simulation(
            Box(200, 200), particles, forces=[Coulomb(k=5.0, softening=0.5, method=method)],
            dt=0.01, collisions="off", integrator="fixed",  # the same steps for both sums
        )  # fmt: skip
        start = sim.energy().total
        scale = sim.energy().kinetic
        sim.run(steps=200)
        drifts.append(abs(sim.energy().total - start) / scale)
    direct_drift, tree_drift = drifts
    assert direct_drift < 2e-3  # leapfrog at dt = 0.01 s in this strongly coupled plasma
    assert abs(tree_drift - direct_drift) < 1e-4  # the tree adds nothing visible to it


@pytest.mark.parametrize("method", ["direct", "tree"])
def test_a_shared_charge_and_charges_of_their_own_run_one_compiled_sum(rng, method):
    """A charge all particles share is a read-only view (`Particles`); the pair kernels get it
    as a plain array, so both scenes run the same compiled sum and stiffness."""
    from collidium.kernels import pairwise, tree

    kernels = (pairwise.direct_serial, pairwise.stiffness_serial, tree.build_tree)
    position = rng.uniform(-5, 5, (30, 2))
    shared = Particles(position, rng.normal(0, 1, (30, 2)), charge=1.0, mass=2.0)
    own = Particles(position, shared.velocity, charge=np.ones(30), mass=np.full(30, 2.0))
    field = ForceField((Coulomb(method=method),))
    box = Box(20, 20)
    compiled = []
    for particles in (shared, own):
        acceleration = field.evaluate(particles, box).copy()
        stiffness = field.stiffness(particles, box)
        compiled.append([set(kernel.signatures) for kernel in kernels])
    assert compiled[0] == compiled[1]
    np.testing.assert_array_equal(field.evaluate(shared, box), acceleration)
    assert field.stiffness(shared, box) == stiffness
