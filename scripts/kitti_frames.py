"""KITTI tracking files and frames for the analysis scripts: the labels and detectors a folder
holds, 4x4 transforms as nested lists, and the transform from a sequence's rectified camera-0
coordinates (its labels) to the world of its velodyne poses (ROOT/poses/SSSS.txt as in AB3DMOT's
data, or ROOT/training/poses/SSSS.txt as the simulator writes them); labelled objects as tracks in
that world."""
import collections
import glob
import math
import os
import sys


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
    if not os.path.exists(path):  # a simulated sequence keeps them under training/
        path = os.path.join(root, "training", "poses", seq + ".txt")
    if not os.path.exists(path):
        print(f"{seq}: no poses, taken as seen from a parked sensor")
        return lambda f: cam_to_velo
    poses = [mat([float(x) for x in line.split()]) for line in open(path)]
    return lambda f: mul(poses[f], cam_to_velo)


def sequences_with_poses(root):
    """The sequences with velodyne poses under ROOT/poses or ROOT/training/poses."""
    names = set()
    for d in (os.path.join(root, "poses"), os.path.join(root, "training", "poses")):
        if os.path.isdir(d):
            names.update(f[:-4] for f in os.listdir(d) if f.endswith(".txt"))
    return sorted(names)


def world_label_tracks(root, seq, classes, to_world=None):
    """The labels of the given classes in sequence seq as tracks: id -> frame -> (x, y, heading) in
    the world of to_world (default camera_to_world(root, seq)); exits naming the line of a label
    with too few fields."""
    to_world = to_world or camera_to_world(root, seq)
    tracks = collections.defaultdict(dict)
    path = os.path.join(root, "training", "label_02", seq + ".txt")
    for n, line in enumerate(open(path), 1):
        t = line.split()
        if len(t) < 17:
            sys.exit(f"{path}:{n}: expected 17 fields, got {len(t)}")
        if t[2] in classes:
            f = int(t[0])
            p = apply(to_world(f), [float(t[13]), float(t[14]), float(t[15])])
            # A camera label's forward axis is (cos ry, 0, -sin ry) in camera coordinates.
            ry = float(t[16])
            o = apply(to_world(f), [0.0, 0.0, 0.0])
            q = apply(to_world(f), [math.cos(ry), 0.0, -math.sin(ry)])
            tracks[int(t[1])][f] = (p[0], p[1], math.atan2(q[1] - o[1], q[0] - o[0]))
    return tracks


def percentile(v, q):
    """The q-quantile of the sorted list v."""
    return v[min(len(v) - 1, int(q * len(v)))]


def labels_and_detectors(argv, usage):
    """ROOT [MIN_SCORE] from argv -> (root, min_score (default 2), label files, detector names):
    ROOT/training/label_02/SSSS.txt and ROOT/detections/<name>/SSSS.txt; exits with usage or
    with what is missing."""
    if len(argv) not in (2, 3):
        sys.exit(usage)
    root = argv[1]
    min_score = float(argv[2]) if len(argv) == 3 else 2.0
    label_files = sorted(glob.glob(os.path.join(root, "training", "label_02", "*.txt")))
    det_root = os.path.join(root, "detections")
    detectors = sorted(os.listdir(det_root)) if os.path.isdir(det_root) else []
    if not label_files or not detectors:
        sys.exit(f"{root}: expected training/label_02/*.txt and detections/<name>/*.txt")
    return root, min_score, label_files, detectors
