#!/usr/bin/env python3
"""Measures the detector's score calibration table (config detector.score_calibration).

For one class group, reads detection files with their labels (KITTI tracking format, camera
frame; PointRCNN's comma-separated files too), matches them as dlslot-detector --eval does
(bird's-eye centre distance <= 2 m, closest pairs first, within 40 m), and computes the local
precision (share of detections that match a label) per score bin, made monotone by pooling
adjacent bins (isotonic regression). The reference files (PointRCNN) give precision -> score;
the detector's (run with an identity calibration, so its scores are raw) give raw score ->
precision; the table maps each detector bin's mean raw score to the PointRCNN score of the same
precision.

  scripts/score-calibration.py --group car --reference cam:LABELS:DETS ... --detector [cam:]LABELS:DETS ...

A pair prefixed "cam:" counts only detections inside the camera image and leaves out unmatched
ones on a DontCare region (real KITTI labels cover only the camera's view).
Standard library only.
"""
import argparse, collections, math

GROUPS = {"car": {"Car", "Van", "Truck"}, "pedestrian": {"Pedestrian", "Person_sitting"}, "cyclist": {"Cyclist"}}
COMMA_TYPES = {"1": "Pedestrian", "2": "Car", "3": "Cyclist"}


def read_rows(path):
    """frame -> rows (type, bbox, x, z, score) of a label or detection file."""
    rows = collections.defaultdict(list)
    with open(path) as f:
        for line in f:
            if "," in line:
                v = line.strip().split(",")
                if len(v) < 14: continue
                rows[int(v[0])].append((COMMA_TYPES.get(v[1], v[1]), tuple(map(float, v[2:6])), float(v[10]), float(v[12]), float(v[6])))
            else:
                v = line.split()
                if len(v) < 17: continue
                score = float(v[17]) if len(v) > 17 else 0.0
                rows[int(v[0])].append((v[2], tuple(map(float, v[6:10])), float(v[13]), float(v[15]), score))
    return rows


def overlap(a, b):
    w, h = min(a[2], b[2]) - max(a[0], b[0]), min(a[3], b[3]) - max(a[1], b[1])
    return w * h if w > 0 and h > 0 else 0.0


def scored_detections(pair, group, max_distance=2.0, max_range=40.0):
    """(score, matched) of every counted detection of the group in one labels:detections pair."""
    camera = pair.startswith("cam:")
    labels_path, dets_path = (pair[4:] if camera else pair).split(":")
    labels, dets = read_rows(labels_path), read_rows(dets_path)
    out = []
    for frame in sorted(set(labels) | set(dets)):
        dontcare = [r[1] for r in labels.get(frame, []) if r[0] == "DontCare"]
        L = [r for r in labels.get(frame, []) if r[0] in group and math.hypot(r[2], r[3]) <= max_range]
        D = [r for r in dets.get(frame, []) if r[0] in group and math.hypot(r[2], r[3]) <= max_range]
        if camera: D = [d for d in D if d[1][0] >= 0]
        pairs = sorted((math.hypot(l[2] - d[2], l[3] - d[3]), i, j) for i, l in enumerate(L) for j, d in enumerate(D))
        used_l, used_d = set(), set()
        for dist, i, j in pairs:
            if dist > max_distance: break
            if i in used_l or j in used_d: continue
            used_l.add(i); used_d.add(j)
        for j, d in enumerate(D):
            if j not in used_d and camera:
                area = (d[1][2] - d[1][0]) * (d[1][3] - d[1][1])
                if area > 0 and any(overlap(d[1], c) >= 0.5 * area for c in dontcare): continue
            out.append((d[4], j in used_d))
    return out


def binned(scored, edges):
    """[(mean score, precision, count)] per non-empty bin, made non-decreasing (pool adjacent violators)."""
    bins = []
    for k, lo in enumerate(edges):
        hi = edges[k + 1] if k + 1 < len(edges) else math.inf
        b = [(s, m) for s, m in scored if lo <= s < hi]
        if b: bins.append([sum(s for s, _ in b) / len(b), sum(m for _, m in b) / len(b), len(b)])
    pooled = []
    for b in bins:
        pooled.append(b)
        while len(pooled) > 1 and pooled[-2][1] > pooled[-1][1]:
            b2, b1 = pooled.pop(), pooled.pop()
            n = b1[2] + b2[2]
            pooled.append([(b1[0] * b1[2] + b2[0] * b2[2]) / n, (b1[1] * b1[2] + b2[1] * b2[2]) / n, n])
    return pooled


def score_for(precision, curve):
    """The reference score whose (monotone) local precision is `precision` (clamped to the curve)."""
    if precision <= curve[0][1]: return curve[0][0]
    for (s0, p0, _), (s1, p1, _) in zip(curve, curve[1:]):
        if p0 <= precision <= p1:
            return s0 if p1 == p0 else s0 + (precision - p0) / (p1 - p0) * (s1 - s0)
    return curve[-1][0]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--group", choices=sorted(GROUPS), required=True)
    ap.add_argument("--reference-group", choices=sorted(GROUPS), help="the reference's group (default: --group)")
    ap.add_argument("--reference", nargs="+", required=True, help="[cam:]LABELS:DETECTIONS of the reference detector")
    ap.add_argument("--detector", nargs="+", required=True, help="[cam:]LABELS:DETECTIONS with raw scores")
    ap.add_argument("--reference-bins", default="-1,0,0.5,1,1.5,2,2.5,3,3.5,4,4.5,5,5.5,6,7,8,10")
    ap.add_argument("--detector-bins", default="-5,0,0.5,1,1.5,2,3")
    a = ap.parse_args()
    group = GROUPS[a.group]
    ref = [x for p in a.reference for x in scored_detections(p, GROUPS[a.reference_group or a.group])]
    det = [x for p in a.detector for x in scored_detections(p, group)]
    curve = binned(ref, [float(x) for x in a.reference_bins.split(",")])
    print(f"reference: {len(ref)} detections; local precision by score (pooled to be monotone):")
    for s, p, n in curve: print(f"  score {s:6.2f}  precision {p:.3f}  ({n})")
    table = binned(det, [float(x) for x in a.detector_bins.split(",")])
    print(f"detector: {len(det)} detections, precision {sum(m for _, m in det) / max(1, len(det)):.3f}; by raw score:")
    raw, cal = [], []
    for s, p, n in table:
        c = score_for(p, curve)
        print(f"  raw {s:6.2f}  precision {p:.3f}  ({n})  -> reference score {c:.2f}")
        raw.append(round(s, 2)); cal.append(round(c, 2))
    print(f"{a.group}: {{raw: {raw}, calibrated: {cal}}}")


if __name__ == "__main__":
    main()
