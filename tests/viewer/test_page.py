"""The viewer's page in real chromium: disks drawn to scale and moving, plots updating, and the
controls changing the simulation as they say."""

from __future__ import annotations

import io
import json
import math
from pathlib import Path

import numpy as np
import pytest

from collidium.presets import preset
from collidium.scenario import Scenario

LETTERBOX = np.round(255 * np.array([0.91, 0.925, 0.945]))


def readout(page, name: str) -> float:
    value = page.get_attribute(f"#readout-{name}", "data-value")
    assert value, f"readout {name} is empty"
    return float(value)


def pixels(page, selector: str) -> np.ndarray:
    from PIL import Image

    picture = Image.open(io.BytesIO(page.locator(selector).screenshot()))
    return np.asarray(picture.convert("RGB")).astype(int)


def hide_legend(page) -> None:
    """Take the colour legend out of the pictures of the vessel (it sits in its corner)."""
    page.evaluate("document.querySelector('#legend').style.visibility = 'hidden'")


def disk_pixels(image: np.ndarray) -> np.ndarray:
    """Pixels inside the 20 m x 20 m vessel, clear of its outline, that are not its white."""
    height, width = image.shape[:2]
    metre = (min(width, height) - 4) / 20.0
    inside = np.zeros((height, width), dtype=bool)
    top, left = round(height / 2 - 10 * metre) + 3, round(width / 2 - 10 * metre) + 3
    inside[top : round(height / 2 + 10 * metre) - 2, left : round(width / 2 + 10 * metre) - 2] = (
        True
    )
    return inside & (image < 200).any(axis=2)


def pause(page) -> None:
    if page.evaluate("window.collidiumViewer.status.playing"):
        page.click("#play")
    page.wait_for_function("!window.collidiumViewer.status.playing")


def test_disks_are_drawn_to_scale_and_move(page):
    hide_legend(page)
    first = pixels(page, "#particles")
    height, width = first.shape[:2]
    metre = min(width, height) / 20.0  # the 20 m x 20 m vessel fills the shorter side
    expected = 200 * math.pi * (0.25 * metre) ** 2  # the gas preset's 200 disks of r = 0.25 m
    drawn = disk_pixels(first).sum()
    # The rim of each disk is drawn darker: allow for it (and for disks partly overlapping in
    # the picture as they pass), but the area must be that of 200 disks of this size.
    assert 0.6 * expected < drawn < 1.15 * expected
    page.wait_for_timeout(500)
    second = pixels(page, "#particles")
    moved = (disk_pixels(first) != disk_pixels(second)).sum()
    assert moved > 0.2 * drawn  # at ~10 m/s, most disks move by more than a radius in 0.5 s


def test_the_vessel_is_drawn_from_the_outline_the_server_sends(page):
    outline = page.evaluate("window.collidiumViewer.scene.vessel.outline")
    assert outline == [[-10.0, -10.0], [10.0, -10.0], [10.0, 10.0], [-10.0, 10.0]]
    hide_legend(page)
    image = pixels(page, "#particles")
    height, width = image.shape[:2]
    metre = (min(width, height) - 4) / 20.0
    left, right = round(width / 2 - 10 * metre), round(width / 2 + 10 * metre)
    top, bottom = round(height / 2 - 10 * metre), round(height / 2 + 10 * metre)
    letterbox = (np.abs(image - LETTERBOX) <= 3).all(axis=2)
    white = (image >= 250).all(axis=2)
    dark = (image <= 160).all(axis=2)  # a 1 px line may be shared out over two pixels
    # Outside the outline (2 px clear of it) only the letterbox; inside, white between disks.
    outside = np.ones((height, width), dtype=bool)
    outside[max(top - 2, 0) : bottom + 3, max(left - 2, 0) : right + 3] = False
    outside[[0, -1], :] = outside[:, [0, -1]] = False  # the element's own edge
    assert letterbox[outside].mean() > 0.99
    assert white[top + 3 : bottom - 2, left + 3 : right - 2].mean() > 0.5
    # The outline itself: dark along the edges (disks may hide a few of its pixels).
    rows = slice(top + 3, bottom - 2)
    for column in (left, right):
        edge = dark[rows, max(column - 1, 0) : column + 2].any(axis=1)
        assert edge.mean() > 0.9


def test_plots_update(page):
    points = page.evaluate("window.collidiumViewer.energyPoints")
    before = pixels(page, "#energy-plot")
    page.wait_for_function(f"window.collidiumViewer.energyPoints > {points + 3}")
    page.wait_for_timeout(300)
    assert (pixels(page, "#energy-plot") != before).any()
    assert pixels(page, "#speed-plot").std() > 0


def test_pause_stops_simulated_time_and_step_advances_it_by_dt(page):
    pause(page)
    page.wait_for_timeout(300)  # readouts already on their way arrive
    stopped = readout(page, "time")
    page.wait_for_timeout(1000)
    assert readout(page, "time") == stopped
    page.click("#step")
    page.wait_for_function(
        f"Number(document.querySelector('#readout-time').dataset.value) > {stopped}"
    )
    assert readout(page, "time") == pytest.approx(stopped + 0.01, abs=1e-9)


def test_heat_raises_the_temperature_readout_by_its_factor(page):
    pause(page)
    page.wait_for_timeout(300)
    before = readout(page, "temperature")
    page.click("#heat")
    page.wait_for_function(
        f"Number(document.querySelector('#readout-temperature').dataset.value) > {before}"
    )
    assert readout(page, "temperature") == pytest.approx(1.25 * before, rel=1e-12)
    page.click("#cool")
    page.wait_for_function(
        f"Number(document.querySelector('#readout-temperature').dataset.value) < {1.2 * before}"
    )
    assert readout(page, "temperature") == pytest.approx(before, rel=1e-12)


def test_switching_preset_changes_n(page):
    assert readout(page, "n") == 200
    page.select_option("#preset", "pool-break")
    page.wait_for_function("document.querySelector('#readout-n').dataset.value === '225'")
    assert not page.is_visible("#set-n")  # pool-break takes no N
    page.select_option("#preset", "gas")
    page.wait_for_function("document.querySelector('#readout-n').dataset.value === '200'")
    page.fill("#set-n", "350")
    page.click("#apply")
    page.wait_for_function("document.querySelector('#readout-n').dataset.value === '350'")


def test_a_malformed_message_gets_an_error_and_the_next_good_one_works(page):
    page.evaluate("window.collidiumViewer.sendRaw('{not json')")
    page.wait_for_function("window.collidiumViewer.lastError !== null")
    error = page.evaluate("window.collidiumViewer.lastError")
    assert error["field"] == "message" and "JSON" in error["reason"]
    assert "message" in page.inner_text("#message")
    pause(page)  # the next good message is obeyed
    assert page.inner_text("#play").strip() == "Play"


def test_an_energy_drift_past_the_limit_is_marked_and_said(page):
    """The seed's charged gas at k = 5000 with the fixed step: its energy explodes, and the
    page says so (the drift readout marked, its warning line in the message bar)."""
    load = {"type": "load", "preset": "charged-gas",
            "overrides": {"k": 5000, "integrator": "fixed"}}  # fmt: skip
    page.evaluate(f"window.collidiumViewer.sendRaw({json.dumps(json.dumps(load))})")
    page.wait_for_function(
        "document.querySelector('#readout-drift').classList.contains('warning')", timeout=60_000
    )
    warning = page.get_attribute("#readout-drift", "title")
    assert warning.startswith("the total energy drifted by") and "limit 0.001" in warning
    assert page.inner_text("#message").startswith("energy: the total energy drifted by")
    assert abs(readout(page, "drift")) > 1e-3
    page.select_option("#preset", "gas")  # a new scene starts unmarked
    page.wait_for_function("window.collidiumViewer.scene.preset === 'gas'")
    page.evaluate("window.statsBefore = window.collidiumViewer.stats")
    page.wait_for_function("window.collidiumViewer.stats !== window.statsBefore")  # the gas's
    assert "warning" not in page.get_attribute("#readout-drift", "class")


def test_collisions_toggle_and_download_give_what_they_say(page):
    page.wait_for_function(
        "Number(document.querySelector('#readout-collisions').dataset.value) > 0"
    )
    page.uncheck("#toggle-collisions")
    page.wait_for_function("window.collidiumViewer.status.collisions === false")
    # The next window of the collision rate counts no collisions at all.
    page.wait_for_function("document.querySelector('#readout-collisions').dataset.value === '0'")
    with page.expect_download() as download:
        page.click("#download")
    saved = download.value
    assert saved.suggested_filename == "gas.toml"
    text = Path(saved.path()).read_text(encoding="utf-8")
    assert Scenario.from_toml_string(text) == preset("gas")


def test_the_page_is_saved_as_a_screenshot(page, artifacts):
    page.check("#toggle-momentum")
    page.wait_for_timeout(500)
    target = artifacts / "viewer.png"
    page.screenshot(path=str(target), full_page=True)
    assert target.stat().st_size > 10_000


TWO_DISKS = """
name = "two"
[vessel]
width = 20.0
height = 20.0
[run]
dt = 0.01
[[particles]]
kind = "explicit"
position = [[-5.0, 0.0], [5.0, 0.0]]
velocity = [[0.0, 0.0], [0.0, 0.0]]
radius = 1.0
"""


def on_screen(page, x: float, y: float) -> tuple[float, float]:
    """Page coordinates of the point (x, y) m of the 20 m x 20 m vessel: centred in the canvas,
    y up, scaled to fill the shorter side less a 2 px margin."""
    box = page.locator("#particles").bounding_box()
    metre = (min(box["width"], box["height"]) - 4) / 20.0
    return box["x"] + box["width"] / 2 + x * metre, box["y"] + box["height"] / 2 - y * metre


def test_click_traces_a_disk_and_drag_gives_it_a_velocity(page):
    page.set_input_files(
        "#open-scenario",
        files=[{"name": "two.toml", "mimeType": "text/plain", "buffer": TWO_DISKS.encode()}],
    )
    page.wait_for_function("document.querySelector('#readout-n').dataset.value === '2'")
    pause(page)
    assert readout(page, "temperature") == 0.0
    page.mouse.click(*on_screen(page, 5.0, 0.0))  # a click on the right-hand disk traces it
    start, end = on_screen(page, 5.0, 0.0), on_screen(page, 5.0, 3.0)
    page.mouse.move(*start)
    page.mouse.down()
    page.mouse.move(*end, steps=8)
    page.mouse.up()  # dragged 3 m up: velocity (0, 3) m/s
    page.wait_for_function(
        "Number(document.querySelector('#readout-temperature').dataset.value) > 0"
    )
    speed = math.sqrt(4 * readout(page, "temperature"))  # kT = KE / N = m v^2 / 4
    box = page.locator("#particles").bounding_box()
    pixel = 20.0 / (min(box["width"], box["height"]) - 4)  # a CSS pixel in m
    assert speed == pytest.approx(3.0, abs=pixel)  # the pointer is only as exact as a pixel
    before = pixels(page, "#overlay")
    page.click("#play")
    page.wait_for_function("Number(document.querySelector('#readout-time').dataset.value) > 1.5")
    x, y = on_screen(page, 5.0, 0.0)
    # The overlay is drawn in animation frames after the readout changes; a busy machine delays
    # them, so the picture is taken again until the path has reached 4.5 m (at most 10 s).
    for _ in range(100):
        after = pixels(page, "#overlay")
        orange = (np.abs(after - [0xFF, 0x7F, 0x0E]) <= 40).all(axis=2)
        rows, columns = np.nonzero(orange & (after != before).any(axis=2))
        offset = columns + box["x"] - x
        path = rows[np.abs(offset) <= 2] + box["y"]
        if path.size and path.min() <= y - 4.5 / pixel:
            break
        page.wait_for_timeout(100)
    # Everything drawn is the path straight up from (5, 0) m and the ring around the disk...
    assert np.all(np.abs(offset) <= (1.0 + 0.2) / pixel)
    # ...and the path is a vertical line from where the disk started to past 1.5 s x 3 m/s.
    assert path.max() >= y - 2 and path.min() <= y - 4.5 / pixel


#: An L with a partition that has a hole, away from the origin: the page draws what the server
#: sends, filled only inside, whatever the shape. Its first corner is one from which a fan of
#: triangles would paint the notch.
L_VESSEL = {
    "shape": "polygon",
    "vertices": [[10, 4], [4, 4], [4, 10], [0, 10], [0, 0], [10, 0]],
    "partitions": [{"name": "p", "start": [2, 0], "end": [2, 4], "gap": 1.0, "gap_at": 0.75}],
}


@pytest.fixture
def l_page(browser):
    from collidium.viewer.server import create_app, running
    from collidium.viewer.session import ViewerSession

    scenario = Scenario.from_dict(
        {"vessel": L_VESSEL, "particles": [{"kind": "random", "n": 5, "radius": 0.1}]}
    )
    with running(create_app(lambda: ViewerSession(scenario))) as url:
        context = browser.new_context(viewport={"width": 1280, "height": 800})
        opened = context.new_page()
        opened.goto(url)
        opened.wait_for_function("window.collidiumViewer && window.collidiumViewer.framesDrawn > 2")
        yield opened
        context.close()


def test_a_polygon_and_its_partition_are_drawn_from_what_the_server_sends(l_page):
    hide_legend(l_page)
    image = pixels(l_page, "#particles")
    height, width = image.shape[:2]
    metre = (min(width, height) - 4) / 20.0  # the view holds [-10, 10] m: the L is off centre

    def at(x0: float, x1: float, y0: float, y1: float) -> np.ndarray:
        """Pixels of the world rectangle [x0, x1] x [y0, y1] (m)."""
        columns = slice(round(width / 2 + x0 * metre), round(width / 2 + x1 * metre))
        rows = slice(round(height / 2 - y1 * metre), round(height / 2 - y0 * metre))
        return image[rows, columns]

    def share(block: np.ndarray, colour: np.ndarray, within: float) -> float:
        return float((np.abs(block - colour) <= within).all(axis=2).mean())

    white = np.array([255, 255, 255])
    assert share(at(0.3, 1.7, 4.5, 9.5), white, 5) > 0.9  # the L's upright arm
    assert share(at(5.0, 9.5, 0.3, 3.5), white, 5) > 0.9  # its foot
    assert share(at(4.5, 9.5, 4.5, 9.5), LETTERBOX, 3) > 0.99  # the notch is outside
    assert share(at(-9.5, -0.5, -9.5, 9.5), LETTERBOX, 3) > 0.99  # left of the L
    # The partition: a line (grey to black as it falls on pixels) along x = 2 m, but for its
    # hole around y = 3 m.
    column = round(width / 2 + 2 * metre)
    dark = (image[:, column - 1 : column + 2] <= 160).all(axis=2).any(axis=1)
    below = dark[round(height / 2 - 2.3 * metre) : round(height / 2 - 0.2 * metre)]
    hole = dark[round(height / 2 - 3.3 * metre) : round(height / 2 - 2.7 * metre)]
    assert below.mean() > 0.9 and hole.mean() < 0.2


# -- colours, legend, highlight, controls from the server ------------------------------------


def load_preset(page, name: str, **overrides) -> None:
    """Load preset ``name`` as the page's controls would, and wait for its first frame."""
    message = json.dumps(json.dumps({"type": "load", "preset": name, "overrides": overrides}))
    page.evaluate(f"window.collidiumViewer.sendRaw({message})")
    page.wait_for_function(f"window.collidiumViewer.scene.preset === {json.dumps(name)}")
    page.evaluate("window.drawnBefore = window.collidiumViewer.framesDrawn")
    page.wait_for_function("window.collidiumViewer.framesDrawn > window.drawnBefore + 1")


def disk_centres(page, picture: str, indices) -> list[tuple[int, int, float]]:
    """(column, row, radius in px) of particles ``indices`` in the screenshot of ``picture``."""
    out = []
    ppm = page.evaluate("window.collidiumViewer.pixelsPerMetre")
    radius = page.evaluate("window.collidiumViewer.scene.radius")
    for i in indices:
        at = page.evaluate(f"window.collidiumViewer.particle({i})")
        x, y = page.evaluate(f"window.collidiumViewer.toCanvas({at['x']}, {at['y']})")
        r = radius[i] if isinstance(radius, list) else radius
        out.append((round(x), round(y), r * ppm))
    return out


def settled_pause(page) -> None:
    """Pause, and wait until the frame drawn and the readouts are those of the paused state."""
    pause(page)
    page.wait_for_timeout(400)


def test_disks_are_coloured_by_speed_on_the_colormap_the_legend_shows(page):
    from matplotlib import colormaps

    settled_pause(page)
    assert page.evaluate("window.collidiumViewer.status.colour") == "speed"
    scale = page.evaluate("window.collidiumViewer.stats.speed_scale")
    legend = page.inner_text("#legend")
    assert legend.startswith("speed") and f"{scale:g} m/s" in legend
    hide_legend(page)
    image = pixels(page, "#particles")
    matches = []
    for i, (column, row, _) in enumerate(disk_centres(page, "#particles", range(40))):
        state = page.evaluate(f"window.collidiumViewer.particle({i})")
        speed = math.hypot(state["vx"], state["vy"])
        expected = 255 * np.array(colormaps["viridis"](min(speed / scale, 1.0))[:3])
        matches.append(np.abs(image[row, column] - expected).max() <= 12)
    # A disk may be hidden under another where two pass: most centres show their own colour.
    assert np.mean(matches) >= 0.85


def test_charges_are_coloured_and_marked_with_their_sign(page):
    load_preset(page, "charged-gas")
    assert page.evaluate("window.collidiumViewer.status.colour") == "charge"
    settled_pause(page)
    legend = page.inner_text("#legend")
    assert "+ positive" in legend and "− negative" in legend and "neutral" not in legend
    hide_legend(page)
    charges = page.evaluate("window.collidiumViewer.scene.charge")
    image = pixels(page, "#overlay")  # the page there: the disks and the marks drawn over them
    whiteness = image.min(axis=2)  # white marks on red or blue disks (whose least channel < 60)
    hits = []
    for i, (column, row, radius) in enumerate(disk_centres(page, "#overlay", range(40))):
        body = image[row + round(0.45 * radius), column + round(0.45 * radius)]
        red = body[0] > 2 * body[2]  # red (0xd6, 0x27, 0x28), shaded or not, against blue
        blue = body[2] > 2 * body[0]  # (0x1f, 0x77, 0xb4)
        # A 1.5 px bar falls on the pixels around its line: the whitest of three is on it, and
        # covered at least three quarters (31 + 0.75 x 224 = 199 on blue, where the line falls
        # on a pixel boundary).
        centre = whiteness[row - 1 : row + 2, column - 1 : column + 2].max()
        above = whiteness[row - round(0.45 * radius), column - 1 : column + 2].max()
        hits.append(
            (red if charges[i] > 0 else blue)
            and centre >= 199  # the bar of both signs crosses the centre
            and (above > 150) == (charges[i] > 0)  # only + has an upright bar
        )
    assert np.mean(hits) >= 0.85


def test_the_colour_control_offers_what_applies_and_switches(page):
    load_preset(page, "pi-blocks")
    options = page.eval_on_selector_all("#colour option", "nodes => nodes.map(n => n.value)")
    assert options == ["speed", "species"]  # two masses, no charges
    page.select_option("#colour", "species")
    page.wait_for_function("window.collidiumViewer.status.colour === 'species'")
    legend = page.inner_text("#legend")
    assert legend.startswith("species") and "mass 1 kg" in legend and "mass 1e+10 kg" in legend


def test_the_cue_ball_is_ringed_and_named(page):
    load_preset(page, "pool-break")
    settled_pause(page)
    assert page.evaluate("window.collidiumViewer.scene.highlight") == 224
    image = pixels(page, "#overlay")
    ((column, row, radius),) = disk_centres(page, "#overlay", [224])
    ring = round(radius + 5)
    gold = np.array([0xE6, 0xA7, 0x00])
    # A 3 px ring: on each side of the disk, one of three pixels across it is all gold.
    across = np.arange(ring - 1, ring + 2)
    for rows, columns in ((row, column + across), (row, column - across), (row + across, column)):
        assert np.abs(image[rows, columns] - gold).max(axis=1).min() <= 10
    # Nowhere else: the rack (far to the right of the cue ball at the start) has no ring.
    golden = (np.abs(image - gold) <= 10).all(axis=2)
    rows, columns = np.nonzero(golden)
    assert np.hypot(rows - row, columns - column).max() <= ring + 3
    assert "cue ball" in page.inner_text("#explanation")


def test_the_parameters_and_the_explanation_come_from_the_server(page):
    page.select_option("#preset", "heat-flow")
    page.wait_for_function("window.collidiumViewer.scene.preset === 'heat-flow'")
    assert page.inner_text("#explanation").startswith("The left wall is hot")
    labels = page.eval_on_selector_all(
        ".overrides label span", "nodes => nodes.map(n => n.textContent)"
    )
    assert "hot wall kT (J)" in labels and "cold wall kT (J)" in labels and "N" in labels
    assert page.input_value("#set-boundary") == "reflecting"
    page.fill("#set-hot", "4")
    page.click("#apply")
    page.wait_for_function("window.collidiumViewer.scene.overrides.hot === 4")
    page.fill("#set-n", "12.5")  # not a whole number: said, not sent
    page.click("#apply")
    assert page.inner_text("#message").startswith('n: "12.5" is not a whole number')


def test_holding_hot_walls_warms_the_gas_on_the_thermometer(page):
    page.wait_for_function(
        "window.collidiumViewer.stats && window.collidiumViewer.stats.temperature > 0"
    )
    before = readout(page, "temperature")
    page.hover("#hold-heat")
    page.mouse.down()
    page.wait_for_function("window.collidiumViewer.status.wall_temperature !== null")
    assert page.evaluate("window.collidiumViewer.status.wall_temperature") == pytest.approx(
        2 * before,
        rel=0.1,  # twice kT at the moment of pressing (a readout later)
    )
    page.wait_for_function(
        f"window.collidiumViewer.stats.temperature > {1.3 * before}", timeout=30_000
    )
    page.mouse.up()
    page.wait_for_function("window.collidiumViewer.status.wall_temperature === null")
    assert page.inner_text("#thermometer-value").startswith("kT ")
    # The pressure's first value waits for a window of readouts, which a loaded machine may not
    # have filled while the gas warmed.
    page.wait_for_function("document.querySelector('#gauge-value').textContent.includes('±')")


def test_the_histogram_can_average_over_readouts_and_a_picked_disk_is_described(page):
    page.select_option("#histogram-window", "20")
    page.wait_for_function("window.collidiumViewer.status.histogram_window === 20")
    page.wait_for_function("window.collidiumViewer.stats.histogram.readouts >= 3")
    page.evaluate("window.collidiumViewer.send({type: 'trace', index: 5})")
    page.wait_for_function(
        "window.collidiumViewer.stats.traced && window.collidiumViewer.stats.traced.index === 5"
    )
    assert page.inner_text("#picked").startswith("disk 5: speed ")


def test_every_preset_opens_with_its_explanation_and_is_saved_as_a_screenshot(page, artifacts):
    from collidium.presets import PRESETS
    from collidium.viewer.guide import GUIDES

    for name in PRESETS:
        load_preset(page, name)
        page.wait_for_timeout(300)
        assert page.evaluate("window.collidiumViewer.lastError") is None, name
        assert page.inner_text("#explanation") == GUIDES[name].explanation
        assert page.evaluate("window.collidiumViewer.status.phase") == "running"
        target = artifacts / f"viewer-{name}.png"
        page.screenshot(path=str(target))
        assert target.stat().st_size > 10_000


def test_the_pump_lets_particles_in_and_out(page):
    page.wait_for_function(
        "window.collidiumViewer.stats && window.collidiumViewer.stats.temperature > 0"
    )
    page.fill("#pump-count", "10")
    page.click("#pump-in")
    page.wait_for_function("window.collidiumViewer.scene.n > 200")
    grown = page.evaluate("window.collidiumViewer.scene.n")
    page.wait_for_function(f"document.querySelector('#readout-n').dataset.value === '{grown}'")
    page.click("#pump-out")
    page.wait_for_function(f"window.collidiumViewer.scene.n === {grown - 10}")
    page.fill("#pump-count", "0")
    page.click("#pump-in")
    assert page.inner_text("#message").startswith('count: "0" is not a whole number')


# -- dragging a wall, momentum arrows, energy lines ------------------------------------------


def test_dragging_the_wall_by_its_grip_compresses_and_heats_the_gas(page):
    page.wait_for_function(
        "window.collidiumViewer.stats && window.collidiumViewer.stats.temperature > 0"
    )
    assert page.evaluate("window.collidiumViewer.wallFace") == [[10, -10], [10, 10]]
    overlay = pixels(page, "#overlay")
    x, y = page.evaluate("window.collidiumViewer.toCanvas(10, 0)")
    grip = overlay[round(y) - 12 : round(y) + 13, round(x) - 2 : round(x) + 3]
    assert (np.abs(grip - [0x8A, 0x5A, 0x2B]) <= 8).all(axis=2).mean() > 0.5  # the grip is drawn
    before = readout(page, "temperature")
    page.mouse.move(*on_screen(page, 10.0, 0.0))
    page.mouse.down()
    page.mouse.move(*on_screen(page, 0.0, 0.0), steps=10)
    page.mouse.up()  # let go: the wall goes on to x = 0 and stays
    page.wait_for_function(
        "window.collidiumViewer.stats.piston && window.collidiumViewer.stats.piston.velocity === 0"
        " && window.collidiumViewer.stats.piston.position < 1",
        timeout=60_000,
    )
    box = page.locator("#particles").bounding_box()
    pixel = 20.0 / (min(box["width"], box["height"]) - 4)  # a CSS pixel in m
    face = page.evaluate("window.collidiumViewer.wallFace")
    assert abs(face[0][0]) <= 2 * pixel  # where the pointer was let go, to the pointer's pixel
    # Half the area: a little more than twice the temperature (the gas is not dilute).
    page.wait_for_function(f"window.collidiumViewer.stats.temperature > {1.9 * before}")


TWO_AT_REST = """
name = "two"
[vessel]
width = 20.0
height = 20.0
[[particles]]
kind = "explicit"
position = [[-5.0, 0.0], [8.0, -5.0]]  # the right one clear of the wall's grip
velocity = [[0.0, 0.0], [0.0, 0.0]]
radius = 1.0
"""


def test_momentum_arrows_have_heads_and_stop_at_the_wall(page):
    page.set_input_files(
        "#open-scenario",
        files=[{"name": "two.toml", "mimeType": "text/plain", "buffer": TWO_AT_REST.encode()}],
    )
    page.wait_for_function("document.querySelector('#readout-n').dataset.value === '2'")
    settled_pause(page)
    hide_legend(page)
    page.check("#toggle-momentum")
    # Equal momenta: each arrow is two diameters (4 m) long; the right one points out of the box.
    for index, (vx, vy) in enumerate([(0.0, 5.0), (5.0, 0.0)]):
        page.evaluate(f"window.collidiumViewer.send({{type: 'set_velocity', index: {index}, "
                      f"vx: {vx}, vy: {vy}}})")  # fmt: skip
    page.wait_for_function("window.collidiumViewer.particle(1).vx === 5")
    page.wait_for_timeout(300)
    image = pixels(page, "#particles")
    dark = (image < 200).all(axis=2)  # a 1 px line, anti-aliased: grey where it falls between
    tip_x, tip_y = page.evaluate("window.collidiumViewer.toCanvas(-5, 4)")
    row, column = round(tip_y) + 5, round(tip_x)
    # Five pixels below the tip of the upward arrow: its shaft and, 2-4 px either side, a barb.
    assert dark[row, column - 1 : column + 2].any()
    assert dark[row, column - 5 : column - 1].any() and dark[row, column + 2 : column + 6].any()
    assert not dark[round(tip_y) + 20, column - 6 : column - 2].any()  # no barbs lower down
    # The right arrow is drawn up to the wall (x = 10 m) and not beyond it.
    wall_x, wall_y = page.evaluate("window.collidiumViewer.toCanvas(10, -5)")
    inside = dark[round(wall_y) - 1 : round(wall_y) + 2, round(wall_x) - 12 : round(wall_x) - 3]
    outside = image[round(wall_y) - 3 : round(wall_y) + 4, round(wall_x) + 3 : round(wall_x) + 40]
    assert inside.any(axis=0).all()
    assert (np.abs(outside - LETTERBOX) <= 3).all()


def test_the_energy_plot_shows_the_total_alone_without_forces(page):
    assert page.evaluate("window.collidiumViewer.energyLines") == ["total"]
    load_preset(page, "charged-gas")
    assert page.evaluate("window.collidiumViewer.energyLines") == ["kinetic", "potential", "total"]
    assert page.locator("#total-speed-plot canvas").count() > 0  # total speed: its own panel
