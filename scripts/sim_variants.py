"""Runs pipeline variants on simulated logs and tabulates their accuracy: the common part of the
tables that compare processes or options on the simulator (planar_wheel_ablation.py,
visual_coupling_table.py). Not a command of its own.

For every config (config/sim/NAME.yaml) and seed, livo-sim writes the log (or a kept one is
reused), then scripts/run_pipeline.sh runs each variant on it, recording only what livo-evaluate
reads, and the row gets per variant the ATE (RMSE after an SE(3) alignment), the end-point drift
and the share of the run with odometry.
"""
import hashlib, json, os, subprocess, sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


class Variant:
    """A pipeline run: the processes started, executables swapped in (process -> binary name in
    build/bin), an overlay merged over the config, the channels recorded besides ODOMETRY,
    GROUND_TRUTH and HEALTH."""

    def __init__(self, name, processes='lio', swaps=None, overlay=None, record=()):
        self.name, self.processes, self.swaps, self.overlay, self.record = name, processes, swaps or {}, overlay, record


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


def has_camera(config):
    """Whether a config file's rig: section has a camera: block."""
    in_rig = False
    for line in open(config):
        if line.startswith('rig:'):
            in_rig = True
        elif line[:1].isalpha():
            in_rig = False
        elif in_rig and line.startswith('  camera:'):
            return True
    return False


def build_dir():
    return os.environ.get('LIVO_BUILD_DIR', os.path.join(ROOT, 'build'))


def require_tools(script, tools):
    bin_dir = os.path.join(build_dir(), 'bin')
    for tool in tools:
        if not os.access(os.path.join(bin_dir, tool), os.X_OK):
            raise SystemExit('%s: %s missing: run scripts/build.sh' % (script, os.path.join(bin_dir, tool)))


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


def sweep(configs, seeds, duration, variants, out, logs=None, keep_logs=False, check_row=None, durations=None,
          resume=False):
    """Runs every variant on every config x seed. Returns (rows, failures): a row is
    {'config', 'seed', 'length', variant name: (ATE m, end-point drift m, coverage)}; check_row(row,
    failures) adds the failures of a finished row. durations maps a config to its own duration.
    Logs go to logs/NAME_sSEED_DURs.lcmlog when `logs` is given (reused when there, kept), else
    beside the runs (removed unless keep_logs). resume: a run whose directory already holds its
    evaluation is not run again (the log is then not needed)."""
    build = build_dir()
    bin_dir = os.path.join(build, 'bin')
    env = dict(os.environ, LIVO_BUILD_DIR=build)
    os.makedirs(out, exist_ok=True)
    rows, failures = [], []
    for name in configs:
        config = config_path('sim_variants.py', name)
        dur = (durations or {}).get(name, duration)
        for seed in seeds:
            tag = '%s_s%s' % (name, seed)
            base = os.path.join(out, tag)
            os.makedirs(base, exist_ok=True)
            if logs:
                os.makedirs(logs, exist_ok=True)
            log = os.path.join(logs, '%s_%gs.lcmlog' % (tag, dur)) if logs else base + '.lcmlog'
            made_log = False
            done = resume and all(evaluation(os.path.join(base, v.name)) for v in variants)
            if not done and not os.path.exists(log):
                print('%s: simulating %g s' % (tag, dur), file=sys.stderr, flush=True)
                part = '%s.%d.part' % (log, os.getpid())  # a concurrent run simulating the same log keeps its own
                if not run([os.path.join(bin_dir, 'livo-sim'), '--config', config, '--out', part, '--seed', seed,
                            '--duration', str(dur), '--quiet'], base + '.sim.txt'):
                    failures.append('%s: livo-sim failed (%s.sim.txt)' % (tag, base))
                    continue
                os.replace(part, log)
                made_log = True
            row = {'config': name, 'seed': seed, 'duration': dur}
            for v in variants:
                run_dir = os.path.join(base, v.name)
                e = evaluation(run_dir) if resume else None
                if e is None:
                    print('%s: %s' % (tag, v.name), file=sys.stderr, flush=True)
                    e = run_variant(v, log, config, run_dir, base, bin_dir, env)
                if e is None:
                    failures.append('%s: the %s run failed (%s/%s.txt)' % (tag, v.name, base, v.name))
                    continue
                row[v.name] = (e['ate']['rmse'], e['end_point']['translation_m'], e['ate']['coverage'])
                row['length'] = e['end_point']['path_length_m']
                if e['ate']['coverage'] < 0.9:
                    failures.append('%s: %s has odometry over only %.0f %% of the run' % (tag, v.name, 100 * e['ate']['coverage']))
            rows.append(row)
            if check_row:
                check_row(row, failures)
            if made_log and not keep_logs and not logs:
                os.remove(log)
    return rows, failures


def markdown(rows, shown, bold=lambda row, variant: False):
    """The table: per row config, seed, seconds, distance and 'ATE / end-point drift' per variant."""
    lines = ['| config | seed | s | distance m | ' + ' | '.join(shown) + ' |',
             '| --- | --- | --- | --- | ' + ' | '.join('---' for _ in shown) + ' |']
    for r in rows:
        cells = []
        for v in shown:
            if v not in r:
                cells.append('-')
                continue
            cell = '%.4f / %.3f' % r[v][:2]
            cells.append('**%s**' % cell if bold(r, v) else cell)
        lines.append('| %s | %s | %g | %s | %s |' % (r['config'], r['seed'], r['duration'],
                                                     '%.0f' % r['length'] if 'length' in r else '-', ' | '.join(cells)))
    return lines


def finish(out, lines, failures):
    """Appends the bars' verdict to the table's lines, writes out/table.md, prints it; the exit status."""
    lines = lines + (['bars missed:'] + ['- ' + x for x in failures] if failures else ['every bar met'])
    text = '\n'.join(lines) + '\n'
    open(os.path.join(out, 'table.md'), 'w').write(text)
    print(text)
    return 1 if failures else 0
