"""The notebook widget: the anywidget's model messages carry the page's protocol."""

from __future__ import annotations

import time

import numpy as np
import pytest

from collidium.errors import InputError
from collidium.presets import preset
from collidium.viewer import Widget, protocol
from collidium.viewer.server import STATIC, TICK


@pytest.fixture
def widget():
    sim = preset("gas", n=40).build()
    shown = Widget(sim)
    shown.sent = []
    shown.send = lambda content, buffers=None: shown.sent.append((content, buffers))
    yield shown
    shown.close()


def message(widget, content):
    """What the widget sends back for one message from its front end."""
    widget.sent.clear()
    widget._on_message(widget, content, [])
    return list(widget.sent)


def test_the_widget_carries_the_bundled_front_end(widget):
    assert widget._esm == (STATIC / "widget.js").read_text(encoding="utf-8")
    assert "render" in widget._esm and "export" in widget._esm
    assert widget._css == (STATIC / "widget.css").read_text(encoding="utf-8")


def test_ready_gets_the_handshake_and_a_frame_as_a_buffer(widget):
    sent = message(widget, {"type": "ready"})
    kinds = [content["type"] for content, _ in sent]
    assert kinds[:4] == ["hello", "scene", "status", "stats"] and "frame" in kinds
    (buffers,) = [buffers for content, buffers in sent if content["type"] == "frame"]
    frame = protocol.decode_frame(buffers[0])
    np.testing.assert_array_equal(
        frame["position"], widget.simulation.particles.position.astype("f4")
    )


def test_acks_release_frames_of_the_running_simulation(widget):
    message(widget, {"type": "ready"})
    times = []
    for k in range(1, 6):
        time.sleep(0.05)  # the simulation runs on wall-clock time
        sent = message(widget, {"type": "ack", "frame": k})
        times += [protocol.decode_frame(buffers[0])["time"] for _, buffers in sent if buffers]
    assert len(times) == 5 and np.all(np.diff(times) > 0)
    assert times[-1] == widget.simulation.time


def test_controls_act_on_the_simulation_shown(widget):
    message(widget, {"type": "ready"})
    before = widget.simulation.energy().kinetic
    sent = message(widget, {"type": "heat", "factor": 2.0})
    assert widget.simulation.energy().kinetic == pytest.approx(2 * before, rel=1e-13)
    stats = [content for content, _ in sent if content["type"] == "stats"]
    assert stats[0]["temperature"] == pytest.approx(2 * before / 40, rel=1e-13)


def test_a_malformed_raw_message_gets_an_error_and_the_next_good_one_works(widget):
    message(widget, {"type": "ready"})
    (error, _), *_ = message(widget, {"type": "raw", "text": "{oops"})
    assert error["type"] == "error" and error["field"] == "message"
    (status, _), *_ = message(widget, {"type": "pause"})
    assert status == {**status, "type": "status", "playing": False}


def test_a_widget_needs_something_to_show():
    with pytest.raises(InputError, match="simulation: must be a Simulation"):
        Widget(42)


def test_the_widget_front_end_runs_in_chromium_against_the_widget(browser, viewer_url):
    """The bundled widget module, rendered as Jupyter would (``render({model, el})``), with a
    model whose messages go to a real `Widget` and back."""
    import base64

    # Compile the engine's kernels first (a clean clone has no numba cache), so that the page's
    # wait for frames below measures the widget, not the compiler.
    preset("gas", n=60).build().run(steps=2)
    shown = Widget(preset("gas", n=60).build())
    replies: list[tuple[dict, list[bytes] | None]] = []
    shown.send = lambda content, buffers=None: replies.append((content, buffers))

    def to_kernel(content: dict) -> list[list]:
        replies.clear()
        shown._on_message(shown, content, [])
        # In Jupyter the kernel's event loop also ticks the widget every TICK; here only the
        # page's messages do, so tick on until a running simulation gives its next frame (an
        # ack that comes before the state moved on would otherwise get none, and the page waits).
        deadline = time.monotonic() + 1.0
        while shown.connection.session.playing and time.monotonic() < deadline:
            if any(b for _, b in replies):
                break
            time.sleep(TICK)
            shown._deliver(shown.connection.tick())
        return [[c, base64.b64encode(b[0]).decode() if b else None] for c, b in replies]

    page = browser.new_page(viewport={"width": 1000, "height": 900})
    page.goto(viewer_url + "static/widget.css")  # any page of the server: same origin
    page.expose_function("toKernel", to_kernel)
    # Jupyter puts the widget's CSS (its _css) in the page; the cell is about 900 px wide.
    page.set_content(
        "<link rel='stylesheet' href='/static/widget.css'><div id='cell' style='width: 900px'>"
    )
    page.evaluate(
        """async () => {
        const listeners = [];
        const bytes = (text) => Uint8Array.from(atob(text), (c) => c.charCodeAt(0));
        const model = {
          on: (name, callback) => listeners.push(callback),
          off: () => {},
          send: async (content) => {
            for (const [reply, buffer] of await window.toKernel(content)) {
              const buffers = buffer === null ? [] : [new DataView(bytes(buffer).buffer)];
              listeners.forEach((callback) => callback(reply, buffers));
            }
          },
        };
        const widget = (await import("/static/widget.js")).default;
        widget.render({ model, el: document.getElementById("cell") });
      }"""
    )
    hook = "document.getElementById('cell').collidiumViewer"
    page.wait_for_function(f"{hook} && {hook}.framesDrawn > 10")
    assert page.get_attribute("#cell #readout-n", "data-value") == "60"
    assert shown.simulation.time > 0
    page.click("#cell #play")
    page.wait_for_function(f"{hook}.status.playing === false")
    stopped = shown.simulation.time
    page.wait_for_timeout(300)
    assert shown.simulation.time == stopped
    page.close()
    shown.close()


def test_a_reloaded_page_gets_the_widget_back(widget):
    """The view that was drawing is gone without acknowledging its frames (a notebook page
    reload); the new one says ready and gets the handshake and frames again, paused or not."""
    message(widget, {"type": "ready"})
    message(widget, {"type": "pause"})
    for _ in range(3):  # the old view's credit runs out
        message(widget, {"type": "step"})
    assert not [buffers for _, buffers in message(widget, {"type": "step"}) if buffers]
    sent = message(widget, {"type": "ready"})
    kinds = [content["type"] for content, _ in sent]
    assert kinds[:4] == ["hello", "scene", "status", "stats"] and "frame" in kinds
    (buffers,) = [buffers for content, buffers in sent if content["type"] == "frame"]
    assert protocol.decode_frame(buffers[0])["time"] == widget.simulation.time
