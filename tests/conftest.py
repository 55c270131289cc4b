"""Shared fixtures: the random generator of the tests (shared helpers live in lattices.py), and
hypothesis's settings."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import settings

# No deadline per example: the property tests assert values, never speed (benchmarks/ times
# things), and a shared two-core machine stalls a worker for a second now and then (a TOML
# round trip of 1 ms once took 1.05 s beside the other worker compiling kernels).
settings.register_profile("collidium", deadline=None)
settings.load_profile("collidium")


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(20241203)
