#!/usr/bin/env python3
"""NEES of the odometry's relative pose between consecutive keyframes against the ground truth.

    tests/loop/keyframe_nees.py --log SIM.lcmlog --outputs RUN/outputs.lcmlog [--band 0.95]
                                [--skip-s 5] [--filter-only] [--json OUT.json]
                                [--check | --check-not-overconfident | --check-below X]

For every KEYFRAME whose relative_to_id is the previous keyframe (livo-lio's increment from its
cloned pose, keyframe_t), the error xi of T_prev^-1 T_this against the ground truth's relative body
pose at the two stamps ([rotation; translation in this keyframe's frame], the message's convention)
gives NEES = xi^T cov^-1 xi, chi-square with 6 degrees of freedom if the covariance is honest.
Printed: the mean NEES over the N increments and the two-sided band (--band) of chi2(6 N) / N that
an honest covariance with independent increments keeps it in, the share of increments below the
chi2(6) 95 % quantile (12.59), and the rotation / translation parts alone (3 degrees of freedom each).
The first --skip-s seconds (the filter's start-up) are left out. --check: exit 1 outside the band;
--check-not-overconfident: exit 1 above it only (a covariance that is honest or cautious passes);
--check-below X: exit 1 if the mean NEES exceeds X (a run whose mean moves with something drawn once
per run, such as a hard config's calibration error, where one run's band says little).

The covariance judged is the message's whole relative_covariance: the filter's part and what the
calibration livo-lio holds at the rig's values adds (relative_covariance_held_calibration, the rig's
stated uncertainty of the LiDAR-IMU extrinsic and the gyro's scale and misalignment). --filter-only
judges the filter's part alone: for a simulation that draws no calibration or IMU errors (the easy
configs, whose rigs still state an uncertainty), where the held part stands for an error the world
does not have.
"""
import argparse, json, math, os, struct, sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import check_loops as cl  # noqa: E402


def read_keyframes(path, filter_only=False):
    """(id, utime, p, q, relative_to_id, relative_cov) of every KEYFRAME (fields before the cloud);
    filter_only: relative_cov without its held-calibration part."""
    out = []
    for _, payload in cl.read_channel(path, "KEYFRAME"):
        o = 8
        utime, kid = struct.unpack_from(">qq", payload, o); o += 16
        p = struct.unpack_from(">3d", payload, o); o += 24
        q = struct.unpack_from(">4d", payload, o); o += 32
        o += 36 * 8  # pose_covariance
        rel_id, = struct.unpack_from(">q", payload, o); o += 8
        rel = np.array(struct.unpack_from(">36d", payload, o)).reshape(6, 6); o += 36 * 8
        if filter_only:
            rel = rel - np.array(struct.unpack_from(">36d", payload, o)).reshape(6, 6)
        out.append((kid, utime, np.array(p), np.array(q), rel_id, rel))
    return out


def quat_to_rot(q):
    w, x, y, z = q
    return np.array([[1 - 2*(y*y + z*z), 2*(x*y - w*z), 2*(x*z + w*y)],
                     [2*(x*y + w*z), 1 - 2*(x*x + z*z), 2*(y*z - w*x)],
                     [2*(x*z - w*y), 2*(y*z + w*x), 1 - 2*(x*x + y*y)]])


def so3_log(R):
    c = max(-1.0, min(1.0, (np.trace(R) - 1.0) / 2.0))
    a = math.acos(c)
    v = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    if a < 1e-9:
        return 0.5 * v
    return a / (2.0 * math.sin(a)) * v


def chi2_quantile(p, k):
    """Wilson-Hilferty: chi2(k)'s p quantile (accurate to ~1e-3 relative for k >= 6)."""
    # the standard normal quantile by bisection on erf
    lo, hi = -10.0, 10.0
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        if 0.5 * (1 + math.erf(mid / math.sqrt(2))) < p:
            lo = mid
        else:
            hi = mid
    z = 0.5 * (lo + hi)
    return k * (1 - 2.0 / (9 * k) + z * math.sqrt(2.0 / (9 * k))) ** 3


def nees_of_run(log, outputs, skip_s=5.0, filter_only=False):
    gt = cl.read_ground_truth(log)
    times = [g[0] for g in gt]
    kfs = read_keyframes(outputs, filter_only)
    if not kfs:
        raise SystemExit("%s: no KEYFRAME messages" % outputs)
    t0 = kfs[0][1] * 1e-6
    by_id = {k[0]: k for k in kfs}
    rows = []
    for kid, utime, p, q, rel_id, cov in kfs:
        prev = by_id.get(rel_id)
        if prev is None or rel_id != kid - 1 or utime * 1e-6 - t0 < skip_s:
            continue
        if not np.all(np.isfinite(cov)) or np.linalg.eigvalsh(0.5 * (cov + cov.T)).min() <= 0:
            continue
        Ra, pa = quat_to_rot(prev[3]), prev[2]
        Rb, pb = quat_to_rot(q), p
        R_rel, t_rel = Ra.T @ Rb, Ra.T @ (pb - pa)
        ga_p, ga_q, _ = cl.interp(gt, times, prev[1] * 1e-6)
        gb_p, gb_q, _ = cl.interp(gt, times, utime * 1e-6)
        GRa, GRb = quat_to_rot(ga_q), quat_to_rot(gb_q)
        G_rel, g_rel = GRa.T @ GRb, GRa.T @ (np.array(gb_p) - np.array(ga_p))
        xi = np.concatenate([so3_log(R_rel.T @ G_rel), R_rel.T @ (g_rel - t_rel)])
        S = 0.5 * (cov + cov.T)
        rows.append((float(xi @ np.linalg.solve(S, xi)), float(xi[:3] @ np.linalg.solve(S[:3, :3], xi[:3])),
                     float(xi[3:] @ np.linalg.solve(S[3:, 3:], xi[3:])), xi, np.sqrt(np.diag(S))))
    return rows


def summary(rows, band=0.95):
    n = len(rows)
    nees = np.array([r[0] for r in rows])
    lo = chi2_quantile((1 - band) / 2, 6 * n) / n
    hi = chi2_quantile(1 - (1 - band) / 2, 6 * n) / n
    err = np.array([np.abs(r[3]) for r in rows])
    sd = np.array([r[4] for r in rows])
    return {
        "increments": n,
        "mean_nees": float(nees.mean()),
        "median_nees": float(np.median(nees)),
        "band": [lo, hi],
        "in_band": bool(lo <= nees.mean() <= hi),
        "share_below_chi2_95": float(np.mean(nees < chi2_quantile(0.95, 6))),
        "mean_nees_rotation": float(np.mean([r[1] for r in rows])),
        "mean_nees_translation": float(np.mean([r[2] for r in rows])),
        "rms_error": [float(x) for x in np.sqrt(np.mean(err ** 2, axis=0))],
        "rms_sigma": [float(x) for x in np.sqrt(np.mean(sd ** 2, axis=0))],
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--log", required=True)
    ap.add_argument("--outputs", required=True)
    ap.add_argument("--band", type=float, default=0.95)
    ap.add_argument("--skip-s", type=float, default=5.0)
    ap.add_argument("--filter-only", action="store_true",
                    help="judge the filter's part alone (a simulation that draws no calibration errors)")
    ap.add_argument("--json")
    ap.add_argument("--check", action="store_true")
    ap.add_argument("--check-not-overconfident", action="store_true")
    ap.add_argument("--check-below", type=float, metavar="X")
    a = ap.parse_args()
    rows = nees_of_run(a.log, a.outputs, a.skip_s, a.filter_only)
    if not rows:
        raise SystemExit("no keyframe increment with a covariance (is livo-lio's relative_covariance filled?)")
    s = summary(rows, a.band)
    if a.json:
        with open(a.json, "w") as f:
            json.dump(s, f, indent=1)
    print("keyframe increments %d: mean NEES %.2f (band %.2f-%.2f for %.0f %%), median %.2f, %.0f %% below 12.59; "
          "rotation %.2f, translation %.2f (3 each)" % (s["increments"], s["mean_nees"], s["band"][0], s["band"][1],
                                                       100 * a.band, s["median_nees"], 100 * s["share_below_chi2_95"],
                                                       s["mean_nees_rotation"], s["mean_nees_translation"]))
    print("rms error  [rad rad rad m m m]: " + " ".join("%.2e" % x for x in s["rms_error"]))
    print("rms sigma  [rad rad rad m m m]: " + " ".join("%.2e" % x for x in s["rms_sigma"]))
    if a.check and not s["in_band"]:
        sys.exit(1)
    if a.check_not_overconfident and s["mean_nees"] > s["band"][1]:
        sys.exit(1)
    if a.check_below is not None and not s["mean_nees"] <= a.check_below:
        sys.exit(1)


if __name__ == "__main__":
    main()
