"""Forces: one module per force behind the `Force` protocol, found by name in `FORCES`.

- `Coulomb` (`coulomb.py`): between charges, seed eq. 9-10;
- `Newton` and `Gravity` (`gravity.py`): between masses, and a uniform field of free fall;
- `UniformField` (`fields.py`): a uniform electric field on the charges, and `FieldMap`
  (`fieldmap.py`): a potential given on a grid;
- `MagneticField` (`magnetic.py`): a uniform magnetic field out of the plane;
- `LinearDrag` and `QuadraticDrag` (`drag.py`), `Friction` (`friction.py`): forces that slow;
- `Langevin` (`thermostat.py`): a heat bath.

The first five act on the positions (`PositionForce`: kicks, with a potential energy), the
others on the velocities (`VelocityForce`: an exact flow on each side of the kicks).

`pair.py` holds what the inverse-distance pair forces share (one pair loop, direct or by tree),
`uniform.py` what the uniform fields share, `velocity.py` what the slowing forces share,
`base.py` the protocols, the registry and `ForceField`, what the integrators step with.
"""

from collidium.forces.base import (
    FORCES,
    Force,
    ForceField,
    PositionForce,
    VelocityForce,
    force_from_dict,
    parameters,
    register,
)
from collidium.forces.coulomb import Coulomb
from collidium.forces.drag import LinearDrag, QuadraticDrag
from collidium.forces.fieldmap import FieldMap
from collidium.forces.fields import UniformField
from collidium.forces.friction import Friction
from collidium.forces.gravity import Gravity, Newton
from collidium.forces.magnetic import MagneticField
from collidium.forces.pair import DEFAULT_THETA, SUM_METHODS, TREE_CROSSOVER, SumMethod
from collidium.forces.thermostat import Langevin

__all__ = [
    "DEFAULT_THETA",
    "FORCES",
    "SUM_METHODS",
    "TREE_CROSSOVER",
    "Coulomb",
    "FieldMap",
    "Force",
    "ForceField",
    "Friction",
    "Gravity",
    "Langevin",
    "LinearDrag",
    "MagneticField",
    "Newton",
    "PositionForce",
    "QuadraticDrag",
    "SumMethod",
    "UniformField",
    "VelocityForce",
    "force_from_dict",
    "parameters",
    "register",
]
