"""The substeps' modified energy kept where the substep changes (`kernels/modified_energy.py`)."""

from __future__ import annotations

import numpy as np
import pytest

from collidium.kernels import modified_energy, reference

SIZE = np.array([6.0, 5.0])


def charges(n: int = 12, seed: int = 3) -> tuple[np.ndarray, ...]:
    """``n`` particles of random masses, under two softened inverse-distance laws (charges of
    both signs, and masses attracting), with the accelerations of those laws."""
    rng = np.random.default_rng(seed)
    position = rng.uniform(-2.5, 2.5, (n, 2))
    velocity = rng.normal(0.0, 2.0, (n, 2))
    mass = rng.uniform(0.5, 2.0, n)
    sources = np.array([rng.choice([-1.0, 1.0], n), mass])
    couplings = np.array([5.0, -0.3])
    softenings2 = np.array([0.01, 0.04])
    acceleration = accelerations(position, mass, sources, couplings, softenings2)
    return position, velocity, acceleration, mass, sources, couplings, softenings2


def accelerations(position, mass, sources, couplings, softenings2, size=None) -> np.ndarray:
    """The laws' forces over the masses (m/s^2)."""
    force = sum(
        reference.inverse_distance_direct(position, q, k, eps2, size)[0]
        for q, k, eps2 in zip(sources, couplings, softenings2, strict=True)
    )
    return force / mass[:, None]


def modified(position, velocity, mass, sources, couplings, softenings2, h) -> float:
    """``S_h = KE + U + h^2 D`` (J), summed in NumPy."""
    kinetic = 0.5 * float(np.sum(mass * np.sum(velocity**2, axis=1)))
    potential = sum(
        float(reference.inverse_distance_direct(position, q, k, eps2)[1].sum())
        for q, k, eps2 in zip(sources, couplings, softenings2, strict=True)
    )
    acceleration = accelerations(position, mass, sources, couplings, softenings2)
    curvature, pulls = reference.modified_energy_terms(
        position, velocity, acceleration, mass, (sources, couplings, softenings2)
    )
    return kinetic + potential + h * h * (curvature / 12.0 - pulls / 24.0)


@pytest.mark.parametrize("periodic", [False, True])
def test_the_terms_equal_their_twin(periodic):
    position, velocity, acceleration, mass, sources, couplings, softenings2 = charges()
    got = modified_energy.curvature_and_pulls(position, velocity, acceleration, mass, sources,
                                              couplings, softenings2, *SIZE, periodic,
                                              np.empty((4, len(mass))))  # fmt: skip
    want = reference.modified_energy_terms(position, velocity, acceleration, mass,
                                           (sources, couplings, softenings2),
                                           SIZE if periodic else None)  # fmt: skip
    assert got == pytest.approx(want, rel=1e-12)


def modified_energy_swings(h: float) -> tuple[float, float]:
    """Velocity Verlet of substep h (s) over an eccentric orbit of two opposite charges,
    through its close approach: the largest changes of H and of ``S_h = H + h^2 D`` relative to
    the energy."""
    position = np.array([[-1.0, 0.0], [1.0, 0.0]])
    velocity = np.array([[0.0, -0.6], [0.0, 0.6]])
    mass, sources = np.ones(2), np.array([[1.0, -1.0]])
    couplings, softenings2 = np.array([5.0]), np.array([0.0])
    acceleration = accelerations(position, mass, sources, couplings, softenings2)
    energies, modified_energies = [], []
    for _ in range(round(1.6 / h)):
        velocity += 0.5 * h * acceleration
        position += h * velocity
        acceleration = accelerations(position, mass, sources, couplings, softenings2)
        velocity += 0.5 * h * acceleration
        energies.append(modified(position, velocity, mass, sources, couplings, softenings2, 0.0))
        modified_energies.append(
            modified(position, velocity, mass, sources, couplings, softenings2, h)
        )
    scale = abs(energies[0])
    return float(np.ptp(energies)) / scale, float(np.ptp(modified_energies)) / scale


def test_leapfrog_keeps_the_modified_energy_the_terms_give():
    """H swings by O(h^2) through the close approach, ``S_h`` only by O(h^4): a thousand times
    less here, and halving h cuts S's swing about sixteenfold (H's fourfold)."""
    coarse, coarse_kept = modified_energy_swings(2e-3)
    fine, fine_kept = modified_energy_swings(1e-3)
    assert coarse > 1e-5 and coarse_kept < coarse / 1000 and fine_kept < fine / 1000
    assert 3.0 < coarse / fine < 5.0
    assert 10.0 < coarse_kept / fine_kept < 25.0


def test_a_change_of_substep_keeps_the_modified_energy_and_the_momentum():
    """From substeps of 2 ms to 0.5 ms: the velocities scaled so that ``S_h`` before equals
    ``S_h'`` after (to round-off; unscaled, S jumps by ``(h'^2 - h^2) D``, ten thousand times
    more), the momentum kept, as the twin does."""
    position, velocity, acceleration, mass, sources, couplings, softenings2 = charges()
    before = modified(position, velocity, mass, sources, couplings, softenings2, 2e-3)
    unscaled = modified(position, velocity, mass, sources, couplings, softenings2, 5e-4)
    assert abs(unscaled / before - 1.0) > 1e4 * 1e-13
    momentum = mass @ velocity
    twin = velocity.copy()
    given = modified_energy.keep_across_step(position, velocity, acceleration, mass, sources,
                                             couplings, softenings2, *SIZE, False,
                                             np.empty((4, len(mass))), 2e-3, 5e-4,
                                             1e-3)  # fmt: skip
    want = reference.modified_energy_keep(
        position, twin, acceleration, mass, (sources, couplings, softenings2), (2e-3, 5e-4), 1e-3
    )
    after = modified(position, velocity, mass, sources, couplings, softenings2, 5e-4)
    assert given != 0.0 and given == pytest.approx(want, rel=1e-12)
    np.testing.assert_allclose(velocity, twin, rtol=1e-13, atol=1e-13)
    assert after == pytest.approx(before, rel=1e-13)
    np.testing.assert_allclose(mass @ velocity, momentum, atol=1e-12)


@pytest.mark.parametrize("case", ["at rest", "beyond the limit"])
def test_a_scaling_too_large_is_left(case):
    """Particles at rest about their centre of mass (no kinetic energy to scale), or a scaling
    beyond ``limit``: nothing changes and no energy is given."""
    position, velocity, acceleration, mass, sources, couplings, softenings2 = charges()
    if case == "at rest":
        velocity[:] = [0.3, -0.2]
    limit = 1e-3 if case == "at rest" else 1e-12
    kept = velocity.copy()
    given = modified_energy.keep_across_step(position, velocity, acceleration, mass, sources,
                                             couplings, softenings2, *SIZE, False,
                                             np.empty((4, len(mass))), 2e-3, 5e-4,
                                             limit)  # fmt: skip
    assert given == 0.0
    np.testing.assert_array_equal(velocity, kept)
