#!/usr/bin/env python3
"""How much a vehicle's body pitches and rolls from one scan to the next, by speed.

usage: scripts/body-ride.py POSES.txt [POSES.txt ...]
Each file: KITTI 3x4 pose rows of the lidar (velodyne) frame, one per scan, 10 Hz (e.g.
../shared/data/kitti-tracking-mot-train/poses/0000.txt, or a simulated sequence's
training/poses/0000.txt). For each pair of consecutive scans the relative rotation's roll and
pitch (the yaw is the vehicle turning, not its ride) give a change sqrt(roll^2 + pitch^2); it is
binned by the horizontal speed between the scans and printed as rms per file and per speed bin
over all files. The simulator's ride (tools/sim/traffic.hpp, BodyRide) is set from this on
KITTI's GPS/INS poses."""
import math, sys

BINS = [(0.0, 0.1), (0.1, 2.0), (2.0, 5.0), (5.0, 8.0), (8.0, 12.0), (12.0, 1e9)]


def load(path):
    poses = []
    for number, line in enumerate(open(path), 1):
        v = line.split()
        if len(v) != 12:
            sys.exit(f"{path}:{number}: expected 12 numbers (a 3x4 pose row), got {len(v)}")
        v = [float(x) for x in v]
        poses.append(([v[0:3], v[4:7], v[8:11]], [v[3], v[7], v[11]]))
    return poses


def changes(poses):
    """(speed m/s, roll-and-pitch change deg) for each consecutive pair."""
    out = []
    for (Ra, ta), (Rb, tb) in zip(poses, poses[1:]):
        R = [[sum(Ra[k][i] * Rb[k][j] for k in range(3)) for j in range(3)] for i in range(3)]  # Ra^T Rb
        roll = math.atan2(R[2][1], R[2][2])
        pitch = math.asin(max(-1.0, min(1.0, -R[2][0])))
        speed = math.hypot(tb[0] - ta[0], tb[1] - ta[1]) / 0.1
        out.append((speed, math.degrees(math.hypot(roll, pitch))))
    return out


def rms(values):
    return math.sqrt(sum(v * v for v in values) / len(values)) if values else float("nan")


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    by_bin = {b: [] for b in BINS}
    for path in sys.argv[1:]:
        pairs = changes(load(path))
        moving = [c for s, c in pairs if s >= 2.0]
        print(f"{path}: {len(pairs)} pairs, change rms {rms(moving):.3f} deg above 2 m/s")
        for s, c in pairs:
            for b in BINS:
                if b[0] <= s < b[1]:
                    by_bin[b].append(c)
    print("speed m/s   pairs   roll-and-pitch change a scan, rms deg")
    for (lo, hi), values in by_bin.items():
        label = f"{lo:g}-{hi:g}" if hi < 1e9 else f">= {lo:g}"
        print(f"{label:10s} {len(values):6d}   {rms(values):.3f}" if values else f"{label:10s} {0:6d}   -")


if __name__ == "__main__":
    main()
