#!/usr/bin/env python3
"""Issue 43's table: does the camera earn its keep on a rig calibrated only as well as real rigs are?

    scripts/camera_table.py --out DIR [--configs room_hard,corridor_hard,...] [--seeds 701,702,703,704,705]
                            [--duration 60] [--logs DIR] [--overlay FILE] [--compare-to DIR/rows.json]
                            [--config-dir DIR] [--keep-logs]

For every config (DIR/NAME.yaml, config/sim by default) and seed, livo-sim writes the log and its
truth (--truth: the calibration errors drawn); scripts/run_pipeline.sh runs the LIO alone (lio) and
with the camera (livo: lio + vio); livo-evaluate gives the ATE, and lio's calibration.csv the
calibration over the run; the ATE is also given at the LiDAR (the estimate moved by the nominal
less the true LiDAR lever arm, --gt-offset), where the held lever arm's error, which both variants
share, is left out (not a bar: what the camera changes, seen without it). DIR/table.md gets a row
per run and these bars (issue 43):
  - LIVO at most 5 % above the LIO on every run;
  - the mean LIVO ATE at most 0.85 x the mean LIO ATE: over every run, and over the runs where the
    LIO does not degenerate (a corridor's LIO loses its axis: metres, which would decide any mean);
  - corridor_hard: LIVO at most 0.10 m on every run;
  - room_hard and campus_loop_hard: from 30 s on, the camera's rotation against the LiDAR within
    0.1 deg of the simulator's truth and the camera's time offset within 1 ms;
  - with --compare-to (the rows.json of another table, e.g. today's build): no config's mean LIVO
    ATE above the other table's, and the LIO alone on room_hard and campus_loop_hard at most 0.8 x
    the other table's mean.
Exit status 1 if a bar is missed or a run failed (a run that did not run is a failure, not a gap).

Results are cached per run in DIR/<config>_s<seed>/<variant>/: a run is reused only if its key (the
config and overlay bytes, seed, duration, the log's key and the executables and scripts it ran) is
the one recorded beside it; logs likewise (config bytes, seed, duration, livo-sim). Runs one after
the other (each uses both cores). --build DIR picks the executables of the runs (the simulator is
always this tree's: LIVO_BUILD_DIR or build/): with --config-dir of the same era, the same command
measures an older build on the same logs.
"""
import argparse, csv, json, math, os, shutil, subprocess, sys

import sim_variants as sv

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_CONFIGS = 'room_hard,corridor_hard,campus_loop_hard,parking_hard,euroc_v1_01_hard,room_fr2_desk_hard'
DURATIONS = {'room_fr2_desk_hard': 52.0, 'room_fr2_desk': 52.0}  # the recording's length
CALIBRATION_CONFIGS = ('room_hard', 'campus_loop_hard')
RUN_EXECUTABLES = ('livo-lio', 'livo-vio', 'livo-playback', 'livo-record', 'livo-evaluate', 'livo-config')


# --- small rotation algebra (no numpy: the scripts run on any python3) ---
def exp_so3(v):
    th = math.sqrt(sum(x * x for x in v))
    if th < 1e-15:
        return [[1.0, -v[2], v[1]], [v[2], 1.0, -v[0]], [-v[1], v[0], 1.0]]
    k = [x / th for x in v]
    c, s, C = math.cos(th), math.sin(th), 1 - math.cos(th)
    x, y, z = k
    return [[c + x * x * C, x * y * C - z * s, x * z * C + y * s],
            [y * x * C + z * s, c + y * y * C, y * z * C - x * s],
            [z * x * C - y * s, z * y * C + x * s, c + z * z * C]]


def quat_to_matrix(q):
    w, x, y, z = q
    n = math.sqrt(w * w + x * x + y * y + z * z)
    w, x, y, z = w / n, x / n, y / n, z / n
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]


def mul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def tr(a):
    return [[a[j][i] for j in range(3)] for i in range(3)]


def log_so3(R):
    c = max(-1.0, min(1.0, (R[0][0] + R[1][1] + R[2][2] - 1) / 2))
    th = math.acos(c)
    f = 0.5 if th < 1e-9 else th / (2 * math.sin(th))
    return [f * (R[2][1] - R[1][2]), f * (R[0][2] - R[2][0]), f * (R[1][0] - R[0][1])]


def camera_lidar_truth_deg(truth):
    """The camera's rotation against the LiDAR's, turned from the rig's (camera frame, deg): what
    lio's calibration.csv reports as camera_lidar_rot_*."""
    e = truth['calibration_errors']
    R_IL = quat_to_matrix(truth['nominal']['T_I_L']['rotation_wxyz'])
    R_IC = quat_to_matrix(truth['nominal']['T_I_C']['rotation_wxyz'])
    R_LC = mul(tr(R_IL), R_IC)
    E_L, E_C = exp_so3(e['lidar']['rotation_vector']), exp_so3(e['camera']['rotation_vector'])
    # R_LC,true = E_L^T R_LC E_C
    return [math.degrees(x) for x in log_so3(mul(tr(R_LC), mul(tr(E_L), mul(R_LC, E_C))))]


def calibration_errors(csv_path, truth, after_s=30.0):
    """Worst camera-LiDAR rotation error (deg) and camera time offset error (ms) from after_s on,
    and both at the end; None without a calibration.csv."""
    if not os.path.exists(csv_path):
        return None
    rows = list(csv.DictReader(open(csv_path)))
    if not rows:
        return None
    cl = camera_lidar_truth_deg(truth)
    dt_true = 1e3 * truth['calibration_errors']['camera']['time_offset_s']

    def err(r):
        rot = max(abs(float(r['camera_lidar_rot_%s_deg' % a]) - cl[i]) for i, a in enumerate('xyz'))
        return rot, float(r['camera_time_shift_ms']) - dt_true
    late = [err(r) for r in rows if float(r['t_s']) >= after_s] or [err(rows[-1])]
    end = err(rows[-1])
    return {'rot_worst_deg': max(e[0] for e in late), 'dt_worst_ms': max(abs(e[1]) for e in late),
            'rot_end_deg': end[0], 'dt_end_ms': end[1], 'truth_deg': cl, 'truth_dt_ms': dt_true}


def lidar_offset(truth):
    """The body-frame offset o that moves an estimated IMU pose to where the LiDAR's true origin is
    from the true IMU pose, as seen through the nominal rig the estimators hold: p + R o with
    o = t_IL,nominal - t_IL,true (the LiDAR's true place less the lever arm the truth adds), so the
    ATE at the LiDAR leaves out the held lever arm's error, which the LIO and the LIVO share (both
    place the LiDAR's points through the nominal extrinsic). Exact up to the estimate's rotation
    error times the true lever arm (0.3 deg x 0.1 m: 0.5 mm)."""
    n, t = truth['nominal']['T_I_L']['translation'], truth['true']['T_I_L']['translation']
    return [n[i] - t[i] for i in range(3)]


def evaluate_at_lidar(build, run_dir, gt, truth):
    """ATE rmse of the run's odometry.tum at the LiDAR (lidar_offset), or None if it did not run (then
    run_dir/evaluate_lidar.txt says why)."""
    out = os.path.join(run_dir, 'evaluation_odometry_lidar.json')
    o = ','.join('%.9g' % x for x in lidar_offset(truth))
    cmd = [os.path.join(build, 'bin', 'livo-evaluate'), '--est', os.path.join(run_dir, 'odometry.tum'), '--gt', gt,
           '--align', 'se3', '--gt-offset', o, '--json', out, '--quiet']
    # livo-evaluate's messages go to the run's folder, beside its other logs
    if not sv.run(cmd, os.path.join(run_dir, 'evaluate_lidar.txt')):
        return None
    return json.load(open(out))['ate']['rmse']


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--out', required=True)
    ap.add_argument('--configs', default=DEFAULT_CONFIGS)
    ap.add_argument('--seeds', default='701,702,703,704,705', help='seeds not used for tuning (1-3 were)')
    ap.add_argument('--duration', type=float, default=60.0)
    ap.add_argument('--logs', help='simulated logs kept here and reused (default: DIR/logs, removed unless --keep-logs)')
    ap.add_argument('--keep-logs', action='store_true')
    ap.add_argument('--overlay', help='a YAML overlay merged over every config (run_pipeline.sh --overlay)')
    ap.add_argument('--config-dir', default=os.path.join(ROOT, 'config', 'sim'))
    ap.add_argument('--build', help='build directory with bin/ (default: LIVO_BUILD_DIR or build/)')
    ap.add_argument('--compare-to', help="rows.json of another table (today's build) for the comparative bars")
    ap.add_argument('--variants', default='lio,livo')
    a = ap.parse_args()
    build = a.build or sv.build_dir()
    sim, sim_hash, run_hash = sv.keyed_executables('camera_table.py', build, RUN_EXECUTABLES,
                                                   [os.path.join(ROOT, 'scripts', 'run_pipeline.sh')])
    env = dict(os.environ, LIVO_BUILD_DIR=build)
    os.makedirs(a.out, exist_ok=True)
    logs = a.logs or os.path.join(a.out, 'logs')
    os.makedirs(logs, exist_ok=True)
    overlay_bytes = open(a.overlay, 'rb').read() if a.overlay else b''
    variants = a.variants.split(',')
    rows, failures = [], []
    for name in a.configs.split(','):
        config = os.path.join(a.config_dir, name + '.yaml')
        if not os.path.exists(config):
            raise SystemExit('camera_table.py: no config %s' % config)
        config_bytes = open(config, 'rb').read()
        if 'vio' in variants and not sv.has_camera(config):
            raise SystemExit('camera_table.py: %s has no camera' % name)
        duration = DURATIONS.get(name, a.duration)
        for seed in a.seeds.split(','):
            tag = '%s_s%s' % (name, seed)
            base = os.path.join(a.out, tag)
            os.makedirs(base, exist_ok=True)
            log = os.path.join(logs, '%s_%gs.lcmlog' % (tag, duration))
            truth_file = log + '.truth.json'
            log_key = sv.key_of(config_bytes, seed, duration, sim_hash)
            made_log = False
            if not (sv.cached(log, log_key) and os.path.exists(truth_file)):
                print('%s: simulating %g s' % (tag, duration), file=sys.stderr, flush=True)
                part = log + '.part'
                if not sv.run([sim, '--config', config, '--out', part, '--seed', seed,
                               '--duration', str(duration), '--quiet', '--truth', truth_file], base + '.sim.txt'):
                    failures.append('%s: livo-sim failed (%s.sim.txt)' % (tag, base))
                    continue
                os.replace(part, log)
                sv.mark(log, log_key)
                made_log = True
            truth = json.load(open(truth_file))
            row = {'config': name, 'seed': seed, 'duration': duration}
            for v in variants:
                run_dir = os.path.join(base, v)
                done_file = os.path.join(run_dir, 'evaluation_odometry.json')
                run_key = sv.key_of(config_bytes, overlay_bytes, seed, duration, log_key, run_hash, v)
                if not sv.cached(done_file, run_key):
                    print('%s: %s' % (tag, v), file=sys.stderr, flush=True)
                    if os.path.exists(run_dir):
                        shutil.rmtree(run_dir)
                    cmd = [os.path.join(ROOT, 'scripts', 'run_pipeline.sh'), '--log', log, '--config', config,
                           '--out', run_dir, '--processes', {'lio': 'lio', 'livo': 'lio,vio'}[v],
                           '--record', 'ODOMETRY,GROUND_TRUTH,HEALTH']
                    if a.overlay:
                        cmd += ['--overlay', a.overlay]
                    ok = sv.run(cmd, os.path.join(base, v + '.txt'), env)
                    rec = os.path.join(run_dir, 'outputs.lcmlog')
                    at_lidar = evaluate_at_lidar(build, run_dir, rec + ':GROUND_TRUTH', truth) if ok else None
                    if os.path.exists(rec):
                        os.remove(rec)  # the bulk of a run, read by nothing here
                    if not ok or not os.path.exists(done_file) or at_lidar is None:
                        failures.append('%s: the %s run failed (%s/%s.txt)' % (tag, v, base, v))
                        continue
                    sv.mark(done_file, run_key)
                e = json.load(open(done_file))
                row[v] = e['ate']['rmse']
                lidar_file = os.path.join(run_dir, 'evaluation_odometry_lidar.json')
                if os.path.exists(lidar_file):
                    row[v + '_lidar'] = json.load(open(lidar_file))['ate']['rmse']
                row[v + '_coverage'] = e['ate']['coverage']
                cal = calibration_errors(os.path.join(run_dir, 'calibration.csv'), truth)
                if cal and v == 'livo':
                    row['calibration'] = cal
            rows.append(row)
            if made_log and not a.keep_logs and not a.logs:
                os.remove(log)
    json.dump(rows, open(os.path.join(a.out, 'rows.json'), 'w'), indent=1)
    return report(a, rows, failures)


def degenerate_lio(row):
    """The LIO lost a direction it cannot observe (a corridor's axis): its ATE is metres."""
    return row.get('lio', 0.0) > 1.0


def mean(xs):
    return sum(xs) / len(xs) if xs else float('nan')


def report(a, rows, failures):
    lines = ['| config | seed | LIO ATE m | LIVO ATE m | LIVO / LIO | at the LiDAR: LIO / LIVO m (ratio) |'
             ' camera-LiDAR rotation error deg (worst from 30 s / end) |'
             ' camera time offset error ms (worst from 30 s / end) |', '| --- | --- | --- | --- | --- | --- | --- | --- |']
    for r in rows:
        ratio = r['livo'] / r['lio'] if 'lio' in r and 'livo' in r and r['lio'] > 0 else None
        cal = r.get('calibration')
        at_lidar = '-'
        if 'lio_lidar' in r and 'livo_lidar' in r:
            at_lidar = '%.4f / %.4f (%.2f)' % (r['lio_lidar'], r['livo_lidar'], r['livo_lidar'] / r['lio_lidar'])
        lines.append('| %s | %s | %s | %s | %s | %s | %s | %s |' % (
            r['config'], r['seed'], '%.4f' % r['lio'] if 'lio' in r else '-', '%.4f' % r['livo'] if 'livo' in r else '-',
            '%.2f' % ratio if ratio is not None else '-', at_lidar,
            '%.3f / %.3f' % (cal['rot_worst_deg'], cal['rot_end_deg']) if cal else '-',
            '%.2f / %.2f' % (cal['dt_worst_ms'], cal['dt_end_ms']) if cal else '-'))
        if ratio is not None and not degenerate_lio(r) and ratio > 1.05:
            failures.append('%s_s%s: LIVO %.4f m is %.0f %% above the LIO %.4f m' % (
                r['config'], r['seed'], r['livo'], 100 * (ratio - 1), r['lio']))
        if r['config'].startswith('corridor') and 'livo' in r and r['livo'] > 0.10:
            failures.append('%s_s%s: corridor LIVO %.4f m > 0.10 m' % (r['config'], r['seed'], r['livo']))
        if r['config'] in CALIBRATION_CONFIGS and 'livo' in r:
            if not cal:
                failures.append('%s_s%s: no calibration.csv from lio' % (r['config'], r['seed']))
            else:
                if cal['rot_worst_deg'] > 0.1:
                    failures.append('%s_s%s: camera-LiDAR rotation %.3f deg off the truth after 30 s' % (
                        r['config'], r['seed'], cal['rot_worst_deg']))
                if cal['dt_worst_ms'] > 1.0:
                    failures.append('%s_s%s: camera time offset %.2f ms off the truth after 30 s' % (
                        r['config'], r['seed'], cal['dt_worst_ms']))
    both = [r for r in rows if 'lio' in r and 'livo' in r]
    lines.append('')
    if both:
        lio_all, livo_all = mean([r['lio'] for r in both]), mean([r['livo'] for r in both])
        nd = [r for r in both if not degenerate_lio(r)]
        lio_nd, livo_nd = mean([r['lio'] for r in nd]), mean([r['livo'] for r in nd])
        lines.append('Mean ATE over all %d runs: LIO %.4f m, LIVO %.4f m (%.2f x); over the %d where the LIO does not '
                     'degenerate: LIO %.4f m, LIVO %.4f m (%.2f x).' % (len(both), lio_all, livo_all, livo_all / lio_all,
                                                                       len(nd), lio_nd, livo_nd, livo_nd / lio_nd))
        at = [r for r in both if 'lio_lidar' in r and 'livo_lidar' in r]
        if at:
            la, va = mean([r['lio_lidar'] for r in at]), mean([r['livo_lidar'] for r in at])
            lines.append('At the LiDAR (the held lever arm both share left out; not a bar): over %d runs LIO %.4f m, '
                         'LIVO %.4f m (%.2f x).' % (len(at), la, va, va / la))
        for label, l, v in (('all runs', lio_all, livo_all), ('runs where the LIO does not degenerate', lio_nd, livo_nd)):
            if not v <= 0.85 * l:
                failures.append('mean LIVO %.4f m over %s is %.2f x the mean LIO %.4f m (bar 0.85 x)' % (v, label, v / l, l))
    per_config = {}
    for r in rows:
        per_config.setdefault(r['config'], []).append(r)
    lines.append('')
    lines.append('| config | runs | mean LIO ATE m | mean LIVO ATE m |' + (' reference LIO | reference LIVO |' if a.compare_to else ''))
    lines.append('| --- | --- | --- | --- |' + (' --- | --- |' if a.compare_to else ''))
    ref = {}
    if a.compare_to:
        for r in json.load(open(a.compare_to)):
            ref.setdefault(r['config'], []).append(r)
    for name, rs in per_config.items():
        ml, mv = mean([r['lio'] for r in rs if 'lio' in r]), mean([r['livo'] for r in rs if 'livo' in r])
        cells = '| %s | %d | %.4f | %.4f |' % (name, len(rs), ml, mv)
        if a.compare_to:
            seeds = {r['seed'] for r in rs}
            rr = [r for r in ref.get(name, []) if r['seed'] in seeds]
            if len(rr) != len(rs):
                failures.append('%s: the reference table has %d of these %d runs' % (name, len(rr), len(rs)))
            rl, rv = mean([r['lio'] for r in rr if 'lio' in r]), mean([r['livo'] for r in rr if 'livo' in r])
            cells += ' %.4f | %.4f |' % (rl, rv)
            if rr and 'livo' in rs[0] and not mv <= rv:
                failures.append('%s: mean LIVO %.4f m above the reference table\'s %.4f m' % (name, mv, rv))
            if name in CALIBRATION_CONFIGS and rr and not ml <= 0.8 * rl:
                failures.append('%s: mean LIO %.4f m is %.2f x the reference table\'s %.4f m (bar 0.8 x)' % (
                    name, ml, ml / rl, rl))
        lines.append(cells)
    lines.append('')
    return sv.finish(a.out, lines, failures)


if __name__ == '__main__':
    sys.exit(main())
