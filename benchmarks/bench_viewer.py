"""The live viewer end to end. Run: ``python benchmarks/bench_viewer.py [--quick]``.

V1  frames per second drawn by the page in headless chromium (software WebGL through SwiftShader
    here: a figure to report, not a gate; the target, 30 frames/s at N = 1e4, is for a machine
    with a GPU), for the exact gas at packing 0.1 with N = 1e3, 1e4 and 1e5, and how fast the
    simulation ran meanwhile (simulated seconds per wall second; 1 is what was asked for).
V2  the server's share: frames per second it delivers to a websocket client that acknowledges
    each at once without drawing, and simulated seconds per wall second meanwhile (the target:
    30 frames/s and real time at N = 1e5), milliseconds to encode one binary frame, bytes per
    frame.

Prints a table and writes ``benchmarks/results/viewer.json``.
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

from collidium.presets import preset
from collidium.viewer.server import create_app, running
from collidium.viewer.session import ViewerSession
from collidium.viewer.testing import HEADLESS_CHROMIUM_ARGS, chromium_path

RESULTS = Path(__file__).parent / "results"
PACKING = 0.1
#: Wall seconds of frames V2 lets pass before it measures.
WARM_UP = 3.0


def gas(n: int) -> ViewerSession:
    """The gas preset with N disks of radius 0.25 m in a square box at packing 0.1."""
    side = round(math.sqrt(n * math.pi * 0.25**2 / PACKING), 1)
    return ViewerSession(preset("gas", n=n, width=side, height=side))


def frames_per_second(browser: object, n: int, seconds: float) -> dict[str, float]:
    """V1: frames drawn per wall second, and simulated per wall second, over ``seconds``."""
    app = create_app(lambda: gas(n))
    with running(app) as url:
        page = browser.new_page(viewport={"width": 1280, "height": 800})  # type: ignore[attr-defined]
        page.goto(url)
        page.wait_for_function("window.collidiumViewer && window.collidiumViewer.framesDrawn > 5",
                               timeout=120_000)  # fmt: skip
        probe = "[window.collidiumViewer.framesDrawn, window.collidiumViewer.stats.time]"
        frames0, time0 = page.evaluate(probe)
        start = time.perf_counter()
        page.wait_for_timeout(seconds * 1000)
        frames1, time1 = page.evaluate(probe)
        elapsed = time.perf_counter() - start
        page.close()
    return {"n": n, "fps": (frames1 - frames0) / elapsed, "speed": (time1 - time0) / elapsed}


def delivered(n: int, seconds: float) -> dict[str, float]:
    """V2: frames per second the server sends to a client that acknowledges at once, and the
    simulated seconds per wall second meanwhile (from the readouts' clock)."""
    import asyncio

    import websockets

    async def client(url: str) -> dict[str, float]:
        async with websockets.connect(url.replace("http", "ws") + "ws", max_size=None) as ws:
            await ws.send(json.dumps({"type": "ready"}))
            frames, start, clock, opened = 0, None, [], time.perf_counter()
            while start is None or time.perf_counter() - start < seconds:
                message = await ws.recv()
                if isinstance(message, bytes):
                    frames += 1
                    # Past compilation, the first measurement of a step's cost, and the time
                    # owed since (made up at the start where the simulation is faster).
                    if start is None and time.perf_counter() - opened > WARM_UP:
                        frames, start = 0, time.perf_counter()
                    await ws.send(json.dumps({"type": "ack", "frame": frames}))
                elif start is not None and (stats := json.loads(message))["type"] == "stats":
                    clock.append((time.perf_counter(), stats["time"]))
            (wall0, sim0), (wall1, sim1) = clock[0], clock[-1]
            return {"server_fps": frames / (time.perf_counter() - start),
                    "server_speed": (sim1 - sim0) / (wall1 - wall0)}  # fmt: skip

    with running(create_app(lambda: gas(n))) as url:
        return asyncio.run(client(url))


def encoding(n: int, repeats: int = 20) -> dict[str, float]:
    """V2: encoding one frame (positions only) of N particles."""
    session = gas(n)
    start = time.perf_counter()
    for k in range(repeats):
        data = session.frame(k)
    return {"n": n, "encode_ms": 1e3 * (time.perf_counter() - start) / repeats,
            "bytes": len(data)}  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="shorter windows")
    args = parser.parse_args()
    seconds = 3.0 if args.quick else 8.0
    path = chromium_path()
    if path is None:
        raise SystemExit("needs chromium: apt-get install chromium")
    from playwright.sync_api import sync_playwright

    sizes = (1_000, 10_000, 100_000)
    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=path,
                                             args=list(HEADLESS_CHROMIUM_ARGS))  # fmt: skip
        drawn = [frames_per_second(browser, n, seconds) for n in sizes]
        browser.close()
    encoded = [encoding(n) | delivered(n, seconds) for n in sizes]
    print(f"{'N':>8} {'page frames/s':>14} {'sim s / wall s':>15} {'server frames/s':>16} "
          f"{'sim s / wall s':>15} {'encode ms':>10} {'bytes':>9}")  # fmt: skip
    for d, e in zip(drawn, encoded, strict=True):
        print(f"{d['n']:>8} {d['fps']:>14.1f} {d['speed']:>15.2f} {e['server_fps']:>16.1f} "
              f"{e['server_speed']:>15.2f} {e['encode_ms']:>10.3f} {e['bytes']:>9}")  # fmt: skip
    RESULTS.mkdir(exist_ok=True)
    out = {"V1": drawn, "V2": encoded, "renderer": "chromium headless, SwiftShader (no GPU)"}
    (RESULTS / "viewer.json").write_text(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
