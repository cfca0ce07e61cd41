#!/usr/bin/env python3
"""Issue 19's table: the estimators on the hard simulator, seeds not tuned on, one command.

    scripts/hard_table.py --out DIR [--configs room_hard,corridor_hard,...] [--seeds 301,302,303]
                          [--duration 60] [--long-duration 300] [--keep-logs]
                          [--without-loop] [--livo-tolerance 0.05]

Issue 15's table (the camera never makes the estimate worse) is the same command on any sim configs
with --without-loop --livo-tolerance 0.05 (LIVO within +5 % of the LIO, and at least 30 % below it
where the LiDAR degenerates). Issue 43's table (the camera earns its keep on a rig calibrated as
well as real ones; the calibration in the filter against the truth) is scripts/camera_table.py.

For every config (config/sim/NAME.yaml) and seed: livo-sim writes the log (campus_loop_long*: the
long duration), then scripts/run_pipeline.sh runs
  lio    the LIO alone                     -> ATE, ATE per distance, divergence, degenerate sweeps
  livo   lio + vio (configs with a camera) -> ATE against the LIO's
  loop   lio + loop (configs with loop:)   -> false loops (tests/loop/check_loops.py against the
                                              ground truth), end-point drift against the LIO's
and DIR/table.md gets one row per run with the bars of issue 19 checked:
  LIO ATE <= 0.10 m and <= 0.5 % of the distance, no divergence (odometry over >= 90 % of the run,
  no pose more than 1 m off), degeneracy flagged in a corridor, LIVO ATE no worse than the LIO's,
  no false loop, and on campus_loop_long_hard the end-point drift cut by at least half.
Where the LIO flags most sweeps degenerate (the corridor: its axis is unobservable to the LiDAR and
left to the IMU) the ATE and divergence bars apply to LIVO, the estimate with a sensor for that axis.
End-point drift: the drift at the run's last return within 10 m of its start (check_loops.revisit_drift).
Exit status 1 if any bar is missed. Runs one after the other (each run uses both cores).
"""
import argparse, json, os, struct, subprocess, sys

import sim_variants as sv

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, 'tests', 'loop'))
import check_loops as cl  # noqa: E402  (LCM log reading, ground truth, interpolation; pure Python)

DEFAULT_CONFIGS = ('room_hard,corridor_hard,campus_loop_hard,campus_loop_long_hard,parking_hard,euroc_v1_01_hard,'
                   'room_fr2_desk_hard')


def degenerate_sweeps(outputs):
    """(ODOMETRY messages with the degenerate flag set, all ODOMETRY messages) (livo.odometry_t)."""
    n = total = 0
    for _, p in cl.read_channel(outputs, 'ODOMETRY'):
        total += 1
        o = 16  # fingerprint, utime
        for _ in range(2):  # parent_frame, child_frame
            length, = struct.unpack_from('>i', p, o)
            o += 4 + length
        o += 8 * (3 + 4 + 3 + 3 + 36 + 9) + 4  # poses, covariances, num_residuals
        n += p[o] != 0
    return n, total


def section_names(config):
    return {line.split(':')[0] for line in open(config) if line[:1].isalpha() and ':' in line}


def diverged(ate):
    return ate['coverage'] < 0.9 or ate['max'] > 1.0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--out', required=True)
    ap.add_argument('--configs', default=DEFAULT_CONFIGS)
    ap.add_argument('--seeds', default='301,302,303', help='seeds not used for tuning (1-5 were; 101-103 and 201-203 were looked at)')
    ap.add_argument('--duration', type=float, default=60.0)
    ap.add_argument('--long-duration', type=float, default=300.0, help='campus_loop_long*')
    ap.add_argument('--keep-logs', action='store_true')
    ap.add_argument('--without-loop', action='store_true', help='skip the loop-closure runs')
    ap.add_argument('--livo-tolerance', type=float, default=0.0,
                    help='LIVO passes at most this fraction above the LIO (issue 15: 0.05); where the LiDAR '
                         'degenerates LIVO must then also be at least 30 %% below it')
    a = ap.parse_args()
    build = os.environ.get('LIVO_BUILD_DIR', os.path.join(ROOT, 'build'))
    bin_dir = os.path.join(build, 'bin')
    env = dict(os.environ, LIVO_BUILD_DIR=build)
    os.makedirs(a.out, exist_ok=True)
    rows, failures = [], []

    for name in a.configs.split(','):
        config = os.path.join(ROOT, 'config', 'sim', name + '.yaml')
        if not os.path.exists(config):
            raise SystemExit('hard_table.py: no config %s' % config)
        sections = section_names(config)
        duration = a.long_duration if name.startswith('campus_loop_long') else a.duration
        for seed in a.seeds.split(','):
            tag = '%s_s%s' % (name, seed)
            base = os.path.join(a.out, tag)
            os.makedirs(base, exist_ok=True)
            log = base + '.lcmlog'
            print('%s: simulating %.0f s' % (tag, duration), file=sys.stderr, flush=True)
            if not sv.run([os.path.join(bin_dir, 'livo-sim'), '--config', config, '--out', log, '--seed', seed,
                        '--duration', str(duration), '--quiet'], base + '.sim.txt'):
                failures.append('%s: livo-sim failed (%s.sim.txt)' % (tag, base))
                continue
            variants = [('lio', 'lio')]
            if 'vio' in sections and sv.has_camera(config):
                variants.append(('livo', 'lio,vio'))
            if 'loop' in sections and not a.without_loop:
                variants.append(('loop', 'lio,loop'))
            ok = {}
            for variant, processes in variants:
                print('%s: %s' % (tag, variant), file=sys.stderr, flush=True)
                ok[variant] = sv.run([os.path.join(ROOT, 'scripts', 'run_pipeline.sh'), '--log', log, '--config', config,
                                   '--out', os.path.join(base, variant), '--processes', processes],
                                  os.path.join(base, variant + '.txt'), env)
            row = {'config': name, 'seed': seed}
            lio = sv.evaluation(os.path.join(base, 'lio'))
            if not ok['lio'] or lio is None:
                failures.append('%s: the LIO run failed (%s/lio.txt)' % (tag, base))
                rows.append(row)
                continue
            ate = lio['ate']
            length = lio['end_point']['path_length_m']
            degenerate, sweeps = degenerate_sweeps(os.path.join(base, 'lio', 'outputs.lcmlog'))
            row.update(lio_ate=ate['rmse'], length=length, percent=100.0 * ate['rmse'] / max(length, 1e-9),
                       diverged=diverged(ate), degenerate=degenerate)
            livo = sv.evaluation(os.path.join(base, 'livo')) if ok.get('livo') else None
            if 'livo' in ok:
                row['livo_ate'] = livo['ate']['rmse'] if livo else float('nan')
            # A scene the LiDAR cannot observe in some direction (flagged on most sweeps: the corridor's
            # axis) leaves that direction to the IMU alone, whose error grows with t^2 whatever the
            # filter does; there the accuracy bars apply to the estimate that has a sensor for it (LIVO).
            judged, judged_ate = ('LIO', ate)
            if degenerate >= 0.5 * max(sweeps, 1) and 'livo' in ok:
                judged, judged_ate = ('LIVO', livo['ate'] if livo else None)
                row['judged'] = 'LIVO'
            if judged_ate is None:
                failures.append('%s: the LIVO run failed (%s/livo.txt)' % (tag, base))
            else:
                percent = 100.0 * judged_ate['rmse'] / max(length, 1e-9)
                if judged_ate['rmse'] > 0.10 or percent > 0.5:
                    failures.append('%s: %s ATE %.4f m, %.3f %% of %.0f m' % (tag, judged, judged_ate['rmse'], percent, length))
                if diverged(judged_ate):
                    failures.append('%s: the %s diverged (coverage %.2f, max error %.2f m)' % (
                        tag, judged, judged_ate['coverage'], judged_ate['max']))
            if name.startswith('corridor') and degenerate == 0:
                failures.append('%s: no degenerate sweep flagged in the corridor' % tag)
            if 'livo' in ok and not row['livo_ate'] <= (1.0 + a.livo_tolerance) * row['lio_ate']:
                failures.append('%s: LIVO ATE %.4f m worse than the LIO\'s %.4f m%s' % (
                    tag, row['livo_ate'], row['lio_ate'],
                    ' (+%.0f %% allowed)' % (100 * a.livo_tolerance) if a.livo_tolerance else ''))
            if 'livo' in ok and a.livo_tolerance and row.get('judged') == 'LIVO' and not row['livo_ate'] <= 0.7 * row['lio_ate']:
                failures.append('%s: LIVO ATE %.4f m not 30 %% below the degenerate LIO\'s %.4f m' % (
                    tag, row['livo_ate'], row['lio_ate']))
            if 'loop' in ok:
                loops_json = os.path.join(base, 'loop', 'loops.json')
                if not ok['loop'] or not os.path.exists(loops_json):
                    failures.append('%s: the loop run failed (%s/loop.txt)' % (tag, base))
                else:
                    check = subprocess.run([sys.executable, os.path.join(ROOT, 'tests', 'loop', 'check_loops.py'),
                                            '--log', log, '--loops', loops_json], capture_output=True, text=True)
                    row['loops'] = len(json.load(open(loops_json))['loops'])
                    counts = [l.split() for l in check.stdout.splitlines() if l.startswith('false loops:')]
                    if check.returncode not in (0, 1) or not counts:
                        failures.append('%s: check_loops.py failed: %s' % (tag, check.stderr.strip()[-200:]))
                        counts = [['', '', '0']]
                    row['false_loops'] = int(counts[-1][2])
                    if row['false_loops']:
                        failures.append('%s: %d false loops' % (tag, row['false_loops']))
                    gt = cl.read_ground_truth(log)
                    times = [g[0] for g in gt]
                    row['end_lio'] = cl.revisit_drift(cl.read_tum(os.path.join(base, 'lio', 'odometry.tum')), gt, times)
                    row['end_loop'] = cl.revisit_drift(cl.read_tum(os.path.join(base, 'loop', 'keyframes.tum')), gt, times)
                    if name.startswith('campus_loop_long') and not row['end_loop'] <= 0.5 * row['end_lio']:
                        failures.append('%s: end-point drift %.3f m with loop closure against %.3f m without' % (
                            tag, row['end_loop'], row['end_lio']))
            rows.append(row)
            if not a.keep_logs:
                os.remove(log)

    def f(row, key, fmt):
        return fmt % row[key] if key in row else '-'
    lines = ['| config | seed | distance m | LIO ATE m | % of distance | diverged | degenerate sweeps | LIVO ATE m |'
             ' loops (false) | drift at the return to the start m: LIO / loop |',
             '| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |']
    for r in rows:
        loops = '%d (%d)' % (r['loops'], r['false_loops']) if 'loops' in r else '-'
        drift = '%.3f / %.3f' % (r['end_lio'], r['end_loop']) if 'end_loop' in r else '-'
        lines.append('| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |' % (
            r['config'], r['seed'], f(r, 'length', '%.0f'), f(r, 'lio_ate', '%.4f'), f(r, 'percent', '%.3f'),
            ('yes' if r['diverged'] else 'no') if 'diverged' in r else '-', f(r, 'degenerate', '%d'),
            f(r, 'livo_ate', '%.4f') + (' (judged: LIO degenerate)' if r.get('judged') == 'LIVO' else ''), loops, drift))
    lines.append('')
    return sv.finish(a.out, lines, failures)


if __name__ == '__main__':
    sys.exit(main())
