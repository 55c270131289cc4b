"""`Connection`: what one front end (a page or a notebook widget) is sent, and when.

It validates each incoming message, applies it to its `ViewerSession`, and on each `tick` runs
the simulation for the wall-clock time that passed and sends the latest frame, if the front end
has credit, and the readouts a few times a second. It knows nothing of websockets or Jupyter: the
server and the widget move its outgoing items (dicts as JSON, bytes as binary frames).
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable, Mapping
from typing import Any

from collidium.errors import InputError, SimulationError
from collidium.viewer import protocol
from collidium.viewer.session import ViewerSession

Outgoing = dict[str, Any] | bytes

#: Frames the front end may have unacknowledged.
MAX_CREDIT = 2
#: Wall-clock seconds between readout updates while the state changes.
STATS_PERIOD = 0.2
#: Frames a second the page gets at the least, while the simulation keeps pace or not.
LEAST_FRAME_RATE = 30
#: Computation one tick may spend running the simulation, s: a frame's period at
#: `LEAST_FRAME_RATE` less 5 ms for the frame, the readouts and their sending.
TICK_BUDGET = 1 / LEAST_FRAME_RATE - 0.005
#: A front end that has acknowledged nothing for this long, s, with frames outstanding, is not
#: watching (a hidden tab, a closed notebook view): the simulation waits for it.
STALL_SECONDS = 1.0
#: Tokens of the rate limit a message costs: rebuilding the simulation costs more.
COSTS = {"load": 10, "scenario": 10, "reset": 10}

log = logging.getLogger("collidium.viewer")


class Connection:
    """One front end's conversation with its session.

    Parameters
    ----------
    session : ViewerSession
        The simulation shown.
    clock : callable
        Wall-clock time in s (monotonic); replaceable in tests.
    """

    def __init__(self, session: ViewerSession, clock: Callable[[], float] = time.monotonic) -> None:
        self.session = session
        self.ready = False
        self.frames_sent = 0
        #: Computation one tick may spend running the simulation, s.
        self.budget = TICK_BUDGET
        self._clock = clock
        self._last_ack = clock()
        self._credit = MAX_CREDIT
        self._framed = -1  # session version of the last frame sent
        self._reported = -1  # session version of the last stats sent
        self._last_tick: float | None = None
        self._last_stats = -float("inf")
        self._tokens = float(protocol.MESSAGE_BURST)
        self._refilled = clock()

    def receive(
        self, data: str | bytes | Mapping[str, Any], nested: bool = False
    ) -> list[Outgoing]:
        """Replies to one message; a bad message gets one ``error`` reply and changes nothing."""
        try:
            try:
                message = protocol.parse_message(data)
            except InputError:
                self._spend_tokens(1)  # malformed messages count against the rate too
                raise
            if isinstance(message, protocol.Raw) and not nested:
                return self.receive(message.text, nested=True)
            if not isinstance(message, protocol.Ack):
                self._spend_tokens(COSTS.get(message.type, 1))
            return self._apply(message)
        except InputError as exc:
            return [_error(exc.field, exc.reason)]
        except SimulationError as exc:
            return [_error("run", str(exc)), self.session.status()]
        except Exception as exc:  # a bug must not end the conversation: report it, go on
            log.exception("viewer: message %.200r failed", data)
            return [_error("server", f"internal error ({type(exc).__name__}: {exc})")]

    def tick(self) -> list[Outgoing]:
        """Run the simulation for the wall-clock time since the last tick; then the latest frame
        (if there is credit and the state changed) and the readouts (every `STATS_PERIOD`)."""
        if not self.ready:
            return []
        now = self._clock()
        elapsed = 0.0 if self._last_tick is None else now - self._last_tick
        self._last_tick = now
        if self._credit == 0 and now - self._last_ack > STALL_SECONDS:
            return []  # nobody is watching: wait
        out: list[Outgoing] = []
        starting = self.session.starting
        try:
            self.session.advance(elapsed, self.budget)
        except SimulationError as exc:
            out += [_error("run", str(exc)), self.session.status()]
        except Exception as exc:
            log.exception("viewer: the simulation failed")
            self.session.playing = False
            out += [_error("server", f"internal error ({type(exc).__name__}: {exc})"),
                    self.session.status()]  # fmt: skip
        if self._credit > 0 and self.session.version != self._framed:
            out.append(self._frame())
        if starting and not self.session.starting:
            out.append(self.session.status())  # the page stops saying "starting"
        if now - self._last_stats >= STATS_PERIOD and self.session.version != self._reported:
            out.append(self._stats())
        return out

    def _frame(self) -> bytes:
        self._credit -= 1
        self._framed = self.session.version
        self.frames_sent += 1
        return self.session.frame(self.frames_sent)

    def _stats(self) -> dict[str, Any]:
        self._last_stats = self._clock()
        self._reported = self.session.version
        return self.session.stats()

    def _spend_tokens(self, cost: int) -> None:
        now = self._clock()
        rate, burst = protocol.MESSAGES_PER_SECOND, protocol.MESSAGE_BURST
        self._tokens = min(burst, self._tokens + (now - self._refilled) * rate)
        self._refilled = now
        if self._tokens < cost:
            raise InputError("message", f"too many messages; at most {rate} per second")
        self._tokens -= cost

    def _apply(self, message: Any) -> list[Outgoing]:
        s = self.session
        if isinstance(message, protocol.Ready):
            # A front end starting (again, after a notebook page reload) has drawn nothing:
            # frames owed to a view that is gone are forgotten, the state now is sent at once.
            self.ready = True
            self._credit, self._framed, self._reported = MAX_CREDIT, -1, -1
            self._last_tick = self._last_ack = self._clock()
            return [s.hello(), s.scene(), s.status(), self._stats()]
        if not self.ready:
            raise InputError("type", "send a ready message first")
        match message:
            case protocol.Ack():
                self._credit = min(MAX_CREDIT, self._credit + 1)
                self._last_ack = self._clock()
                return []
            case protocol.Play() | protocol.Pause():
                s.playing = isinstance(message, protocol.Play)
                return [s.status()]
            case protocol.Speed(value=value):
                s.set_speed(value)
                return [s.status()]
            case protocol.Trace(index=index):
                s.trace(index)
                return [{"type": "traced", "index": index}]
            case protocol.Export():
                return [s.export()]
        return self._change(message)

    def _change(self, message: Any) -> list[Outgoing]:
        """Messages that change the state: the new readouts follow at once."""
        s = self.session
        match message:
            case protocol.Step():
                s.step()
            case protocol.Heat(factor=factor):
                s.heat(factor)
            case protocol.SetVelocity(index=index, vx=vx, vy=vy):
                s.set_velocity(index, vx, vy)
            case protocol.Toggle(type="collisions", enabled=enabled):
                s.enable_collisions(enabled)
            case protocol.Toggle(type="forces", enabled=enabled):
                s.enable_forces(enabled)
            case protocol.Toggle(type="momentum", enabled=enabled):
                s.momentum = enabled
                s.version += 1  # the next frame carries velocities
            case protocol.Colour(mode=mode):
                s.set_colour(mode)
            case protocol.WallTemperature(temperature=kT):
                s.hold_wall_temperature(kT)
            case protocol.Pump(count=count, temperature=kT):
                s.pump(count, kT)
                return [s.scene(), s.status(), self._stats()]
            case protocol.MoveWall(to=to):
                s.move_wall(to)
            case protocol.HistogramWindow(readouts=readouts):
                s.set_histogram_window(readouts)
            case protocol.Reset():
                s.reset()
                return [s.scene(), s.status(), self._stats()]
            case protocol.Load(preset=name, overrides=overrides):
                s.load(name, overrides)
                return [s.scene(), s.status(), self._stats()]
            case protocol.ScenarioText(toml=text):
                s.load_toml(text)
                return [s.scene(), s.status(), self._stats()]
            case _:
                raise InputError("type", f"{message.type} is not accepted here")
        return [s.status(), self._stats()]


def _error(field: str, reason: str) -> dict[str, Any]:
    return {"type": "error", "field": field, "reason": reason}
