#!/usr/bin/env python3
"""The decoder on frames this project did not draw: every view of an outside
corpus (shared/data/outside-corpus, its README says how it was rendered and
scored) decoded by `bsls process` with default options, as a user runs it,
and scored by `bsls evaluate` against the corpus's truth.

As a report:  outside_corpus.py BSLS CORPUS_DIR [--json OUT.json]
As a test:    outside_corpus.py BSLS CORPUS_DIR --check
              (exit 0 when every frame meets the bounds below, 1 otherwise;
              77 when the corpus is not there, CTest's skip code)
Calibrated:   outside_corpus.py BSLS CORPUS_DIR --calibrated [--check]
              each side calibrated by `bsls calibrate` from the corpus's own
              session of that side, every frame processed with that
              calibration into labels with absolute rows and a surface
              (`bsls process --calibration --surface`, its defaults).

Figures per frame: right = truth junctions matched (within 2.5 px, nearest
first) with the right p and q (q up to one even offset per frame); wrong =
matched with a wrong p or q; spurious = decoded junctions that match
nothing; object = the right share of the truth junctions off the base plane
(world z > 1 mm), for the object frames whose base plane shows beside them.

Calibrated, q must equal the truth's slide row (no free offset), and the
surface is scored against the truth's line samples (world mm, one per image
row of every visible line): rms / p95 = distance of each mesh vertex to the
plane fitted to its 8 nearest truth samples; coverage = share of the truth
samples with a mesh vertex within 1 mm (the mesh's vertices lie on the lines,
so this is the share of the lit visible stripes the surface covers).
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

EXIT_NOT_PROCESSED = 1
SKIP = 77

# What every frame must meet.
MAX_WRONG = 0                 # a wrong label, anywhere, fails the frame
FACE_RECALL = 0.98            # right share on every face frame
# Face frames the decoder does not yet bring to FACE_RECALL, held at the
# floor they reach now so that they cannot slip further (docs/decoding.md,
# "Outside corpus", says why each falls short).
FACE_RECALL_NOW = {"face_hard/left": 0.95, "face_lump/right": 0.97}
# Object frames: the right share of what the decoder can reach from line 0
# without a calibration (the object itself); the base plane beside an object
# is reachable only through geometry.
OBJECT_RECALL = {"plane": 0.98, "ramp": 0.85, "ball": 0.75, "bunny": 0.0}
# Calibrated (each side by its own session): the goals, and the
# floors frames are held at until the decoder reaches them.
CALIBRATED_RECALL = 0.95      # base-plane junctions included
SURFACE_RMS_MM = 0.25
SURFACE_COVERAGE = 0.9
# With a calibration, the parts not joined to line 0 (the objects' base
# planes) are placed by the geometry (docs/decoding.md, "Islands placed by the
# geometry"). Frames still short of the goals are held at the floor they
# reach now: single bricks cut off on their own (the ramp's strips of base
# plane at the frame's top and bottom, parts of the bunny's and the ball's
# plane) are too small for the geometry to tell their candidates apart.
# bunny/right is decoded since the geometry confirms another chain of line-0
# candidates where the one nearest the centre row fails.
CALIBRATED_RECALL_NOW = {"ball/left": 0.90, "ball/right": 0.93, "bunny/left": 0.86,
                         "bunny/right": 0.87, "face_hard/left": 0.95, "ramp/left": 0.89,
                         "ramp/right": 0.88}
CALIBRATED_COVERAGE_NOW = {"ball/left": 0.87, "ball/right": 0.93, "bunny/left": 0.82,
                           "bunny/right": 0.84, "ramp/left": 0.88}
EXTRA_PROCESS_ARGS = []      # --chain, when named
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
    match = match_junctions(true_j, decoded, reach)
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


def match_junctions(true_j, decoded, reach=2.5):
    """Greedy nearest-first matching within `reach` px: {truth index: decoded index}."""
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
    return match


def read_ascii_ply_vertices(path):
    """The x, y, z of every vertex of an ASCII PLY written by `bsls process --ascii`."""
    with open(path) as f:
        element, count, props = None, 0, []
        for line in f:
            words = line.split()
            if words[:1] == ["element"]:
                element = words[1]
                if element == "vertex":
                    count = int(words[2])
            elif words[:1] == ["property"] and element == "vertex":
                props.append(words[-1])
            elif words == ["end_header"]:
                break
        rows = [next(f).split() for _ in range(count)]
    cols = [props.index(c) for c in ("x", "y", "z")]
    return np.array([[float(r[c]) for c in cols] for r in rows]).reshape(-1, 3)


def nearest(points, queries, k):
    """Indices and distances of the k nearest of `points` to each query (brute
    force in blocks: a few thousand points each)."""
    idx = np.empty((len(queries), k), dtype=np.int64)
    dist = np.empty((len(queries), k))
    for a in range(0, len(queries), 512):
        q = queries[a:a + 512]
        d2 = ((q[:, None, :] - points[None, :, :]) ** 2).sum(axis=2)
        part = np.argpartition(d2, min(k, points.shape[0] - 1), axis=1)[:, :k]
        idx[a:a + 512] = part
        dist[a:a + 512] = np.sqrt(np.take_along_axis(d2, part, axis=1))
    return idx, dist


def surface_scores(vertices, truth):
    """rms and p95 (mm) of the vertices' distances to the true surface, and the
    share of the truth's line samples covered by the mesh (module docstring)."""
    samples = np.array([s[2:5] for line in truth["lines"] for s in line["samples"]])
    if len(vertices) == 0 or len(samples) < 8:
        return None
    idx, _ = nearest(samples, vertices, 8)
    neighbours = samples[idx]                        # (n, 8, 3)
    centre = neighbours.mean(axis=1)
    cov = np.einsum("nki,nkj->nij", neighbours - centre[:, None], neighbours - centre[:, None])
    normal = np.linalg.eigh(cov)[1][:, :, 0]         # smallest eigenvalue's vector
    d = np.abs(((vertices - centre) * normal).sum(axis=1))
    _, covered = nearest(vertices, samples, 1)
    return {"rms_mm": float(np.sqrt((d ** 2).mean())), "p95_mm": float(np.percentile(d, 95)),
            "coverage": float((covered[:, 0] <= 1.0).mean()), "vertices": int(len(vertices))}


def calibrate_sides(bsls, corpus, work):
    """{side: calibration path or None, side + "_why": reason} from the corpus's sessions."""
    out = {}
    for side in ("left", "right"):
        manifest = os.path.join(corpus, "calibration", side, "manifest.yaml")
        path = os.path.join(work, f"calibration_{side}.yaml")
        proc = run([bsls, "calibrate", manifest, "-o", path])
        out[side] = path if proc.returncode == 0 else None
        out[side + "_why"] = proc.stderr.strip()[-200:]
    return out


def frame_row(obj, side, folder):
    """The frame's truth and the start of its row: name, object, side and
    whether it must be refused."""
    with open(os.path.join(folder, "truth.json")) as f:
        truth = json.load(f)
    row = {"frame": f"{obj}/{side}", "object": obj, "side": side,
           "expect_failure": truth.get("expect_failure", "")}
    return truth, row


def score_frame_calibrated(bsls, obj, side, folder, work, calibration):
    """One frame processed with its side's calibration: labels with absolute
    rows and the surface, scored against the truth."""
    truth, row = frame_row(obj, side, folder)
    if not calibration[side]:
        row.update(refused=True, exit=-1, reason="side not calibrated: " + calibration[side + "_why"])
        return row
    out = os.path.join(work, f"{obj}_{side}_cal.json")
    ply = os.path.join(work, f"{obj}_{side}_cal.ply")
    proc = run([bsls, "process", os.path.join(folder, "image.png"), "--side", side,
                "--calibration", calibration[side], "--surface", ply, "--ascii",
                "--junctions", out] + EXTRA_PROCESS_ARGS)
    if proc.returncode != 0:
        row.update(refused=True, exit=proc.returncode, reason=proc.stderr.strip()[-200:])
        return row
    with open(out) as f:
        decoded = json.load(f)
    true_j = truth["junctions"]
    match = match_junctions(true_j, decoded["junctions"])
    right = sum(1 for t, d in match.items()
                if decoded["junctions"][d]["p"] == true_j[t]["p"]
                and decoded["junctions"][d]["q"] == true_j[t]["q"])
    wrong_p = sum(1 for t, d in match.items() if decoded["junctions"][d]["p"] != true_j[t]["p"])
    row.update(refused=False, truth=len(true_j), right=right, recall=right / max(1, len(true_j)),
               wrong=len(match) - right, wrong_p=wrong_p,
               spurious=len(decoded["junctions"]) - len(match),
               object=object_share(truth, decoded["junctions"]),
               surface=surface_scores(read_ascii_ply_vertices(ply), truth))
    return row


def score_frame(bsls, obj, side, folder, work):
    truth, row = frame_row(obj, side, folder)
    truth_path = os.path.join(folder, "truth.json")
    out = os.path.join(work, f"{obj}_{side}.json")
    proc = run([bsls, "process", os.path.join(folder, "image.png"), "--side", side,
                "--junctions", out])
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


def print_table(columns, rows, failures_of, cells, note=lambda r, why: ""):
    """Prints one line per frame: the label figures, `cells(r)` under the
    `columns` heading, and the bounds it misses; returns how many miss any."""
    print(f"{'frame':22} {'truth':>5} {'right':>6} {'recall':>7} {'wrong':>5} {'spur':>5} "
          f"{columns}  bounds")
    bad = 0
    for r in rows:
        why = failures_of(r)
        bad += bool(why)
        verdict = ("; ".join(why) or "ok") + note(r, why)
        if r["refused"]:
            print(f"{r['frame']:22} refused (exit {r['exit']}): {r['reason'][:60]}  {verdict}")
            continue
        print(f"{r['frame']:22} {r['truth']:5d} {r['right']:6d} {r['recall']:7.3f} {r['wrong']:5d} "
              f"{r['spurious']:5d} {cells(r)}  {verdict}")
    return bad


def calibrated_failures(row):
    """The calibrated bounds `row` misses, as phrases (empty: it meets them)."""
    if row["expect_failure"]:
        return [] if row["refused"] else ["must be refused (" + row["expect_failure"] + ")"]
    if row["refused"]:
        # As without a calibration: refusing an object frame of which no
        # recall is asked yet is honest.
        if OBJECT_RECALL.get(row["object_name"]) == 0.0:
            return []
        return ["refused: " + row["reason"]]
    why = []
    if row["wrong"] > MAX_WRONG:
        why.append(f"{row['wrong']} wrong labels")
    floor = CALIBRATED_RECALL_NOW.get(row["frame"], CALIBRATED_RECALL)
    if row["recall"] < floor:
        why.append(f"recall {row['recall']:.3f} < {floor}")
    surf = row["surface"]
    if surf is None:
        why.append("no surface")
    else:
        if surf["rms_mm"] > SURFACE_RMS_MM:
            why.append(f"surface RMS {surf['rms_mm']:.3f} mm > {SURFACE_RMS_MM}")
        cover = CALIBRATED_COVERAGE_NOW.get(row["frame"], SURFACE_COVERAGE)
        if surf["coverage"] < cover:
            why.append(f"coverage {surf['coverage']:.3f} < {cover}")
    return why


def report_calibrated(bsls, corpus, work):
    """Rows of the calibrated run, printed as a table; the count of frames
    missing their bounds."""
    calibration = calibrate_sides(bsls, corpus, work)
    for side in ("left", "right"):
        if not calibration[side]:
            print(f"calibration of the {side} side refused: {calibration[side + '_why']}")
    rows = []
    for obj, side, folder in frames(corpus):
        r = score_frame_calibrated(bsls, obj, side, folder, work, calibration)
        r["object_name"] = obj
        rows.append(r)

    def cells(r):
        surf = r["surface"] or {"rms_mm": float("nan"), "p95_mm": float("nan"), "coverage": 0.0}
        return f"{surf['rms_mm']:7.3f} {surf['p95_mm']:7.3f} {surf['coverage']:6.3f}"

    bad = print_table(f"{'rms mm':>7} {'p95 mm':>7} {'cover':>6}", rows, calibrated_failures, cells)
    print(f"frames meeting the calibrated bounds: {len(rows) - bad} of {len(rows)}")
    return rows, bad


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("bsls")
    ap.add_argument("corpus")
    ap.add_argument("--check", action="store_true")
    ap.add_argument("--json")
    ap.add_argument("--calibrated", action="store_true")
    ap.add_argument("--chain", choices=("tracks", "skeleton"),
                    help="calibrated: the chain to name (default: the command's own choice)")
    a = ap.parse_args()
    if a.chain:
        EXTRA_PROCESS_ARGS.extend(["--chain", a.chain])
    if not os.path.isdir(os.path.join(a.corpus, "views")):
        print(f"outside corpus not found at {a.corpus}: skipped")
        return SKIP
    if a.calibrated:
        with tempfile.TemporaryDirectory() as work:
            rows, bad = report_calibrated(a.bsls, a.corpus, work)
        if a.json:
            with open(a.json, "w") as f:
                json.dump(rows, f, indent=1)
        return 1 if a.check and bad else 0
    rows = []
    with tempfile.TemporaryDirectory() as work:
        for obj, side, folder in frames(a.corpus):
            row = score_frame(a.bsls, obj, side, folder, work)
            row["object_name"] = obj
            rows.append(row)
    def cells(r):
        obj = "" if r["object"] is None else f"{r['object']:.3f}"
        return f"{obj:>7} {r['line_rms']:7.3f}"

    def note(r, why):
        return " (goal 0.98)" if r["frame"] in FACE_RECALL_NOW and not why else ""

    bad = print_table(f"{'object':>7} {'lineRMS':>7}", rows, failures, cells, note)
    print(f"frames meeting the bounds: {len(rows) - bad} of {len(rows)}")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(rows, f, indent=1)
    return 1 if a.check and bad else 0


if __name__ == "__main__":
    sys.exit(main())
