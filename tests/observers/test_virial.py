"""The virial ratio of the bound cluster: exact on a circular binary, escapers left out."""

from __future__ import annotations

import math

import numpy as np
import pytest

import collidium as cd
from collidium import Box, Newton, Particles
from collidium.observers import VirialRatio
from collidium.scenario import build_observers


def _binary_and_escaper(escaper_speed: float) -> cd.Simulation:
    """Two 4 kg masses 2 m apart on a circular orbit (G = 1: v = sqrt(G m / (2 d)) = 1 m/s)
    and a 1 kg mass 8 m away at ``escaper_speed``."""
    particles = Particles(
        [[-1.0, 0.0], [1.0, 0.0], [0.0, 8.0]],
        velocity=[[0.0, -1.0], [0.0, 1.0], [escaper_speed, 0.0]],
        mass=[4.0, 4.0, 1.0], radius=0.0,
    )  # fmt: skip
    return cd.Simulation(Box(40, 40), particles, forces=[Newton(G=1.0)], collisions="off")


def test_a_circular_binary_is_in_virial_equilibrium_and_an_escaper_is_left_out():
    """Fast enough to escape (1/2 v^2 > G (4 + 4) / 8 = 1 J/kg), the third mass is left out
    and the binary's 2 KE / |W| is 1 to round-off; slow, it is bound and counts."""
    fast = VirialRatio().compute(_binary_and_escaper(3.0))
    assert fast.bound[-1] == pytest.approx(2 / 3)
    assert fast.ratio[-1] == pytest.approx(1.0, rel=1e-14)
    slow = VirialRatio().compute(_binary_and_escaper(0.5))
    assert slow.bound[-1] == 1.0
    kinetic = 0.5 * 4 * 2 + 0.5 * 0.25
    virial = -16 / 2 - 2 * 4 / math.sqrt(1 + 64)  # sum r_ij . F_ij = U_ij for 1/r
    assert slow.ratio[-1] == pytest.approx(2 * kinetic / abs(virial), rel=1e-13)


def test_it_samples_over_a_run_and_sums_up():
    sim = _binary_and_escaper(3.0)
    sim.observers.append(VirialRatio(cd.observers.Interval(0.5)))
    sim.run(time=2.0)
    observer = sim.observers[0]
    assert observer.time.size == 5  # at the start, then every 0.5 s
    summary = observer.summary()
    # The passing mass's tide bends the orbit by about (m3 / M) (d / R)^3 = 2e-3.
    assert summary["mean_virial_ratio"] == pytest.approx(1.0, rel=5e-3)
    assert summary["bound_fraction"] == pytest.approx(2 / 3)
    assert np.isfinite(observer.plot().get_lines()[0].get_ydata()).all()


def test_a_scenario_file_names_it_virial():
    (observer,) = build_observers([{"kind": "virial", "interval": 1.0}])
    assert isinstance(observer, VirialRatio)
