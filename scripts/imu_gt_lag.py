#!/usr/bin/env python3
"""The time offset between a recording's IMU and its ground truth, from the gyro alone.

    scripts/imu_gt_lag.py --imu mav0/imu0/data.csv --gt groundtruth.tum [--range-ms 15] [--step-ms 0.1]
                          [--json OUT.json]

A recorded trajectory that replays its real IMU (livo-sim's `recorded` type with `imu`) renders
the LiDAR and the camera from the ground truth and publishes the IMU as it was: any offset between
the two clocks then reaches the estimators as a time shift of both sensors that the simulator's
truth (`--truth`) does not hold. This measures it the way a temporal calibration does: the body's
rotation over each ground-truth interval [t_i, t_i+1] (Log(q_i^-1 q_i+1), body frame) against the
gyro integrated over [t_i + L, t_i+1 + L], a constant gyro bias fitted per L, for every L in
+/- range. Printed: L at the least RMS (refined by a parabola through its neighbours), that RMS,
the RMS at L +/- 5 ms for scale, and the bias. Add L to the ground truth's stamps to put them on
the IMU's clock. The body frame of both must be the IMU's (EuRoC's ground truth is).
Files: the IMU as ASL csv (ns, w_x, w_y, w_z, ...), the ground truth as TUM (t x y z qx qy qz qw).
"""
import argparse, json, sys

import numpy as np


def refuse_non_finite(path, a):
    """A NaN or infinite value would make every lag's RMS NaN: name its first row instead."""
    bad = ~np.isfinite(a).all(axis=1)
    if bad.any():
        raise SystemExit('imu_gt_lag.py: %s: %d rows with a non-finite value, the first at data row %d'
                         % (path, int(bad.sum()), int(np.argmax(bad)) + 1))


def read_imu(path):
    a = np.loadtxt(path, delimiter=',', comments='#', ndmin=2)
    if a.shape[1] < 4:
        raise SystemExit('imu_gt_lag.py: %s: expected "ns, w_x, w_y, w_z, ..." rows' % path)
    refuse_non_finite(path, a[:, :4])
    return a[:, 0] * 1e-9, a[:, 1:4]


def read_tum(path):
    a = np.loadtxt(path, comments='#', ndmin=2)
    if a.shape[1] != 8:
        raise SystemExit('imu_gt_lag.py: %s: expected TUM rows "t x y z qx qy qz qw"' % path)
    refuse_non_finite(path, a)
    return a[:, 0], a[:, 4:8]


def interval_rotations(q):
    """Body-frame rotation vectors Log(q_i^-1 q_i+1) of quaternions (x y z w)."""
    x1, y1, z1, w1 = (-q[:-1, 0], -q[:-1, 1], -q[:-1, 2], q[:-1, 3])
    x2, y2, z2, w2 = q[1:].T
    d = np.c_[w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2, w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
              w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2, w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2]
    d *= np.where(d[:, 3:4] < 0, -1.0, 1.0)
    s = np.linalg.norm(d[:, :3], axis=1)
    angle = 2.0 * np.arctan2(s, d[:, 3])
    return d[:, :3] * (angle / np.maximum(s, 1e-15))[:, None]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--imu', required=True)
    ap.add_argument('--gt', required=True)
    ap.add_argument('--range-ms', type=float, default=15.0)
    ap.add_argument('--step-ms', type=float, default=0.1)
    ap.add_argument('--json')
    a = ap.parse_args()
    ti, w = read_imu(a.imu)
    tg, q = read_tum(a.gt)
    if np.any(np.diff(ti) <= 0) or np.any(np.diff(tg) <= 0):
        raise SystemExit('imu_gt_lag.py: stamps must increase strictly in both files')
    rot = interval_rotations(q)
    t0, t1 = tg[:-1], tg[1:]
    margin = a.range_ms * 1e-3 + 0.01
    use = (t0 > ti[0] + margin) & (t1 < ti[-1] - margin)
    if use.sum() < 20:
        raise SystemExit('imu_gt_lag.py: the files overlap in fewer than 20 ground-truth intervals')
    rot, t0, t1 = rot[use], t0[use], t1[use]
    dt = (t1 - t0)[:, None]
    # the gyro's running integral (trapezoid), read at any instant by interpolation
    cum = np.vstack([np.zeros((1, 3)), np.cumsum(0.5 * (w[1:] + w[:-1]) * np.diff(ti)[:, None], axis=0)])

    def rms(lag):
        integ = np.column_stack([np.interp(t1 + lag, ti, cum[:, k]) - np.interp(t0 + lag, ti, cum[:, k])
                                 for k in range(3)])
        r = rot - integ
        bias = -(r * dt).sum(0) / (dt ** 2).sum()  # the gyro reads rate + bias: r = -bias dt per interval
        r = r + bias * dt
        return float(np.sqrt((r ** 2).sum(1).mean())), bias

    lags = np.arange(-a.range_ms, a.range_ms + 0.5 * a.step_ms, a.step_ms) * 1e-3
    errs = np.array([rms(L)[0] for L in lags])
    k = int(np.argmin(errs))
    best = lags[k]
    if 0 < k < len(lags) - 1:  # a parabola through the least and its neighbours
        e0, e1, e2 = errs[k - 1], errs[k], errs[k + 1]
        den = e0 - 2.0 * e1 + e2
        if den > 0:
            best += 0.5 * (e0 - e2) / den * (lags[1] - lags[0])
    err, bias = rms(best)
    out = {'lag_s': best, 'rms_rad': err, 'rms_rad_at_minus_5ms': rms(best - 0.005)[0],
           'rms_rad_at_plus_5ms': rms(best + 0.005)[0], 'gyro_bias': bias.tolist(), 'intervals': int(use.sum()),
           'at_range_edge': k in (0, len(lags) - 1)}
    print('lag %+.2f ms (add it to the ground truth\'s stamps to put them on the IMU\'s clock): rotation '
          'residual %.2e rad RMS over %d intervals (%.2e / %.2e at -/+ 5 ms), gyro bias (%.4f, %.4f, %.4f) rad/s'
          % (best * 1e3, err, out['intervals'], out['rms_rad_at_minus_5ms'], out['rms_rad_at_plus_5ms'], *bias))
    if out['at_range_edge']:
        print('imu_gt_lag.py: the least is at the edge of --range-ms; widen it', file=sys.stderr)
    if a.json:
        json.dump(out, open(a.json, 'w'), indent=1)
    return 1 if out['at_range_edge'] else 0


if __name__ == '__main__':
    sys.exit(main())
