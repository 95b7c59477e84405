#!/usr/bin/env python3
"""How long a line through a detector's pedestrian boxes should be, measured on real walkers.

usage: scripts/walker-line-span.py KITTI_DIR [SEQUENCE...]   (default: 0017)
KITTI_DIR holds training/label_02, training/calib, detections/pointrcnn_Pedestrian (AB3DMOT's
comma-separated rows) and optionally poses/SSSS.txt (velodyne poses, KITTI 3x4 rows), e.g.
../shared/data/kitti-tracking-mot-train. A sequence without poses is taken as seen from a parked
sensor (identity poses; 0017, pedestrians crossing in front of a standing car, is one); it says so.
Each labelled pedestrian's truth velocity is the central difference of its labelled centres over
+-0.5 s (as dlslot-eval makes KITTI's). Its boxes are the detections (logit >= 0) nearest its
label within 1 m. For each frame where it moves faster than 0.5 m/s and has a box, the least-
squares line through its boxes of the last S seconds (at least half of them present) gives a
velocity; the RMS and median of its error are printed per span S."""
import collections, math, os, sys

SPANS = (1.0, 1.5, 2.0, 3.0)


def mat(v):
    return [v[0:4], v[4:8], v[8:12], [0, 0, 0, 1]]


def mul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(4)) for j in range(4)] for i in range(4)]


def inverse(t):
    r = [[t[j][i] for j in range(3)] for i in range(3)]
    p = [-sum(r[i][k] * t[k][3] for k in range(3)) for i in range(3)]
    return [r[0] + [p[0]], r[1] + [p[1]], r[2] + [p[2]], [0, 0, 0, 1]]


def apply(t, p):
    return [sum(t[i][k] * p[k] for k in range(3)) + t[i][3] for i in range(2)]


def camera_to_world(root, seq):
    calib = {}
    for line in open(os.path.join(root, "training", "calib", seq + ".txt")):
        t = line.replace(":", " ").split()
        if t:
            calib[t[0]] = [float(x) for x in t[1:]]
    r = calib.get("R_rect", calib.get("R0_rect"))
    rect = [r[0:3] + [0], r[3:6] + [0], r[6:9] + [0], [0, 0, 0, 1]]
    cam_to_velo = inverse(mul(rect, mat(calib.get("Tr_velo_cam", calib.get("Tr_velo_to_cam")))))
    path = os.path.join(root, "poses", seq + ".txt")
    if not os.path.exists(path):
        print(f"{seq}: no poses, taken as seen from a parked sensor")
        return lambda f: cam_to_velo
    poses = [mat([float(x) for x in line.split()]) for line in open(path)]
    return lambda f: mul(poses[f], cam_to_velo)


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    root, sequences = sys.argv[1], sys.argv[2:] or ["0017"]
    errors = {s: [] for s in SPANS}
    for seq in sequences:
        to_world = camera_to_world(root, seq)
        labels = collections.defaultdict(dict)  # id -> frame -> world (x, y)
        for line in open(os.path.join(root, "training", "label_02", seq + ".txt")):
            t = line.split()
            if t[2] == "Pedestrian":
                f = int(t[0])
                labels[int(t[1])][f] = apply(to_world(f), [float(t[13]), float(t[14]), float(t[15])])
        boxes = collections.defaultdict(list)  # frame -> world (x, y)
        for n, line in enumerate(open(os.path.join(root, "detections", "pointrcnn_Pedestrian", seq + ".txt")), 1):
            t = line.strip().split(",")
            if len(t) < 14:
                sys.exit(f"{seq}.txt:{n}: expected 15 comma-separated fields, got {len(t)}")
            if float(t[6]) >= 0:
                f = int(t[0])
                boxes[f].append(apply(to_world(f), [float(t[10]), float(t[11]), float(t[12])]))
        for track in labels.values():
            seen = {}
            for f, p in track.items():
                near = [b for b in boxes[f] if math.hypot(b[0] - p[0], b[1] - p[1]) < 1.0]
                if near:
                    seen[f] = min(near, key=lambda b: math.hypot(b[0] - p[0], b[1] - p[1]))
            for f in track:
                if f - 5 not in track or f + 5 not in track or f not in seen:
                    continue
                truth = [track[f + 5][i] - track[f - 5][i] for i in range(2)]  # over 1.0 s: m/s
                if math.hypot(*truth) < 0.5:
                    continue
                for span in SPANS:
                    n = int(round(span * 10))
                    pts = [(0.1 * k, seen[k]) for k in range(f - n + 1, f + 1) if k in seen]
                    if len(pts) < max(3, n // 2):
                        continue
                    tm = sum(p[0] for p in pts) / len(pts)
                    ss = sum((p[0] - tm) ** 2 for p in pts)
                    v = [sum((p[0] - tm) * p[1][i] for p in pts) / ss for i in range(2)]
                    errors[span].append(math.hypot(v[0] - truth[0], v[1] - truth[1]))
    for span in SPANS:
        e = sorted(errors[span])
        if e:
            rms = math.sqrt(sum(x * x for x in e) / len(e))
            print(f"line over {span:.1f} s: {len(e)} pairs, RMS {rms:.3f} m/s, median {e[len(e) // 2]:.3f}")


if __name__ == "__main__":
    main()
