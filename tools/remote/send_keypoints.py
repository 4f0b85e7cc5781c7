#!/usr/bin/env python3
"""Sends 2D keypoints to a mocap graph (node source.remote_keypoints) over ZeroMQ PUSH, encoded in
the mocap wire format version 3 (docs/wire-format.md) with nothing but `struct` and `zmq`: a model
of what a detector in Python (or on a GPU machine) does. The keypoints come from a folder of
OpenPose *_keypoints.json files; replace read_openpose_folder() with your detector.

  python3 tools/remote/send_keypoints.py ../shared/data/eval/openpose_json/json \\
      --endpoint tcp://127.0.0.1:5570

With CURVE security (docs/security.md; required when the node listens beyond loopback), name the
node's public key and this sender's secret key, files made by `mocap keys generate`:

  python3 tools/remote/send_keypoints.py FOLDER --endpoint tcp://10.0.0.5:5570 \\
      --server-key keys/solve.pub --client-key keys/detector.key

Needs python3-zmq (Debian) or pyzmq. Exit code 0 when every frame was sent, 1 on a usage or
sending error.
"""

import argparse
import json
import math
import os
import re
import struct
import sys
import time

try:
    import zmq
except ImportError:
    sys.exit("send_keypoints.py: python3-zmq is not installed (apt-get install python3-zmq)")

MAGIC, VERSION = b"MOCP", 3
HEADER = struct.Struct("<4sHHQqqqHH")  # 44 bytes, then the stream id
END_OF_STREAM, PEOPLE_2D = 0, 2
LAYOUTS = {"COCO-17": (0, 17), "BODY_25": (1, 25), "BODY_25B": (2, 25), "COCO-18": (3, 18),
           "HumanEva-15": (4, 15)}
BY_COUNT = {17: "COCO-17", 25: "BODY_25", 18: "COCO-18", 15: "HumanEva-15"}
NAN = float("nan")
F32 = struct.Struct("<f")


def f32(value):
    """The value as the receiver will see it (IEEE binary32)."""
    return F32.unpack(F32.pack(value))[0]


def header(kind, seq, capture_ns, frame, stream, payload_frames):
    stream_bytes = stream.encode()
    if len(stream_bytes) > 1024:
        raise ValueError("stream id longer than 1024 bytes")
    return HEADER.pack(MAGIC, VERSION, kind, seq, capture_ns, frame, time.time_ns(),
                       len(stream_bytes), payload_frames) + stream_bytes


def camera_name(name):
    """The camera name as the wire carries it: 1 to 256 bytes of UTF-8, no control characters."""
    data = name.encode()
    if not 1 <= len(data) <= 256 or any(b < 0x20 or b == 0x7f for b in data):
        raise ValueError("camera name must be 1-256 bytes without control characters: %r" % name)
    return struct.pack("<H", len(data)) + data


def encode_people_2d(seq, capture_ns, frame, stream, layout, people, camera="cam_01"):
    """people: list of {"id": int, "joints": [(x, y, confidence), ...]} with the layout's joint
    count. Missing keypoints: confidence 0 (sent as NaN, NaN, 0). The box is the detected
    keypoints' extent, computed in binary32 like the C++ reader does. camera: the name of the
    camera the keypoints were detected in, as in the graph's rig file."""
    code, joints = LAYOUTS[layout]
    meta = [struct.pack("<HHI", code, joints, len(people)) + camera_name(camera)]
    values = []
    for person in people:
        keypoints = person["joints"]
        if len(keypoints) != joints:
            raise ValueError("%s has %d joints, a person has %d" % (layout, joints, len(keypoints)))
        detected = [(f32(x), f32(y)) for x, y, c in keypoints if c > 0]
        box = (0.0, 0.0, 0.0, 0.0)
        if detected:
            x0, x1 = min(p[0] for p in detected), max(p[0] for p in detected)
            y0, y1 = min(p[1] for p in detected), max(p[1] for p in detected)
            box = (x0, y0, f32(x1 - x0), f32(y1 - y0))
        meta.append(struct.pack("<iffff", person.get("id", -1), *box))
        for x, y, c in keypoints:
            values.extend((x, y, c) if c > 0 else (NAN, NAN, 0.0))
    return [header(PEOPLE_2D, seq, capture_ns, frame, stream, 2), b"".join(meta),
            struct.pack("<%df" % len(values), *values)]


def encode_end_of_stream(seq, stream):
    return [header(END_OF_STREAM, seq, 0, 0, stream, 0)]


def read_key_file(path, secret):
    """The Z85 key of a key file written by `mocap keys generate`: its one line that is neither
    blank nor a '#' comment. A secret key file that group or others may access is refused."""
    if secret:
        mode = os.stat(path).st_mode
        if mode & 0o077:
            raise ValueError("%s is open to group or others (mode %04o); chmod 600 %s"
                             % (path, mode & 0o7777, path))
    with open(path, "rb") as f:
        data = f.read(4097)
    if len(data) > 4096:
        raise ValueError("%s: not a key file (larger than 4 KiB)" % path)
    lines = [line.strip() for line in data.decode("ascii", "replace").splitlines()]
    keys = [line for line in lines if line and not line.startswith("#")]
    if len(keys) != 1 or len(keys[0]) != 40:
        raise ValueError("%s: not a key file (expected one line of 40 Z85 characters)" % path)
    return keys[0].encode("ascii")


def use_curve(socket, server_key_file, client_key_file):
    """Makes `socket` a CURVE client of the server whose public key is in server_key_file."""
    if not zmq.has("curve"):
        raise ValueError("this libzmq has no CURVE security")
    secret = read_key_file(client_key_file, secret=True)
    socket.curve_serverkey = read_key_file(server_key_file, secret=False)
    socket.curve_secretkey = secret
    socket.curve_publickey = zmq.curve_public(secret)


def frame_number(name):
    numbers = re.findall(r"\d+", name)
    return int(numbers[-1]) if numbers else None


def read_openpose_file(path):
    """[(person_id, [(x, y, c), ...])] of one OpenPose file; people without body keypoints are
    left out."""
    with open(path, "rb") as f:
        document = json.loads(f.read().decode("utf-8"))
    people = []
    for index, person in enumerate(document.get("people", [])):
        flat = person.get("pose_keypoints_2d", [])
        if not flat:
            continue
        if not isinstance(flat, list) or len(flat) % 3 != 0:
            raise ValueError("people[%d].pose_keypoints_2d is not x, y, c triples" % index)
        values = [float(v) if isinstance(v, (int, float)) else NAN for v in flat]
        pid = person.get("person_id", -1)
        if isinstance(pid, list):
            pid = pid[0] if len(pid) == 1 and isinstance(pid[0], int) else -1
        people.append({"id": pid if isinstance(pid, int) else -1,
                       "joints": [tuple(values[i:i + 3]) for i in range(0, len(values), 3)]})
    return people


def read_openpose_folder(folder):
    """Yields (frame number, people) in frame order. A file that cannot be read is reported and
    sent as a frame without people, so every frame number reaches the graph."""
    files = sorted((frame_number(n), n) for n in os.listdir(folder)
                   if n.endswith("_keypoints.json") and frame_number(n) is not None)
    for number, name in files:
        try:
            yield number, read_openpose_file(os.path.join(folder, name))
        except (OSError, ValueError, TypeError, AttributeError) as e:
            print("send_keypoints.py: %s: %s; sent without people" % (name, e), file=sys.stderr)
            yield number, []


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("folder", help="folder of OpenPose *_keypoints.json files")
    parser.add_argument("--endpoint", required=True,
                        help="the node's endpoint, e.g. tcp://127.0.0.1:5570")
    parser.add_argument("--bind", action="store_true",
                        help="bind instead of connecting (for a node with bind: false)")
    parser.add_argument("--layout", default="auto",
                        help="auto (by keypoint count; 25 is BODY_25), or one of " +
                        ", ".join(LAYOUTS))
    parser.add_argument("--fps", type=float, default=30.0,
                        help="frame rate: capture times are start + frame / fps")
    parser.add_argument("--realtime", action="store_true", help="send at --fps, not at once")
    parser.add_argument("--stream", default="remote", help="stream id of the messages")
    parser.add_argument("--camera", default="cam_01",
                        help="the camera's name in the messages (as in the rig file)")
    parser.add_argument("--limit", type=int, default=0, help="send at most N frames (0: all)")
    parser.add_argument("--no-end", action="store_true", help="do not send EndOfStream")
    parser.add_argument("--linger-ms", type=int, default=10000,
                        help="how long to wait for unsent messages at the end")
    parser.add_argument("--server-key", metavar="NAME.pub",
                        help="CURVE: the node's public key file (with --client-key)")
    parser.add_argument("--client-key", metavar="NAME.key",
                        help="CURVE: this sender's secret key file (mode 0600); the node must "
                        "list its NAME.pub in curve_client")
    args = parser.parse_args()
    if bool(args.server_key) != bool(args.client_key):
        parser.error("--server-key and --client-key go together")
    if args.server_key and args.bind:
        parser.error("CURVE keys are supported when connecting (without --bind)")
    if args.layout != "auto" and args.layout not in LAYOUTS:
        parser.error("unknown layout %s" % args.layout)
    if not os.path.isdir(args.folder):
        parser.error("%s is not a folder" % args.folder)
    try:
        camera_name(args.camera)
    except ValueError as e:
        parser.error(str(e))

    context = zmq.Context()
    socket = context.socket(zmq.PUSH)
    socket.setsockopt(zmq.LINGER, args.linger_ms)
    if args.server_key:
        try:
            use_curve(socket, args.server_key, args.client_key)
        except (OSError, ValueError) as e:
            print("send_keypoints.py: %s" % e, file=sys.stderr)
            return 1
    (socket.bind if args.bind else socket.connect)(args.endpoint)
    start_ns, start = time.time_ns(), time.monotonic()
    seq = 0
    for number, people in read_openpose_folder(args.folder):
        if args.limit and seq >= args.limit:
            break
        counts = {len(p["joints"]) for p in people}
        if len(counts) > 1:
            print("send_keypoints.py: frame %d mixes keypoint counts %s; sent without people"
                  % (number, sorted(counts)), file=sys.stderr)
            people = []
        layout = args.layout
        if layout == "auto":
            layout = BY_COUNT.get(counts.pop() if counts else 25)
            if layout is None:
                print("send_keypoints.py: frame %d: no layout has that many keypoints; sent "
                      "without people" % number, file=sys.stderr)
                layout, people = "BODY_25", []
        elif counts and counts != {LAYOUTS[layout][1]}:
            print("send_keypoints.py: frame %d does not have %d keypoints; sent without people"
                  % (number, LAYOUTS[layout][1]), file=sys.stderr)
            people = []
        if args.realtime:
            time.sleep(max(0.0, start + seq / args.fps - time.monotonic()))
        capture_ns = start_ns + round(1e9 * number / args.fps)
        socket.send_multipart(encode_people_2d(seq, capture_ns, number, args.stream, layout,
                                               people, args.camera))
        seq += 1
    if not args.no_end:
        socket.send_multipart(encode_end_of_stream(seq, args.stream))
    socket.close()  # waits up to --linger-ms for the messages to leave
    context.term()
    print("send_keypoints.py: sent %d frames to %s" % (seq, args.endpoint), file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
