"""`Builder`: scenarios become simulations in a worker process, within a time budget.

Building places the disks and checks them (numba kernels, which hold the interpreter lock): in
the server's own process a heavy request (a hundred thousand disks, a dense region) would freeze
every other page's frames until it ends. The worker builds instead; the page that asked waits
for the answer without holding the lock, and a build over `BUILD_SECONDS` is stopped (the worker
is killed, a fresh one started at the next request) with one error line naming the field.
"""

from __future__ import annotations

import atexit
import socket
import subprocess
import sys
import threading
from multiprocessing.connection import Connection
from typing import TYPE_CHECKING

from collidium.errors import InputError

if TYPE_CHECKING:
    from collidium.scenario import Scenario
    from collidium.simulation import Simulation

#: Wall-clock seconds one build may take (the page then gets an error line).
BUILD_SECONDS = 10.0
#: Wall-clock seconds a new worker may take to start (importing, compiling its kernels once).
START_SECONDS = 300.0


class Builder:
    """Builds scenarios in one worker process, one at a time, each within ``budget`` seconds.

    Parameters
    ----------
    budget : float
        Wall-clock seconds a build may take.
    """

    def __init__(self, budget: float = BUILD_SECONDS) -> None:
        self.budget = budget
        self._lock = threading.Lock()
        self._process: subprocess.Popen[bytes] | None = None
        self._pipe: Connection | None = None

    def build(self, scenario: Scenario, field: str = "scenario") -> Simulation:
        """The simulation of ``scenario``, its observers cleared.

        Raises
        ------
        InputError
            The scenario's own (placement, memory), or naming ``field`` when the build takes
            longer than the budget or the worker dies (out of memory, say).
        """
        with self._lock:
            pipe = self._ready()
            pipe.send(scenario)
            if not pipe.poll(self.budget):
                self.close()
                raise InputError(field, f"took over {self.budget:g} s to build; use fewer disks")
            try:
                ok, value = pipe.recv()
            except (EOFError, OSError):
                self.close()
                raise InputError(field, "the build failed (out of memory?)") from None
        if not ok:
            where, reason, particles = value
            raise InputError(where or field, reason, particles)
        simulation: Simulation = value
        return simulation

    def _ready(self) -> Connection:
        """The pipe to a started worker (one is started if none is).

        The worker is a fresh interpreter running `serve` (not a fork of a process with
        threads, nor one that imports the user's ``__main__`` script again), talking over a
        socket pair.
        """
        if self._pipe is not None:
            return self._pipe
        ours, theirs = socket.socketpair()
        process = subprocess.Popen(
            [sys.executable, "-c", f"import {__name__} as b; b.serve({theirs.fileno()})"],
            pass_fds=[theirs.fileno()],
        )
        theirs.close()
        pipe = Connection(ours.detach())
        try:
            started = pipe.poll(START_SECONDS) and pipe.recv() == "ready"
        except (EOFError, OSError):
            started = False
        self._process, self._pipe = process, pipe
        if not started:
            self.close()
            raise InputError("viewer", "the worker that builds scenarios did not start")
        return pipe

    def close(self) -> None:
        """Stop the worker (a later build starts a new one)."""
        if self._process is not None:
            self._process.kill()
            self._process.wait()
        if self._pipe is not None:
            self._pipe.close()
        self._process = self._pipe = None


def serve(descriptor: int) -> None:
    """The worker: warm up, then build each scenario received on the socket ``descriptor``
    and send the simulation back."""
    pipe = Connection(descriptor)
    from collidium.presets import preset

    # Compile the kernels a build uses once, off the clock of the first request.
    preset("charged-gas", n=20).build()
    pipe.send("ready")
    while True:
        try:
            scenario = pipe.recv()
        except EOFError:
            return
        try:
            simulation = scenario.build()
            simulation.observers.clear()
            pipe.send((True, simulation))
        except InputError as exc:
            pipe.send((False, (exc.field, exc.reason, exc.particles)))
        except Exception as exc:  # the state it starts from runs away, say: one line, go on
            pipe.send((False, (None, f"cannot be built ({type(exc).__name__}: {exc})", ())))


#: The builder of this process's viewer sessions (its worker starts at the first build, and
#: stops when this process ends).
BUILDER = Builder()
atexit.register(BUILDER.close)
