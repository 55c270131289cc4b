"""Electric fields acting on the charges: `UniformField`."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from collidium.forces.base import register
from collidium.forces.uniform import UniformForce


@register
@dataclass(frozen=True)
class UniformField(UniformForce):
    """A uniform electric field: ``F_i = q_i E``, ``U_i = -q_i E . x_i``
    (`collidium.forces.uniform`); between the plates of a capacitor, for instance.

    Parameters
    ----------
    E : tuple of float
        The field (x, y) in N/C (V/m).
    """

    name: ClassVar[str] = "uniform_field"
    vector: ClassVar[str] = "E"
    source: ClassVar[str] = "charge"

    E: tuple[float, float]
