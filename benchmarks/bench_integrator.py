"""Time stepping. Run: ``python benchmarks/bench_integrator.py [--time 60]``.

I1  the seed's charged scenes at their defaults (dt = 0.01 s): wall seconds and the largest
    relative energy error ``max |E(t) - E(0)| / |E(0)|`` over every step, with the fixed and the
    adaptive integrator side by side (charged-gas, bohr-atom, charged-no-collisions, orbit,
    charged-opposite, charged-like).
I2  energy error against tolerance: the adaptive integrator on orbit, bohr-atom and
    charged-no-collisions (20 s) at tolerances from twice the default down to an eighth of it;
    second order, so halving the tolerance quarters it.
I3  the cost of accuracy in the charged gas: charged-gas over I1's time at tolerances from 6e-3
    down to 1e-3, each with its cost against the fixed step timed in the same run (the target:
    max |dE/E| <= 1e-5 over 60 s at no more than 3x the fixed step's cost).
I4  where the error lies, the seed's charged scenes at tolerances from 2e-3 to 6e-3: beside the
    energy error of the state shown (processed, `collidium.kernels.processing`), that of the
    integrator's own state and of its modified energy ``S = H + h^2 (Q / 12 - P / 24)``, which
    kick-drift-kick keeps between contacts and the integrator where the substep changes: the
    contacts and the higher orders move S, and the processing leaves ``h^2 P / 24`` of H's
    swing about it. Every step, in NumPy (minutes).

Prints a table and writes ``benchmarks/results/integrator.json`` (``--only I3`` runs one part).
"""

from __future__ import annotations

import argparse
import json
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

import collidium as cd
from collidium.forces import Coulomb
from collidium.integrators import DEFAULT_TOLERANCE
from collidium.kernels.reference import inverse_distance_direct, modified_energy_terms
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
TOLERANCES = tuple(DEFAULT_TOLERANCE * 2.0**-k for k in range(-1, 4))


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


GAS_TOLERANCES = (6e-3, 4e-3, DEFAULT_TOLERANCE, 2e-3, 1e-3)


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


SPLIT_SCENES = {"charged-gas": 60.0, "charged-opposite": 60.0, "charged-like": 60.0,
                "orbit": 60.0, "bohr-atom": 20.0, "charged-no-collisions": 20.0}  # fmt: skip
SPLIT_TOLERANCES = (2e-3, 3e-3, 4e-3, 6e-3)


def split_errors(name: str, tolerance: float, seconds: float) -> dict[str, float]:
    """Largest relative errors over ``seconds`` of ``name``, every step: of the energy of the
    state shown (processed), of the integrator's own state, and of that state's modified
    energy."""
    sim = cd.load(name, tolerance=tolerance)
    p, (law,) = sim.particles, sim.forces
    assert isinstance(law, Coulomb)
    mass, charge = np.broadcast_to(p.mass, (p.n,)), np.broadcast_to(p.charge, (p.n,))
    laws = (charge[None, :], np.array([law.k]), np.array([law.softening**2]))
    start = sim.energy().total
    shown, own, modified, substeps = [], [], [], []
    for _ in range(round(seconds / sim.dt)):
        sim.run(steps=1)
        h = sim._integrator.substep
        behind = sim._integrator._shown  # the integrator's own state
        position, velocity = (p.position, p.velocity) if behind is None else (
            behind.position, behind.velocity)  # fmt: skip
        force, halves, _ = inverse_distance_direct(position, charge, law.k, law.softening**2)
        curvature, pulls = modified_energy_terms(position, velocity, force / mass[:, None], mass,
                                                 laws)  # fmt: skip
        shown.append(sim.energy().total)
        own.append(0.5 * float(np.sum(mass[:, None] * velocity**2)) + float(halves.sum()))
        modified.append(own[-1] + h * h * (curvature / 12.0 - pulls / 24.0))
        substeps.append(sim.dt / h)

    def worst(values: list[float], origin: float) -> float:
        return float(np.max(np.abs(np.array(values) - origin)) / abs(start))

    return {"shown": worst(shown, start), "own": worst(own, own[0]),
            "modified": worst(modified, modified[0]),
            "substeps_per_dt": float(np.mean(substeps))}  # fmt: skip


def error_split() -> list[dict[str, object]]:
    """I4: the shown state's energy error beside the integrator's own and its modified
    energy's."""
    rows = []
    for name, seconds in SPLIT_SCENES.items():
        for tolerance in SPLIT_TOLERANCES:
            errors = split_errors(name, tolerance, seconds)
            rows.append({"scene": name, "time": seconds, "tolerance": tolerance} | errors)
            print(
                f"{name:18s} {seconds:4g} s tolerance {tolerance:.1e}: "
                f"{errors['substeps_per_dt']:5.1f} substeps a dt; max |dE/E| shown "
                f"{errors['shown']:.2e}, own {errors['own']:.2e}, its modified energy "
                f"{errors['modified']:.2e}",
                flush=True,
            )
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--time", type=float, default=60.0, help="simulated seconds for I1")
    parser.add_argument(
        "--only",
        choices=("I1", "I2", "I3", "I4"),
        help="run one part (the others' results are kept)",
    )
    args = parser.parse_args()
    parts: dict[str, tuple[str, Callable[..., list[dict[str, object]]], tuple[float, ...]]]
    parts = {"scenes": ("I1", scenes, (args.time,)), "tolerance": ("I2", against_tolerance, ()),
             "gas_cost": ("I3", gas_cost, (args.time,)),
             "error_split": ("I4", error_split, ())}  # fmt: skip
    results = {key: run(*arguments) for key, (name, run, arguments) in parts.items()
               if args.only in (None, name)}  # fmt: skip
    RESULTS.mkdir(exist_ok=True)
    path = RESULTS / "integrator.json"
    kept = json.loads(path.read_text()) if path.exists() and args.only else {}
    path.write_text(json.dumps(kept | results, indent=2))


if __name__ == "__main__":
    main()
