"""Exceptions that front ends turn into one clear line.

`InputError` is bad input (a field and the reason); `SimulationError` is a run that went wrong
(a non-finite value or a particle outside its vessel), naming the step and the particles.
"""

from __future__ import annotations


class InputError(ValueError):
    """Bad input: names the offending field and the reason.

    Parameters
    ----------
    field : str
        Dotted name of the field, e.g. ``"particles.mass"`` or ``"dt"``.
    reason : str
        Why the value is refused, in a few words.
    particles : tuple of int, optional
        Indices of the particles at fault (an overlapping pair, a particle outside the vessel), so
        that a front end can name them in its own terms.
    """

    def __init__(self, field: str, reason: str, particles: tuple[int, ...] = ()) -> None:
        self.field = field
        self.reason = reason
        self.particles = particles
        super().__init__(f"{field}: {reason}")


class SimulationError(RuntimeError):
    """A run stopped because its state became invalid (never a silent blow-up)."""


class Interrupted(Exception):
    """Ctrl-C during a run: the message says where it stopped and what was kept. (Not a
    KeyboardInterrupt: the command line's framework would turn that into a silent exit.)"""
