#!/usr/bin/env python3
"""Independent check of an MCAP recording with the Foxglove Python libraries.

Decodes every message of FILE with PyPI `mcap` + `mcap-ros2-support` (which build their
CDR decoders from the schema texts stored in the file, not from armsim's code), prints
the header, the metadata, the epoch, the message count per topic, the first and last
JointState and every obstacle marker, checks a few invariants (log times never decrease
and start at the epoch, unit quaternions, point-cloud sizes), and exits with status 1 on
any decode failure or broken invariant.

Obstacle markers (`visualization_msgs/msg/MarkerArray` on /armsim/obstacles):
  --markers-json OUT   writes what the decoder read (the golden file of the Rust tests)
  --expect-markers F   compares the decoded markers with F (exit 1 on any difference)
  --root DIR           in both, `file://DIR/` in mesh URIs stands as `file://<root>/`

Setup and use (see docs/recording.md):

    python3 -m venv /tmp/venv-mcap
    /tmp/venv-mcap/bin/pip install mcap==1.6.0 mcap-ros2-support==0.6.0
    cargo run --release --example write_sample_mcap -- /tmp/sample.mcap
    /tmp/venv-mcap/bin/python tools/check_mcap.py /tmp/sample.mcap
    cargo run --release -- run tests/data/scenarios/obstacle_markers.toml --out /tmp/om
    /tmp/venv-mcap/bin/python tools/check_mcap.py /tmp/om/obstacle_markers.mcap \
        --root "$PWD" --expect-markers tests/data/obstacle_markers.golden.json
"""

import argparse
import datetime
import json
import math
import sys
from collections import Counter

from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory


def joint_state_line(label, log_time, msg):
    stamp = f"{msg.header.stamp.sec}.{msg.header.stamp.nanosec:09d}"
    pos = ", ".join(f"{x:.6g}" for x in msg.position)
    return (
        f"{label} JointState: log_time {log_time} ns, stamp {stamp} s, "
        f"{len(msg.name)} joints {list(msg.name)}, position [{pos}], "
        f"{len(msg.velocity)} velocities, {len(msg.effort)} efforts"
    )


MARKER_TYPES = {1: "CUBE", 2: "SPHERE", 3: "CYLINDER", 9: "TEXT_VIEW_FACING", 10: "MESH_RESOURCE"}
ROOT_TOKEN = "file://<root>/"


def marker_record(m, root):
    """One decoded marker as plain JSON values (floats as decoded: f64, f32 widened)."""
    mesh = m.mesh_resource
    if root and mesh.startswith(f"file://{root}/"):
        mesh = ROOT_TOKEN + mesh[len(f"file://{root}/"):]
    p, o = m.pose.position, m.pose.orientation
    return {
        "ns": m.ns,
        "id": m.id,
        "type": m.type,
        "action": m.action,
        "frame_id": m.header.frame_id,
        "position": [p.x, p.y, p.z],
        "orientation": [o.x, o.y, o.z, o.w],
        "scale": [m.scale.x, m.scale.y, m.scale.z],
        "color": [m.color.r, m.color.g, m.color.b, m.color.a],
        "lifetime": [m.lifetime.sec, m.lifetime.nanosec],
        "frame_locked": m.frame_locked,
        "text": m.text,
        "mesh_resource": mesh,
    }


def marker_line(r):
    kind = MARKER_TYPES.get(r["type"], str(r["type"]))
    f = lambda v: "[" + ", ".join(f"{x:.6g}" for x in v) + "]"
    mesh = f" mesh {r['mesh_resource']}" if r["mesh_resource"] else ""
    return (
        f"  marker {r['ns']}/{r['id']} {kind} '{r['text']}' in '{r['frame_id']}': "
        f"position {f(r['position'])} orientation {f(r['orientation'])} scale {f(r['scale'])}{mesh}"
    )


def compare_markers(got, want, problems):
    """Exact comparison (the floats are the same f64s on both sides)."""
    if len(got) != len(want):
        problems.append(f"{len(got)} markers, expected {len(want)}")
    for k, (g, w) in enumerate(zip(got, want)):
        for key in w:
            if g.get(key) != w[key]:
                problems.append(f"marker {k} ({w.get('text')}): {key} = {g.get(key)!r}, expected {w[key]!r}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("file")
    ap.add_argument("--markers-json", help="write the decoded obstacle markers to this JSON file")
    ap.add_argument("--expect-markers", help="compare the decoded obstacle markers with this JSON file")
    ap.add_argument("--root", help="directory written as <root> in file:// mesh URIs")
    args = ap.parse_args()
    problems = []
    epoch = None
    markers = None
    marker_times = None
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
            if m.name == "armsim" and "armsim.epoch_ns" in m.metadata:
                epoch = int(m.metadata["armsim.epoch_ns"])
        if epoch is not None:
            when = datetime.datetime.fromtimestamp(epoch / 1e9, tz=datetime.timezone.utc)
            print(f"  epoch (t = 0): {epoch} ns = {when.isoformat()}")

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
                if epoch is not None and message.log_time < epoch:
                    problems.append(f"{channel.topic}: log time {message.log_time} before the epoch {epoch}")
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
                elif name.endswith("MarkerArray") and channel.topic == "/armsim/obstacles":
                    markers = [marker_record(m, args.root) for m in msg.markers]
                    stamps = {m.header.stamp.sec * 10**9 + m.header.stamp.nanosec for m in msg.markers}
                    marker_times = (message.log_time, stamps)
                    for r in markers:
                        print(marker_line(r))
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
        if epoch is not None:
            t0 = first_js[1].header.stamp.sec * 10**9 + first_js[1].header.stamp.nanosec
            print(f"first JointState: stamp - epoch = {t0 - epoch} ns, log time - epoch = {first_js[0] - epoch} ns")
    if markers is not None and epoch is not None:
        log_time, stamps = marker_times
        print(f"obstacles: {len(markers)} markers, log time - epoch = {log_time - epoch} ns, stamps - epoch = {sorted(s - epoch for s in stamps)} ns")
        if stamps != {epoch}:
            problems.append(f"obstacle markers stamped {sorted(stamps)}, not at the epoch {epoch}")
    if args.markers_json:
        if markers is None:
            problems.append("no MarkerArray on /armsim/obstacles")
        else:
            with open(args.markers_json, "w") as out:
                json.dump({"topic": "/armsim/obstacles", "markers": markers}, out, indent=1)
                out.write("\n")
            print(f"wrote {len(markers)} markers to {args.markers_json}")
    if args.expect_markers:
        with open(args.expect_markers) as f:
            want = json.load(f)["markers"]
        before = len(problems)
        compare_markers(markers or [], want, problems)
        if len(problems) == before:
            print(f"markers equal the {len(want)} expected in {args.expect_markers}")
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
