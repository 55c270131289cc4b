"""Wall responses: mirror, restitution and thermal re-emission equal their twins; thermal walls
re-emit from the Maxwell flux distribution; every hit's impulse and energy are booked."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from collidium.kernels import reference
from collidium.kernels.wall_responses import INELASTIC, SPECULAR, THERMAL, bounce, respond, uniform

TABLE = np.array([[SPECULAR, 0.0, 0.0], [INELASTIC, 0.6, 1.0], [THERMAL, 3.0, 2.0]])


def test_responses_equal_their_twins(rng):
    for _ in range(500):
        wall, particle, hit = (
            int(rng.integers(3)),
            int(rng.integers(10**6)),
            int(rng.integers(10**9)),
        )
        outward, along, mass = rng.uniform(0, 5), rng.normal(0, 5), rng.uniform(0.1, 10)
        got = respond(TABLE, wall, outward, along, mass, particle, hit)
        want = reference.wall_respond(TABLE, wall, outward, along, mass, particle, hit)
        np.testing.assert_allclose(got, want, rtol=1e-14, atol=1e-14)
        assert uniform(7.0, particle, hit, 1) == reference.wall_uniform(7, particle, hit, 1)


def test_mirror_and_restitution():
    assert respond(TABLE, 0, 2.0, 1.5, 1.0, 0, 0) == (-2.0, 1.5)
    assert respond(TABLE, 1, 2.0, 1.5, 1.0, 0, 0) == pytest.approx((-1.2, 1.5), rel=1e-15)


def test_thermal_walls_reemit_from_the_maxwell_flux_distribution():
    """The normal speed of a re-emitted disk has density (m v / kT) exp(-m v^2 / 2 kT), so
    m v^2 / 2 kT is exponential with mean 1; the tangential velocity is normal, variance kT / m.
    Kolmogorov-Smirnov over 20,000 hits, at the 0.1% level."""
    mass, kT = 2.0, 3.0
    out = np.array([respond(TABLE, 2, 1.0, 0.0, mass, particle, 0) for particle in range(20_000)])
    assert (out[:, 0] < 0).all()
    assert stats.kstest(mass * out[:, 0] ** 2 / (2 * kT), "expon").pvalue > 1e-3
    assert stats.kstest(out[:, 1] / math.sqrt(kT / mass), "norm").pvalue > 1e-3
    # Successive hits of one particle are as independent as those of different particles.
    series = np.array([respond(TABLE, 2, 1.0, 0.0, mass, 5, hit)[1] for hit in range(20_000)])
    assert abs(np.corrcoef(series[:-1], series[1:])[0, 1]) < 4 / math.sqrt(20_000)


@pytest.mark.parametrize("wall", [0, 1, 2])
def test_a_bounce_books_the_normal_impulse_and_the_energy(wall, rng):
    angle = rng.uniform(0, 2 * np.pi)
    nx, ny = math.cos(angle), math.sin(angle)
    vx, vy = 3.0 * nx - 1.0 * ny, 3.0 * ny + 1.0 * nx  # 3 m/s into the wall, 1 m/s along it
    wx, wy, impulse, heat = bounce(TABLE, wall, vx, vy, nx, ny, 2.0, 4, 9)
    after, slide = respond(TABLE, wall, 3.0, 1.0, 2.0, 4, 9)
    assert wx * nx + wy * ny == pytest.approx(after, abs=1e-14)
    assert wy * nx - wx * ny == pytest.approx(slide, abs=1e-14)
    assert impulse == pytest.approx(2.0 * (3.0 - after), rel=1e-14)
    assert heat == pytest.approx(0.5 * 2.0 * (wx**2 + wy**2 - 10.0), abs=1e-12)
