#!/usr/bin/env python3
# Seeds for fuzz_wire (run inside tests/fuzz/corpus/wire/): messages of the mocap wire format v3
# (docs/wire-format.md), each frame written as a 4-byte little-endian length and its bytes (the
# framing of tests/fuzz/wire.cpp).
import struct, json
J = 15
def header(code, nframes, stream=b"cam0", seq=7, version=3, magic=b"MOCP"):
    return struct.pack("<4sHHQqqqHH", magic, version, code, seq, 1000, 3, 2000, len(stream), nframes) + stream
def msg(*frames):
    return b"".join(struct.pack("<I", len(f)) + f for f in frames)
def w(n, b): open(n, "wb").write(b)
def name(text=b"cam_01"): return struct.pack("<H", len(text)) + text
w("end_of_stream.bin", msg(header(0, 0)))
# VideoFrame 4x2 gray8, stride 4
meta = struct.pack("<IIIBx", 4, 2, 4, 1) + name()
w("video_gray_4x2.bin", msg(header(1, 2), meta, bytes(range(8))))
meta = struct.pack("<IIIBx", 2, 2, 8, 3) + name(b"left")
w("video_bgr_stride.bin", msg(header(1, 2), meta, bytes(16)))
w("video_huge_size.bin", msg(header(1, 2), struct.pack("<IIIBx", 32768, 32768, 131072, 4) + name(), b""))
w("video_empty_camera.bin", msg(header(1, 2), struct.pack("<IIIBx", 4, 2, 4, 1) + name(b""), bytes(8)))
w("video_camera_too_long.bin", msg(header(1, 2), struct.pack("<IIIBx", 4, 2, 4, 1) + struct.pack("<H", 300) + b"c" * 300, bytes(8)))
w("video_camera_control_char.bin", msg(header(1, 2), struct.pack("<IIIBx", 4, 2, 4, 1) + name(b"cam\n1"), bytes(8)))
# People2D: layout 0, 17 joints, 2 people
def people2d(count, joints, layout=0, camera=b"cam_01"):
    meta = struct.pack("<HHI", layout, joints, count) + name(camera) + b"".join(struct.pack("<i4f", i, 1, 2, 30, 40) for i in range(count))
    kp = b"".join(struct.pack("<3f", j, j + 1, 0.5) for _ in range(count) for j in range(joints))
    return meta, kp
w("people2d_two.bin", msg(header(2, 2), *people2d(2, 17)))
w("people2d_empty.bin", msg(header(2, 2), *people2d(0, 25, 1)))
w("people2d_named_camera.bin", msg(header(2, 2), *people2d(1, 15, 4, "kamera_ü".encode())))
m, k = people2d(1, 17)
w("people2d_huge_count.bin", msg(header(2, 2), struct.pack("<HHI", 0, 17, 0xFFFFFFFF) + name(), k))
w("people2d_camera_cut.bin", msg(header(2, 2), struct.pack("<HHI", 0, 17, 0) + struct.pack("<H", 9) + b"cam", b""))
w("people2d_short_keypoints.bin", msg(header(2, 2), m, k[:-4]))
# People3D: 1 person
def people3d(count, world=False):
    frame = struct.pack("<BxH", 1, 0) if world else struct.pack("<Bx", 0) + name()
    meta = struct.pack("<I", count) + frame + b"".join(struct.pack("<iiq4f3f", i, 0, 5, 1, 0, 0, 0, 0.1, 0.2, 3) for i in range(count))
    pos = b"".join(struct.pack("<3f", j, j, j) for _ in range(count) for j in range(J))
    rot = b"".join(struct.pack("<4f", 1, 0, 0, 0) for _ in range(count) for j in range(J))
    clips = b"".join(struct.pack("<H", 5) + b"01_01" for _ in range(count))
    place = struct.pack("<I4f", 1, 0, -1, 0, 1.5) + b"".join(struct.pack("<I", 1) + struct.pack("<3f", 1, 2, 1) * J for _ in range(count))
    return meta, pos, rot, clips, place
w("people3d_one.bin", msg(header(3, 5), *people3d(1)))
w("people3d_none.bin", msg(header(3, 5), *people3d(0)))
w("people3d_world.bin", msg(header(3, 5), *people3d(2, world=True)))
m3 = people3d(1)
w("people3d_bad_frame_kind.bin", msg(header(3, 5), struct.pack("<IBxH", 1, 7, 0) + m3[0][14:], *m3[1:]))
# PoseMatches: 1 person, 2 candidates
meta = struct.pack("<I", 1) + name() + struct.pack("<i4fII", 1, 0, 0, 10, 20, 1, 2)
body = struct.pack("<3f", 1, 1, 1) * J
norm = struct.pack("<f", 0.1) * (2 * (J - 1))
cand = struct.pack("<IIIf", 3, 4, 5, 0.5) + struct.pack("<IIIf", 6, 7, 8, 0.7)
w("pose_matches_one.bin", msg(header(5, 4), meta, body, norm, cand))
w("pose_matches_huge_candidates.bin", msg(header(5, 4), struct.pack("<I", 1) + name() + struct.pack("<i4fII", 1, 0, 0, 10, 20, 1, 0xFFFFFFFF), body, norm, cand))
stats = {"graph": "g", "nodes": [{"node": "a", "type": "t", "process": "", "in": 1, "out": 2, "drops": 0, "p50_us": 1.5, "p95_us": 2.5, "queue_depth": 0, "max_queue_depth": 1, "state": "running", "status": "ok"}]}
w("graph_stats.bin", msg(header(4, 1), json.dumps(stats).encode()))
w("graph_stats_bad_json.bin", msg(header(4, 1), b'{"graph": 1, "nodes": [}'))
w("bad_magic.bin", msg(header(0, 0, magic=b"XXXX")))
w("version1.bin", msg(header(0, 0, version=1)))
w("version2.bin", msg(header(2, 2, version=2), struct.pack("<HHI", 0, 17, 0), b""))
w("unknown_type.bin", msg(header(9, 0)))
w("frame_count_mismatch.bin", msg(header(2, 3), *people2d(1, 17)))
w("stream_id_long.bin", msg(header(0, 0, stream=b"s" * 1100)))
w("short_header.bin", msg(b"MOCP\x03\x00"))
w("twenty_bytes.bin", b"MOCP\x03\x00\x02\x00" + b"\xff" * 12)
w("end_ack.bin", msg(b"MOCP-END-ACK"))
w("empty.bin", b"")
