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
    """

    def __init__(self, field: str, reason: str) -> None:
        self.field = field
        self.reason = reason
        super().__init__(f"{field}: {reason}")


class SimulationError(RuntimeError):
    """A run stopped because its state became invalid (never a silent blow-up)."""
