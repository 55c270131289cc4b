"""Messages from the front end are validated field by field; frames round-trip."""

from __future__ import annotations

import json

import numpy as np
import pytest

from collidium.errors import InputError
from collidium.viewer import protocol


@pytest.mark.parametrize(
    "message",
    [
        {"type": "ready"},
        {"type": "ack", "frame": 3},
        {"type": "play"},
        {"type": "speed", "value": 2},
        {"type": "heat", "factor": 0.8},
        {"type": "forces", "enabled": False},
        {"type": "trace", "index": None},
        {"type": "set_velocity", "index": 4, "vx": 1.5, "vy": -2},
        {"type": "load", "preset": "gas", "overrides": {"n": 300, "collisions": "step"}},
        {"type": "scenario", "toml": "name = 'x'"},
        {"type": "raw", "text": "{"},
    ],
)
def test_good_messages_are_accepted_as_text_and_as_objects(message):
    assert protocol.parse_message(json.dumps(message)).type == message["type"]
    assert protocol.parse_message(message).type == message["type"]


@pytest.mark.parametrize(
    ("data", "field", "words"),
    [
        ("{bad", "message", "not valid JSON"),
        ("[1, 2]", "message", "JSON object"),
        ('{"type": "explode"}', "type", "explode"),
        ('{"kind": "play"}', "type", ""),
        ('{"type": "speed", "value": "fast"}', "value", ""),
        ('{"type": "speed", "value": 1000}', "value", "100"),
        ('{"type": "speed", "value": NaN}', "value", ""),
        ('{"type": "heat", "factor": Infinity}', "factor", ""),
        ('{"type": "set_velocity", "index": -1, "vx": 0, "vy": 0}', "index", ">= 0"),
        ('{"type": "set_velocity", "index": 1, "vx": 1e300, "vy": 0}', "vx", ""),
        ('{"type": "play", "now": true}', "now", ""),
        ('{"type": "trace", "index": 1.5}', "index", ""),
        ('{"type": "collisions", "enabled": "yes"}', "enabled", ""),
    ],
)
def test_a_bad_message_names_its_field(data, field, words):
    with pytest.raises(InputError) as caught:
        protocol.parse_message(data)
    assert caught.value.field == field
    assert words in caught.value.reason
    assert "\n" not in str(caught.value)


def test_an_overlong_message_is_refused_before_parsing():
    text = json.dumps({"type": "scenario", "toml": "#" * protocol.MAX_MESSAGE_BYTES})
    with pytest.raises(InputError, match="longer than"):
        protocol.parse_message(text)


def test_frames_round_trip_in_float32(rng):
    position = rng.uniform(-10, 10, (7, 2))
    velocity = rng.normal(size=(7, 2))
    plain = protocol.decode_frame(protocol.encode_frame(5, 1.25, 3, position))
    assert (plain["n"], plain["number"], plain["time"], plain["generation"]) == (7, 5, 1.25, 3)
    assert plain["flags"] == 0 and plain["velocity"] is None
    np.testing.assert_array_equal(plain["position"], position.astype(np.float32))
    full = protocol.decode_frame(protocol.encode_frame(6, 2.0, 3, position, velocity))
    assert full["flags"] == protocol.FLAG_VELOCITIES
    np.testing.assert_array_equal(full["velocity"], velocity.astype(np.float32))
    assert len(protocol.encode_frame(1, 0.0, 1, position, velocity)) == 32 + 7 * 16


def test_a_frame_carries_the_piston_where_it_is(rng):
    position = rng.uniform(-10, 10, (3, 2))
    face = np.array([[-10.0, 2.5], [10.0, 2.5]])
    data = protocol.encode_frame(2, 1.0, 1, position, None, face)
    frame = protocol.decode_frame(data)
    assert frame["flags"] == protocol.FLAG_PISTON and frame["velocity"] is None
    np.testing.assert_array_equal(frame["piston"], face)
    np.testing.assert_array_equal(frame["position"], position.astype(np.float32))
    assert len(data) == 32 + 3 * 8 + 16
    with pytest.raises(InputError, match="bytes where"):
        protocol.decode_frame(data[:-4])


def test_a_truncated_frame_is_refused(rng):
    data = protocol.encode_frame(1, 0.0, 1, rng.uniform(size=(4, 2)))
    with pytest.raises(InputError, match="bytes where"):
        protocol.decode_frame(data[:-4])
    with pytest.raises(InputError, match="magic"):
        protocol.decode_frame(b"XXXX" + data[4:])


def test_the_listed_types_are_the_union_of_message_models():
    from typing import get_args

    union = get_args(get_args(protocol.Message)[0])
    tags = {tag for model in union for tag in get_args(model.model_fields["type"].annotation)}
    assert tags == set(protocol.MESSAGE_TYPES)
