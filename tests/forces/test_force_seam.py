"""The force seam: every registered force against its own potential, the registry and its
round trips through scenario files and checkpoints."""

from __future__ import annotations

import numpy as np
import pytest

import collidium as cd
from collidium import (
    Box,
    Coulomb,
    FieldMap,
    Friction,
    Gravity,
    InputError,
    Langevin,
    LinearDrag,
    MagneticField,
    Newton,
    Particles,
    QuadraticDrag,
    UniformField,
)
from collidium.forces import FORCES, ForceField, PositionForce, VelocityForce, force_from_dict
from collidium.scenario import Scenario

#: One example of each registered force, with parameters away from their defaults.
EXAMPLES = {
    "coulomb": Coulomb(k=5.0, softening=0.1, method="direct"),
    "newton": Newton(G=2.0, softening=0.1, method="direct"),
    "gravity": Gravity(g=(1.5, -9.81)),
    "uniform_field": UniformField(E=(3.0, -2.0)),
    "field_map": FieldMap.sample(
        lambda x, y: 0.3 * x * y - 0.05 * x**2 + np.sin(y / 3), ((-10, -10), (10, 10)), (9, 11)
    ),
    "magnetic_field": MagneticField(B=0.7),
    "linear_drag": LinearDrag(gamma=0.3),
    "quadratic_drag": QuadraticDrag(c=0.05),
    "friction": Friction(mu=0.1, g=2.0),
    "langevin": Langevin(temperature=3.0, gamma=0.5),
}
POSITION_FORCES = sorted(n for n, f in EXAMPLES.items() if isinstance(f, PositionForce))


def test_every_force_acts_on_positions_or_velocities():
    for force in EXAMPLES.values():
        assert isinstance(force, PositionForce) != isinstance(force, VelocityForce)
    assert POSITION_FORCES == ["coulomb", "field_map", "gravity", "newton", "uniform_field"]


def test_every_registered_force_has_an_example():
    assert set(EXAMPLES) == set(FORCES)


def _scattered(periodic: bool = False) -> tuple[Particles, Box]:
    rng = np.random.default_rng(4)
    particles = Particles(
        rng.uniform(-8, 8, (7, 2)), mass=rng.uniform(0.5, 2.0, 7),
        charge=rng.choice([-2.0, -1.0, 1.0, 3.0], 7), radius=0.0,
    )  # fmt: skip
    return particles, Box(20, 20, "periodic" if periodic else "reflecting")


@pytest.mark.parametrize("name", POSITION_FORCES)
def test_force_is_minus_the_gradient_of_its_potential(name):
    """Central differences of the potential, step h = 1e-5 m: truncation ~ h^2 U''' and
    round-off ~ 1e-16 U / h, both below 1e-8 of the largest force here."""
    particles, box = _scattered()
    field = ForceField((EXAMPLES[name],))
    force = field.evaluate(particles, box) * particles.mass[:, None]
    h = 1e-5
    gradient = np.empty_like(force)
    for i in range(particles.n):
        for axis in range(2):
            energies = []
            for step in (h, -h):
                moved = particles.copy()
                moved.position[i, axis] += step
                energies.append(field.potential(moved, box))
            gradient[i, axis] = (energies[0] - energies[1]) / (2 * h)
    np.testing.assert_allclose(force, -gradient, rtol=0, atol=1e-8 * np.abs(force).max())


@pytest.mark.parametrize("name", POSITION_FORCES)
def test_a_kick_sums_the_same_forces_without_the_energies(name):
    """Without ``energies`` (a kick) a force may skip its energies, never change its forces."""
    particles, box = _scattered()
    forces = []
    for energies in (True, False):
        force = np.full((particles.n, 2), np.nan)
        EXAMPLES[name].compute(particles, box, force, np.empty(7), np.empty(7), {}, energies)
        forces.append(force)
    np.testing.assert_array_equal(forces[0], forces[1])


def test_the_field_sums_energies_when_they_are_read(monkeypatch):
    """Evaluations sum forces alone; a read of the potential or the virial sums the energies
    (once for both); an evaluation that closes a step sums them with the forces only when the
    energies of the step before were read."""
    asked: list[bool] = []
    compute = Coulomb.compute
    monkeypatch.setattr(Coulomb, "compute", lambda self, *args: asked.append(args[-1])
                        or compute(self, *args))  # fmt: skip
    particles, box = _scattered()
    field = ForceField((EXAMPLES["coulomb"],))
    field.evaluate(particles, box)
    field.evaluate(particles, box, closes_step=True)
    assert asked == [False, False]
    potential, virial = field.potential(particles, box), field.virial(particles, box)
    assert asked == [False, False, True]
    field.evaluate(particles, box, closes_step=True)  # read since the last close: with energies
    assert asked[-1] is True
    assert (field.potential(particles, box), field.virial(particles, box)) == (potential, virial)
    assert len(asked) == 4  # read from that evaluation
    field.evaluate(particles, box, closes_step=True)
    field.evaluate(particles, box, closes_step=True)  # not read since: forces alone
    assert asked == [False, False, True, True, True, False]


@pytest.mark.parametrize("name", ["coulomb", "newton"])
def test_pair_forces_sum_to_zero(name):
    particles, box = _scattered()
    force = ForceField((EXAMPLES[name],)).evaluate(particles, box) * particles.mass[:, None]
    assert np.abs(force.sum(axis=0)).max() <= 1e-14 * np.abs(force).sum()


def test_forces_add_up():
    """A charged massive gas under all position forces: the field's acceleration is the sum of
    each's."""
    particles, box = _scattered()
    forces = [EXAMPLES[name] for name in POSITION_FORCES]
    together = ForceField(tuple(forces)).evaluate(particles, box).copy()
    apart = sum(ForceField((f,)).evaluate(particles, box) for f in forces)
    np.testing.assert_allclose(together, apart, rtol=1e-13, atol=1e-13 * np.abs(apart).max())


@pytest.mark.parametrize("name", ["gravity", "uniform_field"])
def test_a_uniform_field_keeps_the_energy_across_the_period(name):
    """In a periodic vessel the potential uses the unwrapped position: a particle falling
    through the floor and in at the top keeps its total energy (to round-off)."""
    particles = Particles([[0.0, -9.0]], velocity=[[0.3, -5.0]], charge=1.0, radius=0.25)
    sim = cd.Simulation(Box(20, 20, "periodic"), particles, forces=[EXAMPLES[name]], dt=0.01)
    start = sim.energy().total
    sim.run(time=3.0)
    assert sim.particles.image[0, 1] <= -1  # it went through at least once
    assert sim.energy().total == pytest.approx(start, rel=1e-12, abs=1e-12 * abs(start))


@pytest.mark.parametrize("name", sorted(EXAMPLES))
def test_a_force_is_its_table(name):
    force = EXAMPLES[name]
    table = force.to_dict()
    assert table["type"] == name == force.name
    assert force_from_dict(table) == force


def test_scenario_files_and_checkpoints_carry_every_force(tmp_path):
    """A scene under every force: exported to TOML and read back it has the same forces;
    saved and restored, it runs on bit for bit as the original."""
    particles, _ = _scattered()
    particles.radius = 0.1
    forces = [*EXAMPLES.values()]
    sim = cd.Simulation(Box(20, 20), particles, forces=forces, dt=0.01, seed=3, name="all")
    sim.run(time=0.2)
    assert Scenario.from_toml_string(Scenario.of_state(sim).to_toml()).build().forces == sim.forces
    sim.save(tmp_path / "all.npz")
    restored = cd.restore(tmp_path / "all.npz")
    assert restored.forces == sim.forces
    restored.run(time=0.3)
    sim.run(time=0.3)
    np.testing.assert_array_equal(restored.particles.position, sim.particles.position)
    np.testing.assert_array_equal(restored.particles.velocity, sim.particles.velocity)


def test_unknown_forces_and_parameters_name_the_field():
    with pytest.raises(InputError, match=r"^forces\.2\.type: unknown force 'yukawa'; choose"):
        force_from_dict({"type": "yukawa"}, "forces.2")
    with pytest.raises(InputError, match=r"^forces\.0\.B: unknown field; allowed: g"):
        force_from_dict({"type": "gravity", "B": 1.0}, "forces.0")
    with pytest.raises(InputError, match=r"^forces\.0\.G: must be >= 0, got -1"):
        force_from_dict({"type": "newton", "G": -1.0}, "forces.0")
    with pytest.raises(InputError, match=r"^forces\.0: not a force: str"):
        cd.Simulation(Box(20, 20), Particles([[0.0, 0.0]]), forces=["gravity"])  # type: ignore[list-item]


@pytest.mark.parametrize(
    ("force", "field", "reason"),
    [
        ({"type": "newton", "G": -1.0}, "forces.0.G", "must be >= 0"),
        ({"type": "newton", "softening": float("nan")}, "forces.0.softening", "finite"),
        ({"type": "gravity", "g": [0.0]}, "forces.0.g", "at least 2 entries"),
        ({"type": "gravity", "g": [0.0, float("inf")]}, "forces.0.g.1", "finite"),
        ({"type": "uniform_field"}, "forces.0.E", "required field is missing"),
        ({"type": "uniform_field", "E": [1.0, 2.0], "B": 3.0}, "forces.0.B", "unknown field"),
    ],
)
def test_a_scenario_names_the_bad_force_parameter(force, field, reason):
    data = {"particles": [{"kind": "explicit", "position": [[0, 0]], "velocity": [[0, 0]]}]}
    with pytest.raises(InputError) as info:
        Scenario.from_dict({**data, "forces": [force]})
    assert info.value.field == field
    assert reason in info.value.reason


@pytest.mark.parametrize(
    ("forces", "known"),
    [
        (["coulomb"], True),
        (["coulomb", "newton", "uniform_field"], True),
        (["uniform_field"], False),  # followed exactly: its modified energy is the energy
        (["coulomb", "magnetic_field"], False),
        (["coulomb", "linear_drag"], False),
        (["coulomb", "field_map"], False),
    ],
)
def test_the_modified_energy_is_kept_where_it_is_known(forces, known):
    """Where the substep changes, the adaptive integrator keeps the substeps' modified energy
    (`collidium.kernels.modified_energy`) only for pair laws summed as their gradients and
    uniform fields: not beside a velocity force, a field map, a gravity the drift carries, a
    tree or a limiter."""
    particles = Particles([[-1.0, 0.0], [1.0, 0.0]], charge=[1.0, -1.0])
    field = ForceField(tuple(EXAMPLES[name] for name in forces))
    assert field.keeps_modified_energy(particles, Box(10, 10)) is known


@pytest.mark.parametrize(
    "forces",
    [
        (Coulomb(k=5.0, method="tree"),),
        (Coulomb(k=5.0, max_acceleration=10.0),),
        (Coulomb(k=5.0), Gravity(g=(0.0, -9.81))),
    ],
)
def test_the_modified_energy_is_not_kept_by_tree_limiter_or_carried_gravity(forces):
    particles = Particles([[-1.0, 0.0], [1.0, 0.0]], charge=[1.0, -1.0])
    field = ForceField(forces, carry_fall=True)
    assert not field.keeps_modified_energy(particles, Box(10, 10))
