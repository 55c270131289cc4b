"""Time stepping. Run: ``python benchmarks/bench_integrator.py [--time 60]``.

I1  the seed's charged scenes at their defaults (dt = 0.01 s): wall seconds and the largest
    relative energy error ``max |E(t) - E(0)| / |E(0)|`` over every step, with the fixed and the
    adaptive integrator side by side (charged-gas, bohr-atom, charged-no-collisions, orbit,
    charged-opposite, charged-like).
I2  energy error against tolerance: the adaptive integrator on orbit, bohr-atom and
    charged-no-collisions (20 s) at tolerances from 4e-3 down to a quarter of the default; second
    order, so halving the tolerance quarters it.
I3  the cost of accuracy in the charged gas: charged-gas over I1's time at tolerances from 6e-3
    down to 1e-3, each with its cost against the fixed step timed in the same run (the target:
    max |dE/E| <= 1e-5 over 60 s at no more than 3x the fixed step's cost).

Prints a table and writes ``benchmarks/results/integrator.json`` (``--only I3`` runs one part).
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import collidium as cd
from collidium.integrators import DEFAULT_TOLERANCE
from collidium.observers import EnergyDrift

RESULTS = Path(__file__).parent / "results"

SCENES = (
    "charged-gas",
    "bohr-atom",
    "charged-no-collisions",
    "orbit",
    "charged-opposite",
    "charged-like",
)
TOLERANCES = (4e-3, 2e-3, 1e-3, DEFAULT_TOLERANCE, DEFAULT_TOLERANCE / 2, DEFAULT_TOLERANCE / 4)


def timed_drift(sim: cd.Simulation, seconds: float) -> tuple[float, float]:
    """``(wall seconds, max relative energy error)`` of a run of ``seconds`` simulated."""
    drift = EnergyDrift()
    sim.observers.append(drift)
    sim.run(steps=0)  # the kernels are compiled before the clock starts
    start = time.perf_counter()
    sim.run(time=seconds)
    return time.perf_counter() - start, drift.max_rel_drift


def scenes(seconds: float) -> list[dict[str, object]]:
    """I1: every scene with both integrators."""
    rows: list[dict[str, object]] = []
    for name in SCENES:
        measured = {}
        for integrator in ("fixed", "adaptive"):
            cd.load(name, integrator=integrator).run(steps=2)  # compile
            wall, error = timed_drift(cd.load(name, integrator=integrator), seconds)
            measured[integrator] = {"wall_seconds": wall, "max_rel_drift": error}
        fixed, adaptive = measured["fixed"], measured["adaptive"]
        ratio = adaptive["wall_seconds"] / fixed["wall_seconds"]
        rows.append({"scene": name, "time": seconds, "cost_ratio": ratio} | measured)
        print(
            f"{name:22s} {seconds:4g} s  fixed {fixed['max_rel_drift']:.2e} in "
            f"{fixed['wall_seconds']:.3g} s   adaptive {adaptive['max_rel_drift']:.2e} in "
            f"{adaptive['wall_seconds']:.3g} s   cost x{ratio:.3g}",
            flush=True,
        )
    return rows


def against_tolerance(seconds: float = 20.0) -> list[dict[str, object]]:
    """I2: energy error against tolerance."""
    rows = []
    for name in ("orbit", "bohr-atom", "charged-no-collisions"):
        for tolerance in TOLERANCES:
            wall, error = timed_drift(cd.load(name, tolerance=tolerance), seconds)
            rows.append({"scene": name, "tolerance": tolerance, "max_rel_drift": error,
                         "wall_seconds": wall})  # fmt: skip
            print(f"{name:22s} tolerance {tolerance:.1e}: {error:.2e} in {wall:.3g} s", flush=True)
    return rows


GAS_TOLERANCES = (6e-3, 4e-3, 2.8e-3, DEFAULT_TOLERANCE, 1e-3)


def gas_cost(seconds: float) -> list[dict[str, object]]:
    """I3: charged-gas's energy error and cost against the fixed step, by tolerance."""
    cd.load("charged-gas", integrator="fixed").run(steps=2)  # compile
    fixed, _ = timed_drift(cd.load("charged-gas", integrator="fixed"), seconds)
    rows = []
    for tolerance in GAS_TOLERANCES:
        wall, error = timed_drift(cd.load("charged-gas", tolerance=tolerance), seconds)
        rows.append({"scene": "charged-gas", "time": seconds, "tolerance": tolerance,
                     "max_rel_drift": error, "wall_seconds": wall,
                     "cost_ratio": wall / fixed})  # fmt: skip
        print(
            f"charged-gas {seconds:4g} s tolerance {tolerance:.1e}: {error:.2e} in "
            f"{wall:.3g} s, cost x{wall / fixed:.3g} of the fixed step",
            flush=True,
        )
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--time", type=float, default=60.0, help="simulated seconds for I1")
    parser.add_argument(
        "--only", choices=("I1", "I2", "I3"), help="run one part (the others' results are kept)"
    )
    args = parser.parse_args()
    parts = {"scenes": ("I1", scenes, (args.time,)), "tolerance": ("I2", against_tolerance, ()),
             "gas_cost": ("I3", gas_cost, (args.time,))}  # fmt: skip
    results = {key: run(*arguments) for key, (name, run, arguments) in parts.items()
               if args.only in (None, name)}  # fmt: skip
    RESULTS.mkdir(exist_ok=True)
    path = RESULTS / "integrator.json"
    kept = json.loads(path.read_text()) if path.exists() and args.only else {}
    path.write_text(json.dumps(kept | results, indent=2))


if __name__ == "__main__":
    main()
