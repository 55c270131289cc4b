"""Fuzzing the command line's inputs: random edits of a scenario file (TOML trees, numbers at the
edges of float64, deep nesting, unicode) and random ``--set`` values. Each case must end in exit 0,
or in one line naming the field and exit 1 (a failed run) or 2 (bad input): never a traceback, a
warning line or a hang."""

from __future__ import annotations

import math
import signal
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import pytest
import tomli_w
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from collidium.cli import main
from collidium.loading import load_scenario

#: Longest a case may take, s: far beyond what a 20-disk scenario needs for one step.
CASE_SECONDS = 30

#: Field names of scenario files, and a few that are not.
KEYS = [
    "seed", "name", "run", "dt", "time", "collisions", "integrator", "tolerance", "restitution",
    "vessel", "shape", "width", "height", "radius", "boundary", "vertices", "walls", "left",
    "response", "temperature", "partitions", "start", "end", "gap", "particles", "kind", "n",
    "mass", "speed", "charge", "charges", "position", "velocity", "region", "forces", "type", "k",
    "softening", "observers", "every", "interval", "after", "bins", "range", "partition", "0",
    "1", "é", "🙂", "a b",
]  # fmt: skip

EDGE_NUMBERS = [
    0, -1, 2**31, 2**63, -(2**63) - 1, 10**400, 0.0, -0.0, 5e-324, 2.2e-308, 1e-300, 1e300,
    1.7976931348623157e308, -1.7976931348623157e308, math.inf, -math.inf, math.nan,
]  # fmt: skip

keys = st.sampled_from(KEYS)
scalars = st.one_of(
    st.sampled_from(EDGE_NUMBERS),
    st.integers(min_value=-(10**6), max_value=3000),  # no count that takes minutes to place
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=8),
    st.booleans(),
)
values = st.recursive(
    scalars,
    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(keys, inner, max_size=3),
    max_leaves=8,
)


def deep(depth: int) -> dict[str, Any]:
    """A table nested ``depth`` levels."""
    table: dict[str, Any] = {"a": 1}
    for _ in range(depth):
        table = {"a": table}
    return table


def leaves(data: Any, path: tuple[str, ...] = ()) -> Iterator[list[str]]:
    """The paths to the values of a scenario's data."""
    items = data.items() if isinstance(data, dict) else enumerate(data)
    for key, value in items:
        tables = isinstance(value, list) and value and isinstance(value[0], dict)
        if isinstance(value, dict) or tables:
            yield from leaves(value, (*path, str(key)))
        else:
            yield [*path, str(key)]


#: A charged gas of 20 disks: its forces and integrator settings are fuzzed too.
BASE = load_scenario("charged-gas", n=20).to_dict()
# Mostly the fields a scenario has, which then reach the build and the run; also any keys.
paths = st.sampled_from(list(leaves(BASE))) | st.lists(keys, min_size=1, max_size=4)
edits = st.lists(
    st.tuples(paths, st.one_of(scalars, scalars, values, st.integers(20, 400).map(deep))),
    max_size=3,
)


def edited(data: dict[str, Any], changes: list[tuple[list[str], Any]]) -> dict[str, Any]:
    """``data`` with each value put at its path, tables made on the way (lists addressed by
    index where the key is one)."""
    for path, value in changes:
        node: Any = data
        for key in path[:-1]:
            if isinstance(node, list) and key.isdigit() and int(key) < len(node):
                node = node[int(key)]
            elif isinstance(node, dict):
                node = node.setdefault(key, {})
            else:
                break
        else:
            if isinstance(node, dict):
                node[path[-1]] = value
    return data


@contextmanager
def bounded(seconds: int) -> Iterator[None]:
    """Fail a case that runs longer than ``seconds`` (a hang)."""

    def timeout(signum: int, frame: object) -> None:
        raise AssertionError(f"no answer within {seconds} s")

    previous = signal.signal(signal.SIGALRM, timeout)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)


def answers_in_one_line(args: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    """Run the command line in this process: exit 0, or 1 or 2 with one ``error:`` line; no
    warning on the way."""
    capsys.readouterr()
    with bounded(CASE_SECONDS), warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        code = main(args)
    err = capsys.readouterr().err
    assert not caught, [str(w.message) for w in caught]
    if code == 0:
        assert err == ""
        return
    assert code in (1, 2), code
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), err


@settings(max_examples=60, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(edits)
def test_random_scenario_files_get_one_line_or_run(tmp_path_factory, capsys, changes):
    import copy

    data = edited(copy.deepcopy(BASE), changes)
    try:
        text = tomli_w.dumps(data)
    except (TypeError, ValueError):  # not representable in TOML (a key path through a list...)
        return
    file = tmp_path_factory.mktemp("fuzz") / "scenario.toml"
    file.write_text(text, encoding="utf-8")
    answers_in_one_line(["run", str(file), "--steps", "1", "--json"], capsys)


setting_text = st.one_of(
    st.sampled_from(EDGE_NUMBERS).map(repr),
    st.text(max_size=12),
    st.sampled_from(["[", "{a = 1}", "1e999", "-inf", "nan", "[[1, 2], [3]]", '"x"', "9" * 5000]),
    values.map(lambda v: tomli_w.dumps({"v": v})[4:].strip() if not isinstance(v, dict) else "{}"),
)


@settings(max_examples=60, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.lists(st.sampled_from(KEYS), min_size=1, max_size=3).map(".".join), setting_text)
def test_random_settings_get_one_line_or_run(capsys, key, text):
    answers_in_one_line(["run", "gas", "--set", "n=20", "--set", f"{key}={text}", "--steps", "1",
                         "--json"], capsys)  # fmt: skip
