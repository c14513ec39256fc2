#!/usr/bin/env python3
"""Independent check of an MCAP recording with the Foxglove Python libraries.

Decodes every message of FILE with PyPI `mcap` + `mcap-ros2-support` (which build their
CDR decoders from the schema texts stored in the file, not from armsim's code), prints
the header, the metadata, the message count per topic and the first and last JointState,
checks a few invariants (log times never decrease, unit quaternions, point-cloud sizes),
and exits with status 1 on any decode failure or broken invariant.

Setup and use (see docs/recording.md):

    python3 -m venv /tmp/venv-mcap
    /tmp/venv-mcap/bin/pip install mcap mcap-ros2-support
    cargo run --release --example write_sample_mcap -- /tmp/sample.mcap
    /tmp/venv-mcap/bin/python tools/check_mcap.py /tmp/sample.mcap
"""

import argparse
import math
import sys
from collections import Counter

from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory


def joint_state_line(label, log_time, msg):
    stamp = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
    pos = ", ".join(f"{x:.6g}" for x in msg.position)
    return (
        f"{label} JointState: log_time {log_time} ns, stamp {stamp:.9f} s, "
        f"{len(msg.name)} joints {list(msg.name)}, position [{pos}], "
        f"{len(msg.velocity)} velocities, {len(msg.effort)} efforts"
    )


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("file")
    args = ap.parse_args()
    problems = []
    with open(args.file, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        header = reader.get_header()
        print(f"{args.file}: profile '{header.profile}', library '{header.library}'")
        summary = reader.get_summary()
        if summary is not None:
            for ch in sorted(summary.channels.values(), key=lambda c: c.topic):
                sc = summary.schemas.get(ch.schema_id)
                print(
                    f"  channel {ch.topic}: {sc.name if sc else '-'} "
                    f"({sc.encoding if sc else '-'} / {ch.message_encoding})"
                )
        for m in reader.iter_metadata():
            print(f"  metadata '{m.name}': {dict(m.metadata)}")

        counts = Counter()
        first_js = last_js = None
        last_log = -1
        try:
            for schema, channel, message, msg in reader.iter_decoded_messages(
                log_time_order=False
            ):
                counts[channel.topic] += 1
                if message.log_time < last_log:
                    problems.append(
                        f"{channel.topic}: log time {message.log_time} < previous {last_log}"
                    )
                last_log = message.log_time
                name = schema.name
                if name.endswith("JointState"):
                    n = len(msg.name)
                    if len(msg.position) != n or len(msg.velocity) not in (0, n) or len(msg.effort) not in (0, n):
                        problems.append(f"{channel.topic}: JointState array lengths differ")
                    if first_js is None:
                        first_js = (message.log_time, msg)
                    last_js = (message.log_time, msg)
                elif name.endswith("TFMessage"):
                    for t in msg.transforms:
                        r = t.transform.rotation
                        norm = math.sqrt(r.x**2 + r.y**2 + r.z**2 + r.w**2)
                        if abs(norm - 1.0) > 1e-9:
                            problems.append(
                                f"{channel.topic}: {t.header.frame_id} -> {t.child_frame_id}: |q| = {norm}"
                            )
                elif name.endswith("PointCloud2"):
                    if len(msg.data) < msg.row_step * msg.height or msg.row_step < msg.point_step * msg.width:
                        problems.append(f"{channel.topic}: cloud data size does not match its layout")
                    fields = [(fl.name, fl.offset, fl.datatype) for fl in msg.fields]
                    print(
                        f"  {channel.topic}: {msg.width * msg.height} points in '{msg.header.frame_id}', fields {fields}"
                    )
                elif name.endswith("DiagnosticArray"):
                    for s in msg.status:
                        vals = {kv.key: kv.value for kv in s.values}
                        print(f"  {channel.topic}: level {s.level} '{s.name}': {s.message} {vals}")
        except Exception as e:  # any decode failure
            print(f"DECODE FAILURE after {sum(counts.values())} messages: {type(e).__name__}: {e}")
            return 1

    print("messages per topic:")
    for topic, n in sorted(counts.items()):
        print(f"  {topic}: {n}")
    if first_js is not None:
        print(joint_state_line("first", *first_js))
        print(joint_state_line("last ", *last_js))
    if not counts:
        problems.append("no messages")
    for p in problems:
        print(f"PROBLEM: {p}")
    if problems:
        return 1
    print("OK: every message decoded")
    return 0


if __name__ == "__main__":
    sys.exit(main())
