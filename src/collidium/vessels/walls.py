"""Wall responses, chosen per wall of any vessel: `Specular` (the default), `Inelastic`,
`Thermal`. The arithmetic is in `collidium.kernels.wall_responses`, which every engine uses."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any, ClassVar

import numpy as np

from collidium.errors import InputError
from collidium.kernels import wall_responses
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
        e = self.restitution
        if not (isinstance(e, int | float) and 0.0 < e <= 1.0):
            raise InputError("restitution", f"must be in (0, 1], got {e!r}")

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


WallResponse = Specular | Inelastic | Thermal

#: Response classes by name (the ``response`` of a scenario's wall table).
RESPONSES: dict[str, type[WallResponse]] = {cls.name: cls for cls in (Specular, Inelastic, Thermal)}


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
        if not isinstance(response, Specular | Inelastic | Thermal):
            raise InputError(
                f"vessel.walls.{name}",
                f"must be Specular, Inelastic or Thermal, got {type(response).__name__}",
            )
        if not isinstance(response, Specular):
            out[name] = response
    return out
