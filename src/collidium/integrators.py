"""Kick-drift-kick leapfrog (seed eq. 1-3); the drift is done by the collision mode."""

from __future__ import annotations

from collidium.collisions import Drift, Tally
from collidium.containers import Box
from collidium.forces import ForceField
from collidium.state import Particles


class Leapfrog:
    """Velocity Verlet in kick-drift-kick form.

    ``v += a dt/2``; drift for dt (free flight with collisions, exact or not); ``a = F(x)/m``;
    ``v += a dt/2``. With exact collisions this is a Strang splitting of the hard-disk flow and the
    soft forces: collisions conserve energy exactly, the soft forces have a bounded O(dt^2) error.
    Without forces the kicks are skipped and the drift alone advances the state.
    """

    def step(
        self,
        particles: Particles,
        box: Box,
        field: ForceField,
        drift: Drift,
        now: float,
        dt: float,
        tally: Tally,
    ) -> None:
        """Advance ``particles`` in place from time ``now`` by ``dt`` (s).

        The acceleration of the current positions must be in the field's cache: `ForceField`
        evaluates it once before the first step, and this method keeps it current.
        """
        if field.active:
            particles.velocity += (0.5 * dt) * field.acceleration
        drift.drift(particles, box, now, dt, tally, field.acceleration if field.active else None)
        if field.active:
            particles.velocity += (0.5 * dt) * field.evaluate(particles, box)
