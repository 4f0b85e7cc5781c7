#!/usr/bin/env python3
"""A program in another language reads a mocap stream: Python with Debian's python3-zmq subscribes
to sink.publish and decodes People2D, VideoFrame and EndOfStream messages by docs/wire-format.md
alone (struct, no mocap code), version 3: each message says its camera.

usage: python_client_test.py MOCAP_BINARY      exit 0 pass, 1 fail, 77 skipped
"""

import os
import struct
import subprocess
import sys
import tempfile

try:
    import zmq
except ImportError:
    print("SKIP: python3-zmq is not installed (apt-get install python3-zmq)")
    sys.exit(77)

HEADER = struct.Struct("<4sHHQqqqHH")  # magic version type seq capture_ns frame send_ns stream_len frames
END_OF_STREAM, VIDEO_FRAME, PEOPLE_2D = 0, 1, 2
BYTES_PER_PIXEL = {1: 1, 2: 3, 3: 3, 4: 4, 5: 4}


def decode(parts):
    magic, version, kind, seq, capture_ns, frame, send_ns, stream_len, count = HEADER.unpack_from(parts[0])
    assert magic == b"MOCP", magic
    assert version == 3, version
    assert len(parts[0]) == HEADER.size + stream_len
    assert len(parts) == count + 1
    message = {"type": kind, "seq": seq, "frame": frame, "capture_ns": capture_ns,
               "stream": parts[0][HEADER.size:].decode()}
    if kind == PEOPLE_2D:
        layout, joints, people, name_len = struct.unpack_from("<HHIH", parts[1])
        message["camera"] = parts[1][10:10 + name_len].decode()
        records = 10 + name_len
        assert len(parts[1]) == records + 20 * people and len(parts[2]) == 12 * people * joints
        values = struct.unpack("<%df" % (3 * people * joints), parts[2])
        message["people"] = []
        for p in range(people):
            person_id, bx, by, bw, bh = struct.unpack_from("<iffff", parts[1], records + 20 * p)
            keypoints = [values[3 * (p * joints + j):3 * (p * joints + j) + 3] for j in range(joints)]
            message["people"].append({"id": person_id, "box": (bx, by, bw, bh), "joints": keypoints})
        message["layout"] = layout
    elif kind == VIDEO_FRAME:
        width, height, stride, pixel_format, _, name_len = struct.unpack_from("<IIIBBH", parts[1])
        assert len(parts[1]) == 16 + name_len
        camera = parts[1][16:16 + name_len].decode()
        assert len(parts[2]) == stride * height
        assert stride >= width * BYTES_PER_PIXEL[pixel_format]
        message.update(camera=camera, width=width, height=height, stride=stride,
                       pixels=parts[2])
    return message


def receive_all(socket, poller, what):
    messages = []
    while True:
        if not poller.poll(30000):
            raise AssertionError("no %s message within 30 s" % what)
        message = decode(socket.recv_multipart())
        if message["type"] == END_OF_STREAM:
            return messages
        messages.append(message)


def main():
    mocap = sys.argv[1]
    with tempfile.TemporaryDirectory(prefix="mocap-python-") as tmp:
        people_endpoint = "ipc://" + os.path.join(tmp, "people")
        frames_endpoint = "ipc://" + os.path.join(tmp, "frames")
        graph = os.path.join(tmp, "publish.yaml")
        with open(graph, "w") as f:
            f.write(f"""
nodes:
  src:    {{ type: test.counter, params: {{ count: 40, people: 2, interval_ms: 2 }} }}
  cam:    {{ type: test.frames, params: {{ count: 5, width: 64, height: 48, camera: left }} }}
  people: {{ type: sink.publish, params: {{ endpoint: "{people_endpoint}", wait_for_subscriber: true }} }}
  frames: {{ type: sink.publish, params: {{ endpoint: "{frames_endpoint}", wait_for_subscriber: true }} }}
edges:
  - [src.out, people.in]
  - [cam.frames, frames.in]
""")
        context = zmq.Context()
        sockets = {}
        poller = {}
        for name, endpoint in (("people", people_endpoint), ("frames", frames_endpoint)):
            socket = context.socket(zmq.SUB)
            socket.setsockopt(zmq.LINGER, 0)
            socket.setsockopt(zmq.SUBSCRIBE, b"")
            socket.connect(endpoint)  # before the publisher binds: ZeroMQ reconnects until it does
            sockets[name] = socket
            poller[name] = zmq.Poller()
            poller[name].register(socket, zmq.POLLIN)
        process = subprocess.Popen([mocap, "run", graph, "--quiet"], stderr=subprocess.PIPE, text=True)
        try:
            people = receive_all(sockets["people"], poller["people"], "People2D")
            frames = receive_all(sockets["frames"], poller["frames"], "VideoFrame")
            assert process.wait(timeout=60) == 0, process.stderr.read()
        finally:
            if process.poll() is None:
                process.kill()
                process.wait()
            context.destroy(linger=0)

    assert [m["seq"] for m in people] == list(range(40)), [m["seq"] for m in people]
    for m in people:
        assert m["stream"] == "counter" and m["frame"] == m["seq"] and m["capture_ns"] > 0
        assert m["layout"] == 0 and len(m["people"]) == 2
        assert m["camera"] == "cam_01", m["camera"]  # a single-camera graph's default name
        for p, person in enumerate(m["people"]):
            assert person["id"] == p and len(person["joints"]) == 17
            x, y, c = person["joints"][4]
            assert (x, y) == ((m["seq"] % 1000) + 2.0, 10 * p + 4), (x, y)
            assert abs(c - 0.96) < 1e-6
    assert [m["seq"] for m in frames] == list(range(5))
    for m in frames:
        assert (m["width"], m["height"], m["stride"]) == (64, 48, 192)
        assert m["camera"] == "left" and m["stream"] == "left", (m["camera"], m["stream"])
        for row in (0, 47):
            assert m["pixels"][row * 192] == (m["seq"] + row) % 256
    print("decoded %d People2D and %d VideoFrame messages from Python" % (len(people), len(frames)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
