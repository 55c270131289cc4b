"""The kernels package: how numba's OpenMP threads wait between parallel loops."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from collidium.kernels import OPENMP_SPINS

PROBE = "import os, collidium.kernels; print(os.environ['GOMP_SPINCOUNT'])"


@pytest.mark.parametrize(("given", "expected"), [(None, str(OPENMP_SPINS)), ("123", "123")])
def test_openmp_threads_spin_briefly_unless_the_environment_says(given, expected):
    # GNU OpenMP reads the spin count when numba starts its threads, after collidium's import.
    env = {key: value for key, value in os.environ.items() if key != "GOMP_SPINCOUNT"}
    if given is not None:
        env["GOMP_SPINCOUNT"] = given
    probe = subprocess.run([sys.executable, "-c", PROBE], env=env, capture_output=True,
                           text=True, check=True)  # fmt: skip
    assert probe.stdout.strip() == expected
