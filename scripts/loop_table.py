#!/usr/bin/env python3
"""Issue 47's table: does loop closure cut drift where there is drift and never make a good trajectory worse?

    scripts/loop_table.py --out DIR [--configs campus_loop_long,campus_loop_long_hard] [--seeds 801,802,803,804,805]
                          [--duration 300] [--logs DIR] [--overlay FILE] [--build DIR]

For every config (config/sim/NAME.yaml) and seed, livo-sim writes the log; scripts/run_pipeline.sh
runs the LIO alone (lio) and with loop closure (loop: lio + loop); tests/loop/drift_bar.py gives the
ATE and the drift at the last return to the start of the LIO's odometry and of the loop run's online
odometry, livo-report's trajectory.tum and livo-loop's keyframes.tum; tests/loop/check_loops.py
checks every accepted loop against the truth; tests/loop/keyframe_nees.py the LIO's increments
(filter's part on a config without `_hard`, all of it on one with). DIR/table.md gets a row per run
and per config the mean and spread, and these bars (issue 47):
  - the mean ATE of the online odometry with loop closure at most the LIO's on every config, and at
    most half of it over the runs where the LIO's ATE exceeds 0.2 m (listed; none is no failure);
  - the keyframes' drift bar of tests/loop/drift_bar.py (ATE at most the LIO's, drift at most half);
  - no false loop.
Exit status 1 if a bar is missed or a run failed (a run that did not run is a failure, not a gap).

Results are cached per run in DIR/<config>_s<seed>/<variant>/: a run is reused only if its key (the
config and overlay bytes, seed, duration, the log's key, the executables and scripts it ran) is the one
recorded beside it; logs likewise (config bytes, seed, duration, livo-sim). The logs are simulated
without images (livo-sim --no-images: neither variant reads them, the LIO's outputs are the same, and
the simulation takes a fraction of the time). --logs keeps the logs there (120 s of the corridor: 0.43 GB);
without it each log is removed once its runs are done. --overlay is
merged over every config in both variants. Runs one after the other (each uses both cores).
"""
import argparse, json, os, shutil, statistics, sys

import sim_variants as sv

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TESTS = os.path.join(ROOT, 'tests', 'loop')
RUN_EXECUTABLES = ('livo-lio', 'livo-loop', 'livo-playback', 'livo-record', 'livo-evaluate', 'livo-report',
                   'livo-config')
SCRIPTS = (os.path.join(ROOT, 'scripts', 'run_pipeline.sh'), os.path.join(TESTS, 'drift_bar.py'),
           os.path.join(TESTS, 'check_loops.py'), os.path.join(TESTS, 'keyframe_nees.py'))
VARIANTS = {'lio': 'lio', 'loop': 'lio,loop'}
DRIFTING_LIO_ATE = 0.2  # m: where the LIO drifts this much, loop closure must halve its ATE


def python(script, *args):
    return ['/usr/bin/python3', script] + list(args)


def run_variant(name, log, config, overlay, base, env):
    run_dir = os.path.join(base, name)
    if os.path.exists(run_dir):
        shutil.rmtree(run_dir)
    cmd = [SCRIPTS[0], '--log', log, '--config', config, '--out', run_dir, '--processes', VARIANTS[name],
           '--record', 'ODOMETRY,KEYFRAME,LOOP_CORRECTION,HEALTH,GROUND_TRUTH']
    if overlay:
        cmd += ['--overlay', overlay]
    return sv.run(cmd, os.path.join(base, name + '.txt'), env)


def measure(log, base, bin_dir, hard):
    """The run pair's figures (drift_bar, check_loops, keyframe_nees), or an error string."""
    bar = os.path.join(base, 'drift_bar.json')
    sv.run(python(SCRIPTS[1], '--log', log, '--lio-only', os.path.join(base, 'lio'), '--with-loop',
                  os.path.join(base, 'loop'), '--bin', bin_dir, '--json', bar), os.path.join(base, 'drift_bar.txt'))
    if not os.path.exists(bar):
        return 'drift_bar.py failed (%s/drift_bar.txt)' % base
    row = json.load(open(bar))
    row['false_loops'] = not sv.run(python(SCRIPTS[2], '--log', log, '--loops', os.path.join(base, 'loop', 'loops.json')),
                                    os.path.join(base, 'check_loops.txt'))
    nees = os.path.join(base, 'nees.json')
    judged = [] if hard else ['--filter-only']
    if not sv.run(python(SCRIPTS[3], '--log', log, '--outputs', os.path.join(base, 'lio', 'outputs.lcmlog'),
                         '--json', nees, *judged), os.path.join(base, 'nees.txt')):
        return 'keyframe_nees.py failed (%s/nees.txt)' % base
    row['nees'] = json.load(open(nees))
    loops = json.load(open(os.path.join(base, 'loop', 'loops.json')))
    row['corrections'] = loops.get('corrections', 0)
    row['loops'] = len(loops.get('loops', []))
    return row


def mean_spread(xs):
    return (statistics.mean(xs), statistics.stdev(xs) if len(xs) > 1 else 0.0)


def report(out, rows, failures):
    lines = ['| config | seed | LIO ATE m | online ATE m (ratio) | keyframes ATE m (ratio) | trajectory.tum ATE m | '
             'LIO drift m | keyframes drift m | corrections | loops | LIO increments NEES (band) |',
             '| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |']
    for r in rows:
        t = r['trajectories']
        lio, online, kf, rep = t['lio'], t['online'], t['keyframes'], t['report']
        n = r['nees']
        lines.append('| %s | %s | %.4f | %.4f (%.2f) | %.4f (%.2f) | %.4f | %.3f | %.3f | %d | %d | %.2f (%.2f-%.2f) |' % (
            r['config'], r['seed'], lio['ate'], online['ate'], online['ate'] / lio['ate'], kf['ate'],
            kf['ate'] / lio['ate'], rep['ate'], lio['drift'], kf['drift'], r['corrections'], r['loops'],
            n['mean_nees'], n['band'][0], n['band'][1]))
    lines.append('')
    for config in sorted({r['config'] for r in rows}):
        rs = [r for r in rows if r['config'] == config]
        parts = []
        for key in ('lio', 'online', 'keyframes'):
            m, s = mean_spread([r['trajectories'][key]['ate'] for r in rs])
            parts.append('%s %.4f +- %.4f m' % (key, m, s))
        m, s = mean_spread([r['trajectories']['online']['ate'] / r['trajectories']['lio']['ate'] for r in rs])
        lines.append('- %s (%d runs): mean ATE %s; online / LIO %.2f +- %.2f; NEES %s' % (
            config, len(rs), ', '.join(parts), m, s, ' '.join('%.2f' % r['nees']['mean_nees'] for r in rs)))
        lio_mean = statistics.mean(r['trajectories']['lio']['ate'] for r in rs)
        online_mean = statistics.mean(r['trajectories']['online']['ate'] for r in rs)
        if online_mean > lio_mean:
            failures.append('%s: mean online ATE %.4f m above the LIO\'s %.4f m' % (config, online_mean, lio_mean))
        drifting = [r for r in rs if r['trajectories']['lio']['ate'] > DRIFTING_LIO_ATE]
        if drifting:
            d_lio = statistics.mean(r['trajectories']['lio']['ate'] for r in drifting)
            d_online = statistics.mean(r['trajectories']['online']['ate'] for r in drifting)
            lines.append('  where the LIO drifts more than %.1f m (seeds %s): online %.4f m against %.4f m' % (
                DRIFTING_LIO_ATE, ','.join(r['seed'] for r in drifting), d_online, d_lio))
            if d_online > 0.5 * d_lio:
                failures.append('%s: where the LIO drifts, the online ATE %.4f m is above half the LIO\'s %.4f m' % (
                    config, d_online, d_lio))
        else:
            lines.append('  the LIO drifts more than %.1f m on none of these runs' % DRIFTING_LIO_ATE)
    for r in rows:
        if not r['bar_met']:
            failures.append('%s seed %s: drift_bar.py bar not met (%s_s%s/drift_bar.txt)' % (
                r['config'], r['seed'], r['config'], r['seed']))
        if r['false_loops']:
            failures.append('%s seed %s: false loops (%s_s%s/check_loops.txt)' % (
                r['config'], r['seed'], r['config'], r['seed']))
    return sv.finish(out, lines, failures)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--out', required=True)
    ap.add_argument('--configs', default='campus_loop_long,campus_loop_long_hard')
    ap.add_argument('--seeds', default='801,802,803,804,805', help='seeds nothing was tuned on')
    ap.add_argument('--duration', type=float, default=300.0)
    ap.add_argument('--logs', help='simulated logs kept here and reused (default: removed after their runs)')
    ap.add_argument('--overlay', help='a YAML overlay merged over every config (run_pipeline.sh --overlay)')
    ap.add_argument('--build', help='build directory with bin/ (default: LIVO_BUILD_DIR or build/)')
    a = ap.parse_args()
    build = a.build or sv.build_dir()
    bin_dir = os.path.join(build, 'bin')
    sim, sim_hash, run_hash = sv.keyed_executables('loop_table.py', build, RUN_EXECUTABLES, SCRIPTS)
    env = dict(os.environ, LIVO_BUILD_DIR=build)
    os.makedirs(a.out, exist_ok=True)
    logs = a.logs or os.path.join(a.out, 'logs')
    os.makedirs(logs, exist_ok=True)
    overlay_bytes = open(a.overlay, 'rb').read() if a.overlay else b''
    rows, failures = [], []
    for name in a.configs.split(','):
        config = sv.config_path('loop_table.py', name)
        config_bytes = open(config, 'rb').read()
        for seed in a.seeds.split(','):
            tag = '%s_s%s' % (name, seed)
            base = os.path.join(a.out, tag)
            os.makedirs(base, exist_ok=True)
            log = os.path.join(logs, '%s_%gs.lcmlog' % (tag, a.duration))
            log_key = sv.key_of(config_bytes, seed, a.duration, sim_hash, 'no-images')
            result = os.path.join(base, 'row.json')
            run_key = sv.key_of(config_bytes, overlay_bytes, seed, a.duration, log_key, run_hash)
            if sv.cached(result, run_key):
                rows.append(json.load(open(result)))
                continue
            if not sv.cached(log, log_key):
                print('%s: simulating %g s' % (tag, a.duration), file=sys.stderr, flush=True)
                part = log + '.part'
                if not sv.run([sim, '--config', config, '--out', part, '--seed', seed, '--duration', str(a.duration),
                               '--no-images', '--quiet'], base + '.sim.txt'):
                    failures.append('%s: livo-sim failed (%s.sim.txt)' % (tag, base))
                    continue
                os.replace(part, log)
                sv.mark(log, log_key)
            ran = True
            for v in VARIANTS:
                print('%s: %s' % (tag, v), file=sys.stderr, flush=True)
                if not run_variant(v, log, config, a.overlay, base, env):
                    failures.append('%s: the %s run failed (%s/%s.txt)' % (tag, v, base, v))
                    ran = False
                    break
            row = measure(log, base, bin_dir, name.endswith('_hard')) if ran else None
            for v in VARIANTS:  # the recordings are the bulk of a run: read once, here
                rec = os.path.join(base, v, 'outputs.lcmlog')
                if os.path.exists(rec):
                    os.remove(rec)
            if not a.logs:
                for f in (log, log + '.key'):
                    if os.path.exists(f):
                        os.remove(f)
            if row is None:
                continue
            if isinstance(row, str):
                failures.append('%s: %s' % (tag, row))
                continue
            row.update(config=name, seed=seed, duration=a.duration)
            json.dump(row, open(result, 'w'), indent=1)
            sv.mark(result, run_key)
            rows.append(row)
    json.dump(rows, open(os.path.join(a.out, 'rows.json'), 'w'), indent=1)
    return report(a.out, rows, failures)


if __name__ == '__main__':
    sys.exit(main())
