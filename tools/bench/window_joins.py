#!/usr/bin/env python3
"""How smoothly a windowed fit's windows join (docs/multiview.md, "The skeleton fit in the stream").

Reads poses.jsonl files written by `mocap reconstruct --calibration ... --fit full` with
`--set solve.window=W --set solve.overlap=O` and prints, per file, the per-joint displacement
between consecutive frames (|p(f) - p(f-1)|) and the per-joint acceleration
(|p(f+1) - 2 p(f) + p(f-1)|), in millimetres, at the joins between windows and inside windows:
the median and the largest. A track's windows emit W - O frames each from its first frame, so its
joins lie between its frames k (W - O) - 1 and k (W - O). Only runs of consecutive frames of one
id count (a track that ends starts new windows).

    tools/bench/window_joins.py W O DIR/poses.jsonl [...]
"""
import json
import statistics
import sys


def tracks(path):
    """id -> list of runs, each a list of (frame, {joint: xyz}) of consecutive frames."""
    runs = {}
    for line in open(path):
        line = line.strip()
        if not line:
            continue
        d = json.loads(line)
        for p in d["people"]:
            world = p.get("joints_world") or {}
            if any(None in v for v in world.values()):
                world = None  # not fitted here (its root was not triangulated): counts, unmeasured
            r = runs.setdefault(p["id"], [])
            if r and r[-1][-1][0] == d["frame"] - 1:
                r[-1].append((d["frame"], world))
            else:
                r.append([(d["frame"], world)])
    return runs


def norm(v):
    return sum(x * x for x in v) ** 0.5 * 1000.0


def measure(path, emit):
    disp = {"join": [], "inside": []}
    accel = {"join": [], "inside": []}
    for runs in tracks(path).values():
        for run in runs:
            for k in range(1, len(run)):
                where = "join" if k % emit == 0 else "inside"
                a, b = run[k - 1][1], run[k][1]
                if not a or not b:
                    continue
                disp[where] += [norm([b[j][i] - a[j][i] for i in range(3)]) for j in a]
            for k in range(1, len(run) - 1):
                # the frames on either side of a join: k = join - 1 or join
                where = "join" if (k + 1) % emit == 0 or k % emit == 0 else "inside"
                a, b, c = run[k - 1][1], run[k][1], run[k + 1][1]
                if not a or not b or not c:
                    continue
                accel[where] += [norm([c[j][i] - 2 * b[j][i] + a[j][i] for i in range(3)]) for j in a]
    return disp, accel


def row(name, values):
    if not values:
        return f"{name:>8}: none"
    return f"{name:>8}: median {statistics.median(values):6.1f}  max {max(values):6.1f}  (n {len(values)})"


def main():
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    window, overlap = int(sys.argv[1]), int(sys.argv[2])
    emit = window - overlap
    for path in sys.argv[3:]:
        disp, accel = measure(path, emit)
        print(path)
        print("  displacement between consecutive frames, mm (per joint)")
        print("  " + row("join", disp["join"]) + "\n  " + row("inside", disp["inside"]))
        print("  acceleration |p(f+1) - 2 p(f) + p(f-1)|, mm (per joint)")
        print("  " + row("join", accel["join"]) + "\n  " + row("inside", accel["inside"]))


if __name__ == "__main__":
    main()
