"""The piston's kernels against their NumPy twins: the response of a moving wall of mass M (its
contacts on parabolas are `collidium.kernels.parabolas.first_contact`'s)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from collidium.kernels import reference
from collidium.kernels.vessels import piston as pistons
from collidium.kernels.wall_responses import moving_wall


def approx(value: float) -> object:
    """Equal to round-off."""
    return pytest.approx(value, rel=1e-9, abs=1e-12)


@settings(max_examples=300, deadline=None)
@given(
    st.floats(-10.0, 10.0), st.floats(-10.0, 10.0), st.floats(0.1, 10.0),
    st.floats(0.1, 1000.0), st.floats(0.05, 1.0),
)  # fmt: skip
def test_moving_wall_equals_its_twin_and_conserves_momentum(outward, wall, m, big, e):
    got = moving_wall(outward, wall, m, big, e)
    np.testing.assert_allclose(got, reference.moving_wall(outward, wall, m, big, e), atol=1e-11)
    assert m * got[0] + big * got[1] == approx(m * outward + big * wall)
    # Relative normal velocity reversed and scaled by e.
    assert got[0] - got[1] == approx(-e * (outward - wall))


def test_elastic_moving_wall_conserves_energy_and_a_driven_one_keeps_its_speed():
    w, u = moving_wall(3.0, -1.0, 1.0, 5.0, 1.0)
    assert 0.5 * w * w + 2.5 * u * u == approx(0.5 * 9.0 + 2.5 * 1.0)
    w, u = moving_wall(3.0, -1.0, 1.0, math.inf, 1.0)
    assert (w, u) == (-5.0, -1.0)  # reflected in the wall's frame: 4 m/s in, 4 m/s out


def test_piston_at_an_end_bounces_when_free_and_stops_when_driven():
    piston = np.zeros(pistons.PISTON_SIZE)
    piston[[pistons.HEIGHT, pistons.SPEED, pistons.MASS, pistons.LOW, pistons.HIGH]] = (
        0.0, 2.0, 1.0, -5.0, 4.0,
    )  # fmt: skip
    pistons.schedule(piston)
    assert piston[pistons.NEXT] == 2.0
    pistons.arrive(piston)
    assert (piston[pistons.HEIGHT], piston[pistons.SPEED]) == (4.0, -2.0)
    assert piston[pistons.NEXT] == 2.0 + 4.5  # 9 m back to the low end at 2 m/s
    piston[pistons.DRIVEN] = 1.0
    pistons.arrive(piston)
    assert (piston[pistons.HEIGHT], piston[pistons.SPEED]) == (-5.0, 0.0)
    assert math.isinf(piston[pistons.NEXT])
