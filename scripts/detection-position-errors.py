#!/usr/bin/env python3
"""How far a detector's vehicle boxes are from the labelled centres, by range, and how much of that
changes from one frame to the next (the part a velocity sees).

usage: scripts/detection-position-errors.py KITTI_DIR [MIN_SCORE]
KITTI_DIR holds training/label_02/SSSS.txt and detections/<name>/SSSS.txt, either AB3DMOT's comma-
separated rows (frame, type, 2-D box, score, h w l, x y z, rotation_y, alpha: ../shared/data/
kitti-tracking-mot-train) or KITTI tracking rows with a trailing score (the simulator's R/data).
A detection with a score of at least MIN_SCORE (default 2; the simulator writes none below) is
matched to the nearest labelled car, van or truck of the same frame within 2 m (camera x, z).

Per 10 m of range: matches, the RMS error along and across the label's heading, and the RMS change
of the along error between consecutive frames of the same label over sqrt 2. That last one equals
the along RMS when the errors are white; when it is smaller, part of the error is a bias that
stays from frame to frame (a partly seen car's box), which a velocity does not see. The backend's
box sigma at the bin's middle (observation_sigma x, y grown by observation_sigma_growth_per_m, read
from config/dlslot.yaml) is printed beside them. Then, for labels within 40 m, the correlation of
each error with the same label's 1, 2, 5, 10, 20 and 40 frames later."""
import collections, math, os, re, sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from kitti_frames import labels_and_detectors  # noqa: E402

VEHICLES = ("Car", "Van", "Truck")


def model_sigmas():
    text = open(os.path.join(os.path.dirname(__file__), "..", "config", "dlslot.yaml")).read()
    sigma = re.search(r"^  observation_sigma: \[([^\]]*)\]", text, re.M)
    growth = re.search(r"^  observation_sigma_growth_per_m: ([0-9.]+)", text, re.M)
    if not sigma or not growth:
        sys.exit("config/dlslot.yaml: expected backend.observation_sigma and observation_sigma_growth_per_m")
    s = [float(v) for v in sigma.group(1).split(",")]
    return s[0], s[1], float(growth.group(1))


def read_detections(path, min_score):
    """frame -> [(x, z)] of vehicle boxes, from either format."""
    out = collections.defaultdict(list)
    for n, line in enumerate(open(path), 1):
        if "," in line:
            t = line.strip().split(",")
            if len(t) < 14:
                sys.exit(f"{path}:{n}: expected 15 comma-separated fields, got {len(t)}")
            # AB3DMOT's detection files name the class by number: 2 is a car.
            if t[1].strip() != "2" or float(t[6]) < min_score:
                continue
            out[int(t[0])].append((float(t[10]), float(t[12])))
        else:
            t = line.split()
            if len(t) < 17:
                sys.exit(f"{path}:{n}: expected 17 or 18 space-separated KITTI tracking fields, got {len(t)}")
            if t[2] not in VEHICLES or (len(t) > 17 and float(t[17]) < min_score):
                continue
            out[int(t[0])].append((float(t[13]), float(t[15])))
    return out


def main():
    root, min_score, label_files, detectors = labels_and_detectors(sys.argv, __doc__)
    sx, sy, growth = model_sigmas()
    errors = {}  # (detector, sequence, frame, label id) -> (along, across, range)
    for path in label_files:
        sequence = os.path.basename(path)
        labels = collections.defaultdict(list)
        for line in open(path):
            t = line.split()
            if t[2] in VEHICLES:
                labels[int(t[0])].append((int(t[1]), float(t[13]), float(t[15]), float(t[16])))
        for detector in detectors:
            det_path = os.path.join(root, "detections", detector, sequence)
            if not os.path.exists(det_path):
                continue
            detections = read_detections(det_path, min_score)
            for frame, objects in labels.items():
                for label_id, x, z, ry in objects:
                    near = [(math.hypot(dx - x, dz - z), dx, dz) for dx, dz in detections[frame]]
                    near = [m for m in near if m[0] < 2.0]
                    if not near:
                        continue
                    _, dx, dz = min(near)
                    # A label's forward direction in the camera's x-z plane.
                    ux, uz = math.cos(ry), -math.sin(ry)
                    ex, ez = dx - x, dz - z
                    key = (detector, sequence, frame, label_id)
                    errors[key] = (ex * ux + ez * uz, -ex * uz + ez * ux, math.hypot(x, z))
    bins = collections.defaultdict(lambda: [0, 0.0, 0.0, 0, 0.0])
    for (det, seq, frame, label_id), (along, across, rng) in errors.items():
        b = bins[(det, min(int(rng // 10) * 10, 80))]
        b[0] += 1
        b[1] += along * along
        b[2] += across * across
        prev = errors.get((det, seq, frame - 1, label_id))
        if prev:
            b[3] += 1
            b[4] += (along - prev[0]) ** 2
    print(f"{'detector':18s} {'range m':>8s} {'matches':>8s} {'along':>7s} {'across':>7s} {'change/sqrt2':>13s}"
          f" {'model x':>8s} {'model y':>8s}")
    for (det, lo), (n, a2, c2, nd, d2) in sorted(bins.items()):
        if n < 20:
            continue
        g = 1.0 + growth * (lo + 5)
        change = f"{math.sqrt(d2 / nd / 2):13.3f}" if nd else f"{'':>13s}"
        print(f"{det:18s} {f'{lo}-{lo + 10}':>8s} {n:8d} {math.sqrt(a2 / n):7.3f} {math.sqrt(c2 / n):7.3f} {change}"
              f" {sx * g:8.3f} {sy * g:8.3f}")

    lags = (1, 2, 5, 10, 20, 40)
    print(f"\n{'detector':18s} {'within 40 m':12s} " + " ".join(f"{f'{k} fr':>6s}" for k in lags))
    for det in sorted({key[0] for key in errors}):
        for axis, name in ((0, "along"), (1, "across")):
            row = []
            for k in lags:
                s01 = s00 = s11 = 0.0
                for (d, seq, frame, label_id), e in errors.items():
                    later = errors.get((d, seq, frame + k, label_id))
                    if d != det or e[2] >= 40 or not later:
                        continue
                    s01 += e[axis] * later[axis]
                    s00 += e[axis] ** 2
                    s11 += later[axis] ** 2
                row.append(f"{s01 / math.sqrt(s00 * s11):6.2f}" if s00 > 0 and s11 > 0 else f"{'':>6s}")
            print(f"{det:18s} {name:12s} " + " ".join(row))


if __name__ == "__main__":
    main()
