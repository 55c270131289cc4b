"""Precompiling the presets' kernels (`collidium.precompile`)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from collidium.kernels.audit import PARALLEL_FROM
from collidium.precompile import _LARGE_GAS_PARAMETERS, LARGE_GAS, groups
from collidium.presets import PRESETS, preset
from collidium.runner import prepare

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
from bench_first_run import timed_run  # the benchmarks folder is not a package


def test_two_groups_hold_every_preset_once_the_neutral_apart_from_those_under_forces():
    neutral, forced = groups(2)
    assert sorted(neutral + forced) == sorted([*PRESETS, LARGE_GAS])
    assert LARGE_GAS in neutral
    assert not any(preset(name).forces for name in neutral if name != LARGE_GAS)
    assert all(preset(name).forces for name in forced)
    assert groups(1) == [[*PRESETS, LARGE_GAS]]


def test_the_large_gas_has_its_passes_run_in_parallel():
    sim, _ = prepare(preset("gas", **_LARGE_GAS_PARAMETERS))
    assert sim.particles.n >= PARALLEL_FROM


def test_an_unknown_preset_gets_one_line_and_exit_2_before_anything_compiles():
    run = subprocess.run([sys.executable, "-m", "collidium.precompile", "gas", "nosuch"],
                         capture_output=True, text=True, timeout=120)  # fmt: skip
    assert run.returncode == 2
    assert run.stdout == ""
    assert run.stderr.startswith("collidium: preset: unknown preset 'nosuch'; choose from head-on")
    assert run.stderr.count("\n") == 1


@pytest.mark.slow
def test_a_run_after_precompiling_its_preset_compiles_nothing(tmp_path):
    subprocess.run([sys.executable, "-m", "collidium.precompile", "head-on"],
                   env=os.environ | {"NUMBA_CACHE_DIR": str(tmp_path)},
                   check=True, timeout=600)  # fmt: skip
    # F1's run: 100 steps, flown between the summary's readings, counting what numba compiled
    assert timed_run("head-on", str(tmp_path))["compiled"] == 0
