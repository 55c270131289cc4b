"""Each vessel shape's wall arithmetic, one kernel file per shape (`collidium.vessels` holds the
shapes themselves)."""
