"""Scenarios are built in a worker process within a time budget."""

from __future__ import annotations

import pytest

from collidium.errors import InputError
from collidium.presets import preset
from collidium.viewer.builder import Builder


@pytest.fixture
def builder():
    built = Builder()
    yield built
    built.close()


def test_worker_builds_the_simulation_of_a_scenario(builder):
    sim = builder.build(preset("charged-gas", n=50))
    reference = preset("charged-gas", n=50).build()
    assert sim.particles.n == 50 and sim.observers == []
    assert (sim.particles.position == reference.particles.position).all()
    assert sim.energy().total == reference.energy().total


def test_a_build_over_budget_gets_one_line_and_the_next_build_works(builder):
    """50 000 disks take far more than a millisecond to place: the worker is stopped, the
    request named, and a new worker serves the next one."""
    builder.budget = 1e-3
    with pytest.raises(InputError) as refused:
        builder.build(preset("gas", n=50_000, radius=0.03), field="n")
    assert refused.value.field == "n" and "took over 0.001 s to build" in refused.value.reason
    builder.budget = 60.0
    assert builder.build(preset("gas", n=30)).particles.n == 30


def test_the_scenarios_own_errors_come_back_with_their_field(builder):
    with pytest.raises(InputError) as refused:
        builder.build(preset("gas", n=65_000, radius=0.03))
    assert refused.value.field == "particles.0.n" and "too dense" in refused.value.reason
    assert builder.build(preset("gas", n=30)).particles.n == 30  # the worker goes on
