"""Observables, files and figures. Run: ``python benchmarks/bench_observables.py [--quick]``.

O1  cost of measuring: the exact gas (packing 0.3) run bare, and with what ``collidium run``
    attaches (energy drift every step, temperature/pressure and collision rate sampled), and with
    a GSD frame every 10 steps: wall seconds and the ratio to the bare run.
O2  files: GSD writing (frames/s, bytes per particle per frame), checkpoint save and restore
    (seconds, bytes per particle) at N = 1e5.
O3  movie: milliseconds per frame for MP4 and GIF (charged gas, 200 disks).
O4  physics: compressibility Z = P A / (N kT) of the periodic hard-disk fluid against Henderson's
    equation of state, and wall against virial pressure in a box.

Prints a table and writes ``benchmarks/results/observables.json``.
"""

from __future__ import annotations

import argparse
import json
import math
import tempfile
import time
from pathlib import Path

import numpy as np

import collidium as cd
from collidium.io.trajectory import GSDWriter, read_trajectory
from collidium.observers import CollisionRate, EnergyDrift, Every, Thermo
from collidium.render import write_movie
from collidium.runner import SAMPLES
from collidium.theory import hard_disk_compressibility

RESULTS = Path(__file__).parent / "results"


def fluid(n: int, packing: float, boundary: str = "reflecting", seed: int = 1) -> cd.Simulation:
    """About N disks of radius 0.25 m at the packing fraction (a square lattice melted), kT = 1 J,
    relaxed for 20 s."""
    radius = 0.25
    per_side = round(math.sqrt(n))
    side = math.sqrt(per_side**2 * math.pi * radius**2 / packing)
    rng = np.random.default_rng(seed)
    spacing = side / per_side
    grid = (np.arange(per_side) + 0.5) * spacing - side / 2
    position = np.stack(np.meshgrid(grid, grid), axis=-1).reshape(-1, 2)
    position += rng.uniform(-1, 1, position.shape) * (0.5 * spacing - radius)
    velocity = rng.normal(0.0, 1.0, position.shape)
    sim = cd.Simulation(cd.Box(side, side, boundary), cd.Particles(position, velocity,
                        radius=radius), dt=0.05)  # fmt: skip
    return sim.run(time=20.0)


def timed(sim: cd.Simulation, steps: int) -> float:
    start = time.perf_counter()
    sim.run(steps=steps)
    return time.perf_counter() - start


def measuring_cost(n: int, steps: int) -> dict[str, float]:
    """O1: the same run bare, measured, and measured with a trajectory."""
    bare = timed(fluid(n, 0.3), steps)
    sim = fluid(n, 0.3)
    period = max(1, steps // SAMPLES)  # as `collidium run` samples
    sim.observers += [EnergyDrift(), Thermo(period), CollisionRate(period)]
    measured = timed(sim, steps)
    with tempfile.TemporaryDirectory() as folder:
        sim = fluid(n, 0.3)
        writer = GSDWriter(Path(folder) / "run.gsd", Every(10))
        sim.observers += [EnergyDrift(), Thermo(period), CollisionRate(period), writer]
        written = timed(sim, steps)
        writer.close()
    return {"n": n, "steps": steps, "bare_s": bare, "measured_s": measured, "gsd_s": written}


def file_speed(n: int, frames: int) -> dict[str, float]:
    """O2: GSD frames per second and size; checkpoint save/restore time and size."""
    sim = fluid(n, 0.3)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "run.gsd"
        writer = GSDWriter(path, Every(1), flush_seconds=0.0)
        sim.observers.append(writer)
        start = time.perf_counter()
        sim.run(steps=frames - 1)
        writer.close()
        gsd_seconds = time.perf_counter() - start
        gsd_bytes = path.stat().st_size
        sim.observers.clear()
        checkpoint = Path(folder) / "run.ckpt"
        start = time.perf_counter()
        sim.save(checkpoint)
        save_seconds = time.perf_counter() - start
        start = time.perf_counter()
        cd.restore(checkpoint)
        restore_seconds = time.perf_counter() - start
        checkpoint_bytes = checkpoint.stat().st_size
    return {
        "n": n,
        "gsd_frames_per_second": frames / gsd_seconds,
        "gsd_bytes_per_particle_frame": gsd_bytes / (n * frames),
        "checkpoint_save_s": save_seconds,
        "checkpoint_restore_s": restore_seconds,
        "checkpoint_bytes_per_particle": checkpoint_bytes / n,
    }


def movie_speed(frames: int) -> dict[str, float]:
    """O3: rendering milliseconds per frame."""
    out: dict[str, float] = {"frames": frames}
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "run.gsd"
        sim = cd.load("charged-gas")
        with GSDWriter(path, Every(5)) as writer:
            sim.observers.append(writer)
            sim.run(steps=5 * (frames - 1))
        trajectory = read_trajectory(path)
        for suffix in ("mp4", "gif"):
            start = time.perf_counter()
            write_movie(trajectory, Path(folder) / f"movie.{suffix}")
            out[f"{suffix}_ms_per_frame"] = 1e3 * (time.perf_counter() - start) / frames
    return out


def physics(n: int, duration: float) -> list[dict[str, float]]:
    """O4: Z against Henderson (periodic) and wall against virial pressure (box)."""
    rows = []
    for packing in (0.05, 0.3, 0.5):
        sim = fluid(n, packing, "periodic")
        thermo = Thermo()
        sim.observers.append(thermo)
        sim.run(time=duration)
        scale = thermo.area / (thermo.n * thermo.temperature)
        box = fluid(n, packing)
        walls = Thermo()
        box.observers.append(walls)
        box.run(time=duration)
        rows.append({
            "packing": packing,
            "z": thermo.compressibility(),
            "z_error": thermo.virial_pressure_error() * scale,
            "z_henderson": hard_disk_compressibility(packing),
            "wall_pressure": walls.wall_pressure()["total"],
            "wall_error": walls.wall_pressure_error(),
            "virial_pressure": walls.virial_pressure(),
            "virial_error": walls.virial_pressure_error(),
        })  # fmt: skip
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="smaller sizes, for a smoke test")
    args = parser.parse_args()
    o1 = measuring_cost(10_000, 200 if args.quick else 2_000)
    o2 = file_speed(10_000 if args.quick else 100_000, 20 if args.quick else 100)
    o3 = movie_speed(20 if args.quick else 100)
    o4 = physics(400 if args.quick else 2_500, 100.0 if args.quick else 400.0)

    print(f"{'workload':<52}{'figure':>14}{'ratio':>10}")
    print(f"{'O1 exact gas N=1e4, bare run, wall s':<52}{o1['bare_s']:>14.3f}")
    for key, label in (("measured_s", "with run's measurements"), ("gsd_s", "and GSD/10 steps")):
        print(f"{'O1   ' + label + ', wall s':<52}{o1[key]:>14.3f}{o1[key] / o1['bare_s']:>9.2f}x")
    print(f"{'O2 GSD frames/s at N=' + format(o2['n'], ',') :<52}"
          f"{o2['gsd_frames_per_second']:>14.1f}")  # fmt: skip
    print(f"{'O2 GSD bytes per particle per frame':<52}{o2['gsd_bytes_per_particle_frame']:>14.1f}")
    print(f"{'O2 checkpoint save / restore, s':<52}"
          f"{o2['checkpoint_save_s']:>7.3f} /{o2['checkpoint_restore_s']:>6.3f}")  # fmt: skip
    print(f"{'O2 checkpoint bytes per particle':<52}{o2['checkpoint_bytes_per_particle']:>14.1f}")
    for suffix in ("mp4", "gif"):
        print(f"{'O3 movie ' + suffix + ', ms per frame':<52}{o3[suffix + '_ms_per_frame']:>14.1f}")
    for row in o4:
        print(f"O4 eta={row['packing']:<4} Z={row['z']:.4f}±{row['z_error']:.4f} "
              f"(Henderson {row['z_henderson']:.4f}); box: wall {row['wall_pressure']:.4g}"
              f"±{row['wall_error']:.2g}, virial {row['virial_pressure']:.4g}"
              f"±{row['virial_error']:.2g} N/m")  # fmt: skip
    RESULTS.mkdir(exist_ok=True)
    out = {"o1_measuring": o1, "o2_files": o2, "o3_movie": o3, "o4_physics": o4}
    (RESULTS / "observables.json").write_text(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
