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

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from kitti_frames import apply, camera_to_world, world_label_tracks  # noqa: E402

SPANS = (1.0, 1.5, 2.0, 3.0)


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    root, sequences = sys.argv[1], sys.argv[2:] or ["0017"]
    errors = {s: [] for s in SPANS}
    for seq in sequences:
        to_world = camera_to_world(root, seq)
        labels = world_label_tracks(root, seq, ("Pedestrian",), to_world)  # id -> frame -> world (x, y, heading)
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
