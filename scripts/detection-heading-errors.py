#!/usr/bin/env python3
"""How well a detector's boxes know an object's heading, per detector file and labelled class.

usage: scripts/detection-heading-errors.py KITTI_DIR [MIN_SCORE]
KITTI_DIR holds training/label_02/SSSS.txt and detections/<name>/SSSS.txt (AB3DMOT's comma-
separated rows: frame, type, 2-D box, score, h w l, x y z, rotation_y, alpha), e.g.
../shared/data/kitti-tracking-mot-train. A detection with a score (logit) of at least MIN_SCORE
(default 2) is matched to the nearest label of the same frame whose centre (camera x, z) lies
within 1 m. The heading error is taken modulo pi (a box and the box turned round are the same
box; how often a detector turns one is its own column). Prints, per (detector, label class):
matches, median, 90th percentile and RMS of the error in rad, and the share turned round."""
import collections, math, os, sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from kitti_frames import labels_and_detectors  # noqa: E402


def wrap(a):
    return (a + math.pi) % (2 * math.pi) - math.pi


def main():
    root, min_score, label_files, detectors = labels_and_detectors(sys.argv, __doc__)
    errors = collections.defaultdict(list)  # (detector, class) -> [(error mod pi, turned round)]
    for path in label_files:
        sequence = os.path.basename(path)
        labels = collections.defaultdict(list)  # frame -> [(class, x, z, rotation_y)]
        for line in open(path):
            t = line.split()
            if t[2] != "DontCare":
                labels[int(t[0])].append((t[2], float(t[13]), float(t[15]), float(t[16])))
        for detector in detectors:
            det_path = os.path.join(root, "detections", detector, sequence)
            if not os.path.exists(det_path):
                continue
            for n, line in enumerate(open(det_path), 1):
                t = line.strip().split(",")
                if len(t) < 14:
                    sys.exit(f"{det_path}:{n}: expected 15 comma-separated fields, got {len(t)}")
                frame, score = int(t[0]), float(t[6])
                x, z, ry = float(t[10]), float(t[12]), float(t[13])
                if score < min_score:
                    continue
                near = [(math.hypot(l[1] - x, l[2] - z), l) for l in labels[frame]]
                near = [m for m in near if m[0] < 1.0]
                if not near:
                    continue
                label = min(near)[1]
                e = wrap(ry - label[3])
                errors[(detector, label[0])].append((min(abs(e), abs(wrap(e + math.pi))), abs(e) > math.pi / 2))
    print(f"{'detector':24s} {'on label class':16s} {'matches':>8s} {'median':>7s} {'p90':>7s} {'RMS':>7s} {'turned':>7s}")
    for (detector, cls), v in sorted(errors.items()):
        if len(v) < 20:
            continue
        e = sorted(x[0] for x in v)
        rms = math.sqrt(sum(x * x for x in e) / len(e))
        turned = sum(x[1] for x in v) / len(v)
        print(f"{detector:24s} {cls:16s} {len(v):8d} {e[len(e) // 2]:7.3f} {e[int(0.9 * len(e))]:7.3f} {rms:7.3f} {turned:7.3f}")


if __name__ == "__main__":
    main()
