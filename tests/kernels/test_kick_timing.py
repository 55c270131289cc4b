"""The second-order kick-timing correction of contacts under forces
(`collidium.kernels.kick_timing`): exact for accelerations that change linearly before and after
the contact, and the same as its NumPy twin."""

from __future__ import annotations

import numpy as np
import pytest

from collidium.kernels import kick_timing, reference
from collidium.kernels.events import LOG_COLUMNS

#: A pair law of unit sources, coupling 5 N m^2 and softening 0.1 m (`pairwise`).
LAW = (np.ones(2), 5.0, 0.01)


def logged(rows):
    """A contact log of these rows (particle, partner, time, normal, bounce factor, velocity
    change), with the columns the correction works in."""
    rows = np.asarray(rows, dtype=float)
    log = np.zeros((rows.shape[0], LOG_COLUMNS))
    log[:, : rows.shape[1]] = rows
    return log


def corrected(contacts, t0, h, start, position, before, after, velocity, mass, laws, size=None,
              shadow=False):  # fmt: skip
    """`kick_timing.correct` on a copy of ``velocity``, the laws stacked as the kernel takes
    them; the modified energy's term left out unless ``shadow``. Its work array of the
    particles' latest contacts is -1 again on return."""
    out = velocity.copy()
    latest = np.full(mass.size, -1, dtype=np.int64)
    contacts = contacts.copy()
    sources = np.array([law[0] for law in laws]).reshape(len(laws), mass.size)
    couplings = np.array([law[1] for law in laws], dtype=float)
    softenings2 = np.array([law[2] for law in laws], dtype=float)
    width, height = (10.0, 10.0) if size is None else size
    kick_timing.correct(contacts, contacts.shape[0], t0, h, start, position, before, after, out,
                        mass, sources, couplings, softenings2, width, height,
                        size is not None, shadow, latest)  # fmt: skip
    assert (latest == -1).all()
    return out


def exact_pair(mass, normal, v0, a0, ac, ah, tau, h):
    """Velocities at the substep's end of an elastic pair whose accelerations go linearly from
    ``a0`` to ``ac`` at the contact (tau s in) and from there to ``ah`` (h s in)."""
    v1, v2 = reference.pair_response(
        mass[0], mass[1], normal, np.zeros(2), *(v0 + 0.5 * (a0 + ac) * tau)
    )
    return np.array([v1, v2]) + 0.5 * (ac + ah) * (h - tau)


def scheme_pair(mass, normal, v0, a0, tau, h):
    """Kick-drift-kick up to the closing kick, with the engine's first-order response
    ``C(v - delta) + delta``, ``delta = a0 (h/2 - tau)``."""
    delta = a0 * (0.5 * h - tau)
    kicked = v0 + 0.5 * h * a0 - delta
    v1, v2 = reference.pair_response(mass[0], mass[1], normal, np.zeros(2), *kicked)
    return np.array([v1, v2]) + delta


def test_a_pair_with_accelerations_linear_on_each_side_of_the_contact_ends_exact():
    """The rest of each acceleration linear over the substep, the mutual force given at the
    start, the contact and the end: the corrected kick-drift-kick velocities are exact."""
    rng = np.random.default_rng(3)
    mass = np.array([1.0, 2.5])
    h, tau = 0.01, 0.0037
    start = np.array([[0.0, 0.0], [0.9, 0.3]])
    position = np.array([[0.02, 0.01], [0.85, 0.32]])
    normal = np.array([-0.45, -0.2])  # x_0 - x_1 at contact
    v0 = np.array([[3.0, 1.0], [-3.0, -1.0]])
    rest0, resth = rng.normal(size=(2, 2)), rng.normal(size=(2, 2))
    separations = {"start": start[0] - start[1], "end": position[0] - position[1],
                   "contact": normal}  # fmt: skip
    pull = {name: reference_pull(separation) for name, separation in separations.items()}
    mutual = {name: np.array([f, -f]) / mass[:, None] for name, f in pull.items()}
    a0, ah = rest0 + mutual["start"], resth + mutual["end"]
    ac = rest0 + (resth - rest0) * tau / h + mutual["contact"]
    contacts = logged([[0, 1, 2.0 + tau, *normal, 2.0, 0.0, 0.0]])
    after_drift = scheme_pair(mass, normal, v0, a0, tau, h)
    final = corrected(contacts, 2.0, h, start, position, a0, ah, after_drift, mass, [LAW])
    final += 0.5 * h * ah
    np.testing.assert_allclose(final, exact_pair(mass, normal, v0, a0, ac, ah, tau, h),
                               rtol=0, atol=1e-13)  # fmt: skip
    # Without the correction the first-order velocities are off by O(h a'), here ~1e-3 m/s.
    assert np.abs(after_drift + 0.5 * h * ah - final).max() > 1e-4


def reference_pull(separation):
    """The force on particle 0 of `LAW` at ``separation`` (x_0 - x_1), N."""
    sources, coupling, softening2 = LAW
    r2 = float(separation @ separation)
    return coupling * sources[0] * sources[1] / (r2 + softening2) ** 1.5 * separation


def test_a_wall_hit_under_an_acceleration_linear_in_time_ends_exact():
    """A mirror has no force of its own: the acceleration linear from ``a0`` to ``aH`` over the
    substep, the corrected velocity is the exact one."""
    h, tau = 0.02, 0.015
    a0, ah = np.array([[4.0, -1.0]]), np.array([[-2.0, 3.0]])
    ac = a0 + (ah - a0) * tau / h
    v0 = np.array([[5.0, 2.0]])
    normal = np.array([1.0, 0.0])  # the right wall's outward normal
    exact = v0 + 0.5 * (a0 + ac) * tau
    exact[0, 0] = -exact[0, 0]
    exact += 0.5 * (ac + ah) * (h - tau)
    delta = a0 * (0.5 * h - tau)
    drifted = v0 + 0.5 * h * a0 - delta
    drifted[0, 0] = -drifted[0, 0]
    drifted += delta
    contacts = logged([[0, -2, tau, *normal, 2.0, 0.0, 0.0]])
    position = np.zeros((1, 2))
    final = corrected(contacts, 0.0, h, position, position, a0, ah, drifted, np.ones(1), [])
    np.testing.assert_allclose(final + 0.5 * h * ah, exact, rtol=0, atol=1e-14)


def test_a_disk_meeting_two_walls_in_a_substep_ends_exact():
    """Two mirrors at an angle hit at tau1 and tau2, the acceleration linear in time: the error
    carried from the first contact through the second (their maps do not commute) leaves the
    exact velocity, where a correction for each contact alone would not."""
    h, tau1, tau2 = 0.02, 0.006, 0.015
    a0, ah = np.array([[4.0, -1.0]]), np.array([[-2.0, 3.0]])
    n1, n2 = np.array([1.0, 0.0]), np.array([-0.6, 0.8])
    v0 = np.array([[5.0, 2.0]])

    def reflect(v, n):
        return v - 2.0 * (v @ n) * n

    def impulse(t0, t1):  # of the acceleration linear in time
        a = lambda t: a0[0] + (ah[0] - a0[0]) * t / h  # noqa: E731
        return 0.5 * (a(t0) + a(t1)) * (t1 - t0)

    exact = reflect(reflect(v0[0] + impulse(0, tau1), n1) + impulse(tau1, tau2), n2)
    exact += impulse(tau2, h)
    # The engine's drift: C(v - delta) + delta at each, delta = a0 (h/2 - tau).
    v = v0[0] + 0.5 * h * a0[0]
    rows = []
    for tau, n in ((tau1, n1), (tau2, n2)):
        delta = a0[0] * (0.5 * h - tau)
        bounced = reflect(v - delta, n) + delta
        rows.append([0, -2, tau, *n, 2.0, *(bounced - v)])
        v = bounced
    position = np.zeros((1, 2))
    final = corrected(logged(rows), 0.0, h, position, position, a0, ah, v[None], np.ones(1), [])
    np.testing.assert_allclose(final[0] + 0.5 * h * ah[0], exact, rtol=0, atol=1e-14)


def test_constant_accelerations_need_no_correction():
    """The engine's first-order response is exact for constant accelerations: nothing to add."""
    a = np.array([[1.0, -2.0], [0.5, 3.0]])
    velocity = np.array([[1.0, 0.0], [-1.0, 0.5]])
    position = np.array([[0.0, 0.0], [0.5, 0.0]])
    contacts = logged([[0, 1, 0.3, -0.5, 0.0, 2.0, 0, 0], [1, -3, 0.6, 0.0, 1.0, 2.0, 0, 0]])
    final = corrected(contacts, 0.0, 1.0, position, position, a, a, velocity, np.ones(2), [])
    np.testing.assert_allclose(final, velocity, rtol=0, atol=1e-15)


def test_contacts_the_engine_did_not_correct_are_left_alone():
    """A bounce factor of 0: a wall that is not a mirror, a piston, a pair still approaching."""
    rng = np.random.default_rng(1)
    velocity = rng.normal(size=(2, 2))
    contacts = logged([[0, 1, 0.3, -0.5, 0.0, 0.0, 1, 0], [1, -3, 0.6, 0.0, 1.0, 0.0, 0, 2]])
    final = corrected(contacts, 0.0, 1.0, rng.normal(size=(2, 2)), rng.normal(size=(2, 2)),
                      rng.normal(size=(2, 2)), rng.normal(size=(2, 2)), velocity, np.ones(2),
                      [LAW])  # fmt: skip
    np.testing.assert_array_equal(final, velocity)


@pytest.mark.parametrize("periodic", [False, True])
def test_correction_matches_its_twin(periodic):
    """Random contacts of pairs and walls, two pair laws, inelastic bounces, a particle in two
    contacts, the modified energy's term: the kernel and `reference.kick_timing_correction` agree
    to round-off."""
    rng = np.random.default_rng(7)
    n, h, t0 = 6, 0.01, 3.0
    size = np.array([4.0, 3.0]) if periodic else None
    start = rng.uniform(-1.5, 1.5, (n, 2))
    position = start + rng.normal(scale=0.05, size=(n, 2))
    before, after = rng.normal(size=(2, n, 2))
    velocity = rng.normal(size=(n, 2))
    mass = rng.uniform(0.5, 2.0, n)
    laws = [(rng.choice([-1.0, 1.0], n), 5.0, 0.0), (mass.copy(), -0.1, 0.04)]
    rows = []
    for i, partner, bounce in [(0, 1, 2.0), (2, -1, 2.0), (1, 3, 1.7), (4, 5, 2.0), (4, -3, 2.0)]:
        normal = rng.normal(size=2)
        if partner < 0:
            normal /= np.linalg.norm(normal)
        rows.append([i, partner, t0 + rng.uniform(0, h), *normal, bounce, *rng.normal(size=2)])
    contacts = logged(rows)
    kernel = corrected(contacts, t0, h, start, position, before, after, velocity, mass, laws,
                       None if size is None else tuple(size), shadow=True)  # fmt: skip
    twin = velocity.copy()
    reference.kick_timing_correction(contacts, t0, h, start, position, before, after, twin, mass,
                                     laws, size)  # fmt: skip
    np.testing.assert_allclose(kernel, twin, rtol=1e-12, atol=1e-12)
    assert not np.array_equal(kernel, velocity)


def wall_hit_jump(h, shadow, share=0.3):
    """The change of velocity Verlet's modified energy ``S = H + h^2/12 w.Hess(U).w -
    h^2/24 |F|^2/m`` over one kick-drift-kick substep h in which a disk hits a mirror (the right
    wall, x = 0) a ``share`` of the way through it, pulled by a charge held fixed (a mass of 1e12
    kg) off to its side, so that the pull's Hessian mixes the normal and the tangent."""
    mass = np.array([1.0, 1e12])
    fixed = np.array([-0.6, 0.8])
    v0 = np.array([3.0, 2.0])

    def force(x):  # on the disk, N
        d = x - fixed
        return LAW[1] * d / (d @ d + LAW[2]) ** 1.5

    def modified(x, v):
        d, u = x - fixed, (x - fixed) @ (x - fixed) + LAW[2]
        hessian = LAW[1] * (3.0 * np.outer(d, d) / u - np.eye(2)) / u**1.5
        f = force(x)
        return (0.5 * v @ v + LAW[1] / np.sqrt(u) + h * h / 12 * v @ hessian @ v
                - h * h / 24 * f @ f)  # fmt: skip

    tau = share * h
    # Start where the half-kicked drift meets the wall at tau (the force along x does not
    # depend on x to the accuracy that matters here: solve by fixed point).
    x0 = np.array([-tau * v0[0], 0.0])
    for _ in range(50):
        x0[0] = -tau * (v0[0] + 0.5 * h * force(x0)[0])
    a0 = force(x0)
    half = v0 + 0.5 * h * a0
    delta = a0 * (0.5 * h - tau)
    bounced = half.copy()
    bounced[0] = -(half[0] - delta[0]) + delta[0]
    x1 = x0 + half * tau + bounced * (h - tau)
    ah = force(x1)
    contacts = logged([[0, -2, tau, 1.0, 0.0, 2.0, *(bounced - half)]])
    start, end = np.array([x0, fixed]), np.array([x1, fixed])
    before, after = np.array([a0, np.zeros(2)]), np.array([ah, np.zeros(2)])
    drifted = np.array([bounced, np.zeros(2)])
    out = corrected(contacts, 0.0, h, start, end, before, after, drifted, mass, [LAW],
                    shadow=shadow)  # fmt: skip
    v1 = out[0] + 0.5 * h * ah
    return modified(x1, v1) - modified(x0, v0)


def test_the_modified_energy_goes_through_a_wall_hit_to_third_order():
    """Between contacts kick-drift-kick keeps its modified energy S, not H; a contact that keeps
    H makes S jump by ``(h^2 - 3 tau (h - tau)) / 12`` times the change of ``w.Hess(U).w``, and
    these jumps, random from contact to contact, are the charged gas's energy drift. Taken out,
    S's jump falls eightfold per halving of h (third order), not fourfold."""
    plain = [wall_hit_jump(h, shadow=False) for h in (2e-3, 1e-3)]
    kept = [wall_hit_jump(h, shadow=True) for h in (2e-3, 1e-3)]
    assert 3.5 < plain[0] / plain[1] < 4.5
    assert 7.0 < kept[0] / kept[1] < 9.0
    assert abs(kept[1]) < abs(plain[1]) / 10
