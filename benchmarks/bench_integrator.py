"""Time stepping. Run: ``python benchmarks/bench_integrator.py [--time 60]``.

I1  the seed's charged scenes at their defaults (dt = 0.01 s): wall seconds and the largest
    relative energy error ``max |E(t) - E(0)| / |E(0)|`` over every step, with the fixed and the
    adaptive integrator side by side (charged-gas, bohr-atom, charged-no-collisions, orbit,
    charged-opposite, charged-like).
I2  energy error against tolerance: the adaptive integrator on orbit and bohr-atom (20 s) at
    tolerances from 4e-3 down to the default; second order, so halving the tolerance quarters it.

Prints a table and writes ``benchmarks/results/integrator.json``.
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
TOLERANCES = (4e-3, 2e-3, 1e-3, DEFAULT_TOLERANCE)


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
    for name in ("orbit", "bohr-atom"):
        for tolerance in TOLERANCES:
            wall, error = timed_drift(cd.load(name, tolerance=tolerance), seconds)
            rows.append({"scene": name, "tolerance": tolerance, "max_rel_drift": error,
                         "wall_seconds": wall})  # fmt: skip
            print(f"{name:22s} tolerance {tolerance:.1e}: {error:.2e} in {wall:.3g} s", flush=True)
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--time", type=float, default=60.0, help="simulated seconds for I1")
    args = parser.parse_args()
    results = {"scenes": scenes(args.time), "tolerance": against_tolerance()}
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "integrator.json").write_text(json.dumps(results, indent=2))


if __name__ == "__main__":
    main()
