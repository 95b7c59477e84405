#!/usr/bin/env python3
"""How fast walking pedestrians walk, from labels: the spread the backend's walker speed prior uses.

usage: scripts/walker-speeds.py KITTI_DIR [SEQUENCE...]
(default: every sequence with poses, and 0017 when labelled: pedestrians crossing in front of a
parked car, so its camera frame is a world frame). KITTI_DIR as for scripts/vehicle-yaw-rates.py. For every labelled Pedestrian and every frame with
labels 0.5 s before and after, its velocity is the central difference of its world centres over
+-0.5 s. Printed: the RMS speed and percentiles of the walkers faster than 0.5 m/s (slower, the
poses' 0.1-0.15 m jitter is most of the motion), which is the prior's RMS speed; and the share of
frames below that, the pedestrians standing."""
import math, os, sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from kitti_frames import percentile, sequences_with_poses, world_label_tracks  # noqa: E402

HALF = 5  # frames: +-0.5 s at 10 Hz
SPAN = 2 * HALF * 0.1  # s
WALKING = 0.5  # m/s


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    root = sys.argv[1]
    sequences = sys.argv[2:] or sequences_with_poses(root)
    if not sys.argv[2:] and "0017" not in sequences and os.path.exists(
            os.path.join(root, "training", "label_02", "0017.txt")):
        sequences.append("0017")
    if not sequences:
        sys.exit(f"{root}: no poses/SSSS.txt or training/poses/SSSS.txt")
    speeds, standing = [], 0
    for seq in sequences:
        for track in world_label_tracks(root, seq, ("Pedestrian",)).values():
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
    print(f"speed m/s: RMS {rms:.3f}, median {percentile(speeds, 0.5):.3f}, p10 {percentile(speeds, 0.1):.3f}, "
          f"p90 {percentile(speeds, 0.9):.3f}, p99 {percentile(speeds, 0.99):.3f}")


if __name__ == "__main__":
    main()
