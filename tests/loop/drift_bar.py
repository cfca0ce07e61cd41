#!/usr/bin/env python3
"""The loop-closure drift bar: loop closure against LIO alone on the same simulated log.

    tests/loop/drift_bar.py --log SIM.lcmlog --lio-only RUN_A --with-loop RUN_B [--bin BUILD/bin]
                            [--max-ate-ratio 1.0] [--max-drift-ratio 0.5] [--json OUT.json]

RUN_A is a scripts/run_pipeline.sh output folder made with `--without loop`, RUN_B one with loop
closure. For each trajectory: ATE RMSE (livo-evaluate, SE(3)-aligned, against the log's
GROUND_TRUTH) and the drift at the run's last return to its start (check_loops.revisit_drift: the
displacement from the first pose, in its frame, against the ground truth's; issue 19's end-point
drift). The bar is checked on RUN_B's keyframes.tum, the optimised keyframe trajectory livo-loop
writes: its drift at most max-drift-ratio of the LIO's, its ATE at most max-ate-ratio of the LIO's
(loop closure must not make the trajectory worse); trajectory.tum (livo-report's loop-corrected
odometry) is printed beside it. --json writes every trajectory's ATE and drift. Exit status 1 if a
bar is missed. Pure Python; GROUND_TRUTH is read
as check_loops.py reads it.
"""
import argparse, json, math, os, subprocess, sys, tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import check_loops as cl  # noqa: E402


def ate_rmse(evaluate, est, log):
    with tempfile.NamedTemporaryFile(suffix='.json') as f:
        subprocess.run([evaluate, '--est', est, '--gt', log + ':GROUND_TRUTH', '--align', 'se3', '--json', f.name,
                        '--quiet'], check=True, stdout=subprocess.DEVNULL)
        return json.load(open(f.name))['ate']['rmse']


def path_length(gt, t0, t1):
    return sum(math.dist(gt[k][1], gt[k - 1][1]) for k in range(1, len(gt)) if t0 <= gt[k][0] <= t1)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--log', required=True)
    ap.add_argument('--lio-only', required=True)
    ap.add_argument('--with-loop', required=True)
    ap.add_argument('--bin', default=os.path.join(os.path.dirname(__file__), '../../build/bin'))
    ap.add_argument('--max-ate-ratio', type=float, default=1.0)
    ap.add_argument('--max-drift-ratio', type=float, default=0.5)
    ap.add_argument('--json', help='every trajectory\'s ATE and drift, and whether the bar is met')
    a = ap.parse_args()
    evaluate = os.path.join(a.bin, 'livo-evaluate')
    gt = cl.read_ground_truth(a.log)
    times = [g[0] for g in gt]
    rows = {}
    for name, path in (('LIO only: odometry.tum', os.path.join(a.lio_only, 'odometry.tum')),
                       ('loop: odometry.tum (online)', os.path.join(a.with_loop, 'odometry.tum')),
                       ('loop: trajectory.tum (livo-report)', os.path.join(a.with_loop, 'trajectory.tum')),
                       ('loop: keyframes.tum (livo-loop)', os.path.join(a.with_loop, 'keyframes.tum'))):
        traj = cl.read_tum(path)
        rows[name] = (ate_rmse(evaluate, path, a.log), cl.revisit_drift(traj, gt, times), traj[0][0], traj[-1][0],
                      len(traj))
    base_ate, base_end = rows['LIO only: odometry.tum'][:2]
    t0, t1 = rows['LIO only: odometry.tum'][2:4]
    print('%.0f s, %.0f m of ground-truth path' % (t1 - t0, path_length(gt, t0, t1)))
    print('%-36s %9s %9s %11s %11s %6s' % ('trajectory', 'ATE m', 'drift m', 'ATE ratio', 'drift ratio', 'poses'))
    for name, (ate, end, _, _, n) in rows.items():
        print('%-36s %9.4f %9.4f %11.3f %11.3f %6d' % (name, ate, end, ate / base_ate, end / base_end, n))
    ate, end = rows['loop: keyframes.tum (livo-loop)'][:2]
    ok = ate <= a.max_ate_ratio * base_ate and end <= a.max_drift_ratio * base_end  # nan (no return): missed
    print('bar (keyframes.tum): ATE ratio %.3f <= %.2f, drift ratio %.3f <= %.2f: %s' % (
        ate / base_ate, a.max_ate_ratio, end / base_end, a.max_drift_ratio, 'met' if ok else 'NOT met'))
    if a.json:
        keys = ('lio', 'online', 'report', 'keyframes')
        json.dump({'trajectories': {k: {'ate': v[0], 'drift': v[1], 'poses': v[4]} for k, v in zip(keys, rows.values())},
                   'bar_met': bool(ok)}, open(a.json, 'w'), indent=1)
    return 0 if ok else 1


if __name__ == '__main__':
    sys.exit(main())
