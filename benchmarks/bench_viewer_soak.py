"""The viewer left running. Run: ``python benchmarks/bench_viewer_soak.py [--minutes 60]``.

W1  four pages (the most the server takes) in headless chromium, one per browser context, on one
    in-process server, each on its own preset (gas, charged-gas, circle-gas, pool-break), kept
    running for ``--minutes``. Every minute each page does what a user would, through its
    controls, in turn: heat, switch to another preset (piston, heat-flow, effusion or granular:
    other sizes, other vessels), cool, switch back, reset, pause and play again; the soak covers
    rebuilds, not only a steady run.
W2  every 30 s: the resident memory of this process (the server, its simulations and the
    Playwright client; ``VmRSS`` of ``/proc/self/status``), the proportional set size of the
    browser and the Playwright driver (its descendants, summed), the Python threads and the OS
    threads, and for each page the frames it received and drew per second since the previous
    sample, its JavaScript heap and whether it is still connected.

Verdict: the median RSS over the 5 minutes after a 2-minute warm-up against the median over the
last 5 minutes, in MB and percent: "flat" if it grew by less than 5 % (a shorter run scales the
warm-up and the windows down). Frame rates here are those of software WebGL (SwiftShader) on a
shared machine: figures to read, not to gate on. Server log records (warnings and above), page
errors and closed websockets are collected and reported.

Prints a table and writes ``benchmarks/results/viewer_soak.json``.
"""

from __future__ import annotations

import argparse
import json
import logging
import os
import statistics
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from collidium.presets import preset
from collidium.viewer.server import create_app, running
from collidium.viewer.session import ViewerSession
from collidium.viewer.testing import HEADLESS_CHROMIUM_ARGS, chromium_path

RESULTS = Path(__file__).parent / "results"
#: The preset each page shows, and the one it visits now and then (one page each).
PRESETS = ("gas", "charged-gas", "circle-gas", "pool-break")
VISITS = ("piston", "heat-flow", "effusion", "granular")
#: What a page does, one a minute, page k starting k places along.
ACTIONS = ("heat", "visit", "cool", "return", "reset", "pause and play")
SAMPLE_SECONDS = 30.0
ACTION_SECONDS = 60.0
WARMUP_MINUTES = 2.0
WINDOW_MINUTES = 5.0
#: Growth of the median RSS, as a fraction, under which the memory is called flat.
FLAT = 0.05
#: Milliseconds a control may take to show its effect on the page.
TIMEOUT_MS = 30_000
MB = 2**20
PROBE = """() => {
    const v = window.collidiumViewer;
    const heap = performance.memory ? performance.memory.usedJSHeapSize : null;
    return {drawn: v.framesDrawn, received: v.framesReceived, connected: v.connected,
            preset: v.scene ? v.scene.preset : null, time: v.stats ? v.stats.time : null,
            heap: heap};
}"""


@dataclass
class Tab:
    """One open page and what it reported.

    Attributes
    ----------
    page : playwright Page
        The page, in its own browser context.
    home, visit : str
        The preset it shows, and the one it switches to now and then.
    problems : list of str
        Page errors, console errors and closed websockets, with the minute they came.
    last : dict
        The previous probe (frame counters), for the rates between samples.
    """

    page: Any
    home: str
    visit: str
    problems: list[str] = field(default_factory=list)
    last: dict[str, Any] = field(default_factory=dict)


class Collected(logging.Handler):
    """Keeps the server's log records (warnings and above) as text, with the minute they came.

    Parameters
    ----------
    start : float
        ``time.perf_counter()`` of the soak's start.
    """

    def __init__(self, start: float) -> None:
        super().__init__(logging.WARNING)
        self.start = start
        self.records: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        minute = (time.perf_counter() - self.start) / 60
        self.records.append(f"{minute:.1f} min {record.name}: {self.format(record)[:2000]}")


# -- memory and threads -------------------------------------------------------------------------


def status_field(name: str, pid: int | str = "self", table: str = "status") -> int:
    """An integer field of ``/proc/<pid>/<table>`` (``VmRSS`` of ``status``, ``Pss`` of
    ``smaps_rollup``: kB); 0 if the process is gone."""
    try:
        with open(f"/proc/{pid}/{table}", encoding="ascii") as status:
            for line in status:
                if line.startswith(name + ":"):
                    return int(line.split()[1])
    except (OSError, ValueError):
        pass
    return 0


def descendants(root: int) -> list[int]:
    """Process ids of every descendant of ``root`` (from the parent ids in ``/proc/*/stat``)."""
    children: dict[int, list[int]] = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat", encoding="ascii", errors="replace") as stat:
                parent = int(stat.read().rsplit(")", 1)[1].split()[1])
        except (OSError, IndexError, ValueError):
            continue
        children.setdefault(parent, []).append(int(entry))
    found, todo = [], [root]
    while todo:
        kids = children.get(todo.pop(), [])
        found += kids
        todo += kids
    return found


def memory() -> dict[str, float]:
    """RSS of this process and PSS of its descendants (browser and driver; proportional, so
    the memory their processes share is counted once) in MB, and the thread counts."""
    browser_kb = sum(status_field("Pss", pid, "smaps_rollup") for pid in descendants(os.getpid()))
    return {
        "rss_mb": status_field("VmRSS") * 1024 / MB,
        "browser_pss_mb": browser_kb * 1024 / MB,
        "python_threads": threading.active_count(),
        "os_threads": status_field("Threads"),
    }


# -- pages --------------------------------------------------------------------------------------


def watch(tab: Tab, start: float) -> None:
    """Record the page's errors, console errors and closed websockets in ``tab.problems``."""

    def note(what: str) -> None:
        tab.problems.append(f"{(time.perf_counter() - start) / 60:.1f} min {what}"[:2000])

    page = tab.page
    page.on("pageerror", lambda error: note(f"page error: {error}"))
    page.on("console", lambda m: note(f"console: {m.text}") if m.type == "error" else None)
    page.on("crash", lambda _: note("page crashed"))
    page.on("websocket", lambda ws: ws.on("close", lambda _: note("websocket closed")))


def show(tab: Tab, name: str) -> None:
    """Pick preset ``name`` in the page's list and wait for its scene."""
    tab.page.select_option("#preset", name)
    tab.page.wait_for_function(
        "name => window.collidiumViewer.scene && window.collidiumViewer.scene.preset === name",
        arg=name,
        timeout=TIMEOUT_MS,
    )


def open_tab(browser: Any, url: str, k: int, start: float) -> Tab:
    """Page ``k``, in a context of its own, connected and showing ``PRESETS[k]``."""
    context = browser.new_context(viewport={"width": 1280, "height": 800})
    context.set_default_timeout(TIMEOUT_MS)
    tab = Tab(context.new_page(), PRESETS[k], VISITS[k])
    watch(tab, start)
    tab.page.goto(url)
    tab.page.wait_for_function(
        "window.collidiumViewer && window.collidiumViewer.framesDrawn > 2", timeout=120_000
    )
    if tab.page.evaluate("window.collidiumViewer.scene.preset") != tab.home:
        show(tab, tab.home)
    tab.last = tab.page.evaluate(PROBE)
    return tab


def play_after_pause(tab: Tab) -> None:
    """Pause (if playing), wait a second, play; wait for the status each time."""
    page = tab.page
    playing = "window.collidiumViewer.status && window.collidiumViewer.status.playing"
    if page.evaluate(playing):
        page.click("#play")
        page.wait_for_function(f"!({playing})")
        page.wait_for_timeout(1000)
    page.click("#play")
    page.wait_for_function(playing)


def reset(tab: Tab) -> None:
    """Press reset and wait for the new scene (its generation goes up)."""
    generation = tab.page.evaluate("window.collidiumViewer.scene.generation")
    tab.page.click("#reset")
    tab.page.wait_for_function(f"window.collidiumViewer.scene.generation > {generation}")


def act(tab: Tab, action: str) -> None:
    """Do ``action`` (one of `ACTIONS`) through the page's controls."""
    if action in ("heat", "cool"):
        tab.page.click(f"#{action}")
    elif action == "visit":
        show(tab, tab.visit)
    elif action == "return":
        show(tab, tab.home)
    elif action == "reset":
        reset(tab)
    else:
        play_after_pause(tab)


def probe(tab: Tab) -> dict[str, Any]:
    """The page's counters now, and its frame rates since the previous probe."""
    now = tab.page.evaluate(PROBE) | {"at": time.perf_counter()}
    seconds = now["at"] - tab.last.get("at", now["at"])
    rates = {
        f"{kind}_per_s": (now[kind] - tab.last[kind]) / seconds if seconds > 0 else None
        for kind in ("drawn", "received")
    }
    tab.last = now
    heap = now["heap"] / MB if now["heap"] is not None else None
    return {"connected": now["connected"], "preset": now["preset"], "sim_time": now["time"],
            "frames_drawn": now["drawn"], "frames_received": now["received"],
            "js_heap_mb": heap} | rates  # fmt: skip


# -- the soak -----------------------------------------------------------------------------------


def sample(tabs: list[Tab], start: float) -> dict[str, Any]:
    """One row: memory, threads, and each page's probe (or the error probing it)."""
    pages = []
    for tab in tabs:
        try:
            pages.append(probe(tab))
        except Exception as exc:  # a dead page is a finding, not the end of the soak
            pages.append({"error": f"{type(exc).__name__}: {exc}"[:500]})
    return {"minute": (time.perf_counter() - start) / 60} | memory() | {"pages": pages}


def act_all(tabs: list[Tab], turn: int, start: float) -> list[dict[str, Any]]:
    """Turn ``turn`` of the actions: page k does ``ACTIONS[(turn + k) % len(ACTIONS)]``."""
    done = []
    for k, tab in enumerate(tabs):
        action = ACTIONS[(turn + k) % len(ACTIONS)]
        entry = {"minute": (time.perf_counter() - start) / 60, "page": k, "action": action}
        try:
            act(tab, action)
        except Exception as exc:
            entry["error"] = f"{type(exc).__name__}: {exc}"[:500]
            tab.problems.append(f"{entry['minute']:.1f} min {action} failed: {entry['error']}")
        done.append(entry)
    return done


def soak(tabs: list[Tab], minutes: float, start: float) -> dict[str, list[dict[str, Any]]]:
    """Sample every `SAMPLE_SECONDS` and act every `ACTION_SECONDS` until ``minutes`` pass."""
    samples, actions = [sample(tabs, start)], []
    print(row(samples[0]), flush=True)
    end = start + 60 * minutes
    next_sample, next_action, turn = start + SAMPLE_SECONDS, start + ACTION_SECONDS, 0
    while (now := time.perf_counter()) < end:
        due = min(next_sample, next_action, end)
        if due > now:
            tabs[0].page.wait_for_timeout(1000 * (due - now))  # Playwright's events keep flowing
        if next_sample < end and time.perf_counter() >= next_sample:  # before the action
            samples.append(sample(tabs, start))
            print(row(samples[-1]), flush=True)
            next_sample += SAMPLE_SECONDS
        if next_action < end and time.perf_counter() >= next_action:
            actions += act_all(tabs, turn, start)
            turn, next_action = turn + 1, next_action + ACTION_SECONDS
    samples.append(sample(tabs, start))
    print(row(samples[-1]), flush=True)
    return {"samples": samples, "actions": actions}


# -- verdict and table --------------------------------------------------------------------------


def windows(minutes: float) -> tuple[float, float]:
    """Warm-up and window lengths in minutes, scaled down for a run shorter than 12 minutes."""
    warmup = min(WARMUP_MINUTES, 0.2 * minutes)
    return warmup, min(WINDOW_MINUTES, (minutes - warmup) / 2)


def verdict(samples: list[dict[str, Any]], minutes: float, before: float) -> dict[str, Any]:
    """Median RSS after the warm-up and at the end; growth in MB and percent; flat or not.

    Parameters
    ----------
    samples : list of dict
        The rows of `sample`, in order.
    minutes : float
        Length of the soak (sets the warm-up and the windows, see `windows`).
    before : float
        RSS in MB before the server started.
    """
    warmup, window = windows(minutes)
    end = samples[-1]["minute"]
    early = [s["rss_mb"] for s in samples if warmup <= s["minute"] <= warmup + window]
    late = [s["rss_mb"] for s in samples if s["minute"] >= end - window]
    first, last = statistics.median(early), statistics.median(late)
    growth = last - first
    return {
        "rss_before_server_mb": before, "rss_start_mb": samples[0]["rss_mb"],
        "rss_after_warmup_mb": first, "rss_end_mb": last, "growth_mb": growth,
        "growth_percent": 100 * growth / first, "flat": growth < FLAT * first,
        "threshold_percent": 100 * FLAT, "warmup_minutes": warmup, "window_minutes": window,
        "browser_pss_start_mb": samples[0]["browser_pss_mb"],
        "browser_pss_end_mb": samples[-1]["browser_pss_mb"],
        "python_threads": [min(s["python_threads"] for s in samples),
                           max(s["python_threads"] for s in samples)],
        "os_threads": [min(s["os_threads"] for s in samples),
                       max(s["os_threads"] for s in samples)],
    }  # fmt: skip


def header() -> str:
    """The table's header: per page, frames drawn per second and JavaScript heap."""
    pages = "".join(f" {f'p{k} fps':>7} {f'p{k} heap':>8}" for k in range(len(PRESETS)))
    return f"{'min':>6} {'RSS MB':>8} {'browser PSS':>11} {'py thr':>6} {'os thr':>6}{pages}"


def row(s: dict[str, Any]) -> str:
    """One sample as a table row (``-`` for a figure the page did not give; ``X`` if it is
    disconnected or could not be probed)."""

    def page(p: dict[str, Any]) -> str:
        if "error" in p or not p["connected"]:
            return f" {'X':>7} {'X':>8}"
        fps = "-" if p["drawn_per_s"] is None else f"{p['drawn_per_s']:.1f}"
        heap = "-" if p["js_heap_mb"] is None else f"{p['js_heap_mb']:.1f}"
        return f" {fps:>7} {heap:>8}"

    return (f"{s['minute']:>6.1f} {s['rss_mb']:>8.1f} {s['browser_pss_mb']:>11.1f} "
            f"{s['python_threads']:>6} {s['os_threads']:>6}"
            + "".join(page(p) for p in s["pages"]))  # fmt: skip


def frames(tabs_out: list[dict[str, Any]], samples: list[dict[str, Any]]) -> None:
    """Add each page's frames received and drawn over the soak, and per second, to its entry."""
    first, last = samples[0], samples[-1]
    seconds = 60 * (last["minute"] - first["minute"])
    for k, entry in enumerate(tabs_out):
        a, b = first["pages"][k], last["pages"][k]
        if "frames_drawn" in a and "frames_drawn" in b and seconds > 0:
            for kind in ("drawn", "received"):
                entry[f"frames_{kind}"] = b[f"frames_{kind}"] - a[f"frames_{kind}"]
            entry["mean_fps"] = entry["frames_drawn"] / seconds
            entry["mean_received_per_s"] = entry["frames_received"] / seconds


def summary(out: dict[str, Any]) -> None:
    """Print the verdict, each page's frames, and the problems found."""
    v = out["verdict"]
    print(
        f"\nRSS: before the server {v['rss_before_server_mb']:.1f} MB, start "
        f"{v['rss_start_mb']:.1f} MB, after warm-up (median of {v['warmup_minutes']:g}-"
        f"{v['warmup_minutes'] + v['window_minutes']:g} min) {v['rss_after_warmup_mb']:.1f} MB, "
        f"end (median of the last {v['window_minutes']:g} min) {v['rss_end_mb']:.1f} MB"
    )
    print(
        f"growth {v['growth_mb']:+.1f} MB ({v['growth_percent']:+.1f} %): "
        f"{'flat' if v['flat'] else 'GROWING'} (flat: under {v['threshold_percent']:g} %)"
    )
    print(f"browser and driver PSS {v['browser_pss_start_mb']:.0f} -> "
          f"{v['browser_pss_end_mb']:.0f} MB; Python threads {v['python_threads']}, "
          f"OS threads {v['os_threads']}")  # fmt: skip
    for k, tab in enumerate(out["pages"]):
        fps = "no frame count"
        if "mean_fps" in tab:
            fps = f"{tab['mean_fps']:.1f} drawn/s ({tab['mean_received_per_s']:.1f} received/s)"
        print(
            f"page {k} ({tab['home']}): {tab.get('frames_drawn', '-')} frames drawn, {fps}, "
            f"{len(tab['problems'])} problems"
        )
        for problem in tab["problems"][:20]:
            print(f"    {problem}")
    print(f"server log: {len(out['server_log'])} records")
    for record in out["server_log"][:20]:
        print(f"    {record}")


# -- main ---------------------------------------------------------------------------------------


def run(browser: Any, minutes: float) -> dict[str, Any]:
    """Serve, open the pages, soak, and gather everything for the results file."""
    app = create_app(lambda: ViewerSession(preset("gas"), preset="gas"))
    start = time.perf_counter()
    before = status_field("VmRSS") * 1024 / MB
    with running(app) as url:
        log = Collected(start)
        for name in ("uvicorn", "collidium"):  # after uvicorn configured its own loggers
            logging.getLogger(name).addHandler(log)
        tabs = [open_tab(browser, url, k, start) for k in range(len(PRESETS))]
        print(header(), flush=True)
        out = soak(tabs, minutes, start)
        for tab in tabs:
            tab.page.context.close()
    out["verdict"] = verdict(out["samples"], minutes, before)
    out["pages"] = [{"home": t.home, "visit": t.visit, "problems": t.problems} for t in tabs]
    frames(out["pages"], out["samples"])
    out["server_log"] = log.records
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=60.0, help="how long to soak")
    args = parser.parse_args()
    path = chromium_path()
    if path is None:
        raise SystemExit("needs chromium: apt-get install chromium")
    from playwright.sync_api import sync_playwright

    with sync_playwright() as playwright:
        chromium_args = [*HEADLESS_CHROMIUM_ARGS, "--enable-precise-memory-info"]
        browser = playwright.chromium.launch(executable_path=path, args=chromium_args)
        out = run(browser, args.minutes)
        browser.close()
    out |= {"minutes": args.minutes, "renderer": "chromium headless, SwiftShader (no GPU)",
            "cpus": os.cpu_count()}  # fmt: skip
    summary(out)
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "viewer_soak.json").write_text(json.dumps(out, indent=2) + "\n")


if __name__ == "__main__":
    main()
