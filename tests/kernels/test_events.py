"""The event-driven engine against the brute-force NumPy twin (all pairs at every event)."""

from __future__ import annotations

import numpy as np
import pytest
from test_event_queue import earliest_slot

from collidium import Box, Circle, Gravity, Particles, Simulation, collisions, load
from collidium.kernels import audit, cells, events, reference
from collidium.kernels.events import contact_delay
from collidium.kernels.vessels import BOX, CIRCLE, box
from lattices import jittered_lattice


def test_contact_delay_head_on():
    # Centres 2 apart, closing at 4 m/s, contact distance 0.5: touch after 1.5 / 4 s.
    assert contact_delay(2.0, 0.0, -4.0, 0.0, 0.5) == pytest.approx(0.375, rel=1e-15)
    assert contact_delay(2.0, 0.0, 4.0, 0.0, 0.5) == np.inf  # separating
    assert contact_delay(2.0, 0.0, 0.0, 4.0, 0.5) == np.inf  # passing by


@pytest.mark.parametrize(
    ("boundary", "width", "duration"),
    [("reflecting", 20.0, 0.3), ("periodic", 6.0, 0.3), ("periodic", 1.3, 0.2)],
)
def test_engine_matches_brute_force_twin(rng, boundary, width, duration):
    """Same collisions, same final state. Round-off (1e-16) grows by a factor of order
    (mean free path / diameter) per collision in a chaotic gas; with ~50 collisions the
    trajectories still agree to ~1e-10 relative."""
    n_side = 12 if width > 10 else (6 if width > 2 else 2)
    r_max = 0.4 * width / n_side
    position = jittered_lattice(n_side, width, r_max, rng)
    n = len(position)
    velocity = rng.uniform(-10, 10, (n, 2))
    mass = rng.uniform(0.5, 2.0, n)
    radius = rng.uniform(0.3 * r_max, r_max, n)
    sim = Simulation(
        Box(width, width, boundary),
        Particles(position.copy(), velocity.copy(), mass=mass, radius=radius),
        dt=duration / 7,
    )
    sim.run(steps=7)
    twin_position, twin_velocity = position.copy(), velocity.copy()
    pairs, walls, virial, wall_impulse = reference.event_drift(
        twin_position, twin_velocity, mass, radius, np.array([width, width]) / 2, duration,
        periodic=boundary == "periodic",
    )  # fmt: skip
    assert pairs > 5
    assert sim.counters.pair_collisions == pairs
    assert sim.counters.wall_collisions == walls
    np.testing.assert_allclose(sim.tally.impulse, [virial, *wall_impulse], rtol=1e-9)
    np.testing.assert_allclose(sim.unwrapped_position(), twin_position, rtol=0, atol=1e-9 * width)
    np.testing.assert_allclose(sim.particles.velocity, twin_velocity, rtol=0, atol=1e-8 * 10)


def test_engine_matches_brute_force_twin_in_a_circle(rng):
    """The rim as an event: same collisions, rim hits and impulses, same final state as the
    all-pairs twin, to the round-off growth of a chaotic gas."""
    rim = 10.0
    position = jittered_lattice(10, 1.3 * rim, 0.4, rng)  # corners at 0.92 of the rim
    n = len(position)
    velocity = rng.uniform(-10, 10, (n, 2))
    mass = rng.uniform(0.5, 2.0, n)
    radius = rng.uniform(0.1, 0.4, n)
    sim = Simulation(
        Circle(rim), Particles(position.copy(), velocity.copy(), mass=mass, radius=radius), dt=0.1
    )
    sim.run(steps=7)
    twin_position, twin_velocity = position.copy(), velocity.copy()
    pairs, walls, virial, wall_impulse = reference.event_drift(
        twin_position, twin_velocity, mass, radius, np.array([rim, rim]), 0.7, rim=rim
    )
    assert pairs > 5 and walls > 5
    assert (sim.counters.pair_collisions, sim.counters.wall_hits["rim"]) == (pairs, walls)
    np.testing.assert_allclose(sim.tally.impulse[:2], [virial, *wall_impulse], rtol=1e-9)
    np.testing.assert_allclose(sim.particles.position, twin_position, rtol=0, atol=1e-9 * rim)
    np.testing.assert_allclose(sim.particles.velocity, twin_velocity, rtol=0, atol=1e-8 * 10)


@pytest.mark.parametrize("shape", ["box", "circle"])
def test_engine_under_gravity_matches_the_twin_on_parabolas(rng, shape):
    """Every disk falls on a parabola between events (pairs meet on straight relative paths,
    walls and the rim at roots of quadratics and quartics): the same collisions, hits and final
    state as the all-pairs twin flying the same parabolas, with the queue built once."""
    g = np.array([0.8, -9.0])
    size = 10.0
    width = 1.3 * size if shape == "circle" else 2.0 * size
    position = jittered_lattice(8, width, 0.4, rng)
    n = len(position)
    velocity = rng.uniform(-10, 10, (n, 2))
    mass = rng.uniform(0.5, 2.0, n)
    radius = rng.uniform(0.1, 0.4, n)
    vessel = Circle(size) if shape == "circle" else Box(width, width)
    sim = Simulation(vessel, Particles(position.copy(), velocity.copy(), mass=mass, radius=radius),
                     forces=[Gravity(g=g)], dt=0.1)  # fmt: skip
    sim.run(steps=7)
    twin_position, twin_velocity = position.copy(), velocity.copy()
    pairs, walls, virial, wall_impulse = reference.event_drift(
        twin_position, twin_velocity, mass, radius, np.array([size, size]), 0.7,
        rim=size if shape == "circle" else None, fall=g,
    )  # fmt: skip
    assert pairs > 5 and walls > 5
    assert sim._drift.rebuilds == 1
    assert (sim.counters.pair_collisions, sim.counters.wall_collisions) == (pairs, walls)
    np.testing.assert_allclose(sim.tally.impulse, [virial, *wall_impulse], rtol=1e-9)
    np.testing.assert_allclose(sim.particles.position, twin_position, rtol=0, atol=1e-9 * size)
    np.testing.assert_allclose(sim.particles.velocity, twin_velocity, rtol=0, atol=1e-8 * 10)


def test_cluster_spreading_in_a_large_box_matches_the_twin(rng, monkeypatch):
    """Disks packed in a corner of a large box: the engine's cells cover only the disks'
    surroundings (`cells.grid_window`, here for any number of disks), and a new window is made
    each time they spread out of it. Same collisions and final state as the all-pairs twin."""
    monkeypatch.setattr(cells, "WINDOW_FROM", 1)
    width = 60.0
    position = jittered_lattice(7, 6.0, 0.04, rng) - 26.0  # about the corner (-26, -26)
    n = len(position)
    velocity = rng.uniform(-10, 10, (n, 2))
    mass = rng.uniform(0.5, 2.0, n)
    radius = rng.uniform(0.02, 0.04, n)
    sim = Simulation(
        Box(width, width),
        Particles(position.copy(), velocity.copy(), mass=mass, radius=radius),
        dt=0.1,
    )
    state = sim._drift._rebuild(sim.particles, sim.container, 0.0, sim.tally.piston)
    assert state["head"].size * 20 < (width / 0.08) ** 2  # not a grid of the whole box
    sim.run(steps=6)
    assert sim._drift.rebuilds >= 3  # the window was made again as the disks spread
    twins = []
    for nudge in (0.0, 1e-15):  # the twin again from velocities 1e-15 apart: round-off's growth
        twin_position, twin_velocity = position.copy(), velocity * (1.0 + nudge)
        pairs, walls, *_ = reference.event_drift(
            twin_position, twin_velocity, mass, radius, np.array([width, width]) / 2, 0.6
        )
        twins.append((twin_position, twin_velocity))
    assert pairs > 10 and walls > 5
    assert (sim.counters.pair_collisions, sim.counters.wall_collisions) == (pairs, walls)
    (twin_position, twin_velocity), (nudged_position, nudged_velocity) = twins
    # A cluster amplifies round-off more than a spread gas: the engine (whose operations differ
    # from the twin's in round-off) agrees with it about as well as the nudged twin does.
    growth = max(np.abs(nudged_position - twin_position).max(), 1e-12)
    assert np.abs(sim.particles.position - twin_position).max() < 100 * growth
    growth = max(np.abs(nudged_velocity - twin_velocity).max(), 1e-12)
    assert np.abs(sim.particles.velocity - twin_velocity).max() < 100 * growth


def _dense_gas(boundary: str, rng: np.random.Generator) -> Simulation:
    position = jittered_lattice(20, 16.0, 0.3, rng)
    n = len(position)
    particles = Particles(position, rng.normal(0, 3, (n, 2)), radius=rng.uniform(0.15, 0.3, n))
    return Simulation(Box(16.0, 16.0, boundary), particles, dt=0.5)


@pytest.mark.parametrize("boundary", ["reflecting", "periodic"])
def test_slot_order_does_not_change_the_outcome(rng, boundary):
    """The engine re-sorts its memory by cell; every tie is broken by particle index, never by
    slot, so re-sorting after every event or never gives bit-for-bit the same run."""
    runs = []
    for interval in (0, 10**9):
        sim = _dense_gas(boundary, np.random.default_rng(7))
        sim._drift.sort_interval = interval  # events per particle between sorts (0: every event)
        sim.run(steps=4)
        runs.append(sim)
    a, b = runs
    assert a.counters.pair_collisions > 3000
    np.testing.assert_array_equal(a.particles.position, b.particles.position)
    np.testing.assert_array_equal(a.particles.velocity, b.particles.velocity)
    np.testing.assert_array_equal(a.tally.counts, b.tally.counts)


@pytest.mark.slow
def test_a_gas_large_enough_to_prefetch_takes_the_same_events_in_any_slot_order():
    """From `events.PREFETCH_EVENTS_FROM` disks the event loop asks for lines ahead
    (`_prefetch_following`): reading where it guesses the next events' slots and partners lie,
    it changes nothing of the run, which is the same bit for bit with the slots sorted by cell
    every event per particle or never."""
    n = events.PREFETCH_EVENTS_FROM
    side = int(np.ceil(np.sqrt(n)))
    runs = []
    for interval in (1, 10**9):
        rng = np.random.default_rng(3)
        position = jittered_lattice(side, float(side), 0.3, rng)
        particles = Particles(position, rng.normal(0, 3, position.shape), radius=0.3)
        sim = Simulation(Box(float(side), float(side), "periodic"), particles, dt=0.3)
        sim._drift.sort_interval = interval
        sim.run(steps=1)
        runs.append(sim)
    a, b = runs
    assert a._drift.events > 2 * n  # a sort or more in the first run
    np.testing.assert_array_equal(a.particles.position, b.particles.position)
    np.testing.assert_array_equal(a.particles.velocity, b.particles.velocity)
    np.testing.assert_array_equal(a.tally.counts, b.tally.counts)


def _by_particle(state: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """The engine's state indexed by particle instead of slot: body rows, the particle of each
    event's partner and kept contact (-1 for none, wall and cell codes kept), event times."""
    ident = state["ident"]
    order = np.argsort(ident)
    partner = {}
    for column in (events.CODE, events.KEPT):
        slots = state["event"][order, column]
        partner[column] = np.where(slots >= 0, ident[np.maximum(slots, 0)], slots)
    return {
        "body": state["body"][order],
        "partner_count": state["event"][order, events.PARTNER_COUNT],
        "code": partner[events.CODE],
        "kept": partner[events.KEPT],
        "cell": state["cell_of"][order],
        "count": state["count"][order],
        "time": state["keys"][order],  # the queue's first entries: the slots' times
    }


@pytest.mark.parametrize("boundary", ["reflecting", "periodic"])
def test_rows_without_radius_and_mass_give_bitwise_the_run_of_full_rows(boundary, monkeypatch):
    """Disks of one radius and one mass: the engine's short rows (radius and mass from
    ``geometry``) and its full rows must give the same run, bit for bit."""
    runs = []
    for full in (False, True):
        if full:
            monkeypatch.setattr(collisions, "_shared_radius_and_mass", lambda particles: None)
        rng = np.random.default_rng(11)
        position = jittered_lattice(20, 16.0, 0.25, rng)
        particles = Particles(position, rng.normal(0, 3, (len(position), 2)), mass=1.5, radius=0.25)
        sim = Simulation(Box(16.0, 16.0, boundary), particles, dt=0.5).run(steps=4)
        runs.append(sim)
    short, full_rows = runs
    assert short._drift._state["body"].shape[1] == events.SHARED_BODY_COLUMNS
    assert full_rows._drift._state["body"].shape[1] == events.BODY_COLUMNS
    assert short.counters.pair_collisions > 3000
    for a, b in zip(_outcome(short), _outcome(full_rows), strict=True):
        np.testing.assert_array_equal(a, b)


def _outcome(sim: Simulation) -> tuple[np.ndarray, ...]:
    p = sim.particles
    return p.position, p.velocity, p.image, sim.tally.counts, sim.tally.impulse


def _tile_rank(cell: np.ndarray, ncx: int) -> np.ndarray:
    """Each cell's place in the order `sort_slots` puts them in: tiles of `events.TILE` cells a
    side row by row, and the cells of a tile row by row."""
    cx, cy = cell % ncx, cell // ncx
    tile = events.TILE
    tiles_across = -(-ncx // tile)
    return ((cy // tile) * tiles_across + cx // tile) * tile**2 + (cy % tile) * tile + cx % tile


def test_sorting_slots_moves_every_reference_with_its_particle(rng):
    """`sort_slots` permutes rows in place along cycles: afterwards the slots are in the order of
    their cells tile by tile (`_tile_rank`), every row, partner, cell list and event time still
    belongs to the same particle, and the queue takes the earliest event first."""
    sim = _dense_gas("periodic", rng)
    sim._drift.sort_interval = 10**9  # never: the slots drift out of cell order
    sim.run(steps=1)
    state = sim._drift._state
    before = _by_particle(state)
    assert np.any(np.diff(_tile_rank(state["cell_of"], state["grid"][0])) < 0)
    events.sort_slots(
        state["body"], state["cell_of"], state["event"], state["head"], state["next"],
        state["keys"], state["items"], state["grid"],
    )  # fmt: skip
    assert np.all(np.diff(_tile_rank(state["cell_of"], state["grid"][0])) >= 0)
    after = _by_particle(state)
    for name in before:
        np.testing.assert_array_equal(after[name], before[name], err_msg=name)
    times = state["keys"][: sim.particles.n]
    first = np.lexsort((state["ident"], times))[0]
    assert earliest_slot(state["keys"], state["items"], state["ident"]) == first
    members = np.full(sim.particles.n, -1)
    for cell, first in enumerate(state["head"]):
        k = first
        while k >= 0:
            members[k] = cell
            k = state["next"][k]
    np.testing.assert_array_equal(members, state["cell_of"])


def test_engine_matches_twin_across_cell_crossings(rng):
    """Small fast disks cross cells thousands of times, so the short prediction after a crossing
    (3 new cells and the kept earliest contact) is taken over and over; with few collisions the
    twin must find the same ones. (Reflecting box: in a
    periodic one the twin, which looks at the 9 nearest images only, misses contacts more than a
    box side of free flight away.)"""
    boundary = "reflecting"
    width = 10.0
    position = jittered_lattice(10, width, 0.001, rng)
    n = len(position)
    velocity = rng.uniform(-10, 10, (n, 2))
    radius = np.full(n, 0.001)
    sim = Simulation(
        Box(width, width, boundary),
        Particles(position.copy(), velocity.copy(), radius=radius),
        dt=0.25,
    )
    sim.run(steps=8)
    assert sim._drift.events > 30 * n  # mostly cell crossings
    twin_position, twin_velocity = position.copy(), velocity.copy()
    pairs, walls, *_ = reference.event_drift(
        twin_position, twin_velocity, np.ones(n), radius, np.array([width, width]) / 2, 2.0,
        periodic=boundary == "periodic",
    )  # fmt: skip
    assert pairs >= 2
    assert (sim.counters.pair_collisions, sim.counters.wall_collisions) == (pairs, walls)
    np.testing.assert_allclose(sim.unwrapped_position(), twin_position, rtol=0, atol=1e-9 * width)


@pytest.mark.parametrize(
    "kernel",
    [
        events.rebuild,
        events.run_events,
        events.synchronise,
        events.synchronise_in_chunks,
        events.refresh,
        events.refresh_in_chunks,
        audit._in_chunks,
    ],
)
def test_the_engine_lets_other_threads_run_while_it_works(kernel):
    """The viewer's server reads and sends while a step of a large gas runs in its worker thread
    (ARCHITECTURE.md, "The viewer's frames"): the step's kernels release Python's lock."""
    assert kernel.targetoptions.get("nogil") is True


def _large_gas(rng, n: int) -> Simulation:
    """n disks of radius 0.25 m at packing 0.1 in a square box, speeds about 10 m/s."""
    side = float(np.sqrt(n * np.pi * 0.25**2 / 0.1))
    position = jittered_lattice(int(np.ceil(np.sqrt(n))), side - 1.0, 0.25, rng)[:n]
    velocity = rng.normal(0.0, 7.0, (n, 2))
    return Simulation(Box(side, side), Particles(position, velocity, radius=0.25), dt=0.01)


def test_the_parallel_passes_write_and_check_what_the_serial_ones_do(rng):
    """`synchronise_in_chunks` writes the same bits and strays as `synchronise`, and
    `refresh_in_chunks` leaves the queue that `refresh` leaves: after a change of velocity in the
    first or the last chunk, of many velocities, of none, and of a position (the queue to be built
    again, -1)."""
    sim = _large_gas(rng, 5 * 4096 + 77)  # five chunks, the last one longer
    sim.run(steps=2)
    s, p = sim._drift._state, sim.particles
    later = sim.time + 0.004  # between events: every particle is moved on from its own time
    written = []
    for synchronise in (events.synchronise, events.synchronise_in_chunks):
        position, velocity = np.full_like(p.position, np.nan), np.full_like(p.velocity, np.nan)
        strays = synchronise(later, s["body"], s["event"], s["geometry"], s["grid"], position,
                             velocity)  # fmt: skip
        written.append((position.tobytes(), velocity.tobytes(), strays))
    assert written[0] == written[1]
    assert not np.isnan(np.frombuffer(written[0][0])).any()
    first, last = int(s["event"][0, events.IDENT]), int(s["event"][-1, events.IDENT])
    many = rng.random(p.n) < 0.1
    none = np.array([], dtype=int)
    for changed, expected in (([first], 1), ([last], 1), (many, many.sum()), (none, 0)):
        velocity = p.velocity.copy()
        velocity[changed, 1] = np.nextafter(velocity[changed, 1], np.inf)
        for moved in (False, True):
            position = p.position.copy()
            position[last, 0] = np.nextafter(position[last, 0], 0.0) if moved else position[last, 0]
            left = []
            for refresh in (events.refresh, events.refresh_in_chunks):
                queue = {name: np.copy(array) for name, array in s.items()}
                answer = refresh(sim.time, *collisions._queue(queue, sim.container), position,
                                 velocity, p.radius, p.mass)  # fmt: skip
                left.append((answer, [queue[name].tobytes() for name in collisions._QUEUE_ARRAYS]))
            if moved:  # the rows are to be built again: only the answer counts
                assert left[0][0] == left[1][0] == -1
            else:
                assert left[0] == left[1]
                assert left[0][0] == expected


@pytest.mark.parametrize("shared", [True, False])
def test_a_queue_is_refreshed_for_new_velocities_alone(rng, shared):
    """`refresh` takes in a changed velocity (1 slot changed); a changed position, radius or mass
    asks for the queue to be built again (-1), with rows of one radius and mass (checked apart,
    in particle order) and with full rows."""
    sim = _large_gas(rng, 500) if shared else _dense_gas("reflecting", rng)
    sim.run(steps=1)
    s, p = sim._drift._state, sim.particles
    assert (s["body"].shape[1] == events.SHARED_BODY_COLUMNS) == shared
    last = int(s["event"][-1, events.IDENT])  # checked last, in slot order
    for name, expected in (("velocity", 1), ("position", -1), ("radius", -1), ("mass", -1)):
        queue = {key: np.copy(array) for key, array in s.items()}
        given = {key: getattr(p, key).copy() for key in ("position", "velocity", "radius", "mass")}
        row = given[name][last : last + 1].reshape(-1)
        row[0] = np.nextafter(row[0], 0.0)
        answer = events.refresh(sim.time, *collisions._queue(queue, sim.container), *given.values())
        assert answer == expected, name


def test_a_large_gas_runs_the_same_bits_with_its_passes_in_parallel_or_not(rng, monkeypatch):
    """From `audit.PARALLEL_FROM` particles the engine writes and checks the particles in
    parallel chunks (`collisions._many`); a run is bit for bit the one made serially."""
    runs, n = [], audit.PARALLEL_FROM + 1000
    for threshold in (audit.PARALLEL_FROM, 10**9):
        monkeypatch.setattr(audit, "PARALLEL_FROM", threshold)
        sim = _large_gas(np.random.default_rng(5), n)
        sim.run(steps=10)
        p = sim.particles
        runs.append((p.position.tobytes(), p.velocity.tobytes(), sim.counters.pair_collisions,
                     sim._drift.rebuilds))  # fmt: skip
    assert runs[0] == runs[1]
    assert runs[0][2] > 1000 and runs[0][3] == 1  # one queue, kept from step to step


def test_the_parallel_rebuild_builds_the_queue_the_serial_one_does(rng):
    """After a kick, `rebuild_in_chunks` gives every array of the queue the bits `rebuild`
    gives it, from the same slots (several chunks, the last one longer)."""
    sim = _large_gas(rng, 5 * 4096 + 77)
    sim.run(steps=2)
    p = sim.particles
    p.velocity += rng.normal(0.0, 0.1, p.velocity.shape)  # a kick: every event changes
    built = []
    for rebuild in (events.rebuild, events.rebuild_in_chunks):
        s = {name: np.copy(array) for name, array in sim._drift._state.items()}
        events.load(p.position, p.velocity, p.radius, p.mass, s["body"], s["event"])
        rebuild(sim.time, *collisions._queue(s, sim.container))
        built.append(s)
    serial, parallel = built
    assert np.isfinite(serial["keys"][: p.n]).all()
    for name in collisions._QUEUE_ARRAYS:
        np.testing.assert_array_equal(serial[name], parallel[name], err_msg=name)


def test_a_queue_built_again_from_the_slots_before_runs_as_a_fresh_one(rng):
    """Under forces the queue is built again at every step from the slots it had (nearly in
    cell order, `events.load`); a run whose every queue starts from particle order, in fresh
    arrays, has the same bits."""
    runs = []
    for fresh in (False, True):
        sim = _dense_gas("reflecting", np.random.default_rng(3))
        kicks = np.random.default_rng(4)
        for _ in range(4):
            sim.particles.velocity *= 1.0 + kicks.uniform(-0.01, 0.01, (sim.particles.n, 1))
            # A moved disk: the queue is built again, not refreshed (`events.refresh`).
            sim.particles.position[0] *= 1.0 - 2**-40
            if fresh:
                sim._drift._state = sim._drift._spare = None
            sim.run(steps=1)
            if not fresh:
                assert not np.array_equal(sim._drift._state["ident"], np.arange(sim.particles.n))
        assert sim._drift.rebuilds == 4
        runs.append(sim)
    kept, fresh_run = runs
    assert kept.counters.pair_collisions > 3000
    for a, b in zip(_outcome(kept), _outcome(fresh_run), strict=True):
        np.testing.assert_array_equal(a, b)


def test_a_disk_off_the_grids_edge_leaves_its_cell_before_it_can_touch_a_wall(rng):
    """The prediction looks for wall contacts only from the cells at the grid's edge
    (`events._walls_in_reach`): in a box without segments, from any other cell, with the cells
    as narrow as the grid allows (one largest diameter), the crossing out of the cell comes
    strictly first, from every place in the cell (its edges too) and in every direction."""
    radius, ncx, ncy = 0.5, 7, 5
    size = 2.0 * radius  # the narrowest cells `cells.event_grid_shape` gives
    half_width, half_height = ncx * size / 2, ncy * size / 2
    geometry = np.zeros(events.GEOMETRY_SIZE)
    geometry[[events.CELL_WIDTH, events.CELL_HEIGHT]] = size
    geometry[[events.GRID_LEFT, events.GRID_BOTTOM]] = -half_width, -half_height
    grid = np.array([ncx, ncy, 0])
    geometry[events.SHAPE] = BOX
    no_segments = np.empty((0, 9))
    tested = 0
    for _ in range(4000):
        cx, cy = rng.integers(0, ncx), rng.integers(0, ncy)
        c = cx + ncx * cy
        # Anywhere in the cell, edges included, and every direction.
        u, v = rng.choice([0.0, 1.0, rng.uniform()], 2)
        x, y = -half_width + (cx + u) * size, -half_height + (cy + v) * size
        vx, vy = rng.normal(size=2) * rng.choice([1e-3, 1.0, 1e3])
        crossing, _ = events._cell_crossing(x, y, vx, vy, c, geometry, grid)
        wall, _ = box.wall_delay(x, y, vx, vy, radius, half_width, half_height)
        if events._walls_in_reach(c, geometry, grid, no_segments):
            continue
        tested += 1
        assert crossing < wall
    assert tested > 1000
    # An edge cell, a box with segments and a circle keep their walls.
    assert events._walls_in_reach(0, geometry, grid, no_segments)
    assert events._walls_in_reach(ncx + 1, geometry, grid, np.zeros((1, 9)))
    geometry[events.SHAPE] = CIRCLE
    assert events._walls_in_reach(ncx + 1, geometry, grid, no_segments)


@pytest.mark.parametrize("trouble", ["none", "outside", "nan", "inf"])
def test_the_audit_of_disks_of_one_radius_gives_the_verdicts_of_full_rows(trouble):
    """`events.audit_in_box` reads a radius that the disks share once, and counts no strays
    where the cells' window is the vessel: whether the disks pass and their largest velocity
    component are those of the same slots in full rows (each its radius), strays counted,
    whatever is wrong with them."""
    sim = load("gas").run(steps=3)
    s = sim._drift._state
    assert s["body"].shape[1] == events.SHARED_BODY_COLUMNS
    body = s["body"].copy()
    k = 17
    if trouble == "outside":
        body[k, events.X] = 0.5 * sim.container.size[0] + 0.1
    elif trouble in ("nan", "inf"):
        body[k, events.VY] = np.nan if trouble == "nan" else -np.inf
    p = sim.particles
    full_rows = np.ascontiguousarray(np.column_stack([body, p.radius, p.mass]))
    assert full_rows.shape[1] == events.BODY_COLUMNS
    limit_x, limit_y = 0.5 * sim.container.size * (1 + 1e-12)
    later = sim.time  # where the drift left the disks: every one inside
    shared, full = (
        events.audit_in_box(later, rows, s["geometry"], s["grid"], limit_x, limit_y, False, one)
        for rows, one in ((body, True), (full_rows, False))
    )
    assert shared[1] == 0
    assert shared[0] == full[0] == (trouble == "none")
    assert shared[2] == full[2] or (np.isnan(shared[2]) and np.isnan(full[2]))
