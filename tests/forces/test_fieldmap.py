"""A potential on a grid: bilinear interpolation, its force the gradient of its energy, and the
grids a scenario file may not hold."""

from __future__ import annotations

import numpy as np
import pytest

import collidium as cd
from collidium import Box, FieldMap, InputError, Particles, UniformField
from collidium.forces import ForceField
from collidium.scenario import Scenario


def _charges() -> Particles:
    rng = np.random.default_rng(9)
    return Particles(rng.uniform(-9, 9, (50, 2)), charge=rng.uniform(-2, 2, 50))


def test_a_linear_potential_is_the_uniform_field():
    """Bilinear interpolation is exact for phi = -E . x: the same forces, and energies that
    differ by a constant only where the potential is measured from."""
    e = np.array([1.5, -0.5])
    grid = FieldMap.sample(lambda x, y: -(e[0] * x + e[1] * y), ((-10, -10), (10, 10)), (5, 7))
    particles, box = _charges(), Box(20, 20)
    mapped, uniform = ForceField((grid,)), ForceField((UniformField(E=tuple(e)),))
    np.testing.assert_allclose(mapped.evaluate(particles, box), uniform.evaluate(particles, box),
                               rtol=0, atol=1e-14)  # fmt: skip
    assert mapped.potential(particles, box) == pytest.approx(uniform.potential(particles, box),
                                                             rel=1e-13)  # fmt: skip


def test_nodes_hold_their_values_and_cells_interpolate_bilinearly():
    grid = FieldMap(((0.0, 1.0), (2.0, 7.0)), region=((0.0, 0.0), (2.0, 1.0)))
    points = Particles([[0.0, 0.0], [2.0, 1.0], [1.0, 0.5], [0.5, 0.25]], charge=1.0)
    # phi(u, w) = u + 2 w + 4 u w on the unit square (u = x / 2, w = y).
    want = [0.0, 7.0, 0.5 + 1.0 + 1.0, 0.25 + 0.5 + 0.25]
    energy = np.empty(4)
    grid.compute(points, Box(4, 4), np.empty((4, 2)), energy, np.empty(4), {}, energies=True)
    np.testing.assert_allclose(energy, want, rtol=1e-15)


def test_beyond_the_grid_the_potential_keeps_its_edge_values():
    grid = FieldMap(((0.0, 1.0), (2.0, 3.0)), region=((-1.0, -1.0), (1.0, 1.0)))
    outside = Particles([[5.0, 0.0]], charge=1.0)
    force = ForceField((grid,)).evaluate(outside, Box(20, 20))
    assert force[0, 0] == 0.0  # flat across the edge
    assert force[0, 1] == pytest.approx(-1.0)  # the edge's own slope: (3 - 1) / 2 V/m


def _energy_error(tolerance: float) -> float:
    """Largest |dE/E| of a charge rolling over potential hills for 8 s, bouncing off walls."""
    bumps = FieldMap.sample(lambda x, y: 2 * np.sin(x / 2) * np.cos(y / 3), ((-10, -10), (10, 10)),
                            (41, 41))  # fmt: skip
    particles = Particles([[-5.0, 1.0]], velocity=[[3.0, 1.3]], charge=1.0, radius=0.2)
    sim = cd.Simulation(Box(20, 20), particles, forces=[bumps], dt=0.01, tolerance=tolerance)
    start = sim.energy().total
    worst = 0.0
    for _ in range(16):
        worst = max(worst, abs(sim.run(time=0.5).energy().total / start - 1))
    assert sim.counters.wall_collisions > 0
    return worst


@pytest.mark.slow
def test_the_energy_error_falls_at_least_as_the_substep():
    """The force of a bilinear map jumps at grid lines, and a substep across one errs on the
    energy by O(h), not O(h^2): a quarter of the tolerance (substeps 4x shorter) cuts the
    error at least 3x (4x for first order, less a margin for the random signs of the
    crossings; the smooth part falls 16x)."""
    assert _energy_error(0.0007 / 4) <= _energy_error(0.0007) / 3


@pytest.mark.parametrize(
    ("potential", "field", "reason"),
    [
        ([[1.0, 2.0]], "forces.0.potential", "at least 2 x 2"),
        ([[1.0, 2.0], [3.0]], "forces.0.potential", "same length"),
        ([[1.0, 2.0], [3.0, float("nan")]], "forces.0.potential.1.1", "finite"),
    ],
)
def test_a_bad_grid_is_named(potential, field, reason):
    data = {
        "particles": [{"kind": "explicit", "position": [[0, 0]], "velocity": [[0, 0]]}],
        "forces": [{"type": "field_map", "potential": potential}],
    }
    with pytest.raises(InputError) as info:
        Scenario.from_dict(data)
    assert info.value.field == field
    assert reason in info.value.reason


def test_a_scenario_file_carries_the_grid_and_region():
    grid = FieldMap(((0.0, 1.0, 2.0), (2.0, 7.0, 1.0)), region=((-5.0, -5.0), (5.0, 5.0)))
    sim = cd.Simulation(Box(20, 20), Particles([[0.0, 0.0]], charge=1.0), forces=[grid])
    assert Scenario.from_toml_string(Scenario.of_state(sim).to_toml()).build().forces == (grid,)
