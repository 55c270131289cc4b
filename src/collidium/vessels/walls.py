"""Wall responses, chosen per wall of any vessel: `Specular` (the default), `Inelastic`,
`Thermal`, and `Piston`, a wall of a box that moves. The arithmetic is in
`collidium.kernels.wall_responses`, which every engine uses, and the piston's motion in
`collidium.kernels.vessels.piston`."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any, ClassVar

import numpy as np

from collidium.errors import InputError
from collidium.kernels import wall_responses
from collidium.kernels.vessels import piston as piston_kernels
from collidium.state import FloatArray


@dataclass(frozen=True)
class Specular:
    """A mirror: the normal velocity is reversed, nothing else changes."""

    name: ClassVar[str] = "specular"
    code: ClassVar[int] = wall_responses.SPECULAR

    @property
    def parameter(self) -> float:
        """Nothing to set (0)."""
        return 0.0


@dataclass(frozen=True)
class Inelastic:
    """The normal velocity is reversed and scaled by ``restitution`` e in (0, 1]; the disk loses
    ``(1 - e^2)`` of its normal kinetic energy to the wall.

    Parameters
    ----------
    restitution : float
        The coefficient e, in (0, 1] (1 is a mirror).
    """

    restitution: float
    name: ClassVar[str] = "inelastic"
    code: ClassVar[int] = wall_responses.INELASTIC

    def __post_init__(self) -> None:
        check_restitution(self.restitution)

    @property
    def parameter(self) -> float:
        """The restitution coefficient."""
        return float(self.restitution)


@dataclass(frozen=True)
class Thermal:
    """A wall at temperature ``temperature`` (kT, J; Boltzmann's constant is 1) that re-emits
    every disk that hits it with a velocity drawn from its Maxwell flux distribution: a gas
    between two such walls at the same temperature reaches it, and between walls at different
    temperatures carries heat from the hot one to the cold one. The energy each wall gives the
    gas is counted (`collidium.simulation.Simulation.wall_heat`).

    Parameters
    ----------
    temperature : float
        kT of the wall in J, > 0.
    """

    temperature: float
    name: ClassVar[str] = "thermal"
    code: ClassVar[int] = wall_responses.THERMAL

    def __post_init__(self) -> None:
        t = self.temperature
        if not (isinstance(t, int | float) and math.isfinite(t) and t > 0.0):
            raise InputError("temperature", f"must be a finite number > 0, got {t!r}")

    @property
    def parameter(self) -> float:
        """kT in J."""
        return float(self.temperature)


@dataclass(frozen=True)
class Piston:
    """A wall of a reflecting box that moves along its normal between guides, its ends being
    the box's edge behind it and the opposite wall (exact engine only).

    A free piston has a mass, may feel a constant external force pushing it into the gas (a
    weight, an outside pressure times its length) and collides with the disks as an exact event
    (`collidium.kernels.wall_responses.moving_wall`); at an end of its guides it bounces back. A
    driven piston moves at a set velocity, whatever hits it, until it reaches ``stop``. Its
    position and velocity are `collidium.simulation.Simulation.piston`'s; the work it does on
    the gas is its wall's `collidium.simulation.Simulation.wall_heat`.

    Parameters
    ----------
    position : float
        Where its face starts, m, as a coordinate along its axis (the y of a top or bottom
        piston, the x of a left or right one).
    mass : float
        kg, > 0 (unused when driven).
    force : float
        External force pushing it into the box, N (>= 0; 0 when driven).
    velocity : float
        Starting velocity along its axis, m/s (> 0 towards +x or +y); a driven piston keeps it.
    driven : bool
        Moved at ``velocity`` whatever the disks do (compression or expansion at a set rate).
    stop : float, optional
        Where a driven piston halts, m, a coordinate along its axis (default: the end of its
        guides).
    restitution : float
        Normal restitution of its collisions with disks, in (0, 1].
    """

    position: float
    mass: float = 1.0
    force: float = 0.0
    velocity: float = 0.0
    driven: bool = False
    stop: float | None = None
    restitution: float = 1.0
    name: ClassVar[str] = "piston"
    code: ClassVar[int] = wall_responses.PISTON

    def __post_init__(self) -> None:
        for field in ("position", "velocity", "force", "mass"):
            if not _finite(getattr(self, field)):
                raise InputError(field, f"must be a finite number, got {getattr(self, field)!r}")
        if self.mass <= 0:
            raise InputError("mass", f"must be > 0, got {self.mass!r}")
        if self.force < 0:
            raise InputError("force", f"must be >= 0 (it pushes into the box), got {self.force!r}")
        if not isinstance(self.driven, bool):
            raise InputError("driven", f"must be true or false, got {self.driven!r}")
        if self.driven and self.force != 0:
            raise InputError("force", "a driven piston keeps its velocity: give no force")
        if self.stop is not None and not self.driven:
            raise InputError("stop", "only a driven piston stops; a free one moves freely")
        if self.stop is not None and not _finite(self.stop):
            raise InputError("stop", f"must be a finite number, got {self.stop!r}")
        check_restitution(self.restitution)

    @property
    def parameter(self) -> float:
        """The restitution coefficient."""
        return float(self.restitution)


def check_restitution(restitution: object) -> None:
    """Refuse a normal restitution coefficient outside (0, 1] (field ``restitution``)."""
    e = restitution
    if not (isinstance(e, int | float) and not isinstance(e, bool) and 0.0 < e <= 1.0):
        raise InputError("restitution", f"must be in (0, 1], got {e!r}")


def _finite(value: object) -> bool:
    """A finite number (not a bool)."""
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)


WallResponse = Specular | Inelastic | Thermal | Piston

#: Response classes by name (the ``response`` of a scenario's wall table).
RESPONSES: dict[str, type[WallResponse]] = {
    cls.name: cls for cls in (Specular, Inelastic, Thermal, Piston)
}


def wall_axis(wall: int) -> tuple[int, float]:
    """The axis a box wall's outward normal lies along (0: x, 1: y) and its sign (+1 for the
    right and top walls), for the wall's index (0 left, 1 right, 2 bottom, 3 top)."""
    return wall // 2, (1.0 if wall % 2 == 1 else -1.0)


def piston_array(
    wall: int, piston: Piston, half: float, position: float, velocity: float, now: float
) -> FloatArray:
    """The exact engine's piston (`collidium.kernels.vessels.piston`) for ``piston`` as box
    wall ``wall`` (0 left, 1 right, 2 bottom, 3 top) of half side ``half`` (m) along its axis,
    its face at ``position`` (m) moving at ``velocity`` (m/s), both along the axis, at time
    ``now`` (s)."""
    k = piston_kernels
    _, sign = wall_axis(wall)
    array = np.zeros(k.PISTON_SIZE)
    array[k.WALL] = wall
    array[k.HEIGHT], array[k.SPEED], array[k.STAMP] = sign * position, sign * velocity, now
    array[k.RESTITUTION] = piston.restitution
    array[k.LOW], array[k.HIGH] = -half, half
    if piston.driven:
        array[k.MASS], array[k.DRIVEN] = math.inf, 1.0
        if piston.stop is not None:
            end = sign * piston.stop
            inward = sign * velocity < 0.0
            array[k.LOW if inward else k.HIGH] = end
    else:
        array[k.MASS], array[k.PULL] = piston.mass, -piston.force / piston.mass
    piston_kernels.schedule(array)
    return array


def response_to_dict(response: WallResponse) -> dict[str, Any]:
    """``{"response": name, **parameters}``, as in a scenario file."""
    return {"response": response.name, **asdict(response)}


def response_from_dict(data: dict[str, Any], field: str) -> WallResponse:
    """The response `response_to_dict` describes; errors name ``field``."""
    values = dict(data)
    name = values.pop("response", "specular")
    if name not in RESPONSES:
        raise InputError(f"{field}.response", f"must be one of {tuple(RESPONSES)}, got {name!r}")
    try:
        return RESPONSES[name](**values)
    except InputError as exc:
        raise InputError(f"{field}.{exc.field}", exc.reason) from None
    except TypeError as exc:
        raise InputError(field, f"bad parameters for a {name} wall ({exc})") from None


def wall_table(names: tuple[str, ...], responses: dict[str, WallResponse]) -> FloatArray:
    """The kernels' wall table (`collidium.kernels.wall_responses`), one row per wall in
    ``names`` order: ``[code, parameter, key]``, the key being the wall's index."""
    table = np.zeros((len(names), wall_responses.WALL_TABLE_COLUMNS))
    for index, name in enumerate(names):
        response = responses.get(name, Specular())
        table[index] = (response.code, response.parameter, index)
    return table


def checked_walls(
    names: tuple[str, ...], walls: dict[str, WallResponse] | None
) -> dict[str, WallResponse]:
    """``walls`` with every name a wall of the vessel and every value a response; specular
    entries dropped (they are the default)."""
    out: dict[str, WallResponse] = {}
    for name, response in (walls or {}).items():
        if name not in names:
            allowed = ", ".join(names) if names else "none (a periodic box has no walls)"
            raise InputError(f"vessel.walls.{name}", f"no such wall; the walls are: {allowed}")
        if not isinstance(response, Specular | Inelastic | Thermal | Piston):
            raise InputError(
                f"vessel.walls.{name}",
                f"must be Specular, Inelastic, Thermal or Piston, got {type(response).__name__}",
            )
        if not isinstance(response, Specular):
            out[name] = response
    return out
