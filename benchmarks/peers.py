"""Peer workloads: the benchmark suite's jobs run in REBOUND and pymunk, for side-by-side ratios.

Each function builds the peer simulation from plain parameters, runs a warm-up, then times the
peer's own stepping with :func:`time.perf_counter` (set-up excluded) and returns a dict of plain,
JSON-serialisable values. Every call is kept to roughly ``max_seconds`` of timed work (plus set-up
and warm-up), so the suite can sweep N from 1e3 to 1e6; where even one step would blow that budget
the function says so (``measured: False``) and gives an estimate instead of running for minutes.

The peers are imported inside the functions, so this module imports without them;
:func:`available` reports which are installed. Large pymunk runs go to a child Python, since
freeing a used pymunk space takes minutes at N = 1e6 (see :func:`pymunk_balls`).

Workloads
---------
:func:`rebound_hard_disks`
    REBOUND hard-sphere gas (tree collision search, leapfrog, fixed step) made 2D.
:func:`rebound_gravity`
    REBOUND direct ("basic") and Barnes-Hut ("tree") gravity on a uniform square of particles,
    with the tree's RMS relative force error measured at the same N.
:func:`rebound_opening_angle_scan`, :func:`rebound_theta_1e3`
    REBOUND tree force error and step time against opening angle; the angle for ~1e-3 error.
:func:`pymunk_balls`
    pymunk (Chipmunk2D) elastic frictionless balls in a box of static segments.
"""

from __future__ import annotations

import ctypes
import json
import math
import subprocess
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

#: REBOUND tree opening angles giving an RMS relative force error of ~1e-3 (at most ~1.05e-3) on
#: a uniform square, by N. The error goes as theta^2 (monopole cells; this wheel's tree carries no
#: quadrupoles) and at fixed angle grows with N, so matched accuracy needs smaller angles. Measured
#: (seed 1): N = 1e3: 0.13 -> 8.9e-4; 5e3: 0.13 -> 9.7e-4; 2e4: 0.10 -> 9.1e-4 (0.13 -> 1.6e-3);
#: 1e5: 0.10 -> 1.05e-3, 0.09 -> 8.7e-4 (0.13 -> 1.9e-3).
REBOUND_THETA_1E3: dict[int, float] = {5_000: 0.13, 20_000: 0.10, 100_000: 0.09}


def rebound_theta_1e3(n: int) -> float:
    """REBOUND opening angle for ~1e-3 RMS relative force error at ``n`` (table above).

    Uses the entry of the smallest tabulated N >= ``n`` (the safe side), the last one beyond.
    """
    for size, theta in sorted(REBOUND_THETA_1E3.items()):
        if n <= size:
            return theta
    return REBOUND_THETA_1E3[max(REBOUND_THETA_1E3)]


#: REBOUND's own default opening angle (``opening_angle2 = 0.25``), ~3e-2 RMS relative error.
REBOUND_THETA_DEFAULT = 0.5


def available() -> dict[str, str | None]:
    """Version of each peer library, or None where it cannot be imported.

    Returns
    -------
    dict
        ``{"rebound": "5.2.2" | None, "pymunk": "7.3.1" | None}``.
    """
    versions: dict[str, str | None] = {}
    try:
        import rebound

        versions["rebound"] = str(rebound.__version__)
    except (ImportError, OSError):  # OSError: the C library failed to load
        versions["rebound"] = None
    try:
        import pymunk

        versions["pymunk"] = str(pymunk.version)
    except (ImportError, OSError):
        versions["pymunk"] = None
    return versions


# --------------------------------------------------------------------------------------------
# Shared set-up
# --------------------------------------------------------------------------------------------


def gas_box_side(n: int, packing: float, radius: float) -> float:
    """Side of the square box holding ``n`` disks of ``radius`` at area fraction ``packing``."""
    return math.sqrt(n * math.pi * radius**2 / packing)


def jittered_lattice(n: int, side: float, radius: float, rng: np.random.Generator) -> np.ndarray:
    """``n`` non-overlapping disk centres in ``[0, side)^2``.

    Each centre sits at a random place inside its own cell of a square lattice (``n`` cells chosen
    at random from the smallest square lattice with at least ``n``), so no two disks overlap, none
    crosses the box edge, and none overlaps across a periodic edge either.

    Raises
    ------
    ValueError
        If the lattice cells are too small for the disks (packing too high for this start).
    """
    k = math.ceil(math.sqrt(n))
    spacing = side / k
    room = 0.5 * spacing - radius
    if room <= 0.0:
        raise ValueError(f"packing too high for a lattice start: cell {spacing:.3g} < 2r")
    grid = (np.arange(k) + 0.5) * spacing
    cells = np.stack(np.meshgrid(grid, grid), axis=-1).reshape(-1, 2)
    cells = cells[rng.choice(len(cells), n, replace=False)]
    return cells + rng.uniform(-room, room, cells.shape)


def enskog_collision_rate(packing: float, radius: float, temperature: float) -> float:
    """Enskog collision frequency per disk (collisions per disk per unit time) in 2D.

    ``nu = 2 sigma n g(sigma) sqrt(pi T)`` with diameter ``sigma = 2r``, number density
    ``n = packing / (pi r^2)``, ``T = kT/m`` the per-component velocity variance and Henderson's
    contact value ``g(sigma) = (1 - 7 eta / 16) / (1 - eta)^2``. It is the yardstick for how many
    collisions a fixed-step code misses (exact event-driven codes land within ~1 % of it).
    """
    eta = packing
    contact = (1.0 - 7.0 * eta / 16.0) / (1.0 - eta) ** 2
    density = eta / (math.pi * radius**2)
    return 2.0 * (2.0 * radius) * density * contact * math.sqrt(math.pi * temperature)


# --------------------------------------------------------------------------------------------
# REBOUND helpers
# --------------------------------------------------------------------------------------------


def _rebound_add(sim: Any, position: np.ndarray, velocity: np.ndarray, mass: float, r: float):
    """Add particles through the C entry point: ~1 us each, 5x faster than ``sim.add(**kw)``.

    ``sim.add`` cannot be skipped by adding placeholders and bulk-setting positions afterwards: the
    tree inserts each particle where it is added, and coincident placeholders break it.
    """
    import rebound

    add = rebound.clibrebound.reb_simulation_add
    ref = ctypes.byref(sim)
    p = rebound.Particle()
    p.m, p.r = mass, r
    for (x, y), (vx, vy) in zip(position.tolist(), velocity.tolist(), strict=True):
        p.x, p.y, p.vx, p.vy = x, y, vx, vy
        add(ref, p)


def _rebound_doubles(sim: Any) -> np.ndarray:
    """The particle array as an (N, fields) view of doubles (numpy cannot read the struct)."""
    import rebound

    width = ctypes.sizeof(rebound.Particle) // 8
    flat = ctypes.cast(sim._particles, ctypes.POINTER(ctypes.c_double))
    return np.ctypeslib.as_array(flat, shape=(sim.N * width,)).reshape(sim.N, width)


def _rebound_acceleration(sim: Any) -> np.ndarray:
    """In-plane accelerations ``(ax, ay)`` left in the particles by the last force evaluation."""
    import rebound

    at = rebound.Particle.ax.offset // 8
    return _rebound_doubles(sim)[:, at : at + 2].copy()


def direct_accelerations(
    position: np.ndarray, mass: float, index: np.ndarray, softening: float, g: float = 1.0
) -> np.ndarray:
    """Exact softened gravitational accelerations on the particles ``index`` (NumPy, chunked).

    Same law as REBOUND: ``a_i = G sum_j m (x_j - x_i) / (|x_j - x_i|^2 + eps^2)^(3/2)``.
    """
    out = np.empty((len(index), 2))
    chunk = max(1, int(4e6 // len(position)))  # keeps the (chunk, N) temporaries ~100 MB
    for start in range(0, len(index), chunk):
        rows = index[start : start + chunk]
        d = position[None, :, :] - position[rows, None, :]
        r2 = np.einsum("ijk,ijk->ij", d, d) + softening**2
        r2[np.arange(len(rows)), rows] = np.inf  # no self-force
        w = r2**-1.5
        out[start : start + len(rows)] = g * mass * np.einsum("ij,ijk->ik", w, d)
    return out


def _rms_relative_error(approx: np.ndarray, exact: np.ndarray) -> float:
    """RMS over particles of ``|a_approx - a_exact| / |a_exact|``."""
    rel = np.linalg.norm(approx - exact, axis=1) / np.linalg.norm(exact, axis=1)
    return float(np.sqrt(np.mean(rel**2)))


def _error_samples(n: int) -> int:
    """How many particles to check exactly: all up to 5000, then ~2e8 pair terms, at least 200."""
    return int(min(n, 5000, max(200, 2e8 // n)))


# --------------------------------------------------------------------------------------------
# REBOUND hard-sphere gas
# --------------------------------------------------------------------------------------------


def rebound_hard_disks(
    n: int,
    packing: float = 0.3,
    radius: float = 0.25,
    target_collisions: int = 100_000,
    max_seconds: float = 5.0,
    displacement: float = 0.05,
    warmup_time: float = 1.0,
    flatten_every: int = 50,
    seed: int = 1,
) -> dict[str, Any]:
    """Time REBOUND's hard-sphere gas: tree collision search, leapfrog, fixed step, 2D.

    ``n`` unit-mass disks of ``radius`` at area fraction ``packing`` in a periodic square of side
    ``sqrt(n pi r^2 / packing)``, centres on a jittered lattice, velocities normal(0, 1) per
    component, all ``z = vz = 0``. ``sim.collision = "tree"``, ``collision_resolve =
    "hardsphere"`` (restitution 1: REBOUND's default when no coefficient function is set),
    ``gravity = "none"``, leapfrog with ``dt = displacement * radius / v_rms`` so the RMS distance
    a disk moves per step is ``displacement`` radii.

    The boundary is periodic (REBOUND's hard walls do not exist; "open" removes leavers), with one
    ring of ghost boxes in x and y so that collisions across the periodic edges are found.

    REBOUND is 3D: its hard-sphere resolve rotates by ``atan2(dz, dy)``, which for ``dz = 0`` and
    ``dy < 0`` is pi, whose sine is 1.2e-16, not 0. That seeds ``vz`` at round-off, chaos grows it
    by ~e^4 per unit time and after ~7 time units disks pass over each other (the collision rate
    collapses). So every ``flatten_every`` steps ``z`` and ``vz`` are reset to 0 (an O(N) copy,
    counted in the timing; at most a few per cent of a step).

    Collisions are REBOUND's own counter ``sim.collisions_log_n``, incremented once per resolved
    collision in ``reb_collision_resolve_hardsphere``. The tree search reports each overlapping,
    approaching pair twice (from each side), but the second report finds the pair already
    receding and returns before counting, so the counter is one per physical collision (checked:
    it matches the Enskog rate to within the few per cent that the fixed step misses).

    Parameters
    ----------
    n, packing, radius
        Number of disks, area fraction and disk radius (m).
    target_collisions
        Stop timing once this many collisions were counted ...
    max_seconds
        ... or once this much wall time was spent timing, whichever comes first (at least one
        step). The warm-up gets at most half as much again.
    displacement
        RMS distance travelled per step, in radii (0.05: ~3 % of collisions missed; 0.025: ~1 %).
    warmup_time
        Simulated time run before timing, so the lattice start has relaxed (~5 collisions per
        disk), unless the warm-up budget runs out first.
    flatten_every
        Steps between resets of ``z``, ``vz`` (see above).
    seed
        Seed of the NumPy generator for positions and velocities.

    Returns
    -------
    dict
        ``peer, version, n, packing, radius, side, boundary, ghost_boxes, collision,
        collision_resolve, restitution, integrator, dt, dt_rule, rms_speed, warmup_steps,
        flatten_every, steps, simulated_time, collisions, collision_counter, seconds,
        seconds_per_step, collisions_per_second, particle_steps_per_second,
        collision_rate_per_particle, enskog_rate_per_particle, fraction_of_enskog, relaxed,
        enskog_collisions_per_second``.
        ``fraction_of_enskog`` is the measured collision rate over the Enskog estimate: ~0.97 at
        the default step once relaxed, i.e. roughly the share of collisions a fixed step still
        finds. ``relaxed`` is False when the budget cut the warm-up short of ``warmup_time``
        (N >~ 1e5): the lattice start then has too few disks in contact and the measured rate is
        low (0.86-0.96 of Enskog at N = 1e5 after ~0.1 time units, 0.16-0.19 at 1e6 after 0.02),
        so compare ``enskog_collisions_per_second`` instead: the collisions of an equilibrium gas
        simulated per wall second at the measured stepping speed (a fixed-step tree search costs
        about the same per step whatever the collision count).
    """
    import rebound

    rng = np.random.default_rng(seed)
    side = gas_box_side(n, packing, radius)
    position = jittered_lattice(n, side, radius, rng) - 0.5 * side  # REBOUND's box is centred
    velocity = rng.normal(0.0, 1.0, (n, 2))
    rms_speed = float(np.sqrt(np.mean(np.sum(velocity**2, axis=1))))

    sim = rebound.Simulation()
    sim.root_size = side  # one root box: REBOUND loops over all root boxes for every particle
    sim.N_root_x, sim.N_root_y, sim.N_root_z = 1, 1, 1
    sim.boundary = "periodic"
    sim.N_ghost_x, sim.N_ghost_y, sim.N_ghost_z = 1, 1, 0
    sim.gravity = "none"
    sim.collision = "tree"
    sim.collision_resolve = "hardsphere"
    sim.integrator = "leapfrog"
    sim.dt = displacement * radius / rms_speed
    _rebound_add(sim, position, velocity, 1.0, radius)

    xyz, vxyz = np.zeros((n, 3)), np.zeros((n, 3))

    def run(steps: int) -> None:
        """``steps`` leapfrog steps, flattening back to the plane every ``flatten_every``."""
        while steps > 0:
            k = min(steps, chunk)
            sim.steps(k)
            sim.serialize_particle_data(xyz=xyz, vxvyvz=vxyz)
            xyz[:, 2] = 0.0
            vxyz[:, 2] = 0.0
            sim.set_serialized_particle_data(xyz=xyz, vxvyvz=vxyz)
            steps -= k

    # Warm-up: one step to learn the cost, then relax for warmup_time within the warm-up budget.
    chunk = 1
    start = time.perf_counter()
    run(1)
    per_step = time.perf_counter() - start
    chunk = max(1, min(flatten_every, int(0.1 * max_seconds / per_step)))
    warmup_steps = 1 + min(
        max(0, math.ceil(warmup_time / sim.dt) - 1), int(0.5 * max_seconds / per_step)
    )
    run(warmup_steps - 1)
    relaxed = bool(sim.t >= warmup_time * (1.0 - 1e-9))

    # Timed part: whole chunks until the collision target or the time budget is reached.
    c0, t0, steps = sim.collisions_log_n, sim.t, 0
    start = time.perf_counter()
    while True:
        run(chunk)
        steps += chunk
        seconds = time.perf_counter() - start
        if sim.collisions_log_n - c0 >= target_collisions or seconds >= max_seconds:
            break
    collisions = int(sim.collisions_log_n - c0)
    simulated = float(sim.t - t0)

    temperature = float(np.mean(vxyz[:, :2] ** 2))  # kT/m per component, after the run
    measured_rate = 2.0 * collisions / (n * simulated)  # two disks per collision
    enskog = enskog_collision_rate(packing, radius, temperature)
    return {
        "peer": "rebound",
        "version": str(rebound.__version__),
        "n": n,
        "packing": packing,
        "radius": radius,
        "side": side,
        "boundary": "periodic",
        "ghost_boxes": 1,
        "collision": "tree",
        "collision_resolve": "hardsphere",
        "restitution": 1.0,
        "integrator": "leapfrog",
        "dt": float(sim.dt),
        "dt_rule": f"rms displacement per step = {displacement} radius",
        "rms_speed": rms_speed,
        "warmup_steps": warmup_steps,
        "flatten_every": chunk,
        "steps": steps,
        "simulated_time": simulated,
        "collisions": collisions,
        "collision_counter": "sim.collisions_log_n",
        "seconds": seconds,
        "seconds_per_step": seconds / steps,
        "collisions_per_second": collisions / seconds,
        "particle_steps_per_second": n * steps / seconds,
        "collision_rate_per_particle": measured_rate,
        "enskog_rate_per_particle": enskog,
        "fraction_of_enskog": measured_rate / enskog,
        "relaxed": relaxed,
        "enskog_collisions_per_second": 0.5 * n * enskog * simulated / seconds,
    }


# --------------------------------------------------------------------------------------------
# REBOUND gravity
# --------------------------------------------------------------------------------------------


def _rebound_gravity_sim(
    position: np.ndarray, method: str, theta: float, softening: float, dt: float
) -> Any:
    """REBOUND simulation of equal masses 1/N at ``position`` (centred square), G = 1."""
    import rebound

    n = len(position)
    side = float(np.ptp(position, axis=0).max())
    sim = rebound.Simulation()
    sim.G = 1.0
    sim.softening = softening
    sim.integrator = "leapfrog"
    sim.dt = dt
    if method == "tree":
        # Open boundary, one root box a little larger than the particle square: nothing leaves
        # during the few timed steps, and no ghost boxes (periodic gravity would add images).
        sim.root_size = 1.05 * side
        sim.boundary = "open"
        sim.N_ghost_x, sim.N_ghost_y, sim.N_ghost_z = 0, 0, 0
        sim.opening_angle2 = theta**2
    sim.gravity = method
    _rebound_add(sim, position, np.zeros_like(position), 1.0 / n, 0.0)
    return sim


def _uniform_square(n: int, seed: int) -> np.ndarray:
    """``n`` points uniform in a centred square of side sqrt(n) (unit number density)."""
    side = math.sqrt(n)
    return np.random.default_rng(seed).uniform(-0.5 * side, 0.5 * side, (n, 2))


def _one_step_seconds(position: np.ndarray, method: str, theta: float, softening: float) -> float:
    """Wall seconds of one REBOUND step (used to size runs before committing to them)."""
    sim = _rebound_gravity_sim(position, method, theta, softening, 1e-3)
    start = time.perf_counter()
    sim.steps(1)
    return time.perf_counter() - start


def rebound_gravity(
    n: int,
    method: str = "basic",
    steps: int | None = None,
    theta: float | None = None,
    softening: float = 0.01,
    max_seconds: float = 10.0,
    measure_error: bool = True,
    seed: int = 1,
) -> dict[str, Any]:
    """Time REBOUND's direct ("basic") or Barnes-Hut ("tree") gravity, 2D, leapfrog.

    ``n`` particles of mass 1/N uniform in a square of side sqrt(N) (unit number density),
    ``z = 0``, at rest, ``G = 1``, Plummer softening ``softening`` (1 % of the mean spacing),
    fixed ``dt = 1e-3`` (nothing moves appreciably: the timing is of the force evaluation plus
    the O(N) drift/kick). For the tree: one root box of side 1.05 sqrt(N), open boundary, no
    ghost boxes, ``opening_angle2 = theta**2``.

    The tree's RMS relative force error is measured at this same N from the warm-up step (taken
    at the initial positions) against an exact NumPy direct sum on a sample of particles (all of
    them up to N = 5000).

    Parameters
    ----------
    n
        Number of particles.
    method
        ``"basic"`` (all pairs, O(N^2); REBOUND sums each pair once and applies it to both) or
        ``"tree"``.
    steps
        Timed steps; default as many as fit in ``max_seconds`` (at least 1, at most 1000).
    theta
        Tree opening angle; default :func:`rebound_theta_1e3` of ``n`` (RMS relative error
        ~1e-3, the accuracy our tree targets). Pass :data:`REBOUND_THETA_DEFAULT` (0.5) for
        REBOUND's own default (~3e-2).
    softening
        Plummer softening length.
    max_seconds
        Budget for the timed steps. If a probe at smaller N predicts that one step would take
        over twice this, nothing is run at full N and ``measured`` is False, with the predicted
        figures (N^2 scaling for basic, N^1.5 for the tree: conservative, cache misses make
        REBOUND's tree grow faster than N log N here).
    measure_error
        Measure the tree's force error (costs a direct sum on the sample).
    seed
        Seed of the NumPy generator for positions.

    Returns
    -------
    dict
        ``peer, version, n, method, measured, G, softening, dt, integrator, steps, seconds,
        seconds_per_step, us_per_particle_step, particle_steps_per_second`` and, for basic,
        ``pair_interactions_per_second`` (counting N(N-1) per step as our W2 does; REBOUND
        evaluates N(N-1)/2 symmetric pairs), for the tree ``theta, opening_angle2, box,
        boundary, force_error_rms, force_error_samples``. When ``measured`` is False:
        ``probe_n`` and ``reason``, and the rates are predictions.
    """
    import rebound

    if method not in ("basic", "tree"):
        raise ValueError(f"method must be 'basic' or 'tree', not {method!r}")
    theta = rebound_theta_1e3(n) if theta is None else float(theta)
    dt = 1e-3
    result: dict[str, Any] = {
        "peer": "rebound",
        "version": str(rebound.__version__),
        "n": n,
        "method": method,
        "G": 1.0,
        "softening": softening,
        "dt": dt,
        "integrator": "leapfrog",
    }
    if method == "tree":
        result |= {
            "theta": theta,
            "opening_angle2": theta**2,
            "box": "one root box, side 1.05 sqrt(N), open boundary, no ghost boxes",
            "boundary": "open",
        }

    def rates(seconds_per_step: float) -> dict[str, float]:
        out = {
            "seconds_per_step": seconds_per_step,
            "us_per_particle_step": 1e6 * seconds_per_step / n,
            "particle_steps_per_second": n / seconds_per_step,
        }
        if method == "basic":
            out["pair_interactions_per_second"] = n * (n - 1) / seconds_per_step
        return out

    # Probe at a smaller N so a hopeless run (basic at 1e6: hours) is not started.
    probe_n = min(n, 2000 if method == "basic" else 10_000)
    if probe_n < n:
        probe = _one_step_seconds(_uniform_square(probe_n, seed), method, theta, softening)
        exponent = 2.0 if method == "basic" else 1.5
        predicted = probe * (n / probe_n) ** exponent
        if predicted > 2.0 * max_seconds:
            return result | {
                "measured": False,
                "probe_n": probe_n,
                "reason": f"one step predicted {predicted:.3g} s > 2 x max_seconds",
                "steps": 0,
                "seconds": 0.0,
                **rates(predicted),
            }

    position = _uniform_square(n, seed)
    sim = _rebound_gravity_sim(position, method, theta, softening, dt)

    # Warm-up step: the velocities are zero, so its forces are those at `position`.
    start = time.perf_counter()
    sim.steps(1)
    warm = time.perf_counter() - start
    if method == "tree" and measure_error:
        m = _error_samples(n)
        index = np.sort(np.random.default_rng(seed + 1).choice(n, m, replace=False))
        exact = direct_accelerations(position, 1.0 / n, index, softening)
        approx = _rebound_acceleration(sim)[index]
        result["force_error_rms"] = _rms_relative_error(approx, exact)
        result["force_error_samples"] = m

    if steps is None:
        steps = int(min(1000, max(1, max_seconds / max(warm, 1e-9))))
    start = time.perf_counter()
    sim.steps(steps)
    seconds = time.perf_counter() - start
    return result | {"measured": True, "steps": steps, "seconds": seconds, **rates(seconds / steps)}


def rebound_opening_angle_scan(
    n: int = 5000,
    thetas: Sequence[float] = (0.1, 0.12, 0.13, 0.14, 0.16, 0.2, 0.3, 0.5, 0.7),
    target: float = 1e-3,
    softening: float = 0.01,
    seed: int = 1,
) -> dict[str, Any]:
    """REBOUND tree RMS relative force error and step time against opening angle.

    Forces of one tree step per angle, on the same uniform square as :func:`rebound_gravity`,
    against REBOUND's own basic (direct) gravity on all ``n`` particles (``n`` up to ~2e4 stays
    cheap). Step times here are of single first steps: indicative only.

    Returns
    -------
    dict
        ``n, target, theta_for_target`` (largest angle scanned with error <= target, or None),
        ``basic_seconds_per_step`` and ``scan``: a list of ``{theta, force_error_rms,
        seconds_per_step}``.
    """
    position = _uniform_square(n, seed)
    basic = _rebound_gravity_sim(position, "basic", 0.0, softening, 1e-3)
    start = time.perf_counter()
    basic.steps(1)
    basic_seconds = time.perf_counter() - start
    exact = _rebound_acceleration(basic)
    scan = []
    for theta in thetas:
        tree = _rebound_gravity_sim(position, "tree", theta, softening, 1e-3)
        start = time.perf_counter()
        tree.steps(1)
        seconds = time.perf_counter() - start
        error = _rms_relative_error(_rebound_acceleration(tree), exact)
        scan.append({"theta": theta, "force_error_rms": error, "seconds_per_step": seconds})
    good = [s["theta"] for s in scan if s["force_error_rms"] <= target]
    return {
        "n": n,
        "target": target,
        "theta_for_target": max(good) if good else None,
        "basic_seconds_per_step": basic_seconds,
        "scan": scan,
    }


# --------------------------------------------------------------------------------------------
# pymunk
# --------------------------------------------------------------------------------------------


def pymunk_balls(
    n: int,
    packing: float = 0.3,
    radius: float = 0.25,
    steps: int | None = None,
    dt: float = 0.01,
    max_seconds: float = 5.0,
    spatial_hash: float | None = None,
    collision_slop: float = 1e-3,
    iterations: int = 10,
    threads: int = 1,
    seed: int = 1,
    isolate: bool | None = None,
) -> dict[str, Any]:
    """Time pymunk (Chipmunk2D) balls in a box: ``space.step(dt)``.

    ``n`` circles of ``radius``, mass 1, elasticity 1, friction 0, no gravity, no damping, in a
    square of side ``sqrt(n pi r^2 / packing)`` bounded by four static segments (elasticity 1,
    friction 0; thick, their inner faces on the box edges, so nothing tunnels out). Centres on a
    jittered lattice, velocities normal(0, 1) per component, fixed ``dt`` (0.01: our step mode).

    Chipmunk resolves contacts with an iterative impulse solver (``iterations`` per step), not
    exact events. Its ``collision_slop`` (allowed overlap) defaults to 0.1, meant for pixel
    units: 40 % of a 0.25 m disk, so it is set to ``collision_slop`` (1 mm) instead; this does not
    change the speed measurably.

    Parameters
    ----------
    n, packing, radius
        Number of balls, area fraction and radius (m).
    steps
        Timed steps; default as many as fit in ``max_seconds`` (at least 1, at most 10000).
    dt
        Time step (s).
    max_seconds
        Budget for the timed steps when ``steps`` is None.
    spatial_hash
        Cell size for ``space.use_spatial_hash(cell, 10 n)``; None keeps Chipmunk's default
        bounding-box tree, which measured 1.1-1.6x faster here at N = 1e4-1e5.
    collision_slop, iterations
        Chipmunk solver settings (see above; 10 iterations is Chipmunk's default).
    threads
        ``> 1`` uses Chipmunk's threaded solver (``Space(threaded=True)``, not on Windows).
    seed
        Seed of the NumPy generator for positions and velocities.
    isolate
        Run in a child Python that exits without tearing the space down; default for
        ``n >= 1e5``. Freeing a used space costs pymunk time growing faster than N (each shape
        removal filters Chipmunk's whole contact cache, bodies are unlinked from an array by
        linear search): ~2 s at N = 1e5, ~7 minutes at 1e6, against 35 s of set-up. The
        timing inside the child is the same; the child's start (~0.5 s) is not timed.

    Returns
    -------
    dict
        ``peer, version, n, packing, radius, side, dt, broadphase, iterations, collision_slop,
        threads, warmup_steps, steps, seconds, seconds_per_step, particle_steps_per_second,
        wall_seconds_per_simulated_second, kinetic_energy_drift`` (relative change of kinetic
        energy over the timed steps: a check that the balls stay elastic), ``isolated``.
    """
    kwargs = {
        "n": n,
        "packing": packing,
        "radius": radius,
        "steps": steps,
        "dt": dt,
        "max_seconds": max_seconds,
        "spatial_hash": spatial_hash,
        "collision_slop": collision_slop,
        "iterations": iterations,
        "threads": threads,
        "seed": seed,
    }
    if isolate is None:
        isolate = n >= 100_000
    if isolate:
        return _run_isolated("_pymunk_balls", kwargs) | {"isolated": True}
    return _pymunk_balls(**kwargs) | {"isolated": False}


def _run_isolated(function: str, kwargs: dict[str, Any]) -> dict[str, Any]:
    """``function(**kwargs)`` of this module in a child Python that skips its own teardown.

    ``function`` parks what it built in its ``keep_alive`` list, so nothing is freed when it
    returns; the child prints the JSON result as its last line and leaves with ``os._exit(0)``:
    no destructors run and the memory goes back to the OS at once.
    """
    code = (
        "import json, os, sys\n"
        f"sys.path.insert(0, {str(Path(__file__).resolve().parent)!r})\n"
        "import peers\n"
        "keep = []\n"
        f"result = peers.{function}(**json.loads(sys.argv[1]), keep_alive=keep)\n"
        "sys.stdout.write('\\n' + json.dumps(result) + '\\n')\n"
        "sys.stdout.flush()\n"
        "os._exit(0)\n"
    )
    child = subprocess.run(
        [sys.executable, "-c", code, json.dumps(kwargs)],
        capture_output=True,
        text=True,
        check=False,
    )
    if child.returncode != 0:
        raise RuntimeError(f"{function} failed in the child process:\n{child.stderr[-4000:]}")
    return json.loads(child.stdout.strip().splitlines()[-1])


def _pymunk_balls(
    n: int,
    packing: float,
    radius: float,
    steps: int | None,
    dt: float,
    max_seconds: float,
    spatial_hash: float | None,
    collision_slop: float,
    iterations: int,
    threads: int,
    seed: int,
    keep_alive: list[Any] | None = None,
) -> dict[str, Any]:
    """:func:`pymunk_balls` in this process; the space goes into ``keep_alive`` if given."""
    import pymunk

    rng = np.random.default_rng(seed)
    side = gas_box_side(n, packing, radius)
    position = jittered_lattice(n, side, radius, rng)
    velocity = rng.normal(0.0, 1.0, (n, 2))

    space = pymunk.Space(threaded=threads > 1)
    if threads > 1:
        space.threads = threads
    space.gravity = (0.0, 0.0)
    space.collision_slop = collision_slop
    space.iterations = iterations
    if spatial_hash is not None:
        space.use_spatial_hash(spatial_hash, 10 * n)
        broadphase = f"spatial hash (cell {spatial_hash}, count {10 * n})"
    else:
        broadphase = "bounding-box tree (Chipmunk default)"

    moment = pymunk.moment_for_circle(1.0, 0.0, radius)
    objects: list[Any] = []
    bodies = []
    for (x, y), (vx, vy) in zip(position.tolist(), velocity.tolist(), strict=True):
        body = pymunk.Body(1.0, moment)
        body.position = (x, y)
        body.velocity = (vx, vy)
        shape = pymunk.Circle(body, radius)
        shape.elasticity, shape.friction = 1.0, 0.0
        objects += (body, shape)
        bodies.append(body)
    w = max(1.0, radius)  # wall half-thickness
    corners = [(-w, -w), (side + w, -w), (side + w, side + w), (-w, side + w)]
    for a, b in zip(corners, corners[1:] + corners[:1], strict=True):
        wall = pymunk.Segment(space.static_body, a, b, w)
        wall.elasticity, wall.friction = 1.0, 0.0
        objects.append(wall)
    space.add(*objects)

    def kinetic() -> float:
        return 0.5 * sum(b.velocity.dot(b.velocity) for b in bodies)  # mass 1 kg

    # Warm-up (up to 20 steps, a fifth of the budget): the first steps build the broad phase and
    # the contact caches.
    start = time.perf_counter()
    space.step(dt)
    first = time.perf_counter() - start
    warmup_steps = 1 + min(19, int(0.2 * max_seconds / max(first, 1e-9)))
    for _ in range(warmup_steps - 1):
        space.step(dt)

    # Timed part: `steps` steps, or steps until max_seconds (a clock read is ~0.1 us, < 1e-3 of
    # a step even at N = 1e3).
    energy = kinetic()
    step, clock = space.step, time.perf_counter
    limit = 10_000 if steps is None else steps
    done = 0
    start = clock()
    while done < limit:
        step(dt)
        done += 1
        if steps is None and clock() - start >= max_seconds:
            break
    seconds = clock() - start
    steps = done
    if keep_alive is not None:
        keep_alive.append((space, objects, bodies))
    return {
        "peer": "pymunk",
        "version": str(pymunk.version),
        "n": n,
        "packing": packing,
        "radius": radius,
        "side": side,
        "dt": dt,
        "broadphase": broadphase,
        "iterations": iterations,
        "collision_slop": collision_slop,
        "threads": threads,
        "warmup_steps": warmup_steps,
        "steps": steps,
        "seconds": seconds,
        "seconds_per_step": seconds / steps,
        "particle_steps_per_second": n * steps / seconds,
        "wall_seconds_per_simulated_second": seconds / (steps * dt),
        "kinetic_energy_drift": kinetic() / energy - 1.0,
    }
