"""The adaptive leapfrog's contact-free substeps under inverse-distance pair forces, compiled.

The adaptive integrator (`collidium.integrators.AdaptiveLeapfrog`) cuts a reporting interval
into n equal kick-drift-kick substeps. In a small charged scene most substeps meet no contact,
and their drift is then a straight flight; a Python call per substep (kick, drift, force sum,
substep rate) costs a hundred times the arithmetic. `smooth_substeps` flies a run of such
substeps under one inverse-distance pair force (every seed scene has one; two take the Python
path) in one call, with the pair sums of `collidium.kernels.pairwise`, and stops before the
first substep whose flight would bring a disk near a wall or another disk, or whose values stop
being finite: the integrator takes that one in Python, where the collision modes and the error
messages are (the divisions here follow NumPy: an overflow gives inf, which stops the
substeps). The two paths differ by round-off only: the exact engine advances a disk at each
cell crossing, in two roundings where the straight flight here takes one.

`smooth_intervals` goes further: it takes whole reporting intervals, as many as meet no contact,
with the integrator's choice of their substep counts and its retries, and records the energies,
virial, momentum and total speed at each interval's end (`RECORD`; of the processed state the
integrator shows, where it shows one and an observer reads them:
`collidium.kernels.processing`), so that a small scene runs many steps between the observers
that read more of its state in one call. An interval that meets a contact is left to the
integrator whole.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from collidium.kernels import events, kick_timing
from collidium.kernels.compilation import uncounted
from collidium.kernels.floats import largest_magnitude
from collidium.kernels.modified_energy import keep_across_step
from collidium.kernels.pairwise import (
    MOST_BLOCKS,
    PRUNE_FROM,
    every_row,
    pair_sums,
    pruned_stiffness,
)
from collidium.kernels.processing import SHARE, curved_velocities
from collidium.kernels.processing import shown as processed
from collidium.kernels.sorting import sort_nearly_sorted
from collidium.kernels.sums import kinetic_energy, momentum, total_speed
from collidium.kernels.vessels import BOX, CIRCLE, contacts

#: What `smooth_intervals` records of each interval's end, its columns: the kinetic and potential
#: energy (J), the pair virial (J), the momentum (kg m/s) and the sum of the speeds (m/s).
RECORD = ("kinetic", "potential", "virial", "px", "py", "total_speed")

#: Relative margin of the contact test: a disk that comes within this fraction of its radius (or
#: of a pair's contact distance) of a contact, within this fraction past the substep, counts as
#: meeting it. The engine finds contacts from the same numbers but at other instants (after a
#: cell crossing), so round-off could otherwise part the two on a grazing contact.
CONTACT_MARGIN = 1e-6

#: Particles up to which the substeps keep each disk's room (`_rooms`): the disks' distances to
#: the walls and to each other, all pairs, from the last contact test that found none, so that
#: the substeps after it need no test while every disk stays in its room (`_in_rooms`). A gas
#: of more meets contacts in most substeps, where the rooms would be small and their pairs many.
ROOMS_UP_TO = 16

#: The substeps read their rate every `rate_stride` substeps and at each interval's end, a
#: stride being at most this fraction of the fastest time scale (``tolerance`` of it a
#: substep): the rate changes by a few percent over it, while each read is a sum over the
#: pairs that costs half a force evaluation.
RATE_SPACING = 1.0 / 32.0


@uncounted()
def energy_scale(kinetic: float, total: float, floor: float) -> float:
    """The energy (J) the substep rate judges the energy error against: ``|E|``, but at least
    ``(KE + |U|) / floor``, with the potential ``U = E - KE`` (``total`` E and ``kinetic`` KE in
    J); 0 only when there is no energy at all."""
    return max(abs(total), (kinetic + abs(total - kinetic)) / floor)


@numba.njit(cache=True, error_model="numpy")
def smooth_substeps(
    position, velocity, acceleration, mass, radius, source, coupling, softening2, uniform, fall,
    turn, region, damp, shape, half_width, half_height, rim, segments, now, dt, first, count, t,
    fastest, total, energy_floor, tolerance, most, contacts,
) -> tuple[int, float, float, float, int, int]:  # fmt: skip
    """Regular substeps ``first, first + 1, ...`` of ``count`` in the interval from ``now`` of
    ``dt`` (s), in place, up to the first that may meet a contact and that the exact engine
    cannot take here (`_contact_drift`), or whose values stop being finite.

    Substep s ends at ``now + dt s / count``; it is the velocity forces' flow for ``h / 2``
    (`_flowed`: the drag, the magnetic field's turn), a kick ``v += a h / 2``, the straight flight
    over h, the accelerations at the new positions, the kick ``v += a h / 2`` and the flow for
    ``h / 2``. After each that `reads_rate`, the squared rate of the forces weighted by energy
    (`collidium.integrators._squared_rate`) raises ``fastest``, and once that needs more than
    ``count`` substeps (`needed`) the interval stops there, to be taken again with more. No
    energy is summed: the rate's energy scale takes the potential as the total energy less the
    kinetic, the total as ``total`` and what the drag gave since.

    Parameters
    ----------
    position, velocity, acceleration : ndarray, shape (N, 2)
        In m, m/s and m/s^2, at time ``t``, which is substep ``first``'s start; updated.
    mass, radius : ndarray, shape (N,)
        In kg and m.
    source : ndarray, shape (N,)
        The pair force's sources (`collidium.kernels.pairwise.inverse_distance_direct`).
    coupling, softening2 : float
        Its coupling (N m^2 per source squared) and squared softening (m^2).
    uniform : ndarray, shape (N, 2) or (0, 2)
        A uniform field's force on each particle, N; empty without one.
    fall : ndarray, shape (2,) or (0,)
        The uniform field's acceleration (m/s^2) where the drift carries it (a gravity): the
        kicks add it, ``acceleration`` has it not, and ``uniform`` counts in the energies only.
        Empty where ``uniform`` is in ``acceleration``.
    turn : ndarray, shape (N,) or (0,)
        A magnetic field's signed cyclotron frequency ``q B / m`` of each particle, rad/s
        (`_flowed`); empty without one.
    region : ndarray, shape (4,)
        Where the magnetic field acts: left, bottom, right, top (m), infinite for the plane.
    damp : ndarray, shape (N,) or (0,)
        A linear drag's ``gamma / m`` of each particle, 1/s (`_flowed`); empty without one.
    shape, half_width, half_height, rim, segments
        The vessel as the exact engine has it (`collidium.kernels.vessels.contacts.earliest`).
    now, dt : float
        The interval's start and length, s.
    first, count : int
        The substep to start with (1 to ``count``) and the interval's number of substeps.
    t : float
        Substep ``first``'s start, s.
    fastest : float
        Largest squared rate so far, 1/s^2; if negative, the rate of the state given (with
        ``first > count``, the call returns just that: the rate of an interval's start).
    total : float
        The total energy (kinetic and potential) at substep ``first``'s start, J.
    energy_floor : float
        The rate's energy scale is ``|KE + U|`` but at least ``(KE + |U|) / energy_floor``
        (`energy_scale`).
    tolerance, most
        The integrator's accuracy parameter and most substeps (`needed`): which boundaries read
        the rate (`reads_rate`), and whether it needs more substeps than ``count``.
    contacts : tuple
        The exact engine for the substeps that meet contacts (`_contact_drift`): its queue's
        arrays, the wall table, the events between re-sorts, the runaway reach (m), the contact
        log's rows and count, the particles' periodic images and the tally's counts, impulses
        and heat, which its contacts add to. With 0 events between re-sorts there is no
        engine: a substep that may meet a contact is left to the integrator.

    Returns
    -------
    tuple
        ``(substep, time, fastest, given, events, drifts)``: the substep not taken
        (``count + 1`` when all were, or when the rate needs more substeps), its start (s), the
        largest squared rate, the energy the drag gave in the substeps taken (J, negative), and
        the events the engine processed in the drifts it took.
    """
    work = _work(mass, source, coupling, softening2, contacts[-3:])
    walls = (shape, half_width, half_height, rim, segments)
    external = (uniform, fall, turn, region, damp)
    accuracy = (tolerance, most, energy_floor)
    return _substeps(position, velocity, acceleration, mass, radius, coupling, softening2,
                     external, walls, now, dt, first, count, t, fastest, total, accuracy, work,
                     contacts)[:6]  # fmt: skip


@numba.njit(cache=True, error_model="numpy")
def smooth_intervals(
    position, velocity, acceleration, mass, radius, source, coupling, softening2, uniform, fall,
    turn, region, damp, shape, half_width, half_height, rim, segments, origin, elapsed, dt,
    count, substeps, substep, keep, tolerance, most_substeps, energy_floor, given, record, heat,
    contacts, counts, impulses, heats, shows, wanted, limits,
) -> tuple[int, int, float, int, int]:  # fmt: skip
    """Up to ``count`` whole reporting intervals of ``dt`` (s), in place, each as the adaptive
    integrator takes one (`collidium.integrators.AdaptiveLeapfrog`), up to the first that meets
    a contact the engine cannot take here or a value that is not finite, or needs more than
    ``most_substeps``: that one is left as it began, for the integrator.

    Interval k starts at ``origin + (elapsed + k) dt``, the simulation's clock. Its substep count
    is the larger of ``substeps`` and the fewest the rate at its start needs (`needed`); it is
    taken again with more if a boundary that reads the rate needs more (`reads_rate`), and the
    count the next interval starts from is this one, or half of it when half would have done.
    The rate at an interval's end is the next one's start's: its pair sum is read once. Where
    its substep differs from the one before, and ``keep``, the velocities are first scaled so
    that the substeps' modified energy goes on
    (`collidium.kernels.modified_energy.keep_across_step`).

    Parameters
    ----------
    position, velocity, acceleration, mass, radius, source, coupling, softening2, uniform, fall,
    turn, region, damp, shape, half_width, half_height, rim, segments
        As in `smooth_substeps`.
    origin : float
        The clock's origin, s.
    elapsed : int
        Steps from the clock's origin to the first interval's start.
    dt : float
        The reporting interval, s.
    count : int
        Most intervals to take (at most ``len(record)``).
    substeps : int
        The substep count the first interval starts from.
    substep : float
        The substep of the interval before the first, s (NaN for none).
    keep : bool
        Whether to keep the modified energy where the substep changes: the forces are the pair
        force and a uniform field, none carried by the drift, and no velocity force.
    tolerance : float
        The integrator's accuracy parameter (`needed`), and the most by which the modified
        energy's keeping may scale the velocities.
    most_substeps : int
        Most substeps in an interval (a power of two).
    energy_floor : float
        As in `smooth_substeps`.
    given : float
        The energy the velocity forces have given the particles before the first interval, J
        (`collidium.collisions.Tally.forces`).
    record : ndarray, shape (count, len(RECORD))
        Output: the `RECORD` of each interval's end, summed as `collidium.simulation.Simulation`
        sums them (`collidium.kernels.sums`, and the forces' as
        `collidium.forces.base.ForceField` sums them).
    heat : ndarray, shape (count,)
        Output: ``given`` at each interval's end, each interval's drag added as the integrator
        adds it to the tally.
    contacts : tuple
        As in `smooth_substeps`.
    counts, impulses, heats : ndarray, shape (count, 1 + W)
        Output: the tally's counts, impulses and heat at each interval's end.
    shows : bool
        Whether the ``record`` of an interval that is ``wanted`` is that of the processed state
        (`collidium.kernels.processing`), the state the integrator shows.
    wanted : ndarray of bool, shape (count,)
        The intervals whose record is read.
    limits : tuple
        ``(limit_x, limit_y, slack)``: the walls as the audit takes them
        (`collidium.vessels.Vessel.audit_arguments`), for the processing.

    Returns
    -------
    tuple
        ``(intervals taken, the substep count the next interval starts from, the last interval's
        substep in s, events, drifts)``: the events the engine processed in the drifts it took.
    """
    n = position.shape[0]
    work = _work(mass, source, coupling, softening2, contacts[-3:])
    tally = contacts[-3:]
    kept = (tally[0].copy(), tally[1].copy(), tally[2].copy())
    processed = drifts = 0
    walls = (shape, half_width, half_height, rim, segments)
    external = (uniform, fall, turn, region, damp)
    flows2 = _flows2(turn, damp)
    start = np.empty((3, n, 2))
    sources = work[3:12]
    energy, virial = _energies(position, coupling, softening2, uniform, sources)
    stiffness = -1.0  # none read yet: the pair sum of the state reached, once read
    accuracy = (tolerance, most_substeps, energy_floor)
    m = n if shows else 0  # the processing's work arrays, none where it records nothing
    shown = np.empty((3, m, 2))  # the processed positions and velocities, the curved velocities
    guard = (np.arange(m), np.empty((3, m)), np.empty((6, m)))
    vessel = (shape, limits[0], limits[1], limits[2], segments)
    for k in range(count):
        now = origin + (elapsed + k) * dt
        total = kinetic_energy(mass, velocity) + energy
        if stiffness < 0.0:
            stiffness = _stiffness(position, velocity, coupling, softening2, sources, work[21:23])
        rate2 = _scaled_rate(stiffness, mass, velocity, total, energy_floor, flows2)
        if not dt * math.sqrt(rate2) <= most_substeps * tolerance:  # also NaN
            return k, substeps, substep, processed, drifts
        taken = max(substeps, needed(rate2, dt, tolerance, most_substeps))
        _keep(position, velocity, acceleration, start)
        _keep_tally(tally, kept)
        while True:
            if keep and substep == substep and dt / taken != substep:  # NaN: none before
                _keep_modified_energy(position, velocity, acceleration, mass, work, substep,
                                      dt / taken, tolerance)  # fmt: skip
            s, _, fastest, drag, done, drifted, reached = _substeps(
                position, velocity, acceleration, mass, radius, coupling, softening2, external,
                walls, now, dt, 1, taken, now, rate2, total, accuracy, work, contacts,
            )  # fmt: skip
            if s <= taken:  # a contact left to Python, or a value not finite
                _restore(position, velocity, acceleration, start)
                _keep_tally(kept, tally)
                return k, substeps, substep, processed, drifts
            processed += done
            drifts += drifted
            required = needed(fastest, dt, tolerance, most_substeps)
            if required <= taken:
                break
            _restore(position, velocity, acceleration, start)
            _keep_tally(kept, tally)
            taken = max(required, 2 * taken)
        substeps = max(1, taken // 2) if required <= taken // 2 else taken
        substep = dt / taken
        stiffness = reached
        given += drag
        heat[k] = given
        # The last substep's pair sums are of the positions now.
        energy, virial = _summed_energies(position, uniform, work[10])
        if shows and wanted[k]:
            _show(position, velocity, acceleration, mass, radius, work[15:18], substep,
                  vessel, guard, shown)  # fmt: skip
            shown_energy, shown_virial = _energies(shown[0], coupling, softening2, uniform,
                                                   sources)  # fmt: skip
            _record(k, mass, shown[1], shown_energy, shown_virial, record)
        else:
            _record(k, mass, velocity, energy, virial, record)
        for w in range(counts.shape[1]):
            counts[k, w] = tally[0][w]
            impulses[k, w] = tally[1][w]
            heats[k, w] = tally[2][w]
    return count, substeps, substep, processed, drifts


@numba.njit(cache=True, inline="always")
def _record(k, mass, velocity, energy, virial, record) -> None:
    """Row k of the `RECORD` of a state of ``velocity`` (N, 2), its potential ``energy`` and
    pair ``virial`` (J)."""
    px, py = momentum(mass, velocity)
    record[k, 0] = kinetic_energy(mass, velocity)
    record[k, 1] = energy
    record[k, 2] = virial
    record[k, 3] = px
    record[k, 4] = py
    record[k, 5] = total_speed(velocity)


@numba.njit(cache=True, error_model="numpy", inline="always")
def _show(position, velocity, acceleration, mass, radius, law, substep, vessel, guard,
          shown) -> None:  # fmt: skip
    """The processed state of substeps of ``substep`` (s) into ``shown[0]`` and ``shown[1]``
    (`collidium.kernels.processing.shown`), the curved velocities into ``shown[2]``; ``guard``
    the processing's work arrays (order, extents, rows)."""
    order, extents, rows = guard
    curved_velocities(position, velocity, law[0], law[1], law[2], rows, shown[2])
    processed(position, velocity, acceleration, mass, shown[2], SHARE * substep * substep,
              radius, vessel, order, extents, shown[0], shown[1])  # fmt: skip


@numba.njit(cache=True, error_model="numpy", inline="always")
def _keep_modified_energy(position, velocity, acceleration, mass, work, substep, following,
                          limit) -> None:  # fmt: skip
    """`collidium.kernels.modified_energy.keep_across_step` from substeps of ``substep`` to
    ``following`` (s), with the pair force's law of `_work`, the vessel's walls making the
    minimum image needless."""
    sources, couplings, softenings2 = work[15:18]
    keep_across_step(position, velocity, acceleration, mass, sources, couplings, softenings2,
                     0.0, 0.0, False, work[23], substep, following, limit)  # fmt: skip


@uncounted()
def needed(rate2: float, dt: float, tolerance: float, most: int) -> int:
    """The fewest substeps, a power of two up to ``most``, that keep ``dt / n`` (s) within
    ``tolerance`` times the time scale ``1 / sqrt(rate2)`` (``rate2`` in 1/s^2)."""
    ratio = dt * math.sqrt(rate2) / tolerance
    if not ratio <= most:  # also NaN
        return most
    if ratio <= 1.0:
        return 1
    mantissa, exponent = math.frexp(ratio)  # ratio = mantissa 2^exponent, exactly
    return 1 << (exponent - 1 if mantissa == 0.5 else exponent)


@uncounted()
def rate_stride(tolerance: float) -> int:
    """The substeps between reads of the rate: the largest power of two whose substeps span at
    most `RATE_SPACING` of the fastest time scale, each ``tolerance`` of it; at least 1."""
    stride = 1
    while 2 * stride * tolerance <= RATE_SPACING:
        stride *= 2
    return stride


@uncounted()
def reads_rate(s: int, count: int, stride: int) -> bool:
    """Whether the end of substep ``s`` (1 to ``count``) reads the rate: every ``stride``
    substeps (`rate_stride`) and at the interval's end."""
    return s % stride == 0 or s == count


@numba.njit(cache=True, error_model="numpy")
def _work(mass, source, coupling, softening2, tally):
    """What `_substeps` works in, for N particles of which m have a source: kicked, flown and
    pulled motions (N, 2); the indices, sources and inverse masses of those m; rows for their
    coordinates and velocities (m,) each, their pair sums (4, m) and the sums' buffer; the
    sweep's order (`_contacts_ahead`) with each particle's latest contact in a substep, -1
    between substeps (`collidium.kernels.kick_timing.correct`), (2, N), and the sweep's
    interval ends (N,); the pair force's law as
    `collidium.kernels.kick_timing.correct` takes it (sources (1, N), coupling and squared
    softening (1,)); a copy of the ``tally``'s counts, impulses and heat, to put back; the
    order and rows of `collidium.kernels.pairwise.pruned_stiffness` (m,) and (6, m); the rows
    of `collidium.kernels.modified_energy.keep_across_step` (4, N); the disks that may meet a
    contact in a substep (N,) (`_contacts_ahead`); the disks' rooms' centres (N, 2) and radii
    (N,), up to `ROOMS_UP_TO` disks (`_rooms`)."""
    n = mass.shape[0]
    m = 0
    for i in range(n):
        if source[i] != 0.0:
            m += 1
    index = np.empty(m, dtype=np.int64)
    charged, inverse_mass = np.empty(m), np.empty(m)
    c = 0
    for i in range(n):
        if source[i] != 0.0:
            index[c], charged[c], inverse_mass[c] = i, source[i], 1.0 / mass[i]
            c += 1
    motion = (np.empty((n, 2)), np.empty((n, 2)), np.empty((n, 2)))
    rows = (np.empty(m), np.empty(m), np.empty(m), np.empty(m))
    sums = (np.empty((4, m)), np.empty(4 * m * (MOST_BLOCKS // 2)))
    # One array for both: one more array in the tuple made the two-body scenes' substeps a
    # sixth slower (orbit 1.17-1.19 ms for 10 s against 0.99-1.04).
    ordered = np.empty((2, n), dtype=np.int64)
    ordered[0] = np.arange(n)
    ordered[1] = -1
    sweep = (ordered, np.empty(n), np.empty(n))
    law = (source.copy().reshape((1, n)), np.full(1, coupling), np.full(1, softening2))
    kept = (tally[0].copy(), tally[1].copy(), tally[2].copy())
    pruning = (np.arange(m), np.empty((6, m)))
    gathered = (np.empty((4, n)),)
    near = (np.zeros(n, dtype=np.bool_),)
    roomy = n if n <= ROOMS_UP_TO else 0
    rooms = (np.empty((roomy, 2)), np.full(roomy, -1.0))  # none yet
    # Concatenated: numba builds an unpacked (*a, *b) through a list, which holds one type.
    return (motion + (index, charged, inverse_mass) + rows + sums + sweep + law  # noqa: RUF005
            + kept + pruning + gathered + near + rooms)  # fmt: skip


@uncounted(error_model="numpy")
def _substeps(position, velocity, acceleration, mass, radius, coupling, softening2, external,
              walls, now, dt, first, count, t, fastest, total, accuracy, work,
              contacts):  # fmt: skip
    """`smooth_substeps` in its work arrays (`_work`), the uniform field and the velocity
    forces as one tuple (``uniform, fall, turn, region, damp``), the vessel as another, the
    tolerance, most substeps and energy floor as a third. Returns `smooth_substeps`'s tuple and
    the pair sum of the rate (`_stiffness`) at the interval's end, -1 where it was not reached.

    Compiled without reference counting (`uncounted`), as are the pair sums it calls: the
    atomic counts numba puts around array arguments were 0.35 us of a two-body substep's
    0.6 us."""
    kicked, flown, pull = work[:3]
    index, charged, _, x, y, _, _, sums, buffer = work[3:12]
    ordered, low, high = work[12:15]
    order, latest = ordered[0], ordered[1]
    law = work[15:18]
    uniform, fall, turn, region, damp = external
    log, logged = contacts[4:6]
    tally = contacts[-3:]
    kept = work[18:21]
    order_x, rows_x = work[21:23]
    near = work[24]
    centres, rooms = work[25:27]
    engine = contacts[2] > 0  # events between re-sorts: 0 for no engine
    tolerance, most, energy_floor = accuracy
    stride = rate_stride(tolerance)
    n = position.shape[0]
    given = 0.0
    processed = drifts = 0
    flows2 = _flows2(turn, damp)
    if fastest < 0.0:
        stiffness = _stiffness(position, velocity, coupling, softening2, work[3:12], work[21:23])
        fastest = _scaled_rate(stiffness, mass, velocity, total, energy_floor, flows2)
    for s in range(first, count + 1):
        end = now + dt * s / count
        h = end - t
        before = 0.0
        for i in range(n):  # the flow for h / 2, then the kick
            wx, wy, heat = _flowed(i, velocity[i, 0], velocity[i, 1], position, mass, turn,
                                   region, damp, 0.5 * h)  # fmt: skip
            kicked[i, 0] = _kicked(wx, acceleration[i, 0], fall, 0, 0.5 * h)
            kicked[i, 1] = _kicked(wy, acceleration[i, 1], fall, 1, 0.5 * h)
            before += heat
        if not _finite(kicked):
            return s, t, fastest, given, processed, drifts, -1.0
        if _in_rooms(position, kicked, h, centres, rooms):  # no contact: the test would find none
            meets = False
        else:
            meets = _contacts_ahead(position, kicked, radius, h, walls, order, low, high, near)
            if not meets:
                _rooms(position, radius, walls, centres, rooms)
        if meets:  # the exact engine takes the drift, if it may
            if not engine:
                return s, t, fastest, given, processed, drifts, -1.0
            _keep_tally(tally, kept)
            done = _contact_drift(position, kicked, radius, mass, acceleration, t, h, contacts,
                                  near, flown)  # fmt: skip
            if done < 0:
                _keep_tally(kept, tally)
                return s, t, fastest, given, processed, drifts, -1.0
        else:
            done = 0
            for i in range(n):
                for d in range(2):
                    flown[i, d] = position[i, d] + kicked[i, d] * h
        # The energies only where an interval ends (`smooth_intervals` reads them there): a
        # fifth of the pair sum's time (`collidium.kernels.pairwise._row`).
        _accelerations(flown, mass, coupling, softening2, uniform, fall, index, charged, x, y,
                       s == count, sums, buffer, pull)  # fmt: skip
        if not _finite(pull):
            if meets:
                _keep_tally(kept, tally)
            return s, t, fastest, given, processed, drifts, -1.0
        if meets:
            kick_timing.correct(log, logged[0], t, h, position, flown, acceleration, pull,
                                kicked, mass, law[0], law[1], law[2], 0.0, 0.0, False, True,
                                latest)  # fmt: skip
            processed += done
            drifts += 1
        after = 0.0
        for i in range(n):  # the kick, then the flow for h / 2
            for d in range(2):
                position[i, d] = flown[i, d]
                acceleration[i, d] = pull[i, d]
            wx = _kicked(kicked[i, 0], pull[i, 0], fall, 0, 0.5 * h)
            wy = _kicked(kicked[i, 1], pull[i, 1], fall, 1, 0.5 * h)
            velocity[i, 0], velocity[i, 1], heat = _flowed(i, wx, wy, position, mass, turn,
                                                           region, damp, 0.5 * h)  # fmt: skip
            after += heat
        given += before + after
        t = end
        if reads_rate(s, count, stride):
            stiffness = _stiffness(position, velocity, coupling, softening2, work[3:12],
                                   (order_x, rows_x))  # fmt: skip
            fastest = max(fastest, _scaled_rate(stiffness, mass, velocity, total + given,
                                                energy_floor, flows2))  # fmt: skip
            if s == count:
                return count + 1, t, fastest, given, processed, drifts, stiffness
            if needed(fastest, dt, tolerance, most) > count:  # taken again with more
                return count + 1, t, fastest, given, processed, drifts, -1.0
    return count + 1, t, fastest, given, processed, drifts, -1.0


@uncounted(error_model="numpy")
def _contact_drift(position, kicked, radius, mass, acceleration, t, h, contacts, near,
                   flown) -> int:  # fmt: skip
    """The drift of a substep that meets contacts, by the exact engine, as
    `collidium.collisions.ExactCollisions.drift` takes it: the queue built afresh from the
    positions at ``t`` (s) and the ``kicked`` velocities (the pairs searched for the ``near``
    disks alone, `collidium.kernels.events.rebuild_near`), run to ``t + h`` with the kick timing
    of ``acceleration`` and the contacts logged, the positions and velocities at the end written
    to ``flown`` and ``kicked``. Returns the events processed, or -1 where the integrator must
    take the substep (a runaway speed, time stuck, more contacts than the log holds); the
    tallies are then part-way, for the caller to put back."""
    queue, walls, sort_every, reach, log, logged, image, counts, impulse, heat = contacts
    body, geometry, grid, head, next_, event, keys, items, segments, piston = queue
    if not largest_magnitude(kicked) * h <= reach:  # also NaN
        return -1
    events.load(position, kicked, radius, mass, body, event)
    events.rebuild_near(t, body, geometry, grid, head, next_, event, keys, items, segments,
                        piston, near)  # fmt: skip
    logged[0] = 0
    done = events.run_events(t + h, body, image, geometry, grid, head, next_, event, keys, items,
                             counts, impulse, acceleration, t + 0.5 * h, sort_every, log,
                             logged, walls, heat, segments, piston)  # fmt: skip
    if done < 0 or logged[0] > log.shape[0]:
        return -1
    events.synchronise(t + h, body, event, geometry, grid, flown, kicked)
    return done


@numba.njit(cache=True, inline="always")
def _keep_tally(source, target) -> None:
    """Copy the tally's counts, impulses and heat ``source`` into ``target``."""
    counts, impulse, heat = source
    to_counts, to_impulse, to_heat = target
    for w in range(counts.shape[0]):
        to_counts[w] = counts[w]
        to_impulse[w] = impulse[w]
        to_heat[w] = heat[w]


@numba.njit(cache=True, inline="always")
def _kicked(v: float, a: float, fall, d: int, lag: float) -> float:
    """A velocity component ``v`` (m/s) kicked by ``(a + fall[d]) lag``, ``a`` in m/s^2, the
    carried ``fall`` (2,) only where there is one."""
    return v + lag * (a if fall.shape[0] == 0 else a + fall[d])


@uncounted()
def _keep(position, velocity, acceleration, start) -> None:
    """The motion into ``start`` (3, N, 2), to take an interval again."""
    for i in range(position.shape[0]):
        for d in range(2):
            start[0, i, d] = position[i, d]
            start[1, i, d] = velocity[i, d]
            start[2, i, d] = acceleration[i, d]


@uncounted()
def _restore(position, velocity, acceleration, start) -> None:
    """The motion back from ``start`` (`_keep`)."""
    for i in range(position.shape[0]):
        for d in range(2):
            position[i, d] = start[0, i, d]
            velocity[i, d] = start[1, i, d]
            acceleration[i, d] = start[2, i, d]


@numba.njit(cache=True, inline="always")
def _finite(values: np.ndarray) -> bool:
    """Whether every entry of ``values`` (N, 2) is finite."""
    for i in range(values.shape[0]):
        if not (math.isfinite(values[i, 0]) and math.isfinite(values[i, 1])):
            return False
    return True


@numba.njit(cache=True, error_model="numpy", inline="always")
def _pair_sums(position, coupling, softening2, index, charged, x, y, energies, sums,
               buffer) -> None:  # fmt: skip
    """The pair sums (4, m) into ``sums`` of the m particles with a source (``index``, sources
    ``charged``) at ``position`` (N, 2) (`collidium.kernels.pairwise.pair_sums`, as
    `collidium.kernels.pairwise.inverse_distance_direct` takes them; the energies only if
    ``energies``), their coordinates gathered into ``x`` and ``y``."""
    for c in range(index.shape[0]):
        x[c] = position[index[c], 0]
        y[c] = position[index[c], 1]
    pair_sums(x, y, charged, coupling, softening2, 0.0, 0.0, False, energies, sums, buffer)


@numba.njit(cache=True, error_model="numpy", inline="always")
def _accelerations(position, mass, coupling, softening2, uniform, fall, index, charged, x, y,
                   energies, sums, buffer, out) -> None:  # fmt: skip
    """The accelerations (N, 2) of the pair force and the ``uniform`` field's forces (N, 2), or
    (0, 2) without one; not where the drift carries it, ``fall`` not empty) into ``out``: the
    forces over the masses, as `collidium.forces.base.ForceField.evaluate` forms them
    (`_pair_sums`, its energies too if ``energies``)."""
    _pair_sums(position, coupling, softening2, index, charged, x, y, energies, sums, buffer)
    for i in range(position.shape[0]):  # loops: an array expression costs more than 3 bodies
        out[i, 0] = 0.0
        out[i, 1] = 0.0
    for c in range(index.shape[0]):
        out[index[c], 0] += sums[0, c]
        out[index[c], 1] += sums[1, c]
    for i in range(uniform.shape[0] if fall.shape[0] == 0 else 0):
        out[i, 0] += uniform[i, 0]
        out[i, 1] += uniform[i, 1]
    for i in range(position.shape[0]):
        out[i, 0] /= mass[i]
        out[i, 1] /= mass[i]


@uncounted(error_model="numpy")
def _energies(position, coupling, softening2, uniform, sources) -> tuple[float, float]:
    """The potential energy and the pair virial (J) of the positions (`_summed_energies`), their
    pair sums taken here. ``sources``: the arrays of `_work` from the indices to the sums'
    buffer."""
    index, charged, _, x, y, _, _, sums, buffer = sources
    _pair_sums(position, coupling, softening2, index, charged, x, y, True, sums, buffer)
    return _summed_energies(position, uniform, sums)


@numba.njit(cache=True, error_model="numpy", inline="always")
def _summed_energies(position, uniform, sums) -> tuple[float, float]:
    """The potential energy and the pair virial (J) as `collidium.forces.base.ForceField` sums
    them, force by force, from the pair sums (4, m) of the positions: those halved to the
    particles and summed in particle order (`collidium.kernels.sums.ordered_sum`; the particles
    without a source add nothing), and the ``uniform`` field's ``-F_i . x_i`` in particle order
    (`collidium.forces.uniform`; no virial). Two sums added to 0 in either order give the same
    bits."""
    energy = 0.0
    virial = 0.0
    for c in range(sums.shape[1]):
        energy += 0.5 * sums[2, c]
        virial += 0.5 * sums[3, c]
    field = 0.0
    for i in range(uniform.shape[0]):
        field += -(position[i, 0] * uniform[i, 0] + position[i, 1] * uniform[i, 1])
    return 0.0 + energy + field, 0.0 + virial  # the field adds its forces' sums to 0


@uncounted(error_model="numpy")  # that of the inlined rows
def _stiffness(position, velocity, coupling, softening2, sources, pruning) -> float:
    """The squared rate's pair sum, ``(|U_ij| rate_ij^2)^2`` at its largest, J^2/s^4
    (`collidium.kernels.pairwise.pruned_stiffness`), of the particles with a source (``sources``:
    the arrays of `_work` from the indices to the sums' buffer), gathered into its rows, in the
    ``order`` of x kept from call to call (``pruning``: the order and the pruning's rows)."""
    index, charged, inverse_mass, x, y, vx, vy, _, _ = sources
    order, rows = pruning
    for c in range(index.shape[0]):
        i = index[c]
        x[c], y[c] = position[i, 0], position[i, 1]
        vx[c], vy[c] = velocity[i, 0], velocity[i, 1]
    if index.shape[0] < PRUNE_FROM:  # no call for a few bodies: a tenth of their substep
        return every_row(x, y, vx, vy, charged, inverse_mass, coupling, softening2)
    return pruned_stiffness(x, y, vx, vy, charged, inverse_mass, coupling, softening2, order,
                            rows)  # fmt: skip


@numba.njit(cache=True, inline="always")
def _scaled_rate(stiffness, mass, velocity, total, floor, flows2) -> float:
    """`collidium.integrators._squared_rate`, 1/s^2, of a pair sum ``stiffness``
    (`_stiffness`), given the total energy (J): its square root over the energy scale
    (`energy_scale`), or ``flows2``, the velocity forces' (`_flows2`), whichever is larger."""
    scale = energy_scale(kinetic_energy(mass, velocity), total, floor)
    energy = math.sqrt(stiffness) / scale if scale > 0.0 else 0.0
    return max(energy, flows2)


@numba.njit(cache=True, inline="always")
def _flows2(turn, damp) -> float:
    """The square of the velocity forces' fastest rate, 1/s^2: of the cyclotron frequencies
    ``turn`` (inside the field's region or not) and the damping rates ``damp``, as their forces'
    `rate` gives them. It depends on the particles' masses and charges alone: once a call."""
    fastest = 0.0
    for i in range(turn.shape[0]):
        fastest = max(fastest, abs(turn[i]))
    for i in range(damp.shape[0]):
        fastest = max(fastest, damp[i])
    return fastest * fastest


@numba.njit(cache=True, inline="always")
def _flowed(i, vx, vy, position, mass, turn, region, damp, lag) -> tuple[float, float, float]:
    """The velocity forces' flows for ``lag`` seconds of particle i's velocity ``(vx, vy)``
    (m/s): damped by ``exp(-damp[i] lag)`` (`collidium.forces.drag.LinearDrag.advance`) and,
    inside the ``region`` (left, bottom, right, top, m) at its ``position``, turned by
    ``-turn[i] lag`` (`collidium.forces.magnetic.MagneticField.advance`); the two commute.
    Without either (``damp`` or ``turn`` empty), that one is left out. Returns the new
    velocity and the energy the drag gave, J."""
    given = 0.0
    if damp.shape[0] > 0:
        factor = math.exp(-damp[i] * lag)
        given = 0.5 * mass[i] * (vx * vx + vy * vy) * (factor * factor - 1.0)
        vx, vy = vx * factor, vy * factor
    if turn.shape[0] > 0:
        x, y = position[i, 0], position[i, 1]
        if region[0] <= x <= region[2] and region[1] <= y <= region[3]:
            angle = -turn[i] * lag
            cos, sin = math.cos(angle), math.sin(angle)
            vx, vy = cos * vx - sin * vy, sin * vx + cos * vy
    return vx, vy, given


@numba.njit(cache=True, inline="always")
def _contacts_ahead(position, velocity, radius, lag, walls, order, low, high, near) -> bool:
    """Whether a straight flight of ``lag`` seconds may bring a disk to a wall or another disk
    (within `CONTACT_MARGIN`), and which: ``near`` (N,) gets True for those, False for the
    others.

    Pairs are swept and pruned along x: ``low`` and ``high`` (N,) get the x-interval each disk
    sweeps, and ``order`` (N,) lists the disks by its low end, kept from the last call (a nearly
    sorted list); a pair is tested only if their intervals overlap, which two disks that meet
    must do."""
    n = position.shape[0]
    shape, half_width, half_height, rim, segments = walls
    horizon = lag * (1.0 + CONTACT_MARGIN)
    meets = False
    for i in range(n):
        near[i] = False
    for i in range(n):
        x, y, vx, vy = position[i, 0], position[i, 1], velocity[i, 0], velocity[i, 1]
        wide = radius[i] * (1.0 + CONTACT_MARGIN)
        if segments.shape[0] == 0 and _clear_of_shape(x, y, vx, vy, wide, horizon, shape,
                                                      half_width, half_height, rim):  # fmt: skip
            continue
        delay, _ = contacts.earliest(x, y, vx, vy, wide, shape, half_width, half_height, rim,
                                     segments)  # fmt: skip
        if delay <= horizon:
            near[i] = meets = True
    for i in range(n):
        reach = radius[i] * (1.0 + 2.0 * CONTACT_MARGIN)  # wider than the test: never prunes a hit
        x, travel = position[i, 0], velocity[i, 0] * horizon
        low[i] = min(x, x + travel) - reach
        high[i] = max(x, x + travel) + reach
    sort_nearly_sorted(order, low)
    for a in range(n):
        i = order[a]
        for b in range(a + 1, n):
            j = order[b]
            if low[j] > high[i]:
                break
            sigma = (radius[i] + radius[j]) * (1.0 + CONTACT_MARGIN)
            if sigma > 0.0 and _closest(position, velocity, i, j, horizon) <= sigma * sigma:
                near[i] = near[j] = meets = True
    return meets


#: The relative slack of `_clear_of_shape` and `_rooms`, far above the round-off of their sums.
_SLACK = 1e-12


@numba.njit(cache=True, inline="always")
def _rooms(position, radius, walls, centres, rooms) -> None:
    """Each disk's room: a circle about its position (``centres`` (N, 2), m) of a radius
    (``rooms`` (N,), m) that keeps it clear of the walls and of every other disk's room by the
    contact test's margin, so that while every disk stays in its room (`_in_rooms`), no straight
    flight meets a contact, nor within `CONTACT_MARGIN` of one: at most the distance to the
    box's sides or the circle's rim less the widened radius, and half a pair's gap less the
    widened contact distance. Other shapes get no room (-1); nor does anything when the disks
    are more than `ROOMS_UP_TO` (``rooms`` empty)."""
    n = rooms.shape[0]
    shape, half_width, half_height, rim = walls[0], walls[1], walls[2], walls[3]
    for i in range(n):
        x, y = position[i, 0], position[i, 1]
        wide = radius[i] * (1.0 + CONTACT_MARGIN)
        if walls[4].shape[0] > 0:  # segments: no room
            room = -1.0
        elif shape == BOX:
            room = min(half_width - abs(x), half_height - abs(y)) - wide
        elif shape == CIRCLE:
            room = rim - math.hypot(x, y) - wide
        else:
            room = -1.0
        for j in range(n):
            sigma = (radius[i] + radius[j]) * (1.0 + CONTACT_MARGIN)
            if j != i and sigma > 0.0:
                gap = math.hypot(position[j, 0] - x, position[j, 1] - y) - sigma
                room = min(room, 0.5 * gap)
        centres[i, 0], centres[i, 1] = x, y
        rooms[i] = room * (1.0 - _SLACK) if room > 0.0 else -1.0


@numba.njit(cache=True, inline="always")
def _in_rooms(position, velocity, lag, centres, rooms) -> bool:
    """Whether every disk's straight flight over ``lag`` seconds (within `CONTACT_MARGIN` past
    it, as the contact test takes it) stays in its room (`_rooms`): start and end inside a
    circle, and the path with them. False where there are no rooms."""
    if rooms.shape[0] == 0:
        return False
    horizon = lag * (1.0 + CONTACT_MARGIN)
    for i in range(rooms.shape[0]):
        room = rooms[i]
        dx, dy = position[i, 0] - centres[i, 0], position[i, 1] - centres[i, 1]
        ex, ey = dx + velocity[i, 0] * horizon, dy + velocity[i, 1] * horizon
        reach = room * room
        if not (room > 0.0 and dx * dx + dy * dy < reach and ex * ex + ey * ey < reach):
            return False  # also NaN
    return True


@numba.njit(cache=True, inline="always")
def _clear_of_shape(x, y, vx, vy, reach, horizon, shape, half_width, half_height, rim) -> bool:
    """Whether a disk of radius ``reach`` (m) at (x, y) moving at (vx, vy) stays clear of its
    shape's own walls (a box's sides, a circle's rim) for ``horizon`` seconds, by a bound
    without divisions: where it holds, the wall's contact time is later, and most disks of a
    small scene are that far from the walls at every substep. False for other shapes."""
    if shape == BOX:
        return (abs(x) + abs(vx) * horizon + reach < half_width * (1.0 - _SLACK)
                and abs(y) + abs(vy) * horizon + reach < half_height * (1.0 - _SLACK))  # fmt: skip
    if shape == CIRCLE:
        return math.hypot(x, y) + math.hypot(vx, vy) * horizon + reach < rim * (1.0 - _SLACK)
    return False


@numba.njit(cache=True, inline="always")
def _closest(position, velocity, i, j, horizon) -> float:
    """The smallest squared distance (m^2) of disks i and j on straight paths within
    ``horizon`` seconds."""
    dx = position[j, 0] - position[i, 0]
    dy = position[j, 1] - position[i, 1]
    wx = velocity[j, 0] - velocity[i, 0]
    wy = velocity[j, 1] - velocity[i, 1]
    w2 = wx * wx + wy * wy
    approach = -(dx * wx + dy * wy)
    s = 0.0 if approach <= 0.0 or w2 == 0.0 else min(approach / w2, horizon)
    cx = dx + wx * s
    cy = dy + wy * s
    return cx * cx + cy * cy
