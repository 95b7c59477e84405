#!/usr/bin/env python3
"""How fast moving vehicles turn and brake: yaw rate, lateral and longitudinal acceleration, from labels.

usage: scripts/vehicle-yaw-rates.py KITTI_DIR [SEQUENCE...]   (default: every sequence with poses)
KITTI_DIR holds training/label_02, training/calib and the velodyne poses (poses/SSSS.txt, e.g.
../shared/data/kitti-tracking-mot-train, or training/poses/SSSS.txt as the simulator writes them).
For every labelled Car, Van and Truck and every frame with labels 0.5 s before and after, the
speed is the central difference of its world centres and the yaw rate that of its world heading
(the box's, taken modulo pi: a label turned round is not a turn), both over +-0.5 s; the lateral
acceleration is their product, and the lateral jerk the change of that product from 0.5 s before
to 0.5 s after, over 1 s. Printed for vehicles faster than 2 m/s (slower, the poses' 0.1-0.15 m
jitter is a large part of the motion): RMS and percentiles of |yaw rate|, |lateral acceleration|
and |lateral jerk|, and the RMS of the yaw rate in speed bands. The jerk differences the labels'
headings twice, so their noise is in it, and its 1 s spans smooth a sharp turn-in: a loose bound."""
import collections, math, os, sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from kitti_frames import percentile, sequences_with_poses, world_label_tracks  # noqa: E402

VEHICLES = ("Car", "Van", "Truck")
HALF = 5  # frames: +-0.5 s at 10 Hz
SPAN = 2 * HALF * 0.1  # s


def speed_at(track, f):
    """The speed at frame f: the central difference of the centres HALF frames either side."""
    a, b = track[f - HALF], track[f + HALF]
    return math.hypot(b[0] - a[0], b[1] - a[1]) / SPAN


def yaw_rate_at(track, f):
    """The signed yaw rate at frame f: the central difference of the headings HALF frames either side."""
    return modulo_pi(track[f + HALF][2] - track[f - HALF][2]) / SPAN


def lateral_acceleration_at(track, f):
    return yaw_rate_at(track, f) * speed_at(track, f)


def modulo_pi(a):
    return (a + math.pi / 2) % math.pi - math.pi / 2


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    root = sys.argv[1]
    sequences = sys.argv[2:] or sequences_with_poses(root)
    if not sequences:
        sys.exit(f"{root}: no poses/SSSS.txt or training/poses/SSSS.txt")
    rates, lateral, longitudinal, jerk = [], [], [], []
    by_speed = collections.defaultdict(list)
    for seq in sequences:
        for track in world_label_tracks(root, seq, VEHICLES).values():
            for f in track:
                if f - HALF not in track or f + HALF not in track:
                    continue
                speed = speed_at(track, f)
                if speed < 2.0:
                    continue
                rate = yaw_rate_at(track, f)
                if f - 2 * HALF in track and f + 2 * HALF in track:
                    longitudinal.append(abs(speed_at(track, f + HALF) - speed_at(track, f - HALF)) / SPAN)
                    jerk.append(abs(lateral_acceleration_at(track, f + HALF) - lateral_acceleration_at(track, f - HALF)) / SPAN)
                rates.append(abs(rate))
                lateral.append(abs(rate) * speed)
                by_speed[min(int(speed // 5) * 5, 20)].append(rate)
    if not rates:
        sys.exit("no moving vehicle with labels +-0.5 s around a frame")
    rms = lambda v: math.sqrt(sum(x * x for x in v) / len(v))
    rates.sort()
    lateral.sort()
    print(f"{len(rates)} frames of moving vehicles in {len(sequences)} sequences")
    print(f"yaw rate rad/s: RMS {rms(rates):.3f}, median {percentile(rates, 0.5):.3f}, "
          f"p90 {percentile(rates, 0.9):.3f}, p99 {percentile(rates, 0.99):.3f}")
    print(f"lateral acceleration m/s^2: RMS {rms(lateral):.3f}, median {percentile(lateral, 0.5):.3f}, "
          f"p90 {percentile(lateral, 0.9):.3f}, p99 {percentile(lateral, 0.99):.3f}")
    if longitudinal:
        longitudinal.sort()
        print(f"longitudinal acceleration m/s^2 ({len(longitudinal)} frames): RMS {rms(longitudinal):.3f}, "
              f"median {percentile(longitudinal, 0.5):.3f}, p90 {percentile(longitudinal, 0.9):.3f}, "
              f"p99 {percentile(longitudinal, 0.99):.3f}")
    if jerk:
        jerk.sort()
        print(f"lateral jerk m/s^3 ({len(jerk)} frames): RMS {rms(jerk):.3f}, median {percentile(jerk, 0.5):.3f}, "
              f"p90 {percentile(jerk, 0.9):.3f}, p99 {percentile(jerk, 0.99):.3f}")
    for lo in sorted(by_speed):
        hi = "" if lo == 20 else f"-{lo + 5}"
        print(f"  speed {lo}{hi or '+'} m/s: {len(by_speed[lo])} frames, yaw rate RMS {rms(by_speed[lo]):.3f} rad/s")


if __name__ == "__main__":
    main()
