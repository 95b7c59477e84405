#!/usr/bin/env python3
"""Where a run's dynamic-object velocity error comes from.

usage: scripts/velocity-error-parts.py EVAL_DIR [RUN_DIR]
EVAL_DIR holds dlslot-eval's velocity_errors.csv; RUN_DIR (default EVAL_DIR) the trajectories
trajectory_slot_kitti.txt and trajectory_groundtruth_kitti.txt. Frames are 0.1 s apart.
Pairs are in each scan's lidar axes (dlslot-eval). Parts, as shares of the total mean square:
  young: pairs of tracks younger than 5 scans;
  ego: the ego's own per-frame velocity error (slot trajectory, backward difference, lidar axes)
       subtracted from each mature pair;
  lag: mature pairs' error explained by -tau * (truth acceleration), tau fitted;
  bias: mean error per axis (mature, after ego and lag);
  jitter: what is left, split into slow (5-frame moving mean per track) and fast parts."""
import csv, math, sys, collections

def load_traj(path):
    P = []
    for line in open(path):
        v = [float(x) for x in line.split()]
        P.append(([[v[0], v[1], v[2]], [v[4], v[5], v[6]], [v[8], v[9], v[10]]], [v[3], v[7], v[11]]))
    return P

def rt_mul(R, x):  # R^T x
    return [sum(R[k][i] * x[k] for k in range(3)) for i in range(3)]

def ego_vel(P, t, dt=0.1):  # backward difference, lidar axes of t
    if t == 0: return None
    d = [P[t][1][i] - P[t - 1][1][i] for i in range(3)]
    return [x / dt for x in rt_mul(P[t][0], d)]

run = sys.argv[1]
young_age = 5
tdir = sys.argv[2] if len(sys.argv) > 2 else run
est = load_traj(tdir + '/trajectory_slot_kitti.txt')
gt = load_traj(tdir + '/trajectory_groundtruth_kitti.txt')
rows = [r for r in csv.DictReader(open(run + '/velocity_errors.csv')) if r['dynamic'] == '1']
for r in rows:
    for k in ('truth_vx', 'truth_vy', 'track_vx', 'track_vy'): r[k] = float(r[k])
    r['f'] = int(r['frame_index']); r['age'] = int(r['track_age'])
    r['ex'] = r['track_vx'] - r['truth_vx']; r['ey'] = r['track_vy'] - r['truth_vy']
N = len(rows)
tot = sum(r['ex'] ** 2 + r['ey'] ** 2 for r in rows) / N
# truth acceleration (lidar axes; truth velocities by label and frame, world via gt rotation)
byl = collections.defaultdict(dict)
for r in rows:
    R = gt[r['f']][0]
    w = [R[i][0] * r['truth_vx'] + R[i][1] * r['truth_vy'] for i in range(3)]
    byl[r['label_id']][r['f']] = w
for r in rows:
    d = byl[r['label_id']]; f = r['f']
    a = None
    if f - 1 in d and f + 1 in d:
        aw = [(d[f + 1][i] - d[f - 1][i]) / 0.2 for i in range(3)]
        a = rt_mul(gt[f][0], aw)
    r['a'] = a
    eg, tg = ego_vel(est, f), ego_vel(gt, f)
    r['eego'] = None if eg is None else [eg[0] - tg[0], eg[1] - tg[1]]
young = [r for r in rows if r['age'] < young_age]
mature = [r for r in rows if r['age'] >= young_age]
ms = lambda rs, fx, fy: sum(fx(r) ** 2 + fy(r) ** 2 for r in rs) / N  # share of the total's sum
S_young = ms(young, lambda r: r['ex'], lambda r: r['ey'])
S_mat = ms(mature, lambda r: r['ex'], lambda r: r['ey'])
# ego part
mat = [r for r in mature if r['eego'] is not None and r['a'] is not None]
S_mat2 = ms(mat, lambda r: r['ex'], lambda r: r['ey'])
for r in mat:
    r['rx'] = r['ex'] - r['eego'][0]; r['ry'] = r['ey'] - r['eego'][1]
S_noego = ms(mat, lambda r: r['rx'], lambda r: r['ry'])
# regression coefficient of error on ego error
num = sum(r['ex'] * r['eego'][0] + r['ey'] * r['eego'][1] for r in mat)
den = sum(r['eego'][0] ** 2 + r['eego'][1] ** 2 for r in mat)
k_ego = num / den if den else 0
for r in mat:
    r['rx'] = r['ex'] - k_ego * r['eego'][0]; r['ry'] = r['ey'] - k_ego * r['eego'][1]
S_noego_k = ms(mat, lambda r: r['rx'], lambda r: r['ry'])
# lag: e = -tau a
num = sum(r['rx'] * r['a'][0] + r['ry'] * r['a'][1] for r in mat)
den = sum(r['a'][0] ** 2 + r['a'][1] ** 2 for r in mat)
tau = -num / den if den else 0
for r in mat:
    r['rx'] += tau * r['a'][0]; r['ry'] += tau * r['a'][1]
S_nolag = ms(mat, lambda r: r['rx'], lambda r: r['ry'])
mx = sum(r['rx'] for r in mat) / len(mat); my = sum(r['ry'] for r in mat) / len(mat)
for r in mat:
    r['rx'] -= mx; r['ry'] -= my
S_nobias = ms(mat, lambda r: r['rx'], lambda r: r['ry'])
# slow vs fast jitter per track
byt = collections.defaultdict(dict)
for r in mat: byt[r['track_id']][r['f']] = r
for r in mat:
    nb = [byt[r['track_id']][g] for g in range(r['f'] - 2, r['f'] + 3) if g in byt[r['track_id']]]
    r['sx'] = sum(q['rx'] for q in nb) / len(nb); r['sy'] = sum(q['ry'] for q in nb) / len(nb)
S_slow = ms(mat, lambda r: r['sx'], lambda r: r['sy'])
S_fast = ms(mat, lambda r: r['rx'] - r['sx'], lambda r: r['ry'] - r['sy'])
# ego velocity error RMS and mean along x
ev = [ (ego_vel(est, t), ego_vel(gt, t)) for t in range(1, len(est))]
ego_rms = math.sqrt(sum((a[0] - b[0]) ** 2 + (a[1] - b[1]) ** 2 for a, b in ev) / len(ev))
ego_bias_x = sum(a[0] - b[0] for a, b in ev) / len(ev)
speed = sum(math.hypot(b[0], b[1]) for a, b in ev) / len(ev)
# along / across (mean error in lidar x, y) for mature
bx = sum(r['ex'] for r in mature) / len(mature); by = sum(r['ey'] for r in mature) / len(mature)
arms = math.sqrt(sum(r['a'][0] ** 2 + r['a'][1] ** 2 for r in mat) / len(mat))
print(f"{run}: pairs {N} (young {len(young)}), RMSE {math.sqrt(tot):.3f}, young RMSE {math.sqrt(S_young*N/max(1,len(young))):.3f}, mature RMSE {math.sqrt(S_mat*N/len(mature)):.3f}")
print(f"  ego: speed {speed:.2f} m/s, velocity error RMS {ego_rms:.3f}, mean along x {ego_bias_x:+.3f}; objects' mature mean error x {bx:+.3f} y {by:+.3f}; truth accel RMS {arms:.2f} m/s2")
print(f"  shares of total MSE {tot:.4f}: young {S_young/tot:.1%}, mature {S_mat/tot:.1%} (of which analysed {S_mat2/tot:.1%})")
print(f"  mature: minus ego error (x1) -> {S_noego/tot:.1%}; regression k_ego={k_ego:.2f} -> {S_noego_k/tot:.1%}; lag tau={tau*1000:.0f} ms -> {S_nolag/tot:.1%}; bias ({mx:+.3f},{my:+.3f}) -> {S_nobias/tot:.1%}; slow {S_slow/tot:.1%} fast {S_fast/tot:.1%}")

# The lag directly: the mature tracks' RMSE against the truth k frames earlier (a minimum at k > 0
# is a velocity that trails the object).
truth = collections.defaultdict(dict)
for r in rows: truth[r['label_id']][r['f']] = (r['truth_vx'], r['truth_vy'])
out = []
for k in (0, 1, 2, 3, 4):
    s = n = 0
    for r in mature:
        d = truth[r['label_id']]
        if r['f'] - k not in d or r['f'] - 4 not in d: continue
        tv = d[r['f'] - k]
        s += (r['track_vx'] - tv[0]) ** 2 + (r['track_vy'] - tv[1]) ** 2; n += 1
    out.append(f"{k}: {math.sqrt(s / n):.3f}" if n else f"{k}: -")
print("  mature RMSE against the truth k frames earlier: " + ", ".join(out))
