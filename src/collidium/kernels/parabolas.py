"""Free flight under a uniform acceleration: when a disk on a parabola first meets a line, or
first comes to a given distance from a point, for every engine (a piston's flight, and the exact
engine's disks under a uniform gravity they all share).

After t seconds a body at x moving at v under the acceleration g is at ``x + v t + g t^2 / 2``.
Its distance to a line is a quadratic in t (`first_contact`, `first_root`); its squared distance
to a point is a quartic (`distance_crossing`), whose first crossing is isolated between the
roots of its derivatives: the second derivative is a quadratic (closed form), the first a cubic
and the distance itself monotone between their roots, where a safeguarded Newton iteration
finds each root to round-off. Grazes (nearly double roots) carry ``sqrt(eps)`` of the time to
reach them, as with straight paths.
"""

from __future__ import annotations

import math

from collidium.kernels.compilation import inlined, uncounted

#: Newton-bisection iterations at most for one root (bisection alone halves the bracket each
#: time: 64 from any bracket of floats down to round-off, with margin).
ITERATIONS = 200


@inlined
def first_contact(gap: float, rate: float, pull: float) -> float:
    """The first time t >= 0 at which ``gap + rate t + pull t^2 / 2`` reaches 0 from above, s.

    Parameters
    ----------
    gap : float
        The distance now, m (a negative value is round-off and counts as 0).
    rate : float
        Its rate of change now, m/s (< 0: closing).
    pull : float
        Its constant second derivative, m/s^2.

    Returns
    -------
    float
        The delay in s, inf if the gap never closes. Stable forms of the roots (no
        cancellation for slow or grazing approaches); without a pull exactly ``gap / -rate``.
    """
    gap = max(gap, 0.0)
    if pull == 0.0:
        return gap / -rate if rate < 0.0 else math.inf
    if rate < 0.0:
        disc = rate * rate - 2.0 * pull * gap
        if disc < 0.0:
            return math.inf  # turns back before touching (pull > 0)
        return 2.0 * gap / (-rate + math.sqrt(disc))
    if pull > 0.0:
        return math.inf
    return (rate + math.sqrt(rate * rate - 2.0 * pull * gap)) / -pull


@inlined
def first_root(a: float, b: float, c: float, rising: bool) -> float:
    """The root of ``a t^2 + b t + c`` at which it is rising (slope > 0) or falling, s; NaN if
    there is none. Stable forms: no cancellation whatever the signs."""
    if a == 0.0:
        if (b > 0.0) == rising and b != 0.0:
            return -c / b
        return math.nan
    disc = b * b - 4.0 * a * c
    if disc < 0.0:
        return math.nan
    root = math.sqrt(disc)
    # The root with slope +root is (-b + root) / 2a, the one with slope -root (-b - root) / 2a.
    if rising:
        return (-b + root) / (2.0 * a) if b <= 0.0 else 2.0 * c / (-b - root)
    return (-b - root) / (2.0 * a) if b >= 0.0 else 2.0 * c / (-b + root)


@inlined
def _state(px, py, vx, vy, gx, gy, t):
    """Position and velocity after t seconds on the parabola."""
    return (px + (vx + 0.5 * gx * t) * t, py + (vy + 0.5 * gy * t) * t, vx + gx * t, vy + gy * t)


@uncounted()
def _evaluate(kind, px, py, vx, vy, gx, gy, reach, sense, t):
    """``(value, slope)`` at time t of what `_solve` looks for the root of: for ``kind`` 0 the
    rate ``x . u`` at which the squared distance changes (half of it; its slope ``|u|^2 +
    x . g``), for kind 1 ``sense (|x| - reach)`` (its slope ``sense x . u / |x|``)."""
    x, y, ux, uy = _state(px, py, vx, vy, gx, gy, t)
    rate = x * ux + y * uy
    if kind == 0:
        return rate, ux * ux + uy * uy + x * gx + y * gy
    size = math.hypot(x, y)
    slope = sense * rate / size if size > 0.0 else 0.0
    return sense * (size - reach), slope


@uncounted()
def _solve(kind, px, py, vx, vy, gx, gy, reach, sense, lo, hi, rising):
    """The root in ``[lo, hi]`` of `_evaluate`'s function, which is monotone there, rising
    (``rising``) or falling through 0 between the ends: Newton's iteration kept inside the
    bracket, bisection where it would leave it or stall."""
    t = 0.5 * (lo + hi)
    width = hi - lo
    for _ in range(ITERATIONS):
        value, slope = _evaluate(kind, px, py, vx, vy, gx, gy, reach, sense, t)
        if value == 0.0:
            break
        if (value < 0.0) == rising:
            lo = t
        else:
            hi = t
        step = value / slope if slope != 0.0 else math.inf
        if lo < t - step < hi and abs(step) < 0.5 * width:
            width, t = abs(step), t - step
        else:
            width, t = hi - lo, 0.5 * (lo + hi)
        if width <= 1e-16 * t or hi - lo <= 4e-16 * hi:
            break
    return t


@uncounted()
def _crossing_in(px, py, vx, vy, gx, gy, reach, sense, lo, hi) -> float:
    """The crossing on ``[lo, hi]``, an interval on which the distance is monotone (`
    distance_crossing`): its time, ``lo`` if the body is already across there and moving on
    across, inf if none."""
    if not lo < hi:
        return math.inf
    if _evaluate(1, px, py, vx, vy, gx, gy, reach, sense, 0.5 * (lo + hi))[1] <= 0.0:
        return math.inf  # moving back from the crossing
    if _evaluate(1, px, py, vx, vy, gx, gy, reach, sense, lo)[0] >= 0.0:
        return lo
    if _evaluate(1, px, py, vx, vy, gx, gy, reach, sense, hi)[0] < 0.0:
        return math.inf
    return _solve(1, px, py, vx, vy, gx, gy, reach, sense, lo, hi, True)


@uncounted()
def distance_crossing(px, py, vx, vy, gx, gy, reach, outward, horizon) -> float:
    """The first time t in ``[0, horizon]`` at which a body at (px, py) moving at (vx, vy) under
    the acceleration (gx, gy), not both 0, crosses the distance ``reach`` (m) from the origin
    outwards (``outward``: a disk inside a circle reaching its rim) or inwards (a disk's centre
    coming its radius from a point), s; inf if it does not by ``horizon`` (s; inf: ever).

    A body already across that is moving on across gets 0, and one already across that turns
    on across later gets the time it turns (round-off leaves a disk that just bounced a hair
    across).
    """
    sense = 1.0 if outward else -1.0
    g2 = gx * gx + gy * gy
    speed2 = vx * vx + vy * vy
    if horizon < math.inf:
        travel = horizon * (math.sqrt(speed2) + 0.5 * math.sqrt(g2) * horizon)
        if sense * (math.hypot(px, py) - reach) + travel < 0.0:
            return math.inf  # too far to get there by the horizon
    else:
        # Cauchy's bound on the roots of |x|^2 - reach^2 (leading coefficient |g|^2 / 4).
        largest = max(
            abs(vx * gx + vy * gy),
            abs(speed2 + px * gx + py * gy),
            abs(2.0 * (px * vx + py * vy)),
            abs(px * px + py * py - reach * reach),
        )
        horizon = 1.0 + 4.0 * largest / g2
    # The distance is monotone between the roots of x . u (the turning points), and x . u
    # between the roots of its own derivative |u|^2 + x . g = 3/2 |g|^2 t^2 + 3 v . g t +
    # |v|^2 + p . g (the bends).
    a, b, c = 1.5 * g2, 3.0 * (vx * gx + vy * gy), speed2 + px * gx + py * gy
    bends = (first_root(a, b, c, False), first_root(a, b, c, True), horizon)
    lo = 0.0  # start of the present interval of monotone distance
    start = 0.0  # start of the present interval of monotone x . u
    start_rate = px * vx + py * vy
    for stop in bends:
        if not start < stop <= horizon:  # also NaN
            continue
        stop_rate = _evaluate(0, px, py, vx, vy, gx, gy, reach, sense, stop)[0]
        if (start_rate < 0.0 < stop_rate) or (stop_rate < 0.0 < start_rate):
            turn = _solve(0, px, py, vx, vy, gx, gy, reach, sense, start, stop, stop_rate > 0.0)
            when = _crossing_in(px, py, vx, vy, gx, gy, reach, sense, lo, turn)
            if when < math.inf:
                return when
            lo = turn
        start, start_rate = stop, stop_rate
    return _crossing_in(px, py, vx, vy, gx, gy, reach, sense, lo, horizon)
