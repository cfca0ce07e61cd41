#!/usr/bin/env python3
"""Which of a hard rig's errors costs the LIO and the camera what: each error the simulator draws
switched off on its own, the estimators run unchanged (issue 43: "measure which of them the filter
can take out").

    scripts/error_budget.py --out DIR [--config room_hard] [--seeds 802,803,804,805,806]
                            [--variants as_is,exact_calibration,...] [--duration 60] [--logs DIR]

Each variant is the config with one overlay merged over it (livo-config merge; the rig's stated
figure changes with the simulator's where the variant changes what the sensor is, e.g. its range
noise). scripts/camera_table.py runs the LIO alone and the LIO with the camera on every variant and
seed (its cache: a run is reused only for the same config bytes, seed, log and executables), and
DIR/budget.md gets per variant the mean and spread of both ATEs, their ratio to the config as it
is, and the camera's rotation against the LiDAR at the end against the simulator's truth.
Exit status 1 if a variant or a run did not run.
"""
import argparse, json, math, os, subprocess, sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, 'scripts'))
import sim_variants as sv  # noqa: E402

# one error each, as the hard configs' simulator draws it (processes/sim/README.md)
VARIANTS = {
    'as_is': '',
    'exact_calibration': 'sim: {calibration_errors: {draw: false, lidar: {translation: [0, 0, 0], rpy_deg: [0, 0, 0]},'
                         ' camera: {translation: [0, 0, 0], rpy_deg: [0, 0, 0]},'
                         ' lidar_time_offset_s: 0.0, camera_time_offset_s: 0.0}}\n',
    'global_shutter': 'rig: {camera: {rolling_shutter_s: 0.0}}\nsim: {camera: {rolling_shutter_s: 0.0}}\n',
    'ideal_imu': 'sim: {imu: {gyro_scale_ppm: [0, 0, 0], accel_scale_ppm: [0, 0, 0], gyro_misalignment_mrad: [0, 0, 0],'
                 ' accel_misalignment_mrad: [0, 0, 0], gyro_g_sensitivity: [0, 0, 0], gyro_bias_per_c: [0, 0, 0],'
                 ' accel_bias_per_c: [0, 0, 0]}}\n',
    'range_noise_1cm': 'rig: {lidar: {range_noise_std: 0.01}}\n',
    'no_beam_footprint': 'sim: {lidar: {range_noise_per_m: 0.0, max_range_at_10pct: 0.0, beam_divergence_mrad: [0.0, 0.0]}}\n',
}


def mean_sd(xs):
    if not xs:
        return float('nan'), float('nan')
    m = sum(xs) / len(xs)
    sd = math.sqrt(sum((x - m) ** 2 for x in xs) / (len(xs) - 1)) if len(xs) > 1 else 0.0
    return m, sd


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--out', required=True)
    ap.add_argument('--config', default='room_hard')
    ap.add_argument('--seeds', default='802,803,804,805,806', help='not used for tuning (801 and 1-3 were)')
    ap.add_argument('--variants', default=','.join(VARIANTS))
    ap.add_argument('--duration', type=float, default=60.0)
    ap.add_argument('--logs', help='simulated logs kept here and reused (default: DIR/logs)')
    a = ap.parse_args()
    names = a.variants.split(',')
    for v in names:
        if v not in VARIANTS:
            raise SystemExit('error_budget.py: unknown variant %s (known: %s)' % (v, ', '.join(VARIANTS)))
    build = sv.build_dir()
    base = os.path.join(ROOT, 'config', 'sim', a.config + '.yaml')
    if not os.path.exists(base):
        raise SystemExit('error_budget.py: no config %s' % base)
    out = os.path.abspath(a.out)
    configs = os.path.join(out, 'configs')
    os.makedirs(configs, exist_ok=True)
    scenes = os.path.join(configs, 'scenes')  # the configs name their scene relative to themselves
    if not os.path.exists(scenes):
        os.symlink(os.path.join(ROOT, 'config', 'sim', 'scenes'), scenes)
    tags = []
    for v in names:
        tag = '%s__%s' % (a.config, v)
        overlay = os.path.join(configs, v + '.overlay.yaml')
        with open(overlay, 'w') as f:
            f.write(VARIANTS[v] or '{}\n')
        merged = os.path.join(configs, tag + '.yaml')
        cmd = [os.path.join(build, 'bin', 'livo-config'), 'merge', base, '--overlay', overlay, '--out', merged]
        if subprocess.run(cmd).returncode != 0:
            raise SystemExit('error_budget.py: %s did not merge (%s)' % (v, ' '.join(cmd)))
        tags.append(tag)
    table = os.path.join(out, 'runs')
    rows_file = os.path.join(table, 'rows.json')
    if os.path.exists(rows_file):
        os.remove(rows_file)  # a call that stops early must not leave an earlier call's rows to be read
    cmd = [sys.executable, os.path.join(ROOT, 'scripts', 'camera_table.py'), '--out', table, '--config-dir', configs,
           '--configs', ','.join(tags), '--seeds', a.seeds, '--duration', str(a.duration),
           '--logs', a.logs or os.path.join(out, 'logs')]
    subprocess.run(cmd, stdout=subprocess.DEVNULL)  # its own bars are not this table's: the rows decide
    if not os.path.exists(rows_file):
        raise SystemExit('error_budget.py: camera_table.py wrote no rows (%s)' % table)
    rows = json.load(open(rows_file))
    seeds = a.seeds.split(',')
    failures, lines = [], []
    lines.append('# %s: the hard rig\'s errors one at a time (seeds %s, %g s)\n' % (a.config, a.seeds, a.duration))
    lines.append('| variant | LIO ATE mm | LIVO ATE mm | LIO / as is | LIVO / as is | LIVO / LIO | camera-LiDAR rotation error deg at the end |')
    lines.append('| --- | --- | --- | --- | --- | --- | --- |')
    ref = None
    for v, tag in zip(names, tags):
        got = {r['seed']: r for r in rows if r['config'] == tag}
        missing = [s for s in seeds if s not in got or 'lio' not in got[s] or 'livo' not in got[s]]
        if missing:
            failures.append('%s: no run for seeds %s (%s/%s_s*)' % (v, ','.join(missing), table, tag))
            continue
        lio = [1e3 * got[s]['lio'] for s in seeds]
        livo = [1e3 * got[s]['livo'] for s in seeds]
        rot = [got[s]['calibration']['rot_end_deg'] for s in seeds if 'calibration' in got[s]]
        (ml, sl), (mv, sdv), (mr, sr) = mean_sd(lio), mean_sd(livo), mean_sd(rot)
        if v == 'as_is':
            ref = (ml, mv)
        rel = ('%.2f' % (ml / ref[0]), '%.2f' % (mv / ref[1])) if ref else ('-', '-')
        lines.append('| %s | %.1f ± %.1f | %.1f ± %.1f | %s | %s | %.2f | %.2f ± %.2f |' % (
            v, ml, sl, mv, sdv, rel[0], rel[1], mv / ml, mr, sr))
    lines.append('\nmean ± sample standard deviation over the seeds; "as is" is the config unchanged.')
    if failures:
        lines.append('\nvariants that did not run:')
        lines += ['- ' + f for f in failures]
    text = '\n'.join(lines) + '\n'
    open(os.path.join(out, 'budget.md'), 'w').write(text)
    print(text, end='')
    return 1 if failures else 0


if __name__ == '__main__':
    sys.exit(main())
