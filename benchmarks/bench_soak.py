"""Soak and traps. Run: ``python benchmarks/bench_soak.py [--collisions 1e8] [--quick]``.

S1  a dense gas (packing 0.7 of the plane, hexagonal lattice start, one disk at 1000 m/s) in a
    box, a circle and a five-pointed star (five reflex corners), each run to ``--collisions``
    pair collisions: escapes (the audit stops a run that loses a disk), overlapping pairs
    checked after every step, and the largest relative energy error over the run, which must
    stay within 1e-11 (round-off over 1e8 collisions).
S2  disks packed in one corner of a large box (200 000 of radius 0.05 m in 100 m x 100 m of a
    10 km box): seconds to build the simulation and to take its first step, in the exact and the
    step mode, against the same disks filling a 100 m box (the peer: no trap). The cell grids
    cover the disks' surroundings, not the vessel's area, so the two are alike.

Prints a table and writes ``benchmarks/results/soak.json``.
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import numpy as np

import collidium as cd
from collidium.initial import hexagonal_positions
from collidium.kernels.cells import first_overlap, grid_shape, grid_window, window_sides
from collidium.scenario import Scenario

RESULTS = Path(__file__).parent / "results"
RADIUS = 0.25
PACKING = 0.7
ENERGY_TARGET = 1e-11

#: A five-pointed star: five reflex corners.
STAR = cd.Polygon([
    [r * math.cos(math.pi / 2 + k * math.pi / 5), r * math.sin(math.pi / 2 + k * math.pi / 5)]
    for k, r in zip(range(10), [20.0, 9.0] * 5, strict=True)
])  # fmt: skip
VESSELS = {"box": cd.Box(24.0, 24.0), "circle": cd.Circle(13.5), "star": STAR}


def overlaps(sim: cd.Simulation) -> bool:
    """Whether any two disks overlap now (`first_overlap` on the disks' cells)."""
    p, vessel = sim.particles, sim.container
    width, height = (float(side) for side in vessel.extent)
    window = grid_window(p.position, 2 * RADIUS, (width, height), vessel.periodic)
    shape = grid_shape(*window_sides(window), 2 * RADIUS, p.n)
    pair = first_overlap(p.position, p.radius, width, height, vessel.periodic, window, *shape)
    return pair != (-1, -1)


def dense_gas(vessel: cd.vessels.Vessel, collisions: float) -> dict[str, float]:
    """S1 for one vessel."""
    rng = np.random.default_rng(1)
    position = hexagonal_positions(vessel, RADIUS, PACKING)
    n = len(position)
    velocity = rng.normal(0.0, 1.0, (n, 2))
    velocity[n // 2] = [1000.0 * math.cos(0.3), 1000.0 * math.sin(0.3)]
    sim = cd.Simulation(vessel, cd.Particles(position, velocity, radius=RADIUS), dt=0.5)
    energy = sim.energy().total
    worst, overlapped, start = 0.0, 0, time.perf_counter()
    while sim.counters.pair_collisions < collisions:
        sim.run(steps=1)  # the audit checks after every step that no disk left
        overlapped += overlaps(sim)
        worst = max(worst, abs(sim.energy().total - energy) / energy)
    wall = time.perf_counter() - start
    return {"n": n, "pair_collisions": sim.counters.pair_collisions,
            "wall_collisions": sim.counters.wall_collisions, "escaped": sim.escaped(),
            "steps_with_overlaps": overlapped, "max_rel_energy_error": worst,
            "wall_seconds": wall}  # fmt: skip


def clustered(n: int, side: float, mode: str) -> dict[str, float]:
    """S2: ``n`` disks at random in the 100 m corner of a box ``side`` m wide."""
    corner = [[-side / 2, -side / 2], [-side / 2 + 100.0, -side / 2 + 100.0]]
    start = time.perf_counter()
    sim = Scenario.from_dict({
        "name": "cluster", "vessel": {"width": side, "height": side},
        "run": {"dt": 0.01, "time": 0.01, "collisions": mode},
        "particles": [{"kind": "random", "n": n, "radius": 0.05, "speed": 1.0, "region": corner}],
    }).build()  # fmt: skip
    built = time.perf_counter()
    sim.run(steps=1)
    return {"build_seconds": built - start, "first_step_seconds": time.perf_counter() - built}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--collisions", type=float, default=1e8, help="pair collisions per run")
    parser.add_argument("--quick", action="store_true", help="1e6 collisions, 20 000 disks")
    args = parser.parse_args()
    collisions = 1e6 if args.quick else args.collisions
    n = 20_000 if args.quick else 200_000
    clustered(1000, 1e4, "exact")  # the kernels are compiled before the clock starts
    clustered(1000, 1e4, "step")
    out: dict[str, object] = {"S1": {}, "S2": {}}
    for name, vessel in VESSELS.items():
        row = dense_gas(vessel, collisions)
        out["S1"][name] = row  # type: ignore[index]
        verdict = "ok" if row["max_rel_energy_error"] <= ENERGY_TARGET else "OVER"
        print(f"S1 {name:6s} N = {row['n']}: {row['pair_collisions']:.3g} collisions, "
              f"{row['wall_collisions']:.3g} wall hits, escaped {row['escaped']}, steps with "
              f"overlaps {row['steps_with_overlaps']}, max |dE/E| "
              f"{row['max_rel_energy_error']:.2e} ({verdict}) in {row['wall_seconds']:.0f} s",
              flush=True)  # fmt: skip
    for mode in ("exact", "step"):
        for label, side in (("corner of 10 km", 1e4), ("filling 100 m", 100.0)):
            row = clustered(n, side, mode)
            out["S2"][f"{mode}, {label}"] = row  # type: ignore[index]
            print(f"S2 {mode:5s} {n} disks, {label:15s}: build {row['build_seconds']:.2f} s, "
                  f"first step {row['first_step_seconds']:.2f} s", flush=True)  # fmt: skip
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "soak.json").write_text(json.dumps(out, indent=2) + "\n")


if __name__ == "__main__":
    main()
