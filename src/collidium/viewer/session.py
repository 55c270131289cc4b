"""`ViewerSession`: one simulation as the viewer shows and drives it, whatever the transport.

The session owns the `Simulation` and what the controls change (playing, speed, heating,
toggles, the traced particle). It answers with plain dicts (the JSON messages of
`collidium.viewer.protocol`) and binary frames; `Connection` decides when to send them.
"""

from __future__ import annotations

import math
import re
import time as clock
from collections import deque
from typing import Any

import numpy as np

from collidium import __version__
from collidium.errors import InputError, SimulationError
from collidium.observers.energy import conserved_energy, drift_warning
from collidium.observers.speeds import SpeedHistogram
from collidium.observers.thermo import Thermo
from collidium.presets import PRESETS, describe_presets, preset
from collidium.scenario import Scenario
from collidium.simulation import PistonState, Simulation
from collidium.state import PROPERTIES, FloatArray, Particles, uniform_or_each
from collidium.theory import MaxwellBoltzmann2D
from collidium.vessels import Vessel
from collidium.vessels.walls import Thermal, WallResponse, wall_axis
from collidium.viewer import protocol
from collidium.viewer.builder import BUILDER
from collidium.viewer.guide import ColourMode, guide, parameter_specs
from collidium.viewer.moving_wall import SPEED_FRACTION, movable_wall

#: Bins of the live speed histogram.
HISTOGRAM_BINS = 30
#: Pressure and collision rate are averages over this many intervals between stats samples (the
#: pressure's error is that of their block average).
WINDOW_SAMPLES = 5
#: Most wall-clock time the simulation may owe, s: a backlog beyond it (a long pause, steps
#: slower than real time) is dropped, not caught up.
MAX_CATCH_UP = 0.25
#: A step that takes longer than this, in s, pauses the session with an error (dt or N is too
#: large for a live view).
MAX_STEP_SECONDS = 2.0


class ViewerSession:
    """A simulation with the viewer's controls.

    Parameters
    ----------
    scenario : Scenario, optional
        What the session builds (and rebuilds on reset); its observers are not run.
    simulation : Simulation, optional
        A simulation to show and run in place, its observers included (give this or
        ``scenario``); reset starts a copy of the state it had when the session started.
    preset : str, optional
        The preset ``scenario`` came from, and ``overrides`` its parameters, shown on the page.
    """

    def __init__(
        self,
        scenario: Scenario | None = None,
        simulation: Simulation | None = None,
        preset: str | None = None,
        overrides: dict[str, Any] | None = None,
    ) -> None:
        if (scenario is None) == (simulation is None):
            raise InputError("session", "give a scenario or a simulation")
        self.generation = 0
        self.playing = True
        self.speed = 1.0
        self.momentum = False
        #: Bumped whenever the state shown changes (a frame is due).
        self.version = 0
        if scenario is not None:
            self._install(scenario, preset, overrides or {})
        else:
            assert simulation is not None
            _check_size(simulation.particles.n, bool(simulation.forces), "particles")
            self._initial = simulation.copy()
            self._start(simulation, None, None, {})

    # -- set-up -----------------------------------------------------------------------------

    def _install(self, scenario: Scenario, name: str | None, overrides: dict[str, Any]) -> None:
        field = "n" if "n" in overrides else "particles"
        _check_size(scenario.particle_count, bool(scenario.forces), field)
        self._start(BUILDER.build(scenario, field), scenario, name, overrides)

    def _start(
        self,
        sim: Simulation,
        scenario: Scenario | None,
        name: str | None,
        overrides: dict[str, Any],
    ) -> None:
        self.sim = sim
        self._scenario = scenario
        self._preset = name
        self._overrides = dict(overrides)
        self._mode = sim.collisions if sim.collisions != "off" else "exact"
        self._forces = sim.forces
        self.traced: int | None = None
        #: kT (J) of the thermal walls held while heating or cooling continuously, or None.
        self.wall_temperature: float | None = None
        self._vessel = sim.container  # with its own walls, given back when the hold ends
        self._movable = movable_wall(sim, self._vessel)
        # Where the dragged wall is headed (m along its axis) and how fast (m/s); a box's wall
        # keeps its target after the drag, a free piston is let go.
        self._wall_target: float | None = None
        self._wall_speed = 0.0
        self.histogram_window = 1
        # (upper speed, density, time, kT) of the last readouts' histograms
        self._histograms: deque[tuple[float, FloatArray, float, float]] = deque(
            maxlen=protocol.MAX_HISTOGRAM_WINDOW
        )
        self._species, self._species_labels = _species(sim.particles)
        self.colour: ColourMode = self._colour_modes()[0]
        wanted = guide(name).colour
        if wanted in self._colour_modes():
            self.colour = wanted
        self.generation += 1
        self._carry = 0.0
        # Measured on the second step: the first also loads the kernels (the scenario was
        # built in another process), and is neither timed nor judged.
        self._seconds_per_step: float | None = None
        self._loaded = False
        self._upper_speed = 0.0
        self._changed()

    def _changed(self) -> None:
        """The state was changed from outside the dynamics: restart the drift and the windows."""
        self._reference = conserved_energy(self.sim)
        self._worst_drift = 0.0  # largest relative energy drift since
        self._thermo = Thermo()
        self._pressure: float | None = None
        self._pressure_error: float | None = None
        self._rate: float | None = None
        self._window: tuple[float, int] | None = None
        self.version += 1

    def _fresh(self) -> Simulation:
        """A new simulation in the starting state."""
        if self._scenario is not None:
            return BUILDER.build(self._scenario)
        return self._initial.copy()

    # -- controls ---------------------------------------------------------------------------

    def load(self, name: str, overrides: dict[str, Any]) -> None:
        """Switch to a preset with parameter overrides (validated like the command line's)."""
        if name not in PRESETS:
            raise InputError("preset", f"unknown preset {name!r}; choose from {', '.join(PRESETS)}")
        self._install(preset(name, **overrides), name, overrides)

    def load_toml(self, text: str) -> None:
        """Switch to a scenario given as TOML text (validated like a scenario file)."""
        scenario = Scenario.from_toml_string(text, source="scenario")
        if scenario.observers:
            raise InputError(
                "observers", "the viewer measures by itself; remove the [[observers]] tables"
            )
        self._install(scenario, None, {})

    def reset(self) -> None:
        """Back to the starting state (the toggles too)."""
        self._start(self._fresh(), self._scenario, self._preset, self._overrides)

    def step(self) -> None:
        """One time step (pauses first)."""
        self.playing = False
        self._run(1)

    def set_speed(self, value: float) -> None:
        """Simulated seconds per wall-clock second."""
        self.speed = float(value)
        self._carry = 0.0

    def heat(self, factor: float) -> None:
        """Multiply the kinetic energy by ``factor`` (velocities by its square root)."""
        self.sim.particles.velocity *= math.sqrt(factor)
        self._changed()

    def hold_wall_temperature(self, kT: float | None) -> None:
        """Make the vessel's walls thermal walls at ``kT`` (J), heating or cooling the gas
        continuously through them, until called with None, which gives the walls back their
        own responses (a piston, and a wall the user has moved, stay as they are). The energy
        they exchange is counted as wall heat, so the energy drift readout stays that of the
        dynamics."""
        if kT is not None and not self._heatable_walls():
            raise InputError("temperature", "a periodic box has no walls to heat through; "
                             "use the heat and cool buttons")  # fmt: skip
        self.wall_temperature = kT
        self._set_walls()

    def move_wall(self, to: float | None) -> None:
        """Drag the vessel's movable wall (`collidium.viewer.moving_wall`) towards ``to`` (m, a
        coordinate along its axis, kept within its range) as a driven piston moving at
        `SPEED_FRACTION` of the gas's rms speed: compressing heats the gas, expanding cools
        it, and the work done is counted as that wall's heat. None lets go: a free piston
        moves freely again, a box's wall goes on to where it was last sent and stays there."""
        wall = self._movable
        if wall is None:
            raise InputError("wall", "only a box with exact collisions and no forces has a wall "
                             "to move")  # fmt: skip
        if to is None:
            if wall.piston is not None:
                self._wall_target = None
        else:
            self._wall_target = wall.clip(to)
            p = self.sim.particles
            rms = math.sqrt(2.0 * self.sim.energy().kinetic / float(np.sum(p.mass))) if p.n else 0
            # A gas at rest: across the range in 1 s.
            self._wall_speed = SPEED_FRACTION * rms or (wall.high - wall.low)
        self._set_walls()

    def _heatable_walls(self) -> list[str]:
        """The vessel's walls but its piston and the wall the user has moved."""
        vessel = self._vessel
        moving = {vessel.piston[0]} if vessel.piston is not None else set()
        if self._movable is not None and self._wall_target is not None:
            moving.add(self._movable.wall)
        return [name for k, name in enumerate(vessel.shape_walls) if k not in moving]

    def _set_walls(self) -> None:
        """The simulation's vessel: its own, with the walls held at `wall_temperature` and the
        dragged wall driven towards its target from where it is now."""
        responses: dict[str, WallResponse] = {}
        if self.wall_temperature is not None:
            responses |= {name: Thermal(self.wall_temperature) for name in self._heatable_walls()}
        wall = self._movable
        if wall is not None and self._wall_target is not None:
            state = self.sim.piston()
            at = wall.rest if state is None or state.wall != wall.name else state.position
            responses[wall.name] = wall.driven(at, self._wall_target, self._wall_speed)
        self.sim.container = self._vessel.with_walls(responses) if responses else self._vessel

    def pump(self, count: int, kT: float | None = None) -> int:
        """Let ``count`` particles in through the hatch (the middle of the vessel's first wall,
        of the part of it on the gas's side of a piston)
        at temperature ``kT`` (J; default the gas's), or, with ``count`` < 0, let out the
        ``-count`` nearest the hatch. A particle let in is a copy of particle 0 (mass, radius,
        charge) with a velocity drawn as a thermal wall emits (`collidium.vessels.walls.Thermal`):
        those that would overlap another wait for a later pump. Returns how many went in or out.
        """
        hatch, inward = _hatch(self._vessel, self.sim.piston())
        p = self.sim.particles
        if count < 0:
            nearest = np.argsort(np.hypot(*(p.position - hatch).T))[: min(-count, p.n)]
            self.sim.remove_particles(nearest)
        else:
            count = min(count, protocol.MAX_PARTICLES - p.n)
            kT = kT if kT is not None else (self.sim.temperature() if p.n else 0.0)
            if p.n == 0 or not kT > 0:
                raise InputError("temperature", "give the temperature of the gas to let in")
            added = _arrivals(p, self.sim.rng, count, kT, hatch, inward)
            blocked = _blocked(added, p) | _outside(self.sim, added)
            added = added.without(np.flatnonzero(blocked))
            self.sim.add_particles(added)
            count = added.n
        self._changed()
        return abs(count)

    def set_histogram_window(self, readouts: int) -> None:
        """Average the speed histogram over the last ``readouts`` stats messages (1: none)."""
        self.histogram_window = readouts
        self.version += 1

    def enable_collisions(self, enabled: bool) -> None:
        """Collisions between disks on (the scenario's mode) or off (walls still reflect)."""
        self.sim.collisions = self._mode if enabled else "off"
        self._changed()

    def enable_forces(self, enabled: bool) -> None:
        """The scenario's forces on or off."""
        if enabled and not self._forces:
            raise InputError("forces", "this scenario has no forces to switch on")
        self.sim.forces = self._forces if enabled else ()
        self._changed()

    def trace(self, index: int | None) -> None:
        """Follow particle ``index`` (None: none)."""
        if index is not None:
            self._check_index(index)
        self.traced = index

    def set_velocity(self, index: int, vx: float, vy: float) -> None:
        """Give particle ``index`` the velocity (vx, vy) in m/s."""
        self._check_index(index)
        self.sim.particles.velocity[index] = (vx, vy)
        self._changed()

    @property
    def starting(self) -> bool:
        """True until the first step has run (on a fresh installation it compiles the
        kernels)."""
        return not self._loaded

    @property
    def collisions_enabled(self) -> bool:
        """Whether disks collide with each other."""
        return self.sim.collisions != "off"

    @property
    def forces_enabled(self) -> bool:
        """Whether the scenario's forces act."""
        return bool(self.sim.forces)

    def set_colour(self, mode: ColourMode) -> None:
        """Colour the disks by ``mode``: "speed", "charge" or "species" (see `_colour_modes`)."""
        offered = self._colour_modes()
        if mode not in offered:
            raise InputError(
                "mode", f"{mode!r} does not apply to this scene; choose from {', '.join(offered)}"
            )
        self.colour = mode
        self.version += 1  # the next frame carries velocities (or stops carrying them)

    def _colour_modes(self) -> list[ColourMode]:
        """Speed always; charge when some disk is charged; species when there are several."""
        modes: list[ColourMode] = ["speed"]
        if np.any(self.sim.particles.charge != 0):
            modes.append("charge")
        if len(self._species_labels) > 1:
            modes.append("species")
        return modes

    def _check_index(self, index: int) -> None:
        n = self.sim.particles.n
        if index >= n:
            raise InputError("index", f"no particle {index}; there are {n}")

    # -- running ----------------------------------------------------------------------------

    def advance(self, wall_seconds: float, budget: float) -> None:
        """Run for ``wall_seconds`` times the speed of simulated time, in whole steps: as many
        of those owed as fit ``budget`` s of computation (at least one). Time not run is owed
        to the next calls, up to `MAX_CATCH_UP` s of wall-clock time; past that the simulation
        runs slower than asked.

        Raises
        ------
        SimulationError
            If the run goes wrong; the session pauses.
        """
        if not self.playing:
            return
        dt = self.sim.dt
        owed = self._carry + wall_seconds * self.speed  # simulated s
        self._carry = min(owed, MAX_CATCH_UP * self.speed)
        wanted = self._carry / dt + 1e-9  # the slack keeps whole multiples whole
        if wanted < 1:
            return
        per_step = self._seconds_per_step
        # Owed time is kept, not dropped: the time lost to a tick that ran long (another
        # program took the core) is made up by the next ones, which fit more steps than keep pace.
        fit = 1 if per_step is None else max(1, int(budget / max(per_step, 1e-9)))
        count = fit if wanted >= fit else int(wanted)  # (wanted may be inf: a tiny dt)
        self._carry -= count * dt
        start = clock.perf_counter()
        self._run(count)
        spent = (clock.perf_counter() - start) / count
        if not self._loaded:
            self._loaded = True
            return
        self._seconds_per_step = spent if per_step is None else 0.7 * per_step + 0.3 * spent
        if spent > MAX_STEP_SECONDS:
            self.playing = False
            raise SimulationError(
                f"one step took {spent:.3g} s, too slow to watch; paused: lower N or dt"
            )

    def _run(self, steps: int) -> None:
        try:
            self.sim.run(steps=steps)
        except SimulationError:
            self.playing = False
            raise
        finally:
            self.version += 1

    # -- what the front end is sent ---------------------------------------------------------

    def hello(self) -> dict[str, Any]:
        """The presets with their main parameters, and the limits."""
        presets = [
            {
                "name": entry["name"],
                "description": entry["description"],
                "explanation": guide(entry["name"]).explanation,
                "parameters": parameter_specs(entry["parameters"]),
            }
            for entry in describe_presets()
        ]
        limits = {
            "max_particles": protocol.MAX_PARTICLES,
            "max_charged_particles": protocol.MAX_CHARGED_PARTICLES,
            "speed": list(protocol.SPEED_RANGE),
            "max_message_bytes": protocol.MAX_MESSAGE_BYTES,
            "messages_per_second": protocol.MESSAGES_PER_SECOND,
        }
        return {"type": "hello", "version": __version__, "presets": presets, "limits": limits}

    def scene(self) -> dict[str, Any]:
        """The vessel and what each particle looks like."""
        sim = self.sim
        p = sim.particles
        vessel = sim.container
        notes = guide(self._preset)
        highlight = None
        if notes.highlight is not None and -p.n <= notes.highlight < p.n:
            highlight = notes.highlight % p.n
        return {
            "type": "scene", "generation": self.generation, "name": sim.name,
            "preset": self._preset, "overrides": self._overrides, "n": p.n,
            "vessel": vessel.to_dict() | {
                "description": vessel.describe(), "periodic": vessel.periodic,
                "outline": vessel.outline().tolist(), "bounds": vessel.bounds.tolist(),
                "fill": vessel.fill().tolist(),
                "partition_lines": vessel.partition_lines().tolist(),
                "walls": list(vessel.wall_names),
            },
            "radius": _compact(p.radius), "charge": _compact(p.charge),
            "mass": _compact(p.mass), "dt": sim.dt, "collisions": self._mode,
            "has_forces": bool(self._forces),
            "has_charges": bool(self._forces) and bool(np.any(p.charge != 0)),
            "species": _compact(self._species.astype(float)) if p.n else 0.0,
            "species_labels": self._species_labels, "colour_modes": self._colour_modes(),
            "explanation": notes.explanation, "highlight": highlight,
            "movable_wall": None if self._movable is None else self._movable.to_dict(),
            "highlight_label": notes.highlight_label if highlight is not None else "",
        }  # fmt: skip

    def status(self) -> dict[str, Any]:
        """Playing, speed, the toggles, and the phase: "starting" until the first step has run
        (on a fresh installation it compiles the kernels, for up to half a minute)."""
        return {
            "type": "status", "playing": self.playing, "speed": self.speed,
            "collisions": self.collisions_enabled, "forces": self.forces_enabled,
            "momentum": self.momentum, "colour": self.colour,
            "wall_temperature": self.wall_temperature, "histogram_window": self.histogram_window,
            "has_walls": bool(self._vessel.shape_walls),
            "phase": "starting" if self.starting else "running",
        }  # fmt: skip

    def stats(self) -> dict[str, Any]:
        """Readouts, energies and the speed histogram now (pressure and collision rate averaged
        over the last window of `WINDOW_SAMPLES` calls)."""
        sim = self.sim
        self._sample_window()
        energy = sim.energy()
        n = sim.particles.n
        kT = energy.kinetic / n if n else None
        conserved = conserved_energy(sim, energy)
        drift = (conserved - self._reference) / abs(self._reference) if self._reference else None
        if drift is not None and math.isfinite(drift):
            self._worst_drift = max(self._worst_drift, abs(drift))
        return {
            "type": "stats", "time": sim.time, "steps": sim.steps, "n": n,
            "temperature": _number(kT), "pressure": self._pressure,
            "pressure_error": self._pressure_error, "piston": self._piston(),
            "traced": self._traced(),
            "pressure_kind": "virial" if sim.container.periodic else "wall",
            "collision_rate": self._rate, "drift": _number(drift),
            "warning": drift_warning(self._worst_drift),
            "energy": {"kinetic": _number(energy.kinetic), "potential": _number(energy.potential),
                       "total": _number(energy.total)},
            "total_speed": _number(sim.total_speed()), "histogram": self._histogram(kT),
            "speed_scale": 0.5 * self._upper_speed or None,
        }  # fmt: skip

    def _sample_window(self) -> None:
        sim = self.sim
        if self._window is None:
            self._window = (sim.time, sim.counters.pair_collisions)
            self._sampled_at = sim.time
            self._thermo.compute(sim)
            return
        if sim.time == self._sampled_at:
            return  # paused: nothing new to average
        self._sampled_at = sim.time
        self._thermo.compute(sim, reset=False)
        if self._thermo.samples <= WINDOW_SAMPLES:  # samples bound WINDOW_SAMPLES intervals
            return
        start, pairs = self._window
        if sim.container.periodic:
            self._pressure = _number(self._thermo.virial_pressure())
            self._pressure_error = _number(self._thermo.virial_pressure_error())
        else:
            self._pressure = _number(self._thermo.wall_pressure()["total"])
            self._pressure_error = _number(self._thermo.wall_pressure_error())
        self._rate = (sim.counters.pair_collisions - pairs) / (sim.time - start)
        self._window = (sim.time, sim.counters.pair_collisions)
        self._thermo.compute(sim)

    def _histogram(self, kT: float | None) -> dict[str, Any]:
        """The speed histogram, averaged over the last `histogram_window` readouts taken with the
        same bins, and the Maxwell-Boltzmann density at their mean temperature."""
        sim = self.sim
        scale = math.sqrt(kT / float(sim.particles.mass.min())) if kT and kT > 0 else math.nan
        if not math.isfinite(scale) or scale == 0:
            return {"edges": [], "density": [], "maxwell_boltzmann": None, "readouts": 0}
        if not scale * 4 <= self._upper_speed <= scale * 10:
            self._upper_speed = _nice_ceiling(5 * scale)
        histogram = SpeedHistogram(HISTOGRAM_BINS, (0.0, self._upper_speed)).compute(sim)
        recent = self._histograms
        if recent and recent[-1][0] != self._upper_speed:
            recent.clear()  # other bins: start again
        elif recent and recent[-1][2] == sim.time:
            recent.pop()  # the same moment again (paused): counted once
        assert kT is not None
        recent.append((self._upper_speed, histogram.density, sim.time, kT))
        window = list(recent)[-self.histogram_window :]
        density = np.mean([entry[1] for entry in window], axis=0)
        law = MaxwellBoltzmann2D(float(np.mean([entry[3] for entry in window])), sim.particles.mass)
        return {
            "edges": histogram.bin_edges.tolist(),
            "density": density.tolist(),
            "maxwell_boltzmann": law.pdf(histogram.bin_centers).tolist(),
            "readouts": len(window),
        }

    def _piston(self) -> dict[str, float] | None:
        """Where the piston is and how fast it moves, or None without one."""
        piston = self.sim.piston()
        if piston is None:
            return None
        return {"position": piston.position, "velocity": piston.velocity}

    def _traced(self) -> dict[str, float] | None:
        """The followed particle's speed (m/s), kinetic energy (J), mass, charge and radius."""
        i = self.traced
        if i is None or i >= self.sim.particles.n:
            return None
        p = self.sim.particles
        mass = float(p.mass[i])
        speed = float(np.hypot(*p.velocity[i]))
        return {
            "index": i, "speed": speed, "kinetic": 0.5 * mass * speed**2, "mass": mass,
            "charge": float(p.charge[i]),
            "radius": float(p.radius[i]),
        }  # fmt: skip

    def frame(self, number: int) -> bytes:
        """The binary frame of the current state (velocities included with momentum on or
        colour by speed, the piston's face with a piston)."""
        p = self.sim.particles
        piston = self.sim.piston()
        line = None if piston is None else self.sim.container.piston_line(piston.position)
        velocities = self.momentum or self.colour == "speed"
        return protocol.encode_frame(number, self.sim.time, self.generation, p.position,
                                     p.velocity if velocities else None, line)  # fmt: skip

    def export(self) -> dict[str, Any]:
        """The scenario that reset returns to, as TOML, with a file name."""
        scenario = self._scenario or Scenario.of_state(self._fresh())
        filename = re.sub(r"[^A-Za-z0-9._-]+", "-", scenario.name).strip("-.") or "scenario"
        return {"type": "export", "filename": f"{filename}.toml", "toml": scenario.to_toml()}


def _check_size(n: int, forces: bool, field: str) -> None:
    """Refuse more particles than a live view can run (fewer with forces: their pair sum is
    O(N^2) per step)."""
    most = protocol.MAX_CHARGED_PARTICLES if forces else protocol.MAX_PARTICLES
    if n > most:
        what = " with forces" if forces else ""
        raise InputError(field, f"{n} particles; the viewer takes at most {most}{what}")


def _species(particles: Particles) -> tuple[np.ndarray, list[str]]:
    """Each particle's species (the index of its distinct mass, radius and charge) and a label
    for each species naming what sets it apart."""
    if particles.n == 0:
        return np.zeros(0, dtype=np.int64), []
    fields = (("mass", "kg"), ("radius", "m"), ("charge", "C"))
    table = np.column_stack([getattr(particles, f) for f, _ in fields])
    kinds, index = np.unique(table, axis=0, return_inverse=True)
    differing = [j for j in range(len(fields)) if np.unique(kinds[:, j]).size > 1]
    labels = [
        ", ".join(f"{fields[j][0]} {kind[j]:g} {fields[j][1]}" for j in differing) or "all"
        for kind in kinds
    ]
    return index.reshape(-1), labels


def _hatch(vessel: Vessel, piston: PistonState | None) -> tuple[FloatArray, FloatArray]:
    """The middle of the part of the vessel's first wall on the gas's side of its ``piston``
    (a box's wall, `collidium.vessels.walls.Piston`), and the unit normal into the vessel
    there."""
    outline = vessel.outline()
    if vessel.periodic or outline.shape[0] < 3:
        raise InputError("pump", "a periodic box has no wall to pump through")
    start, end = outline[0], outline[1]
    if piston is not None:  # the gas lies where sign * x[axis] <= sign * face
        wall = vessel.wall_names.index(piston.wall)
        axis, sign = wall_axis(wall)
        beyond = [sign * point[axis] > sign * piston.position for point in (start, end)]
        if beyond[0] != beyond[1]:
            cut = start + (piston.position - start[axis]) / (end[axis] - start[axis]) * (
                end - start
            )
            start, end = (cut, end) if beyond[0] else (start, cut)
    along = (end - start) / np.hypot(*(end - start))
    return 0.5 * (start + end), np.array([-along[1], along[0]])  # the outline turns left


def _arrivals(
    like: Particles,
    rng: np.random.Generator,
    count: int,
    kT: float,
    hatch: FloatArray,
    inward: FloatArray,
) -> Particles:
    """``count`` copies of particle 0 of ``like`` in a row along the wall at ``hatch``, one
    radius and a little inside, moving in as a thermal wall at ``kT`` emits them (normal speed
    Rayleigh-distributed, tangential Gaussian)."""
    mass, radius, charge = (float(getattr(like, name)[0]) for name in PROPERTIES)
    spacing = 2.0 * radius * 1.05 + 1e-6
    offsets = (np.arange(count) - 0.5 * (count - 1)) * spacing
    along = np.array([inward[1], -inward[0]])
    position = hatch + np.outer(offsets, along) + inward * (radius * 1.05 + 1e-6)
    sigma = math.sqrt(kT / mass)
    normal = sigma * np.sqrt(-2.0 * np.log1p(-rng.random(count)))
    tangential = sigma * rng.standard_normal(count)
    velocity = np.outer(normal, inward) + np.outer(tangential, along)
    return Particles(position, velocity, mass, radius, charge)


def _blocked(added: Particles, present: Particles) -> np.ndarray:
    """Which of ``added`` (a few) would overlap one of ``present``: O(added x present)."""
    gaps = np.hypot(*(added.position[:, None, :] - present.position[None, :, :]).transpose(2, 0, 1))
    return (gaps < added.radius[:, None] + present.radius[None, :]).any(axis=1)


def _outside(sim: Simulation, added: Particles) -> np.ndarray:
    """Which of ``added`` lie outside the vessel (or beyond its piston)."""
    piston = sim.piston()
    where = sim.container.outside(added.position, added.radius,
                                  None if piston is None else piston.position)  # fmt: skip
    out = np.zeros(added.n, dtype=bool)
    out[where] = True
    return out


def _compact(values: FloatArray) -> float | list[float]:
    """One number when all particles share it, else one per particle."""
    shared = uniform_or_each(values)
    return shared if isinstance(shared, float) else shared.tolist()


def _number(value: float | None) -> float | None:
    """``value``, or None if it is missing or not finite (JSON has no NaN)."""
    return value if value is not None and math.isfinite(value) else None


def _nice_ceiling(value: float) -> float:
    """The smallest round number (1, 1.5, 2, 2.5, 3, 4, 5, 6 or 8 times a power of ten) at or
    above ``value``."""
    power = 10.0 ** math.floor(math.log10(value))
    steps = (1, 1.5, 2, 2.5, 3, 4, 5, 6, 8, 10)
    return next(m * power for m in steps if m * power >= value * (1 - 1e-12))
