#!/usr/bin/env python3
"""Cross-checks an MCAP file written by the simulator with Foxglove's own Python readers.

Usage: check_mcap.py FILE.mcap COUNTS.json [--values VALUES.json] [--rates TOPIC=HZ]...

COUNTS.json maps each topic to its expected message count. Every message is decoded with
mcap-ros2-support (`mcap_ros2.reader.read_ros2_messages`, from the schema text in the file):
the counts must match and no message may fail to decode. Each decoded message is also encoded
again from the same schema and must give back the stored CDR bytes exactly (so field order,
types, alignment and the encapsulation header all agree). With --values (topic -> list of the
messages as JSON, in log-time order, as the Rust test writes them), every field's name, order
and value must match too. With --rates, the mean rate of each named topic, (n - 1) / (last log
time - first log time), must be within 2 % of HZ. A topic counted 0 must have no messages.

Needs: pip install mcap==1.6.0 mcap-ros2-support==0.6.0 (tests/run.sh installs them).
Exits 0 and prints "N passed, 0 failed" on success.
"""

import argparse
import json
import math
import sys
from collections import Counter

from mcap.reader import make_reader
from mcap_ros2._dynamic import serialize_dynamic
from mcap_ros2.decoder import DecoderFactory
from mcap_ros2.reader import read_ros2_messages


def compare(got, want, where):
    """Raises AssertionError at the first difference between a decoded value and its JSON."""
    if isinstance(want, dict):
        fields = list(getattr(got, "__slots__", []))
        assert fields == list(want), f"{where}: fields {fields}, expected {list(want)}"
        for key, value in want.items():
            compare(getattr(got, key), value, f"{where}.{key}")
    elif isinstance(want, list):
        got = list(got)  # bytes (uint8[]) become ints
        assert len(got) == len(want), f"{where}: {len(got)} elements, expected {len(want)}"
        for i, (g, w) in enumerate(zip(got, want)):
            compare(g, w, f"{where}[{i}]")
    elif isinstance(want, float):
        assert isinstance(got, float), f"{where}: {got!r} is not a float"
        assert math.isclose(got, want, rel_tol=1e-6, abs_tol=1e-9), f"{where}: {got} != {want}"
    else:
        assert got == want, f"{where}: {got!r} != {want!r}"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("mcap")
    parser.add_argument("counts")
    parser.add_argument("--values")
    parser.add_argument("--rates", action="append", default=[], metavar="TOPIC=HZ")
    args = parser.parse_args()
    rates = {}
    for spec in args.rates:
        topic, _, hz = spec.rpartition("=")
        rates[topic] = float(hz)
    with open(args.counts) as f:
        expected_counts = json.load(f)
    expected_values = None
    if args.values:
        with open(args.values) as f:
            expected_values = json.load(f)

    passed, failures = 0, []

    def check(name, fn):
        nonlocal passed
        try:
            fn()
            passed += 1
        except Exception as e:  # noqa: BLE001 - every failure is reported the same way
            failures.append(f"{name}: {type(e).__name__}: {e}")

    # 1. The profile and encodings of the file, and its attachment.
    def header():
        with open(args.mcap, "rb") as f:
            reader = make_reader(f)
            assert reader.get_header().profile == "ros2", reader.get_header().profile
            summary = reader.get_summary()
            for schema in summary.schemas.values():
                assert schema.encoding == "ros2msg", (schema.name, schema.encoding)
                assert schema.name.count("/msg/") == 1, schema.name
            for channel in summary.channels.values():
                assert channel.message_encoding == "cdr", channel.topic
                assert "offered_qos_profiles" in channel.metadata, channel.topic
            names = [a.name for a in reader.iter_attachments()]
            assert "scenario.toml" in names, names

    check("header", header)

    # 2. Counts and decoding with the high-level API, in log-time order.
    counts, decoded, times = Counter(), {}, {}

    def decode_all():
        last = -1
        for m in read_ros2_messages(args.mcap):
            assert m.log_time_ns >= last, "messages out of log-time order"
            last = m.log_time_ns
            counts[m.channel.topic] += 1
            decoded.setdefault(m.channel.topic, []).append(m.ros_msg)
            times.setdefault(m.channel.topic, []).append(m.log_time_ns)

    check("decode every message", decode_all)
    for topic, n in expected_counts.items():
        check(f"count {topic}", lambda t=topic, n=n: _eq(counts[t], n))
    check(
        "no other topics",
        lambda: _eq(sorted(counts), sorted(t for t, n in expected_counts.items() if n)),
    )
    for topic, hz in rates.items():
        check(f"rate {topic}", lambda t=topic, hz=hz: _rate(times.get(t, []), hz))

    # 3. Decode then encode again: the stored bytes come back.
    def reencode():
        encoders = {}
        with open(args.mcap, "rb") as f:
            reader = make_reader(f, decoder_factories=[DecoderFactory()])
            for schema, channel, message, msg in reader.iter_decoded_messages():
                if schema.name not in encoders:
                    encoders[schema.name] = serialize_dynamic(
                        schema.name, schema.data.decode()
                    )[schema.name]
                again = encoders[schema.name](msg)
                assert again == message.data, (
                    f"{channel.topic} seq {message.sequence}: re-encoded "
                    f"{len(again)} bytes differ from the stored {len(message.data)}"
                )

    check("re-encode every message", reencode)

    # 4. Field names, order and values.
    if expected_values is not None:
        for topic, msgs in expected_values.items():
            check(
                f"values {topic}",
                lambda t=topic, w=msgs: compare(decoded.get(t, []), w, t),
            )

    for failure in failures:
        print("FAIL", failure)
    print(f"{sum(counts.values())} messages on {len(counts)} topics")
    print(f"{passed} passed, {len(failures)} failed")
    return 1 if failures else 0


def _eq(got, want):
    assert got == want, f"{got!r} != {want!r}"


def _rate(times_ns, hz):
    assert len(times_ns) >= 2, f"{len(times_ns)} messages: no rate"
    mean = (len(times_ns) - 1) / ((times_ns[-1] - times_ns[0]) * 1e-9)
    assert abs(mean - hz) <= 0.02 * hz, f"mean rate {mean:.4f} Hz, expected {hz} Hz"


if __name__ == "__main__":
    sys.exit(main())
