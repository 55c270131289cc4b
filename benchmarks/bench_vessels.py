"""Vessels. Run: ``python benchmarks/bench_vessels.py [--quick] [--rounds 4]``.

V1  the exact hard-disk gas at packing 0.3 (one thread), N = 1e5, in a box, a circle and a
    regular 12-sided polygon of the same area: pair collisions per second, and the circle's and
    the polygon's rates over the box's. The shapes are measured in alternating rounds in the same
    run (the machine may be shared), so the ratios are given per round as well as their range.

Prints a table and writes ``benchmarks/results/vessels.json``.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numba

import collidium as cd
from collidium.vessels import regular_polygon

sys.path.insert(0, str(Path(__file__).parent))
from bench_core import PACKING, RADIUS, exact_collisions_per_second

RESULTS = Path(__file__).parent / "results"


def vessels_of_area(n: int) -> dict[str, cd.vessels.Vessel]:
    """A square box, a circle and a regular 12-gon, each of the area that holds ``n`` disks at
    `PACKING`."""
    area = n * math.pi * RADIUS**2 / PACKING
    corners = 12
    circumradius = math.sqrt(2.0 * area / (corners * math.sin(2.0 * math.pi / corners)))
    return {
        "box": cd.Box(math.sqrt(area), math.sqrt(area)),
        "circle": cd.Circle(math.sqrt(area / math.pi)),
        "12-gon": regular_polygon(corners, circumradius),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="N = 1e4, for a smoke test")
    parser.add_argument("--rounds", type=int, default=4, help="alternating rounds of the shapes")
    args = parser.parse_args()
    n = 10_000 if args.quick else 100_000
    numba.set_num_threads(1)
    shapes = vessels_of_area(n)
    rounds = []
    for k in range(args.rounds):
        rates = {name: exact_collisions_per_second(n, 2e5 if args.quick else 2e6, 1, vessel)
                 ["per_second"] for name, vessel in shapes.items()}  # fmt: skip
        for name in ("circle", "12-gon"):
            rates[f"{name}_over_box"] = rates[name] / rates["box"]
        rounds.append(rates)
        measured = ", ".join(f"{name} {rates[name]:.3g}/s" for name in shapes)
        versus = f"{rates['circle_over_box']:.2f}, {rates['12-gon_over_box']:.2f}"
        print(f"round {k + 1}: {measured}; ratios to the box {versus}")
    ranges = {}
    for name in ("circle", "12-gon"):
        ratios = [r[f"{name}_over_box"] for r in rounds]
        ranges[name] = [min(ratios), max(ratios)]
        print(f"V1 N = {n}: {name} / box = {min(ratios):.2f} .. {max(ratios):.2f}")
    RESULTS.mkdir(exist_ok=True)
    out = {"n": n, "packing": PACKING, "rounds": rounds, "ratio_range": ranges}
    (RESULTS / "vessels.json").write_text(json.dumps(out, indent=2) + "\n")


if __name__ == "__main__":
    main()
