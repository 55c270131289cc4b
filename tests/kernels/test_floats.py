"""The largest magnitude by bit patterns against NumPy's ``max(abs(values))``."""

from __future__ import annotations

import math

import numpy as np
import pytest

from collidium.kernels.floats import largest_magnitude


@pytest.mark.parametrize("size", [1, 2, 3, 7, 200, 1001])
def test_largest_magnitude_is_numpys(rng, size):
    """Every size the vectorised loop may split (remainders included), signed values spread
    over many orders of magnitude, subnormals and signed zeros among them: the same float."""
    values = rng.normal(0.0, 1.0, (size, 2)) * 10.0 ** rng.uniform(-320, 300, (size, 2))
    values[0, 1] = -0.0
    assert largest_magnitude(values) == float(np.max(np.abs(values)))
    values[size // 2, size % 2] = -np.inf
    assert largest_magnitude(values) == math.inf


@pytest.mark.parametrize("where", [(0, 0), (5, 1), (199, 1)])
def test_a_nan_anywhere_gives_nan(rng, where):
    """A NaN is kept wherever it is, even beside an infinity, as in NumPy's maximum."""
    values = rng.normal(0.0, 1.0, (200, 2))
    values[100, 0] = np.inf
    values[where] = np.nan
    assert math.isnan(largest_magnitude(values))
    assert math.isnan(float(np.max(np.abs(values))))


def test_no_values_give_zero():
    assert largest_magnitude(np.empty((0, 2))) == 0.0
