#!/usr/bin/env python3
"""The full virtual multi-view sweep in a few tables (docs/multiview.md, "The full sweep").

Reads the JSON files written by `mocap eval multiview --json FILE` (one or several, e.g. one per
camera count) and prints, in Markdown:
  * per noise level, MPJPE (mm) after the full skeleton fit, with the baseline's in brackets, for
    every camera count (rows) and number of people (columns);
  * per method, wrong associations and id switches over all cases;
  * the cases where the issue's targets (fit <= 25 mm and >= 30 % below the baseline; wrong
    associations <= 0.1 % of person-frames; no id switch) are not met, and the cases where a
    method stopped at its CPU budget.

    tools/bench/multiview_sweep_tables.py v2.json v3.json ...
Standard library only.
"""
import collections
import json
import sys


def method_kind(name):
    for prefix, kind in (("(i) ", "baseline"), ("(ii) ", "per frame"), ("(iii) ", "tracking")):
        if name.startswith(prefix):
            return kind
    return "fit live" if "live" in name else "fit full" if "full" in name else name


def load(paths):
    cases = collections.defaultdict(dict)
    for path in paths:
        with open(path) as f:
            for r in json.load(f)["results"]:
                key = (r["views"], r["people"], round(100 * r["noise"]))
                cases[key][method_kind(r["method"])] = r
    return cases


def mpjpe_tables(cases):
    views = sorted({k[0] for k in cases})
    people = sorted({k[1] for k in cases})
    for noise in sorted({k[2] for k in cases}):
        print(f"\nσ {noise} %: MPJPE mm after the full fit (baseline in brackets)\n")
        print("| views | " + " | ".join(f"{p} people" for p in people) + " |")
        print("|---:|" + "---:|" * len(people))
        for v in views:
            cells = []
            for p in people:
                c = cases.get((v, p, noise))
                cells.append(f"{c['fit full']['mpjpe_mm']:.1f} ({c['baseline']['mpjpe_mm']:.1f})"
                             if c else "–")
            print(f"| {v} | " + " | ".join(cells) + " |")


def totals(cases):
    print("\n| method | wrong associations | of person-frames | id switches |")
    print("|---|---:|---:|---:|")
    kinds = ["baseline", "per frame", "tracking", "fit full", "fit live"]
    for kind in kinds:
        rows = [c[kind] for c in cases.values() if kind in c]
        wrong = sum(r["wrong_associations"] for r in rows)
        frames = sum(r["person_frames"] for r in rows)
        switches = sum(r["id_switches"] for r in rows if isinstance(r["id_switches"], int))
        ids = str(switches) if kind not in ("baseline", "per frame") else "– (no ids)"
        print(f"| {kind} | {wrong} ({100 * wrong / max(frames, 1):.3f} %) | {frames} | {ids} |")


def misses(cases):
    print("\nCases off a target (views, people, σ %):\n")
    for key in sorted(cases):
        c = cases[key]
        fit, base, track = c["fit full"]["mpjpe_mm"], c["baseline"]["mpjpe_mm"], c["tracking"]
        why = []
        if fit > 25:
            why.append(f"fit {fit:.1f} mm > 25")
        if fit > 0.7 * base:
            why.append(f"fit {fit:.1f} mm not 30 % below the baseline's {base:.1f}")
        if track["wrong_associations"] > 0.001 * track["person_frames"]:
            why.append(f"{track['wrong_associations']} wrong of {track['person_frames']}")
        if track["id_switches"]:
            why.append(f"{track['id_switches']} id switches")
        short = [f"{kind} {r['frames']} of {c['fit full']['frames']} frames"
                 for kind, r in c.items() if r["frames"] < c["fit full"]["frames"]]
        if short:
            why.append("budget: " + ", ".join(short))
        if why:
            print(f"- {key[0]}, {key[1]}, {key[2]}: " + "; ".join(why))


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    cases = load(sys.argv[1:])
    mpjpe_tables(cases)
    totals(cases)
    misses(cases)


if __name__ == "__main__":
    main()
