"""Each vessel shape's wall arithmetic, one kernel file per shape (`collidium.vessels` holds the
shapes themselves), walls made of segments (`segments`: polygons and partitions) and the
dispatch over them (`contacts`). The engines tell the shapes apart by these codes, which each
`collidium.vessels.Vessel` names as its ``shape_code``."""

#: Shape codes: a rectangle centred on the origin (`box`), a circle centred on it (`circle`), a
#: polygon, whose walls are all segments (`segments`).
BOX, CIRCLE, POLYGON = 0, 1, 2
