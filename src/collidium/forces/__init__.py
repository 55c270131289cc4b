"""Forces: one module per force behind the `Force` protocol, found by name in `FORCES`.

- `Coulomb` (`coulomb.py`): between charges, seed eq. 9-10;
- `Newton` and `Gravity` (`gravity.py`): between masses, and a uniform field of free fall;
- `UniformField` (`fields.py`): a uniform electric field on the charges.

`pair.py` holds what the inverse-distance pair forces share (one pair loop, direct or by tree),
`uniform.py` what the uniform fields share, `base.py` the protocol, the registry and
`ForceField`, the sum the integrators kick with.
"""

from collidium.forces.base import FORCES, Force, ForceField, force_from_dict, parameters, register
from collidium.forces.coulomb import Coulomb
from collidium.forces.fields import UniformField
from collidium.forces.gravity import Gravity, Newton
from collidium.forces.pair import DEFAULT_THETA, SUM_METHODS, TREE_CROSSOVER, SumMethod

__all__ = [
    "DEFAULT_THETA",
    "FORCES",
    "SUM_METHODS",
    "TREE_CROSSOVER",
    "Coulomb",
    "Force",
    "ForceField",
    "Gravity",
    "Newton",
    "SumMethod",
    "UniformField",
    "force_from_dict",
    "parameters",
    "register",
]
