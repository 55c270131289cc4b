"""`Widget`: the viewer in a Jupyter notebook cell (an anywidget with the page's front end).

The front end and the kernel exchange the page's messages (`collidium.viewer.protocol`) as
custom widget messages; a binary frame travels as ``{"type": "frame"}`` with the frame as its
buffer. While the kernel's event loop runs (as it does in Jupyter), a task ticks the connection
60 times a second; every message from the front end ticks it too.
"""

from __future__ import annotations

import asyncio
from collections.abc import Mapping, Sequence
from typing import Any

import anywidget

from collidium.errors import InputError
from collidium.scenario import Scenario
from collidium.simulation import Simulation
from collidium.viewer.connection import Connection, Outgoing
from collidium.viewer.server import STATIC, TICK, check_built
from collidium.viewer.session import ViewerSession


class Widget(anywidget.AnyWidget):
    """Shows and runs a simulation in a notebook cell, with the page's plots and controls.

    Parameters
    ----------
    simulation : Simulation, Scenario or str
        What to show: a simulation (run in place; reset returns to its state now), a scenario,
        or a preset name.

    Examples
    --------
    >>> import collidium as cd                                        # doctest: +SKIP
    >>> sim = cd.load("gas", n=500)                                   # doctest: +SKIP
    >>> cd.viewer.Widget(sim)                                         # doctest: +SKIP
    """

    _esm = STATIC / "widget.js"
    _css = STATIC / "widget.css"

    def __init__(self, simulation: Simulation | Scenario | str, **kwargs: Any) -> None:
        check_built()
        if isinstance(simulation, Simulation):
            session = ViewerSession(simulation=simulation)
        elif isinstance(simulation, Scenario):
            session = ViewerSession(simulation)
        elif isinstance(simulation, str):
            from collidium.loading import load_scenario

            session = ViewerSession(load_scenario(simulation), preset=simulation)
        else:
            raise InputError(
                "simulation", f"must be a Simulation, Scenario or preset name, not {simulation!r}"
            )
        super().__init__(**kwargs)
        self.connection = Connection(session)
        self._ticking: asyncio.Task[None] | None = None
        self.on_msg(self._on_message)

    @property
    def simulation(self) -> Simulation:
        """The simulation shown (a new one after reset or after loading a preset)."""
        return self.connection.session.sim

    def _on_message(self, _: Any, content: Mapping[str, Any], buffers: Sequence[bytes]) -> None:
        self._deliver(self.connection.receive(content) + self.connection.tick())
        self._start_ticking()

    def _deliver(self, items: list[Outgoing]) -> None:
        for item in items:
            if isinstance(item, bytes):
                self.send({"type": "frame"}, buffers=[item])
            else:
                self.send(item)

    def _start_ticking(self) -> None:
        if self._ticking is not None or not self.connection.ready:
            return
        try:
            loop = asyncio.get_running_loop()
        except RuntimeError:  # no event loop: messages from the front end drive it alone
            return
        self._ticking = loop.create_task(self._tick_forever())

    async def _tick_forever(self) -> None:
        while self.comm is not None:
            self._deliver(self.connection.tick())
            await asyncio.sleep(TICK)

    def close(self) -> None:
        """Stop ticking and close the widget."""
        ticking = getattr(self, "_ticking", None)  # absent if __init__ refused its argument
        if ticking is not None:
            ticking.cancel()
            self._ticking = None
        super().close()
