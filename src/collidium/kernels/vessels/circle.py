"""The circle's wall arithmetic, for every engine: the time to the rim, the contact point and
normal (exact engine, and the hit-by-hit flight of the step and off modes in `contacts`) and the
outside test (audit).

The circle is centred on the origin with radius ``rim`` (m); its one wall, the rim, is wall 0.
A disk of radius r touches it when its centre is ``rim - r`` from the origin; the outward
normal there is the centre's direction.
"""

from __future__ import annotations

import math

from collidium.kernels import parabolas
from collidium.kernels.compilation import inlined


@inlined
def wall_delay(
    x: float,
    y: float,
    vx: float,
    vy: float,
    r: float,
    rim: float,
    gx: float = 0.0,
    gy: float = 0.0,
    horizon: float = math.inf,
) -> tuple[float, int]:
    """Time until a disk of radius ``r`` at (x, y) moving at (vx, vy) under the acceleration
    (gx, gy) (m/s^2) touches the rim.

    On a straight path, the later root of ``|x + v t| = rim - r`` (the disk is inside); on a
    parabola, the first outward crossing (`collidium.kernels.parabolas.distance_crossing`),
    looked for up to ``horizon`` (s; a contact after it may be reported as inf). Returns
    ``(delay in s, 0)``, or ``(inf, -1)`` at rest; a disk at or past the rim moving outwards
    gets 0.
    """
    if gx != 0.0 or gy != 0.0:
        delay = parabolas.distance_crossing(x, y, vx, vy, gx, gy, rim - r, True, horizon)
        return (delay, 0) if delay < math.inf else (math.inf, -1)
    speed2 = vx * vx + vy * vy
    if speed2 == 0.0:
        return math.inf, -1
    reach = rim - r
    b = x * vx + y * vy
    c = x * x + y * y - reach * reach
    if c >= 0.0 and b >= 0.0:
        return 0.0, 0
    root = math.sqrt(max(b * b - speed2 * c, 0.0))
    # Stable forms of (-b + root) / speed2: no cancellation whatever the sign of b.
    delay = (root - b) / speed2 if b <= 0.0 else -c / (b + root)
    return max(delay, 0.0), 0


@inlined
def outward_normal(x: float, y: float) -> tuple[float, float]:
    """Unit outward normal of the rim at the direction of (x, y) (x axis at the centre)."""
    length = math.hypot(x, y)
    if length == 0.0:
        return 1.0, 0.0
    return x / length, y / length


@inlined
def contact_point(x: float, y: float, r: float, rim: float) -> tuple[float, float]:
    """(x, y) moved along its direction to ``rim - r`` from the centre: where a disk of radius
    ``r`` touching the rim there is (the snap that keeps round-off from leaving it outside)."""
    nx, ny = outward_normal(x, y)
    reach = rim - r
    return nx * reach, ny * reach


@inlined
def reaches_outside(x: float, y: float, reach: float, limit: float) -> bool:
    """Whether a disk at (x, y) reaching ``reach`` m from its centre passes ``limit`` m from the
    origin (the rim with its round-off allowance)."""
    return math.hypot(x, y) + reach > limit
