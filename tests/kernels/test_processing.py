"""The processed state the adaptive integrator shows (`kernels/processing.py`)."""

from __future__ import annotations

import numpy as np
import pytest
from test_modified_energy import accelerations, charges, modified

from collidium import Box, Circle
from collidium.kernels import processing, reference

OPEN = (0, 1e9, 1e9, 0.0, np.empty((0, 9)))  # no walls within reach


def vessel_arguments(vessel) -> tuple:
    """The walls as `processing.shown` takes them."""
    shape, limit_x, limit_y, slack, _ = vessel.audit_arguments()
    return shape, limit_x, limit_y, slack, vessel.segments()


def shown(position, velocity, acceleration, mass, curved, scale, radius, walls):
    """`processing.shown` with fresh work arrays: ``(positions, velocities, disks put back)``."""
    n = len(mass)
    out_position, out_velocity = np.empty((n, 2)), np.empty((n, 2))
    kept = processing.shown(position, velocity, acceleration, mass, curved, scale, radius, walls,
                            np.arange(n), np.empty((3, n)), out_position,
                            out_velocity)  # fmt: skip
    return out_position, out_velocity, kept


def test_the_curved_velocities_equal_their_twin_and_give_the_curvature():
    """Two laws (charges of both signs, masses attracting): the compiled sums equal the NumPy
    twin's, and ``sum_i v_i . Hess(U) v`` is the quadratic form Q of the modified energy."""
    position, velocity, acceleration, mass, sources, couplings, softenings2 = charges()
    curved = np.empty_like(position)
    processing.curved_velocities(position, velocity, sources, couplings, softenings2,
                                 np.empty((6, len(mass))), curved)  # fmt: skip
    laws = (sources, couplings, softenings2)
    np.testing.assert_allclose(curved, reference.curved_velocities(position, velocity, laws),
                               rtol=1e-12, atol=1e-12 * np.abs(curved).max())  # fmt: skip
    curvature, _ = reference.modified_energy_terms(position, velocity, acceleration, mass, laws)
    assert float(np.sum(velocity * curved)) == pytest.approx(curvature, rel=1e-12)
    np.testing.assert_allclose(curved.sum(axis=0), 0.0, atol=1e-12 * np.abs(curved).max())


@pytest.mark.parametrize("vessel", [Box(5.2, 5.2), Circle(3.0)])
@pytest.mark.parametrize("scale", [1e-4, 3e-3, -3e-3])
def test_the_processed_state_equals_its_twin(vessel, scale):
    """Shifts small and large enough to bring disks past the walls and onto each other (both
    ways: the inverse processing has a negative scale): the compiled state equals the twin's,
    the disks put back the same."""
    position, velocity, acceleration, mass, sources, couplings, softenings2 = charges(n=40)
    position *= 0.9 if isinstance(vessel, Box) else 0.5
    radius = np.full(40, 0.12)
    radius[::7] = 0.0  # points take no part in pair contacts
    acceleration = accelerations(position, mass, sources, couplings, softenings2)
    curved = reference.curved_velocities(position, velocity, (sources, couplings, softenings2))
    walls = vessel_arguments(vessel)
    got = shown(position, velocity, acceleration, mass, curved, scale, radius, walls)
    want = reference.processed_state(position, velocity, acceleration, mass, curved, scale,
                                     radius, walls)  # fmt: skip
    np.testing.assert_array_equal(got[0], want[0])
    np.testing.assert_allclose(got[1], want[1], rtol=1e-15, atol=0.0)
    assert got[2] == want[2]
    if abs(scale) > 1e-3:
        assert got[2] > 0


def test_a_disk_the_shift_would_bring_onto_a_wall_or_a_disk_is_shown_where_it_is():
    """Two disks 1e-6 m apart pulled together and a disk 1e-6 m from a wall pulled into it are
    shown where they are; a free disk, and two disks overlapping by 1e-6 m (a contact's
    round-off) pulled apart, are shifted; every velocity is processed."""
    position = np.array([[0.0, 0.0], [1.0 + 1e-6, 0.0], [4.5 - 1e-6, 0.0], [-3.0, -3.0],
                         [-3.0, 3.0], [-2.0 - 1e-6, 3.0]])  # fmt: skip
    acceleration = np.array([[1.0, 0.0], [-1.0, 0.0], [1.0, 0.0], [1.0, 1.0], [-1.0, 0.0],
                             [1.0, 0.0]])  # fmt: skip
    velocity, curved = np.ones((6, 2)), np.full((6, 2), 2.0)
    mass, radius = np.full(6, 2.0), np.full(6, 0.5)
    got, moving, kept = shown(position, velocity, acceleration, mass, curved, 1e-3, radius,
                              vessel_arguments(Box(10, 10)))  # fmt: skip
    assert kept == 3
    np.testing.assert_array_equal(got[:3], position[:3])
    np.testing.assert_array_equal(got[3:], position[3:] + 1e-3 * acceleration[3:])
    np.testing.assert_array_equal(moving, velocity + 1e-3 * curved / 2.0)


def processed_swings(h: float) -> tuple[float, float, float]:
    """Kick-drift-kick of substep h (s) through the close approach of two opposite charges (as
    `test_modified_energy.modified_energy_swings`): the swings of H and of the processed
    state's energy, and the largest distance of that energy from ``S_h - h^2 P / 24``, all
    relative to the energy."""
    position = np.array([[-1.0, 0.0], [1.0, 0.0]])
    velocity = np.array([[0.0, -0.6], [0.0, 0.6]])
    mass, laws = np.ones(2), (np.array([[1.0, -1.0]]), np.array([5.0]), np.array([0.0]))
    acceleration = accelerations(position, mass, *laws)
    energies, processed, off = [], [], []
    for _ in range(round(1.6 / h)):
        velocity += 0.5 * h * acceleration
        position += h * velocity
        acceleration = accelerations(position, mass, *laws)
        velocity += 0.5 * h * acceleration
        curved = reference.curved_velocities(position, velocity, laws)
        x, v, _ = shown(position, velocity, acceleration, mass, curved, h * h / 12, np.zeros(2),
                        OPEN)  # fmt: skip
        energies.append(modified(position, velocity, mass, *laws, 0.0))
        processed.append(modified(x, v, mass, *laws, 0.0))
        pulls = float(np.sum(mass * np.sum(acceleration**2, axis=1)))
        off.append(
            processed[-1] - modified(position, velocity, mass, *laws, h) + h * h * pulls / 24
        )
        np.testing.assert_allclose(mass @ v, mass @ velocity, atol=1e-13)  # momentum kept
        np.testing.assert_allclose(mass @ x, mass @ position, atol=1e-13)  # and the centre
    scale = abs(energies[0])
    return np.ptp(energies) / scale, np.ptp(processed) / scale, np.abs(off).max() / scale


def test_the_processed_energy_is_the_modified_energy_less_the_pulls():
    """The processed state's energy is ``S_h - h^2 P / 24`` to O(h^4) (sixteenfold less per
    halving of h, and thousands of times below H's swing): Q's share of the swing is gone, and
    the swing here is less than half H's."""
    raw, processed, off = processed_swings(2e-3)
    _, _, off_fine = processed_swings(1e-3)
    assert processed < raw / 2 and off < raw / 1e4
    assert 10.0 < off / off_fine < 25.0
