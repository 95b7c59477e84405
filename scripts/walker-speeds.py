#!/usr/bin/env python3
"""How fast walking pedestrians walk, from labels: the spread the backend's walker speed prior uses.

usage: scripts/walker-speeds.py KITTI_DIR [SEQUENCE...]
(default: every sequence with poses, and 0017 when labelled: pedestrians crossing in front of a
parked car, so its camera frame is a world frame). KITTI_DIR as for scripts/vehicle-yaw-rates.py. For every labelled Pedestrian and every frame with
labels 0.5 s before and after, its velocity is the central difference of its world centres over
+-0.5 s. Printed: the RMS speed and percentiles of the walkers faster than 0.5 m/s (slower, the
poses' 0.1-0.15 m jitter is most of the motion), which is the prior's RMS speed; and the share of
frames below that, the pedestrians standing."""
import collections, math, os, sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from kitti_frames import apply, camera_to_world  # noqa: E402
from importlib import import_module

yaw = import_module("vehicle-yaw-rates")
HALF, SPAN = yaw.HALF, yaw.SPAN
WALKING = 0.5  # m/s


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    root = sys.argv[1]
    sequences = sys.argv[2:] or yaw.sequences_with_poses(root)
    if not sys.argv[2:] and "0017" not in sequences and os.path.exists(
            os.path.join(root, "training", "label_02", "0017.txt")):
        sequences.append("0017")
    if not sequences:
        sys.exit(f"{root}: no poses/SSSS.txt or training/poses/SSSS.txt")
    speeds, standing = [], 0
    for seq in sequences:
        to_world = camera_to_world(root, seq)
        tracks = collections.defaultdict(dict)  # id -> frame -> (x, y)
        path = os.path.join(root, "training", "label_02", seq + ".txt")
        for n, line in enumerate(open(path), 1):
            t = line.split()
            if len(t) < 17:
                sys.exit(f"{path}:{n}: expected 17 fields, got {len(t)}")
            if t[2] == "Pedestrian":
                f = int(t[0])
                p = apply(to_world(f), [float(t[13]), float(t[14]), float(t[15])])
                tracks[int(t[1])][f] = (p[0], p[1])
        for track in tracks.values():
            for f in track:
                if f - HALF in track and f + HALF in track:
                    a, b = track[f - HALF], track[f + HALF]
                    speed = math.hypot(b[0] - a[0], b[1] - a[1]) / SPAN
                    if speed > WALKING:
                        speeds.append(speed)
                    else:
                        standing += 1
    if not speeds:
        sys.exit("no walking pedestrian with labels +-0.5 s around a frame")
    speeds.sort()
    rms = math.sqrt(sum(s * s for s in speeds) / len(speeds))
    print(f"{len(speeds)} frames of pedestrians faster than {WALKING} m/s in {len(sequences)} sequences "
          f"({standing} slower: {100 * standing / (standing + len(speeds)):.0f} %)")
    print(f"speed m/s: RMS {rms:.3f}, median {yaw.percentile(speeds, 0.5):.3f}, p10 {yaw.percentile(speeds, 0.1):.3f}, "
          f"p90 {yaw.percentile(speeds, 0.9):.3f}, p99 {yaw.percentile(speeds, 0.99):.3f}")


if __name__ == "__main__":
    main()
