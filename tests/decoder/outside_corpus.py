#!/usr/bin/env python3
"""The decoder on frames this project did not draw: every view of an outside
corpus (shared/data/outside-corpus, its README says how it was rendered and
scored) decoded by `bsls process` with default options, as a user runs it,
and scored by `bsls evaluate` against the corpus's truth.

As a report:  outside_corpus.py BSLS CORPUS_DIR [--json OUT.json]
As a test:    outside_corpus.py BSLS CORPUS_DIR --check
              (exit 0 when every frame meets the bounds below, 1 otherwise;
              77 when the corpus is not there, CTest's skip code)

Figures per frame: right = truth junctions matched (within 2.5 px, nearest
first) with the right p and q (q up to one even offset per frame); wrong =
matched with a wrong p or q; spurious = decoded junctions that match
nothing; object = the right share of the truth junctions off the base plane
(world z > 1 mm), for the object frames whose base plane shows beside them.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

EXIT_NOT_PROCESSED = 1
SKIP = 77

# What every frame must meet.
MAX_WRONG = 0                 # a wrong label, anywhere, fails the frame
FACE_RECALL = 0.98            # right share on every face frame
# Face frames the decoder does not yet bring to FACE_RECALL, held at the
# floor they reach now so that they cannot slip further (docs/decoding.md,
# "Outside corpus", says why each falls short).
FACE_RECALL_NOW = {"face_hard/left": 0.93, "face_lump/right": 0.965}
# Object frames: the right share of what the decoder can reach from line 0
# without a calibration (the object itself); the base plane beside an object
# is reachable only through geometry.
OBJECT_RECALL = {"plane": 0.98, "ramp": 0.85, "ball": 0.75, "bunny": 0.0}
FACES = ("face", "face_lump", "face_cavity", "face_hard")
BASE_PLANE_MM = 1.0


def run(args, **kw):
    return subprocess.run(args, capture_output=True, text=True, timeout=300, **kw)


def frames(corpus):
    views = os.path.join(corpus, "views")
    for obj in sorted(os.listdir(views)):
        for side in ("left", "right"):
            folder = os.path.join(views, obj, side)
            if os.path.isfile(os.path.join(folder, "image.png")):
                yield obj, side, folder


def object_share(truth, decoded, reach=2.5):
    """Right share of the truth junctions off the base plane (greedy nearest
    first, q up to the frame's even offset found on them)."""
    true_j = [j for j in truth["junctions"] if j["world"][2] > BASE_PLANE_MM]
    if not true_j:
        return None
    pairs = []
    for t, tj in enumerate(true_j):
        for d, dj in enumerate(decoded):
            dist = ((tj["x"] - dj["x"]) ** 2 + (tj["y"] - dj["y"]) ** 2) ** 0.5
            if dist <= reach:
                pairs.append((dist, t, d))
    pairs.sort()
    match, used = {}, set()
    for _, t, d in pairs:
        if t in match or d in used:
            continue
        match[t] = d
        used.add(d)
    offsets = {}
    for t, d in match.items():
        if decoded[d]["p"] == true_j[t]["p"]:
            off = decoded[d]["q"] - true_j[t]["q"]
            offsets[off] = offsets.get(off, 0) + 1
    if not offsets:
        return 0.0
    off = max(offsets, key=offsets.get)
    right = sum(1 for t, d in match.items()
                if decoded[d]["p"] == true_j[t]["p"] and decoded[d]["q"] - true_j[t]["q"] == off)
    return right / len(true_j)


def score_frame(bsls, obj, side, folder, work):
    truth_path = os.path.join(folder, "truth.json")
    with open(truth_path) as f:
        truth = json.load(f)
    out = os.path.join(work, f"{obj}_{side}.json")
    proc = run([bsls, "process", os.path.join(folder, "image.png"), "--side", side,
                "--junctions", out])
    row = {"frame": f"{obj}/{side}", "object": obj, "side": side,
           "expect_failure": truth.get("expect_failure", "")}
    if proc.returncode != 0:
        row.update(refused=True, exit=proc.returncode, reason=proc.stderr.strip()[-200:])
        return row
    ev = run([bsls, "evaluate", out, truth_path, "--json"])
    if ev.returncode != 0:
        raise RuntimeError(f"bsls evaluate {out}: {ev.stderr.strip()}")
    s = json.loads(ev.stdout)
    with open(out) as f:
        decoded = json.load(f)["junctions"]
    row.update(refused=False, truth=s["truth"], right=s["right"],
               recall=s["right_recall"], wrong=s["wrong_p"] + s["wrong_q"],
               wrong_p=s["wrong_p"], spurious=s["unmatched"],
               line_rms=s["line_rms_px"], object=object_share(truth, decoded))
    return row


def failures(row):
    """The bounds `row` misses, as phrases (empty: it meets them)."""
    why = []
    if row["expect_failure"]:
        if not row["refused"] or row["exit"] != EXIT_NOT_PROCESSED:
            why.append("must be refused (" + row["expect_failure"] + ")")
        return why
    if row["refused"]:
        # Refusing an object frame whose labels cannot be proven is honest,
        # where no recall is asked of it yet.
        if OBJECT_RECALL.get(row["object_name"]) == 0.0:
            return []
        return ["refused: " + row["reason"]]
    if row["wrong"] > MAX_WRONG:
        why.append(f"{row['wrong']} wrong labels")
    obj = row["object"]
    face_bound = FACE_RECALL_NOW.get(row["frame"], FACE_RECALL)
    if row["object_name"] in FACES and row["recall"] < face_bound:
        why.append(f"recall {row['recall']:.3f} < {face_bound}")
    bound = OBJECT_RECALL.get(row["object_name"])
    if bound is not None and obj is not None and obj < bound:
        why.append(f"object recall {obj:.3f} < {bound}")
    return why


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("bsls")
    ap.add_argument("corpus")
    ap.add_argument("--check", action="store_true")
    ap.add_argument("--json")
    a = ap.parse_args()
    if not os.path.isdir(os.path.join(a.corpus, "views")):
        print(f"outside corpus not found at {a.corpus}: skipped")
        return SKIP
    rows = []
    with tempfile.TemporaryDirectory() as work:
        for obj, side, folder in frames(a.corpus):
            row = score_frame(a.bsls, obj, side, folder, work)
            row["object_name"] = obj
            rows.append(row)
    bad = 0
    print(f"{'frame':22} {'truth':>5} {'right':>6} {'recall':>7} {'wrong':>5} {'spur':>5} "
          f"{'object':>7} {'lineRMS':>7}  bounds")
    for r in rows:
        why = failures(r)
        bad += bool(why)
        if r["refused"]:
            print(f"{r['frame']:22} refused (exit {r['exit']}): {r['reason'][:60]}"
                  f"  {'; '.join(why) or 'ok'}")
            continue
        obj = "" if r["object"] is None else f"{r['object']:.3f}"
        short = (" (goal 0.98)" if r["frame"] in FACE_RECALL_NOW and not why else "")
        print(f"{r['frame']:22} {r['truth']:5d} {r['right']:6d} {r['recall']:7.3f} {r['wrong']:5d} "
              f"{r['spurious']:5d} {obj:>7} {r['line_rms']:7.3f}  {'; '.join(why) or 'ok'}{short}")
    print(f"frames meeting the bounds: {len(rows) - bad} of {len(rows)}")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(rows, f, indent=1)
    return 1 if a.check and bad else 0


if __name__ == "__main__":
    sys.exit(main())
