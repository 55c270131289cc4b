"""Shared fixtures: the random generator of the tests (shared helpers live in lattices.py)."""

from __future__ import annotations

import numpy as np
import pytest


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(20241203)
