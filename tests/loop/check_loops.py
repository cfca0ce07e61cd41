#!/usr/bin/env python3
"""Checks a run's loops.json against the log's GROUND_TRUTH (pure Python, no LCM bindings).

    tests/loop/check_loops.py --log SIM.lcmlog --loops RUN/loops.json [--max-trans 0.5] [--max-rot-deg 2]
                              [--odometry TUM]

A loop is false if its T_to_from disagrees with the ground-truth relative body pose of the two
keyframes (interpolated at their stamps) by more than the bounds. Exit status 1 if any is false.
--odometry (an odometry.tum, e.g. of the LIO alone on the same log) adds a line per loop: the loop's
error against the truth as the right perturbation its `information` is for ([rotation in deg;
translation in m in the newer keyframe's frame], T_true = T_loop (R Exp(phi), t + R tau)), the NEES
of that error with the loop's information (chi-square with 6 degrees of freedom if it is honest),
and the odometry's error of the same relative pose taken the same way: where the two errors are
alike the odometry and the loop share the error (a held calibration's, say) and the loop cannot
mend it; where they differ, the smaller says which of the two a correction should believe.
"""
import argparse, bisect, json, math, struct, sys


def read_channel(path, channel):
    """(utime, payload) of every event on one channel of an LCM log."""
    out = []
    want = channel.encode()
    with open(path, "rb") as f:  # streamed: a run's outputs log can be gigabytes of clouds
        while True:
            at = f.tell()
            head = f.read(28)
            if len(head) < 28:
                break
            sync, _, utime, clen, dlen = struct.unpack(">IqqII", head)
            if sync != 0xEDA1DA01:
                raise SystemExit("%s: bad sync at byte %d" % (path, at))
            if f.read(clen) == want:
                out.append((utime, f.read(dlen)))
            else:
                f.seek(dlen, 1)
    return out


def read_ground_truth(path, channel="GROUND_TRUTH"):
    out = []
    for _, payload in read_channel(path, channel):
        o = 8  # fingerprint
        utime, = struct.unpack_from(">q", payload, o); o += 8
        for _ in range(2):
            n, = struct.unpack_from(">i", payload, o); o += 4 + n
        p = struct.unpack_from(">3d", payload, o); o += 24
        q = struct.unpack_from(">4d", payload, o)
        out.append((utime * 1e-6, p, q))
    return out


def qmul(a, b):
    w1, x1, y1, z1 = a; w2, x2, y2, z2 = b
    return (w1*w2 - x1*x2 - y1*y2 - z1*z2, w1*x2 + x1*w2 + y1*z2 - z1*y2,
            w1*y2 - x1*z2 + y1*w2 + z1*x2, w1*z2 + x1*y2 - y1*x2 + z1*w2)


def qconj(q):
    return (q[0], -q[1], -q[2], -q[3])


def qrot(q, v):
    r = qmul(qmul(q, (0.0,) + tuple(v)), qconj(q))
    return r[1:]


def interp(gt, times, t):
    k = bisect.bisect_left(times, t)
    k = min(max(k, 1), len(gt) - 1)
    (t0, p0, q0), (t1, p1, q1) = gt[k - 1], gt[k]
    a = 0.0 if t1 == t0 else min(max((t - t0) / (t1 - t0), 0.0), 1.0)
    p = tuple(p0[i] + a * (p1[i] - p0[i]) for i in range(3))
    if sum(x*y for x, y in zip(q0, q1)) < 0: q1 = tuple(-x for x in q1)
    q = tuple(q0[i] + a * (q1[i] - q0[i]) for i in range(4))
    n = math.sqrt(sum(x*x for x in q))
    return p, tuple(x / n for x in q), abs(t - (t0 if a < 0.5 else t1))


def read_tum(path):
    """(t, position, quaternion w x y z) of every pose of a TUM trajectory file."""
    out = []
    for line in open(path):
        if line.startswith('#') or not line.strip():
            continue
        v = [float(x) for x in line.split()]
        out.append((v[0], tuple(v[1:4]), (v[7], v[4], v[5], v[6])))
    return out


def revisit_drift(traj, gt, times, radius=10.0, min_path=100.0):
    """Drift at the last return to the start: the trajectory's displacement from its first pose to
    its pose nearest the true start (horizontally) during its last pass within `radius` m of it,
    after `min_path` m of travel, in the first pose's frame, against the ground truth's taken the same
    way. Relative, so the start attitude (a few mrad of tilt and heading from an IMU's errors) costs
    only the closest approach's distance times that angle, where a first-pose alignment of a far end
    would turn it into metres; nan if the run never comes back."""
    if not traj:
        return float('nan')
    t0, p0, q0 = traj[0]
    g0p, g0q, _ = interp(gt, times, t0)
    path, last, inside, end = 0.0, g0p, False, None
    for t, p, _ in traj:
        gp, _, _ = interp(gt, times, t)
        path += math.dist(gp, last)
        last = gp
        d = math.dist(gp[:2], g0p[:2])
        if path < min_path or d > radius:
            inside = False
            continue
        if not inside or d < end[0]:  # a new pass starts, or a closer pose in this one
            end = (d, p, gp)
        inside = True
    if end is None:
        return float('nan')
    _, p, gp = end
    est = qrot(qconj(q0), tuple(p[i] - p0[i] for i in range(3)))
    true = qrot(qconj(g0q), tuple(gp[i] - g0p[i] for i in range(3)))
    return math.dist(est, true)


def qmat(q):
    w, x, y, z = q
    return [[1 - 2*(y*y + z*z), 2*(x*y - w*z), 2*(x*z + w*y)],
            [2*(x*y + w*z), 1 - 2*(x*x + z*z), 2*(y*z - w*x)],
            [2*(x*z - w*y), 2*(y*z + w*x), 1 - 2*(x*x + y*y)]]


def log_q(q):
    """The rotation vector (rad) of a unit quaternion w, x, y, z."""
    w, v = q[0], q[1:]
    if w < 0:
        w, v = -w, tuple(-x for x in v)
    n = math.sqrt(sum(x*x for x in v))
    if n < 1e-12:
        return (2*v[0], 2*v[1], 2*v[2])
    a = 2*math.atan2(n, w)
    return tuple(a*x/n for x in v)


def right_error(q_est, t_est, q_true, t_true):
    """xi = [phi; tau] with T_true = (R_est Exp(phi), t_est + R_est tau)."""
    phi = log_q(qmul(qconj(q_est), q_true))
    tau = qrot(qconj(q_est), tuple(t_true[i] - t_est[i] for i in range(3)))
    return list(phi) + list(tau)


def relative(tr, times, t_to, t_from):
    """T_to_from = T_W_to^-1 T_W_from of a trajectory at two stamps: (q, t)."""
    pf, qf, _ = interp(tr, times, t_from)
    pt, qt, _ = interp(tr, times, t_to)
    return qmul(qconj(qt), qf), qrot(qconj(qt), tuple(pf[i] - pt[i] for i in range(3)))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--log", required=True)
    ap.add_argument("--loops", required=True)
    ap.add_argument("--max-trans", type=float, default=0.5)
    ap.add_argument("--max-rot-deg", type=float, default=2.0)
    ap.add_argument("--odometry", help="odometry.tum: its error of each loop's relative pose, beside the loop's")
    a = ap.parse_args()
    odo = read_tum(a.odometry) if a.odometry else None
    odo_times = [o[0] for o in odo] if odo else None
    nees = []
    gt = read_ground_truth(a.log)
    times = [g[0] for g in gt]
    loops = json.load(open(a.loops))
    false = 0
    print("keyframes %d, loops %d" % (loops["num_keyframes"], len(loops["loops"])))
    for l in loops["loops"]:
        pf, qf, _ = interp(gt, times, l["from_time"])
        pt, qt, _ = interp(gt, times, l["to_time"])
        # ground truth T_to_from = T_W_to^-1 T_W_from
        qtf = qmul(qconj(qt), qf)
        ttf = qrot(qconj(qt), tuple(pf[i] - pt[i] for i in range(3)))
        e = l["T_to_from"]
        qe = tuple(e["rotation_wxyz"]); te = e["translation"]
        dq = qmul(qconj(qtf), qe)
        rot = 2 * math.degrees(math.acos(min(1.0, abs(dq[0]))))
        tr = math.sqrt(sum((te[i] - ttf[i]) ** 2 for i in range(3)))
        bad = tr > a.max_trans or rot > a.max_rot_deg
        false += bad
        print("%5d -> %5d  t %.1f -> %.1f  gt |t| %.2f m  err %.3f m %.3f deg  inl %d fit %.3f ov %.2f %s" % (
            l["from_id"], l["to_id"], l["from_time"], l["to_time"], math.sqrt(sum(x*x for x in ttf)), tr, rot,
            l["coarse_inliers"], l["fitness"], l["overlap"], "FALSE" if bad else "ok"))
        if odo:
            xi = right_error(qe, te, qtf, ttf)
            info = l["information"]
            n = sum(xi[i] * info[6*i + j] * xi[j] for i in range(6) for j in range(6))
            nees.append(n)
            qo, to = relative(odo, odo_times, l["to_time"], l["from_time"])
            xo = right_error(qo, to, qtf, ttf)
            fmt = lambda x: "rot [%s] deg  trans [%s] m" % (" ".join("%6.3f" % math.degrees(v) for v in x[:3]),
                                                            " ".join("%7.4f" % v for v in x[3:]))
            print("        loop %s  NEES %.1f%s\n        odom %s" % (
                fmt(xi), n, "  (corrected)" if l.get("corrected") else "", fmt(xo)))
    if nees:
        print("loops' NEES against the truth: mean %.1f, median %.1f (6 for an honest information)" % (
            sum(nees) / len(nees), sorted(nees)[len(nees) // 2]))
    print("false loops: %d of %d" % (false, len(loops["loops"])))
    return 1 if false else 0


if __name__ == "__main__":
    sys.exit(main())
