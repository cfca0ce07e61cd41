"""Runs pipeline variants on simulated logs and tabulates their accuracy: the common part of the
tables that compare processes or options on the simulator (planar_wheel_ablation.py,
visual_coupling_table.py). Not a command of its own.

For every config (config/sim/NAME.yaml) and seed, livo-sim writes the log (or a kept one with the
same key is reused), then scripts/run_pipeline.sh runs each variant on it, recording only what
livo-evaluate reads, and the row gets per variant the metrics of livo-evaluate's JSON (METRICS: the
ATE after an SE(3) and after a 4-DoF alignment, the vertical drift, the roll and pitch RMSE, the
end-point drift, and for a variant with ground_map the ground-map thickness of its registered scans)
and the share of the run with odometry. Logs and runs are reused only when the key
written beside them (what they were made from: config bytes, seed, duration, the executables'
hashes) matches.
"""
import hashlib, json, os, subprocess, sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


class Variant:
    """A pipeline run: the processes started, executables swapped in (process -> binary name in
    build/bin), an overlay merged over the config, the channels recorded besides ODOMETRY,
    GROUND_TRUTH and HEALTH, and whether to measure the ground-map thickness (run_pipeline.sh
    --ground-map: REGISTERED_SCAN recorded too, the bulk of the recording while it lasts)."""

    def __init__(self, name, processes='lio', swaps=None, overlay=None, record=(), ground_map=False):
        self.name, self.processes, self.swaps, self.overlay, self.record = name, processes, swaps or {}, overlay, record
        self.ground_map = ground_map


# --- results reused only for the same inputs: a key over everything a result depends on ---
def file_hash(path, h=None):
    h = h or hashlib.sha256()
    with open(path, 'rb') as f:
        for block in iter(lambda: f.read(1 << 20), b''):
            h.update(block)
    return h


def key_of(*parts):
    h = hashlib.sha256()
    for p in parts:
        h.update(repr(p).encode())
        h.update(b'\0')
    return h.hexdigest()


def cached(path, key):
    """Whether path exists with the key `mark` recorded beside it."""
    kf = path + '.key'
    return os.path.exists(path) and os.path.exists(kf) and open(kf).read().strip() == key


def mark(path, key):
    open(path + '.key', 'w').write(key + '\n')


def keyed_executables(script, build, executables, scripts):
    """The simulator (always this tree's: the logs come from it, whichever build runs), its hash and
    the key of what a run executes (`executables` in build/bin, `scripts` by path); exits naming a
    missing executable."""
    bin_dir = os.path.join(build, 'bin')
    sim = os.path.join(build_dir(), 'bin', 'livo-sim')
    for tool in [sim] + [os.path.join(bin_dir, t) for t in executables]:
        if not os.access(tool, os.X_OK):
            raise SystemExit('%s: %s missing: run scripts/build.sh' % (script, tool))
    run_key = key_of(*[file_hash(os.path.join(bin_dir, t)).hexdigest() for t in executables],
                     *[file_hash(s).hexdigest() for s in scripts])
    return sim, file_hash(sim).hexdigest(), run_key


def run(cmd, log, env=None):
    with open(log, 'w') as f:
        return subprocess.run(cmd, stdout=f, stderr=subprocess.STDOUT, env=env).returncode == 0


def evaluation(run_dir, name='odometry'):
    """livo-evaluate's JSON of a run (evaluation_NAME.json), None if there is none."""
    path = os.path.join(run_dir, 'evaluation_%s.json' % name)
    return json.load(open(path)) if os.path.exists(path) else None


def section_line(config, section, prefix):
    """The first line of a config file's top-level `section:` that starts with `prefix`, or None."""
    inside = False
    for line in open(config):
        if line.startswith(section + ':'):
            inside = True
        elif line[:1].isalpha():
            inside = False
        elif inside and line.startswith(prefix):
            return line
    return None


def has_camera(config):
    """Whether a config file's rig: section has a camera: block."""
    return section_line(config, 'rig', '  camera:') is not None


def config_duration(config):
    """A config file's sim.duration_s (seconds), None if it has none."""
    line = section_line(config, 'sim', '  duration_s:')
    return float(line.split(':', 1)[1].split('#', 1)[0]) if line else None


def parse_durations(script, text):
    """--duration-of's NAME=SECONDS,... as a dict."""
    durations = {}
    for item in filter(None, text.split(',')):
        name, _, seconds = item.partition('=')
        try:
            durations[name] = float(seconds)
        except ValueError:
            raise SystemExit('%s: --duration-of wants NAME=SECONDS, not %r' % (script, item))
    return durations


def build_dir():
    return os.environ.get('LIVO_BUILD_DIR', os.path.join(ROOT, 'build'))


def config_path(script, name):
    config = os.path.join(ROOT, 'config', 'sim', name + '.yaml')
    if not os.path.exists(config):
        raise SystemExit('%s: no config %s' % (script, config))
    return config


def run_variant(v, log, config, run_dir, base, bin_dir, env):
    """One variant on one log; its evaluation, or None if the run failed."""
    # only what the evaluation reads: dozens of runs of every output would fill a disk
    cmd = [os.path.join(ROOT, 'scripts', 'run_pipeline.sh'), '--log', log, '--config', config,
           '--out', run_dir, '--processes', v.processes,
           '--record', ','.join(('ODOMETRY', 'GROUND_TRUTH', 'HEALTH') + tuple(v.record))]
    if v.ground_map:
        cmd += ['--ground-map']
    for process, exe in sorted(v.swaps.items()):
        cmd += ['--swap', '%s=%s' % (process, os.path.join(bin_dir, exe))]
    if v.overlay:
        path = os.path.join(base, v.name + '.overlay.yaml')
        open(path, 'w').write(v.overlay)
        cmd += ['--overlay', path]
    ok = run(cmd, os.path.join(base, v.name + '.txt'), env)
    # the recording is the bulk of a run's directory and nothing reads it again
    rec = os.path.join(run_dir, 'outputs.lcmlog')
    if os.path.exists(rec):
        os.remove(rec)
    return evaluation(run_dir) if ok else None


# what a run's row holds per variant, from livo-evaluate's JSON
METRICS = (
    ('ate', 'ATE m', lambda e: e['ate']['rmse']),
    ('ate_4dof', 'ATE 4-DoF m', lambda e: e.get('ate_4dof')),
    ('z_end', 'z error at the end m', lambda e: e.get('vertical', {}).get('end_m')),
    ('z_per_100m', 'z error per 100 m', lambda e: e.get('vertical', {}).get('per_100m')),
    ('roll', 'roll RMSE deg', lambda e: e.get('attitude', {}).get('roll_rmse_deg')),
    ('pitch', 'pitch RMSE deg', lambda e: e.get('attitude', {}).get('pitch_rmse_deg')),
    ('end', 'end-point drift m', lambda e: e['end_point']['translation_m']),
    # the heading a run ends with, against the truth's: on a ground vehicle mostly the yaw drift
    ('end_rotation', 'end-point rotation deg', lambda e: e['end_point'].get('rotation_deg')),
    # None unless the variant asked for it (Variant.ground_map)
    ('ground_thickness', 'ground-map thickness m', lambda e: (e.get('ground_map') or {}).get('thickness_rms_m')),
)
# measured only when a variant asks (None otherwise): a table leaves them out when no run has them
OPTIONAL_METRICS = ('ground_thickness',)
# what a variant's run executes besides its own processes (livo-sim is keyed through the log's key)
PIPELINE_TOOLS = ('livo-playback', 'livo-record', 'livo-evaluate', 'livo-config', 'livo-loginfo', 'livo-report')


def metrics_of(e):
    return {name: get(e) for name, _, get in METRICS} | {'coverage': e['ate']['coverage']}


def sim_overlay_of(script, path):
    """--sim-overlay's file and bytes ((None, b'') without one); exits unless the file exists and holds
    only a sim: section. The overlay changes what the simulator renders, never the rig the estimators
    read (rig:) nor their options: that is what makes it a control."""
    if not path:
        return None, b''
    if not os.path.exists(path):
        raise SystemExit('%s: --sim-overlay: no file %s' % (script, path))
    sections = [line.split(':', 1)[0] for line in open(path) if line[:1].isalpha()]
    if sections != ['sim']:
        raise SystemExit('%s: --sim-overlay %s: wants one top-level section, sim: (has %s)' % (
            script, path, ', '.join(sections) or 'none'))
    return os.path.abspath(path), open(path, 'rb').read()


def sweep(script, configs, seeds, duration, variants, out, executables, logs=None, keep_logs=False,
          durations=None, resume=False, images=True, sim_overlay=None):
    """Runs every variant on every config x seed. Returns (rows, failures): a row is {'config', 'seed',
    'duration', 'length', variant name: metrics_of(its evaluation)}; a variant that did not run or
    wrote no trajectory is a failure and has no entry, one with odometry over less than 90 % of the
    log a failure with its entry. durations maps
    a config to its own duration; a config without one runs for `duration`, or when that is None for
    its own sim.duration_s. images=False simulates without the camera's images (livo-sim --no-images:
    a fraction of the time) when no variant reads them. `executables` (build/bin names) are what the variants run besides
    the pipeline's tools; exits naming a missing one. sim_overlay: a file merged over every config by
    livo-sim only (livo-sim --overlay; a sim: section, sim_overlay_of), e.g. a control with some of the
    simulator's sensor errors off; its bytes are in the log's key and its name in the log's.

    Logs go to logs/NAME_sSEED_DURs[_noimages].lcmlog when `logs` is given (kept), else beside the runs (removed
    unless keep_logs); a log is reused only when its key (the config's bytes, seed, duration and
    livo-sim's hash, written beside it) matches. resume: a run is reused only when the key written
    beside its evaluation (config bytes, the variant's processes, swaps, overlay, recorded channels and
    ground map, seed, duration, the log's key, the executables' and run_pipeline.sh's hashes)
    matches; else it runs again."""
    build = build_dir()
    bin_dir = os.path.join(build, 'bin')
    tools = sorted(set(PIPELINE_TOOLS) | set(executables))
    sim, sim_hash, run_hash = keyed_executables(script, build, tools,
                                                [os.path.join(ROOT, 'scripts', 'run_pipeline.sh')])
    env = dict(os.environ, LIVO_BUILD_DIR=build)
    overlay_path, overlay_bytes = sim_overlay_of(script, sim_overlay)
    overlay_tag = '_' + os.path.basename(overlay_path).rsplit('.', 1)[0] if overlay_path else ''
    os.makedirs(out, exist_ok=True)
    rows, failures = [], []
    for name in configs:
        config = config_path(script, name)
        config_bytes = open(config, 'rb').read()
        dur = (durations or {}).get(name, duration)
        if dur is None:
            dur = config_duration(config)
            if dur is None:
                raise SystemExit('%s: %s has no sim.duration_s: give --duration' % (script, config))
        for seed in seeds:
            tag = '%s_s%s' % (name, seed)
            base = os.path.join(out, tag)
            os.makedirs(base, exist_ok=True)
            if logs:
                os.makedirs(logs, exist_ok=True)
            suffix = ('' if images else '_noimages') + overlay_tag
            log = os.path.join(logs, '%s_%gs%s.lcmlog' % (tag, dur, suffix)) if logs else base + '.lcmlog'
            log_key = key_of(config_bytes, seed, dur, sim_hash, *([] if images else ['no-images']),
                             *([overlay_bytes] if overlay_path else []))
            run_keys = {v.name: key_of(config_bytes, v.processes, sorted(v.swaps.items()), v.overlay, v.record,
                                       seed, dur, log_key, run_hash, *(['ground-map'] if v.ground_map else []))
                        for v in variants}
            done = {v.name: resume and cached(os.path.join(base, v.name, 'evaluation_odometry.json'),
                                              run_keys[v.name]) for v in variants}
            made_log = False
            if not all(done.values()) and not cached(log, log_key):
                print('%s: simulating %g s' % (tag, dur), file=sys.stderr, flush=True)
                part = '%s.%d.part' % (log, os.getpid())  # a concurrent run simulating the same log keeps its own
                if not run([sim, '--config', config, '--out', part, '--seed', seed, '--duration', str(dur),
                            '--quiet'] + ([] if images else ['--no-images']) +
                           (['--overlay', overlay_path] if overlay_path else []), base + '.sim.txt'):
                    failures.append('%s: livo-sim failed (%s.sim.txt)' % (tag, base))
                    continue
                os.replace(part, log)
                mark(log, log_key)
                made_log = True
            row = {'config': name, 'seed': seed, 'duration': dur}
            for v in variants:
                run_dir = os.path.join(base, v.name)
                done_file = os.path.join(run_dir, 'evaluation_odometry.json')
                if done[v.name]:
                    e = evaluation(run_dir)
                else:
                    print('%s: %s' % (tag, v.name), file=sys.stderr, flush=True)
                    if os.path.exists(done_file + '.key'):
                        os.remove(done_file + '.key')
                    e = run_variant(v, log, config, run_dir, base, bin_dir, env)
                    if e is not None:
                        mark(done_file, run_keys[v.name])
                if e is None:
                    failures.append('%s: the %s run failed or wrote no trajectory (%s/%s.txt)' % (tag, v.name, base, v.name))
                    continue
                if e['ate']['coverage'] < 0.9:
                    failures.append('%s: %s has odometry over only %.0f %% of the run' % (tag, v.name, 100 * e['ate']['coverage']))
                row[v.name] = metrics_of(e)
                row['length'] = e['end_point']['path_length_m']
            rows.append(row)
            if made_log and not keep_logs and not logs:
                os.remove(log)
                os.remove(log + '.key')
    return rows, failures


def add_arguments(ap, configs, variants, images=True):
    """The command line every table script shares: --out, --configs (default `configs`), --seeds,
    --duration, --duration-of, --keep-logs, --resume, --logs, --variants (default `variants`)."""
    ap.add_argument('--out', required=True)
    ap.add_argument('--configs', default=configs)
    ap.add_argument('--seeds', default='2,3,4,5,6', help='seeds not used for tuning (seed 1 was)')
    ap.add_argument('--duration', type=float, default=None,
                    help="seconds of every run (default: each config's own sim.duration_s)")
    ap.add_argument('--duration-of', default='', help='NAME=S,...: a duration of its own for a config')
    ap.add_argument('--keep-logs', action='store_true')
    ap.add_argument('--resume', action='store_true',
                    help='reuse the runs already evaluated in --out whose key (config, seed, binaries) matches')
    ap.add_argument('--logs', help='a directory for the logs (NAME_sSEED_DURs%s.lcmlog): kept, reused when their '
                                   'key matches' % ('' if images else '_noimages'))
    ap.add_argument('--variants', default=variants)
    ap.add_argument('--sim-overlay', default='',
                    help='a YAML file with a sim: section merged over every config by the simulator only (e.g. '
                         'config/sim/controls/exact_imu.yaml: a control with sensor errors off); the estimators '
                         'read the configs as they are')


def sim_overlay_line(a):
    """A table's line naming --sim-overlay (empty list without one)."""
    return ['Simulated with `%s` merged over each config (livo-sim --overlay; the estimators read the '
            'configs unchanged).' % a.sim_overlay, ''] if a.sim_overlay else []


def chosen_variants(script, a, variants):
    """The variant names --variants chose (exits naming an unknown one), after checking every
    --configs name has its config."""
    chosen = a.variants.split(',')
    unknown = [v for v in chosen if v not in [x.name for x in variants]]
    if unknown:
        raise SystemExit('%s: unknown variant(s) %s' % (script, ','.join(unknown)))
    for name in a.configs.split(','):
        config_path(script, name)
    return chosen


def missing_variants(bar, needed, chosen, failures):
    """A bar whose variants were not all chosen is a failure (not checked is not met); False then."""
    left_out = [v for v in needed if v not in chosen]
    if left_out:
        failures.append('%s: not checked, variant(s) %s not run' % (bar, ','.join(left_out)))
    return not left_out


def per_config(rows, variants, metric, magnitude=False):
    """{config: {variant: [value per run]}} of one metric over the rows that have it."""
    table = {}
    for r in rows:
        for v in variants:
            if v in r and r[v].get(metric) is not None:
                x = r[v][metric]
                table.setdefault(r['config'], {}).setdefault(v, []).append(abs(x) if magnitude else x)
    return table


def mean_sd(xs):
    """Mean and sample standard deviation (0 for one value)."""
    m = sum(xs) / len(xs)
    sd = (sum((x - m) ** 2 for x in xs) / (len(xs) - 1)) ** 0.5 if len(xs) > 1 else 0.0
    return m, sd


def fmt(x, digits=4):
    return '-' if x is None else '%.*f' % (digits, x)


def table_metrics(rows, shown):
    """METRICS but the optional ones no run of the shown variants measured."""
    return [(m, h, get) for m, h, get in METRICS
            if m not in OPTIONAL_METRICS or any(r[v].get(m) is not None for r in rows for v in shown if v in r)]


def markdown(rows, shown, bold=lambda row, variant: False):
    """Per run and variant every metric (table_metrics); bold: the variants `bold` picks."""
    metrics = table_metrics(rows, shown)
    lines = ['| config | seed | s | distance m | variant | ' + ' | '.join(h for _, h, _ in metrics) + ' |',
             '| --- | --- | --- | --- | --- | ' + ' | '.join('---' for _ in metrics) + ' |']
    for r in rows:
        for v in shown:
            if v not in r:
                cells = ['(did not run)'] + ['-'] * (len(metrics) - 1)
            else:
                cells = [fmt(r[v][m], 3 if m in ('roll', 'pitch', 'end', 'z_end', 'z_per_100m') else 4)
                         for m, _, _ in metrics]
            name = '**%s**' % v if v in r and bold(r, v) else v
            lines.append('| %s | %s | %g | %s | %s | %s |' % (r['config'], r['seed'], r['duration'],
                                                            '%.0f' % r['length'] if 'length' in r else '-', name,
                                                            ' | '.join(cells)))
    return lines


def summary(rows, shown):
    """Per config and variant the mean ± standard deviation over its runs of every metric (the
    vertical errors as magnitudes: a drift up and one down do not cancel)."""
    metrics = table_metrics(rows, shown)
    lines = ['| config | variant | runs | ' + ' | '.join(h for _, h, _ in metrics) + ' |',
             '| --- | --- | --- | ' + ' | '.join('---' for _ in metrics) + ' |']
    tables = {m: per_config(rows, shown, m, magnitude=m in ('z_end', 'z_per_100m')) for m, _, _ in metrics}
    for config in dict.fromkeys(r['config'] for r in rows):
        for v in shown:
            cells, n = [], 0
            for m, _, _ in metrics:
                xs = tables[m].get(config, {}).get(v, [])
                n = max(n, len(xs))
                cells.append('%s ± %s' % (fmt(mean_sd(xs)[0]), fmt(mean_sd(xs)[1])) if xs else '-')
            lines.append('| %s | %s | %d | %s |' % (config, v, n, ' | '.join(cells)))
    return lines


def finish(out, lines, failures):
    """Appends the bars' verdict to the table's lines, writes out/table.md, prints it; the exit status."""
    lines = lines + (['bars missed:'] + ['- ' + x for x in failures] if failures else ['every bar met'])
    text = '\n'.join(lines) + '\n'
    open(os.path.join(out, 'table.md'), 'w').write(text)
    print(text)
    return 1 if failures else 0
