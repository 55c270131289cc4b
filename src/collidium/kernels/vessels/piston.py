"""A piston's arithmetic for the exact engine: one wall of a box that moves along its normal.

The piston is kept as one float64 array (`PISTON_SIZE` entries, `collidium.vessels.walls.
piston_array`), in coordinates along the wall's outward normal: the face's height ``h`` (m, the
box's centre at 0), its speed ``u`` (m/s, > 0 moving out of the box) and its constant
acceleration ``a = -F / M`` (m/s^2) from the external force F pushing it in. Between hits it
flies on the parabola ``h + u t + a t^2 / 2``, so its contacts with disks on straight paths, or
on parabolas of their own under a uniform gravity, are exact roots of quadratics
(`collidium.kernels.parabolas.first_contact`). Its travel is ``[LOW, HIGH]``, the ends of its
guides: a free piston bounces elastically at an end, a driven one stops there.

Disk-piston hits are the response `collidium.kernels.wall_responses.moving_wall`. The box's other
three walls are met as usual (`earliest`).
"""

from __future__ import annotations

import math

import numpy as np

from collidium.kernels import wall_responses
from collidium.kernels.compilation import inlined, uncounted
from collidium.kernels.parabolas import first_contact
from collidium.kernels.vessels import box

#: Entries of the piston array: the box wall it is (0 left, 1 right, 2 bottom, 3 top), its
#: height (m) and speed (m/s) along the outward normal at time STAMP (s), its acceleration
#: (m/s^2), mass (kg, inf when driven), restitution, the ends of its travel (m), the time of its
#: next arrival at an end (s) and whether it is driven (1.0) or free (0.0).
WALL, HEIGHT, SPEED, PULL, STAMP, MASS, RESTITUTION, LOW, HIGH, NEXT, DRIVEN = range(11)
PISTON_SIZE = 11


@inlined
def motion(piston: np.ndarray, t: float) -> tuple[float, float]:
    """The piston's height (m) and speed (m/s) along its outward normal at time t (s)."""
    lag = t - piston[STAMP]
    speed = piston[SPEED]
    return piston[HEIGHT] + (speed + 0.5 * piston[PULL] * lag) * lag, speed + piston[PULL] * lag


@inlined
def move_to(piston: np.ndarray, t: float) -> None:
    """Bring the piston's stamped state to time t (s)."""
    height, speed = motion(piston, t)
    piston[HEIGHT] = height
    piston[SPEED] = speed
    piston[STAMP] = t


@inlined
def _axis_and_sign(piston: np.ndarray) -> tuple[int, float]:
    wall = int(piston[WALL])
    return wall // 2, (1.0 if wall % 2 == 1 else -1.0)


@inlined
def delay(piston, now, x, y, vx, vy, r, gx=0.0, gy=0.0) -> float:
    """Time (s) from ``now`` until a disk of radius r at (x, y) moving at (vx, vy) under the
    acceleration (gx, gy) (m/s^2) touches the piston; inf if never on their present paths."""
    axis, sign = _axis_and_sign(piston)
    s = sign * (x if axis == 0 else y)
    v = sign * (vx if axis == 0 else vy)
    g = sign * (gx if axis == 0 else gy)
    height, speed = motion(piston, now)
    return first_contact(height - s - r, speed - v, piston[PULL] - g)


@uncounted()
def earliest(x, y, vx, vy, r, half_width, half_height, piston, now, gx=0.0, gy=0.0
             ) -> tuple[float, int]:  # fmt: skip
    """`collidium.kernels.vessels.box.wall_delay` for a box one of whose walls is the piston:
    ``(delay in s, wall)`` of the first of the three fixed walls and the piston that the disk,
    under the acceleration (gx, gy) (m/s^2), touches. Ties go to the fixed walls, in their
    order."""
    moving = int(piston[WALL])
    best = math.inf
    wall = -1
    for w in range(4):
        if w == moving:
            continue
        d = w // 2
        sign = 1.0 if w % 2 == 1 else -1.0
        touching = box.contact_coordinate(w, r, half_width, half_height)
        # The gap to the wall, closing at the disk's outward speed; as in box.wall_delay.
        gap = sign * (touching - (x if d == 0 else y))
        when = first_contact(gap, -sign * (vx if d == 0 else vy), -sign * (gx if d == 0 else gy))
        if when < best:
            best, wall = when, w
    when = delay(piston, now, x, y, vx, vy, r, gx, gy)
    if when < best:
        best, wall = when, moving
    return best, wall


@uncounted()
def touch(piston, t, x, y, r) -> tuple[float, float, float, float]:
    """A disk of radius r at (x, y) touching the piston at time t: ``(x, y, nx, ny)``, its
    centre snapped onto the contact line (so round-off never leaves it past the face) and the
    piston's outward unit normal."""
    axis, sign = _axis_and_sign(piston)
    height, _ = motion(piston, t)
    touching = sign * (height - r)
    if axis == 0:
        return touching, y, sign, 0.0
    return x, touching, 0.0, sign


@uncounted()
def hit(piston, t, vx, vy, mass, elastic_below) -> tuple[float, float, float, float]:
    """A disk of ``mass`` kg moving at (vx, vy) m/s hits the piston at time t (s): the piston's
    state is brought to t and its speed changed (`wall_responses.moving_wall`). A hit slower
    than ``elastic_below`` m/s is elastic (a disk resting on an inelastic piston would otherwise
    collide infinitely often in a finite time).

    Returns
    -------
    tuple of float
        The disk's new velocity (m/s), the momentum the piston receives along its outward
        normal (kg m/s) and the energy the piston gives the disk, the work done on the gas (J).
    """
    move_to(piston, t)
    axis, sign = _axis_and_sign(piston)
    outward = sign * (vx if axis == 0 else vy)
    wall = piston[SPEED]
    e = piston[RESTITUTION] if outward - wall >= elastic_below else 1.0
    after, piston[SPEED] = wall_responses.moving_wall(outward, wall, mass, piston[MASS], e)
    work = 0.5 * mass * (after * after - outward * outward)
    if axis == 0:
        vx = sign * after
    else:
        vy = sign * after
    return vx, vy, mass * (outward - after), work


@uncounted()
def schedule(piston: np.ndarray) -> None:
    """Set the time at which the piston next reaches an end of its travel (NEXT, s; inf if
    never on its present path)."""
    height, speed, pull = piston[HEIGHT], piston[SPEED], piston[PULL]
    out = first_contact(piston[HIGH] - height, -speed, -pull)
    back = first_contact(height - piston[LOW], speed, pull)
    piston[NEXT] = piston[STAMP] + min(out, back)


@uncounted()
def arrive(piston: np.ndarray) -> None:
    """The piston reaches an end of its travel at time NEXT: a driven one stops there, a free
    one bounces back elastically from the guides' end."""
    move_to(piston, piston[NEXT])
    upper = abs(piston[HEIGHT] - piston[HIGH]) <= abs(piston[HEIGHT] - piston[LOW])
    piston[HEIGHT] = piston[HIGH] if upper else piston[LOW]  # exactly at the end
    piston[SPEED] = 0.0 if piston[DRIVEN] != 0.0 else -piston[SPEED]
    schedule(piston)
