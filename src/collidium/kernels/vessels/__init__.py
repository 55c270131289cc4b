"""Each vessel shape's wall arithmetic, one kernel file per shape (`collidium.vessels` holds the
shapes themselves). The engines tell the shapes apart by these codes, which each
`collidium.vessels.Vessel` names as its ``shape_code``."""

#: Shape codes: a rectangle centred on the origin (`box`), a circle centred on it (`circle`).
BOX, CIRCLE = 0, 1
