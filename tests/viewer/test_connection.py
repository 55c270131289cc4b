"""What a front end is sent, and when: handshake, credit, readouts, bad messages, rate limit."""

from __future__ import annotations

import pytest

from collidium.errors import SimulationError
from collidium.presets import preset
from collidium.viewer import protocol
from collidium.viewer.connection import MAX_CREDIT, STALL_SECONDS, STATS_PERIOD, Connection
from collidium.viewer.session import ViewerSession


class Clock:
    """A wall clock the test moves by hand."""

    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


@pytest.fixture
def clock() -> Clock:
    return Clock()


@pytest.fixture
def connection(clock) -> Connection:
    made = Connection(ViewerSession(preset("gas", n=50), preset="gas"), clock=clock)
    made.budget = 1e9  # the test's clock decides how far it runs, not the machine's speed
    return made


def kinds(items):
    return ["frame" if isinstance(item, bytes) else item["type"] for item in items]


def test_nothing_is_sent_before_ready_and_ready_gets_the_handshake(connection):
    assert connection.tick() == []
    (error,) = connection.receive({"type": "play"})
    assert error == {"type": "error", "field": "type", "reason": "send a ready message first"}
    assert kinds(connection.receive({"type": "ready"})) == ["hello", "scene", "status", "stats"]
    assert kinds(connection.tick()) == ["frame"]


def test_the_page_hears_when_the_first_step_has_run(connection, clock):
    """The first step compiles the kernels on a fresh installation: the page says "starting"
    until a status says the simulation runs."""
    ready = connection.receive({"type": "ready"})
    assert [item["phase"] for item in ready if item["type"] == "status"] == ["starting"]
    clock.now += 0.05
    sent = connection.tick()
    assert [
        item["phase"] for item in sent if isinstance(item, dict) and item["type"] == "status"
    ] == ["running"]
    clock.now += 0.05
    assert "status" not in kinds(connection.tick())  # said once


def test_frames_wait_for_acknowledgement_and_carry_the_latest_state(connection, clock):
    connection.receive({"type": "ready"})
    frames = []
    for _ in range(10):
        clock.now += 0.05
        frames += [item for item in connection.tick() if isinstance(item, bytes)]
    assert len(frames) == MAX_CREDIT  # the simulation ran on; no more frames without acks
    connection.receive({"type": "ack", "frame": 1})
    clock.now += 0.05
    (latest,) = [item for item in connection.tick() if isinstance(item, bytes)]
    assert protocol.decode_frame(latest)["time"] == connection.session.sim.time
    assert connection.session.sim.time == pytest.approx(0.55)


def test_acks_never_raise_credit_above_the_limit(connection, clock):
    connection.receive({"type": "ready"})
    for k in range(5):
        connection.receive({"type": "ack", "frame": k})
    frames = 0
    for _ in range(10):
        clock.now += 0.05
        frames += sum(isinstance(item, bytes) for item in connection.tick())
    assert frames == MAX_CREDIT


def test_readouts_follow_changes_at_most_every_period_and_stop_while_paused(connection, clock):
    connection.receive({"type": "ready"})
    connection.tick()
    clock.now += STATS_PERIOD * 0.6
    assert "stats" not in kinds(connection.tick())
    clock.now += STATS_PERIOD * 0.6
    assert "stats" in kinds(connection.tick())
    assert kinds(connection.receive({"type": "pause"})) == ["status"]
    time = connection.session.sim.time
    for _ in range(5):
        clock.now += STATS_PERIOD
        assert "stats" not in kinds(connection.tick())
    assert connection.session.sim.time == time
    (_status, stats) = connection.receive({"type": "step"})
    assert stats["time"] == pytest.approx(time + connection.session.sim.dt)


def test_heat_answers_with_the_new_temperature(connection):
    connection.receive({"type": "ready"})
    before = connection.session.sim.temperature()
    _status, stats = connection.receive({"type": "heat", "factor": 1.25})
    assert stats["temperature"] == pytest.approx(1.25 * before, rel=1e-13)


def test_a_malformed_message_gets_an_error_and_the_next_good_one_works(connection):
    connection.receive({"type": "ready"})
    (error,) = connection.receive("{not json")
    assert error["type"] == "error" and error["field"] == "message"
    (error,) = connection.receive({"type": "raw", "text": '{"type": "speed", "value": -1}'})
    assert error["field"] == "value"
    assert connection.receive({"type": "pause"}) == [connection.session.status()]
    assert connection.session.playing is False


def test_a_raw_message_inside_a_raw_message_is_refused(connection):
    connection.receive({"type": "ready"})
    inner = '{"type": "raw", "text": "{\\"type\\": \\"pause\\"}"}'
    (error,) = connection.receive({"type": "raw", "text": inner})
    assert error["field"] == "type"
    assert connection.session.playing


def test_control_messages_are_rate_limited_but_acks_are_not(connection):
    connection.receive({"type": "ready"})
    replies = [connection.receive({"type": "play"})[0] for _ in range(protocol.MESSAGE_BURST)]
    assert sum(reply["type"] == "error" for reply in replies) == 1  # ready took one token
    assert replies[-1]["reason"].startswith("too many messages")
    assert connection.receive("{malformed")[0]["reason"].startswith("too many messages")
    assert connection.receive({"type": "ack", "frame": 1}) == []
    connection._clock.now += 1.0  # a second later the bucket has refilled
    assert kinds(connection.receive({"type": "pause"})) == ["status"]


def test_rebuilding_costs_more_of_the_rate_than_a_control(connection):
    connection.receive({"type": "ready"})
    answers = [connection.receive({"type": "reset"})[0]["type"] for _ in range(11)]
    assert answers.count("scene") == protocol.MESSAGE_BURST // 10 - 1  # ready took a token
    assert answers[-1] == "error"


@pytest.mark.parametrize(
    "data",
    [
        "[" * 100_000,
        '{"type": "trace", "index": ' + "9" * 5000 + "}",
        {"type": "load", "preset": "pool-break", "overrides": {"speed": "fast"}},
        {"type": "scenario", "toml": "a = " + "[" * 5000},
        {
            "type": "scenario",
            "toml": "[[particles]]\nkind = 'random'\nn = 10\n[run]\ndt = 5e-324\n",
        },
    ],
    ids=["deep-json", "huge-int", "preset-type", "deep-toml", "tiny-dt"],
)
def test_hostile_messages_get_an_error_or_run_safely_and_the_session_goes_on(
    connection, clock, data
):
    connection.receive({"type": "ready"})
    replies = connection.receive(data)
    clock.now += 0.25
    replies += connection.tick()
    assert all(isinstance(reply, bytes) or reply["type"] != "error"
               or reply["field"] != "server" for reply in replies)  # fmt: skip
    assert connection.receive({"type": "pause"}) == [connection.session.status()]


@pytest.mark.filterwarnings("ignore:overflow encountered")
def test_heating_without_bound_ends_in_an_error_not_in_a_dead_connection(connection, clock):
    connection.receive({"type": "ready"})
    for _ in range(400):  # the kinetic energy overflows to infinity
        connection.session.heat(10.0)
    clock.now += 0.25
    replies = connection.tick()
    errors = [r for r in replies if not isinstance(r, bytes) and r["type"] == "error"]
    assert errors and errors[0]["field"] == "run" and "run away" in errors[0]["reason"]
    assert connection.receive({"type": "reset"})[0]["type"] == "scene"


def test_a_front_end_that_stops_acknowledging_stops_the_simulation(connection, clock):
    connection.receive({"type": "ready"})
    for _ in range(3):
        clock.now += 0.1
        connection.tick()  # two frames are sent, then credit runs out
    clock.now += STALL_SECONDS + 0.1
    connection.tick()
    stopped = connection.session.sim.time
    for _ in range(5):
        clock.now += 0.5
        assert connection.tick() == []
    assert connection.session.sim.time == stopped
    connection.receive({"type": "ack", "frame": 1})
    clock.now += 0.1
    assert "frame" in kinds(connection.tick())
    assert connection.session.sim.time > stopped


def test_a_failing_run_pauses_and_reports_one_line(connection, clock, monkeypatch):
    connection.receive({"type": "ready"})

    def fail(**_):
        raise SimulationError("step 3 (t = 0.03 s): particle(s) 4 left the vessel")

    monkeypatch.setattr(connection.session.sim, "run", fail)
    clock.now += 0.1
    error, status = connection.tick()[:2]
    assert error == {"type": "error", "field": "run",
                     "reason": "step 3 (t = 0.03 s): particle(s) 4 left the vessel"}  # fmt: skip
    assert status["playing"] is False
