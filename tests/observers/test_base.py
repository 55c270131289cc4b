"""Triggers: every K steps, every T seconds, after a time, any callable."""

from __future__ import annotations

import pytest

import collidium as cd
from collidium.errors import InputError
from collidium.observers import After, Every, Interval, Measurement, Observer
from collidium.observers.base import as_trigger


class Record:
    """Observer that notes the steps and times it fired at."""

    def __init__(self, trigger):
        self.trigger = trigger
        self.attached = 0
        self.steps: list[int] = []
        self.times: list[float] = []

    def attach(self, sim):
        self.attached += 1

    def update(self, sim):
        self.steps.append(sim.steps)
        self.times.append(sim.time)


def _fired(trigger, steps=100, dt=0.01):
    sim = cd.load("head-on", dt=dt)
    record = Record(trigger)
    sim.observers.append(record)
    sim.run(steps=steps)
    return record


def test_every_k_steps():
    assert _fired(Every(25)).steps == [25, 50, 75, 100]


def test_interval_fires_on_the_first_step_at_or_past_each_multiple():
    # 0.1 s is not a whole number of steps of 0.03 s: fires at 0.12, 0.21, 0.3 (exact multiple).
    record = _fired(Interval(0.1), steps=10, dt=0.03)
    assert record.steps == [4, 7, 10]
    # An interval that is a whole number of steps fires exactly on the multiples despite
    # round-off in k * dt.
    assert _fired(Interval(0.1), steps=50).steps == [10, 20, 30, 40, 50]


def test_after_a_time_then_another_trigger():
    assert _fired(After(0.5, Every(20))).steps == [60, 80, 100]
    assert _fired(After(0.95)).steps == [95, 96, 97, 98, 99, 100]


def test_callable_and_whole_number_triggers():
    assert _fired(lambda sim: sim.steps in (3, 7)).steps == [3, 7]
    assert as_trigger(30) == Every(30)
    assert as_trigger(None) == Every(1)


@pytest.mark.parametrize(
    ("make", "field"),
    [(lambda: Every(0), "trigger.period"), (lambda: Interval(-1.0), "trigger.interval"),
     (lambda: After(float("nan")), "trigger.after"), (lambda: as_trigger("often"), "trigger")],
)  # fmt: skip
def test_bad_triggers_name_the_field(make, field):
    with pytest.raises(InputError) as caught:
        make()
    assert caught.value.field == field


def test_observer_is_attached_once_across_runs():
    sim = cd.load("head-on")
    record = Record(Every(10))
    sim.observers.append(record)
    sim.run(steps=20).run(steps=20)
    assert record.attached == 1
    assert record.steps == [10, 20, 30, 40]
    assert isinstance(record, Observer)


def test_measurement_base_requires_compute():
    with pytest.raises(NotImplementedError):
        Measurement().compute(cd.load("head-on"))


def test_windows_start_at_the_run_or_when_an_after_trigger_opens():
    from collidium.observers import SpeedHistogram, Thermo

    sim = cd.load("gas")
    from_start, later, snapshots = (
        Thermo(Every(10)),
        Thermo(After(2.0, Every(10))),
        SpeedHistogram(trigger=Every(100)),
    )
    sim.observers += [from_start, later, snapshots]
    sim.run(time=5.0)
    assert from_start.duration == pytest.approx(5.0)
    assert later.duration == pytest.approx(3.0)
    assert snapshots.frames == 5  # the trigger's snapshots only, not the starting state
