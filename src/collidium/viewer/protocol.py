"""Messages between the viewer's front end (page or notebook widget) and its simulation.

Every message from the front end is a JSON object with a ``type``; the server answers with JSON
objects and binary frames. On opening, the front end sends ``{"type": "ready"}``.

Front end to server (validated by `parse_message`; a bad one gets an ``error`` reply)::

    ready                                    start: hello, scene, status, stats, then frames
    ack            frame: int                a frame was drawn: one more frame may be sent
    play | pause | step | reset | export
    speed          value: float              simulated seconds per wall-clock second
    heat           factor: float             multiply the kinetic energy (cool: factor < 1)
    collisions | forces | momentum           enabled: bool
    colour         mode: str                 colour the disks by "speed", "charge" or "species"
    wall_temperature  temperature: float | null  hold the walls at kT (J) (heat or cool
                                             continuously); null gives them back
    pump           count: int, temperature   let particles in through the hatch at kT (J; null:
                                             the gas's), or out (count < 0)
    move_wall      to: float | null          drag the scene's movable wall towards a coordinate
                                             along its axis (m); null lets go
    histogram_window  readouts: int          average the speed histogram over the last readouts
    trace          index: int | null         follow a particle's path (null: none)
    set_velocity   index: int, vx, vy        m/s
    load           preset: str, overrides    a preset with its main parameters (n, dt, k,
                                             collisions...)
    scenario       toml: str                 a scenario file's text, validated like a file
    raw            text: str                 (widget only) a message as the page would send it

Server to front end (JSON): ``hello`` (version; presets with their explanation and the controls
of their parameters: name, label, unit, kind, default, choices; limits), ``scene`` (vessel
outline and walls, per-particle radius, charge, mass and species, whether forces act, the
colour modes that apply, the highlighted particle, the preset's explanation, the wall that may
be dragged (name, axis, rest, low, high) or null; sent again after load, scenario and reset),
``status`` (playing, speed, toggles, colour mode), ``stats`` (time, readouts, energies, speed
histogram with its Maxwell-Boltzmann curve), ``traced``, ``export`` (filename, toml) and
``error`` (field, reason).

Binary frames (little-endian): ``b"CLD1"``, u32 n, u32 flags (bit 0: velocities follow), u32
frame number, f64 simulated time (s), u32 scene generation, u32 reserved; then float32 positions
``x0 y0 x1 y1 ...`` (m), with flag bit 0 float32 velocities (m/s) and, with flag bit 1, the
piston's face as float32 ``x0 y0 x1 y1`` (m) where it is now. The server sends a frame
only while the front end has credit (two frames unacknowledged at most); a frame always carries
the state when it is sent, so the latest frame wins.
"""

from __future__ import annotations

import json
import struct
from collections.abc import Mapping
from typing import Annotated, Any, Literal, cast

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, TypeAdapter, ValidationError

from collidium.errors import InputError
from collidium.state import FloatArray

#: Most particles a viewer simulates (a scenario asking for more is refused).
MAX_PARTICLES = 200_000
#: Most particles with forces between them: the tree sums 50,000 charges in about 0.1 s a step
#: (a periodic box sums directly, N^2 a step; the step-time guard pauses one that is too slow).
MAX_CHARGED_PARTICLES = 50_000
#: Longest message accepted, in bytes (a scenario's TOML included).
MAX_MESSAGE_BYTES = 1 << 20
#: Control messages accepted per second on average (acknowledgements are not counted).
MESSAGES_PER_SECOND = 50
#: Burst of control messages accepted at once.
MESSAGE_BURST = 100
#: Range of the simulation speed, simulated seconds per wall-clock second.
SPEED_RANGE = (0.01, 100.0)
#: Range of the factor by which heat multiplies the kinetic energy.
HEAT_RANGE = (0.1, 10.0)
#: Hottest a wall may be held, kT in J.
MAX_WALL_TEMPERATURE = 1e12
#: Most particles one pump message lets in or out.
MAX_PUMPED = 100
#: Most readouts the speed histogram may be averaged over.
MAX_HISTOGRAM_WINDOW = 50
#: Fastest speed a particle may be given by dragging, m/s.
MAX_SET_SPEED = 1e6

FRAME_MAGIC = b"CLD1"
FRAME_HEADER = struct.Struct("<4sIIIdII")
FLAG_VELOCITIES = 1
FLAG_PISTON = 2


class _Message(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=True)


class Ready(_Message):
    type: Literal["ready"]


class Ack(_Message):
    type: Literal["ack"]
    frame: Annotated[int, Field(ge=0)]


class Play(_Message):
    type: Literal["play"]


class Pause(_Message):
    type: Literal["pause"]


class Step(_Message):
    type: Literal["step"]


class Reset(_Message):
    type: Literal["reset"]


class Export(_Message):
    type: Literal["export"]


class Speed(_Message):
    type: Literal["speed"]
    value: Annotated[float, Field(ge=SPEED_RANGE[0], le=SPEED_RANGE[1], allow_inf_nan=False)]


class Heat(_Message):
    type: Literal["heat"]
    factor: Annotated[float, Field(ge=HEAT_RANGE[0], le=HEAT_RANGE[1], allow_inf_nan=False)]


class Toggle(_Message):
    type: Literal["collisions", "forces", "momentum"]
    enabled: bool


class Colour(_Message):
    type: Literal["colour"]
    mode: Literal["speed", "charge", "species"]


class WallTemperature(_Message):
    type: Literal["wall_temperature"]
    temperature: Annotated[float, Field(gt=0, le=MAX_WALL_TEMPERATURE, allow_inf_nan=False)] | None


class Pump(_Message):
    type: Literal["pump"]
    count: Annotated[int, Field(ge=-MAX_PUMPED, le=MAX_PUMPED)]
    temperature: (
        Annotated[float, Field(gt=0, le=MAX_WALL_TEMPERATURE, allow_inf_nan=False)] | None
    ) = None


class MoveWall(_Message):
    type: Literal["move_wall"]
    to: Annotated[float, Field(allow_inf_nan=False)] | None


class HistogramWindow(_Message):
    type: Literal["histogram_window"]
    readouts: Annotated[int, Field(ge=1, le=MAX_HISTOGRAM_WINDOW)]


class Trace(_Message):
    type: Literal["trace"]
    index: Annotated[int, Field(ge=0)] | None


class SetVelocity(_Message):
    type: Literal["set_velocity"]
    index: Annotated[int, Field(ge=0)]
    vx: Annotated[float, Field(ge=-MAX_SET_SPEED, le=MAX_SET_SPEED, allow_inf_nan=False)]
    vy: Annotated[float, Field(ge=-MAX_SET_SPEED, le=MAX_SET_SPEED, allow_inf_nan=False)]


class Load(_Message):
    type: Literal["load"]
    preset: Annotated[str, Field(max_length=100)]
    overrides: dict[Annotated[str, Field(max_length=100)], bool | int | float | str] = Field(
        default_factory=dict, max_length=20
    )


class ScenarioText(_Message):
    type: Literal["scenario"]
    toml: str


class Raw(_Message):
    type: Literal["raw"]
    text: str


Message = Annotated[
    Ready | Ack | Play | Pause | Step | Reset | Export | Speed | Heat | Toggle | Colour
    | WallTemperature | Pump | MoveWall | HistogramWindow | Trace
    | SetVelocity | Load | ScenarioText | Raw,
    Field(discriminator="type"),
]  # fmt: skip
# (cast: pydantic < 2.7 types TypeAdapter's argument as a class, not any type form)
_MESSAGE: TypeAdapter[Message] = TypeAdapter(cast(Any, Message))
#: The ``type`` of each message the front end may send.
MESSAGE_TYPES = (
    "ready", "ack", "play", "pause", "step", "reset", "export", "speed", "heat", "collisions",
    "forces", "momentum", "colour", "wall_temperature", "pump", "move_wall", "histogram_window",
    "trace", "set_velocity", "load", "scenario", "raw",
)  # fmt: skip


def parse_message(data: str | bytes | Mapping[str, Any]) -> Message:
    """Validate one message from the front end.

    Parameters
    ----------
    data : str, bytes or mapping
        JSON text (as sent over a websocket) or an already decoded object (as a widget gets).

    Raises
    ------
    InputError
        Naming the offending field (``message`` for one that is not a JSON object, ``type`` for
        an unknown kind) and the reason.
    """
    if isinstance(data, bytes | str):
        if len(data) > MAX_MESSAGE_BYTES:
            raise InputError("message", f"longer than {MAX_MESSAGE_BYTES} bytes")
        try:
            data = json.loads(data)
        except (ValueError, RecursionError) as exc:  # bad JSON or encoding, huge or deep values
            raise InputError("message", f"not valid JSON ({exc})") from None
    if not isinstance(data, Mapping):
        raise InputError("message", f"must be a JSON object, got {type(data).__name__}")
    kind = data.get("type")
    if kind not in MESSAGE_TYPES:
        given = "missing" if kind is None else f"unknown message type {kind!r}"
        raise InputError("type", f"{given}; choose from {', '.join(MESSAGE_TYPES)}")
    try:
        return _MESSAGE.validate_python(dict(data))
    except ValidationError as exc:
        from collidium.scenario import field_and_reason

        field, reason = field_and_reason(exc)
        raise InputError(field.split(".", 1)[-1], reason) from None  # without the type's name


def encode_frame(
    number: int,
    time: float,
    generation: int,
    position: FloatArray,
    velocity: FloatArray | None = None,
    piston: FloatArray | None = None,
) -> bytes:
    """One binary frame (see the module docstring).

    Parameters
    ----------
    number : int
        Frame number.
    time : float
        Simulated time in s.
    generation : int
        Scene generation the positions belong to.
    position : ndarray, shape (N, 2)
        Positions in m.
    velocity : ndarray, shape (N, 2), optional
        Velocities in m/s, included when given.
    piston : ndarray, shape (2, 2), optional
        The piston's face, its two ends in m (`collidium.vessels.Vessel.piston_line`).
    """
    n = position.shape[0]
    flags = (FLAG_VELOCITIES if velocity is not None else 0) | (
        FLAG_PISTON if piston is not None else 0
    )
    header = FRAME_HEADER.pack(FRAME_MAGIC, n, flags, number & 0xFFFFFFFF, time,
                               generation & 0xFFFFFFFF, 0)  # fmt: skip
    parts = [header, np.ascontiguousarray(position, dtype="<f4").tobytes()]
    if velocity is not None:
        parts.append(np.ascontiguousarray(velocity, dtype="<f4").tobytes())
    if piston is not None:
        parts.append(np.ascontiguousarray(piston, dtype="<f4").tobytes())
    return b"".join(parts)


def decode_frame(data: bytes) -> dict[str, Any]:
    """The fields of a binary frame (for tests and tools): n, flags, number, time, generation,
    position (N, 2), velocity (N, 2) or None and piston (2, 2) or None."""
    magic, n, flags, number, time, generation, _ = FRAME_HEADER.unpack_from(data)
    if magic != FRAME_MAGIC:
        raise InputError("frame", f"bad magic {magic!r}")
    arrays = 2 if flags & FLAG_VELOCITIES else 1
    size = FRAME_HEADER.size + 8 * n * arrays + (16 if flags & FLAG_PISTON else 0)
    if len(data) != size:
        raise InputError("frame", f"{len(data)} bytes where {size} were expected")
    values = np.frombuffer(data, dtype="<f4", offset=FRAME_HEADER.size)
    particles = values[: 2 * n * arrays].reshape(arrays, n, 2)
    return {
        "n": n, "flags": flags, "number": number, "time": time, "generation": generation,
        "position": particles[0], "velocity": particles[1] if flags & FLAG_VELOCITIES else None,
        "piston": values[2 * n * arrays :].reshape(2, 2) if flags & FLAG_PISTON else None,
    }  # fmt: skip
