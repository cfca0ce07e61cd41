#!/usr/bin/env python3
"""The second paper's Table 4 on simulated ground-vehicle scenes, one command.

    scripts/planar_wheel_ablation.py --out DIR [--configs bridge_deck_graded,tree_campus_graded,long_slope]
                                     [--seeds 2,3,4,5,6] [--duration S] [--duration-of NAME=S,...]
                                     [--keep-logs] [--logs DIR] [--resume] [--variants graph,...]
                                     [--sim-overlay config/sim/controls/FILE.yaml]

For every config (config/sim/NAME.yaml) and seed, livo-sim writes the log (without the camera's
images: no variant reads them), then scripts/run_pipeline.sh
runs the LiDAR subsystem alone on it in six variants (sim_variants.py; --logs DIR keeps the logs
there and reuses them when their key matches):
  graph          livo-lio-graph, adaptive planar factors and wheel preintegration (the paper's system)
  graph-wheel    livo-lio-graph, planar factors off            (lio_graph.planar_factors: false)
  graph-planar   livo-lio-graph, wheels off                    (lio_graph.wheel: false)
  graph-bare     livo-lio-graph, neither
  lio            livo-lio (paper 1's ESIKF) with its wheel update
  lio-nowheel    livo-lio without the wheels                   (lio.wheel.enabled: false)
and DIR/table.md gets, per run and variant, the ATE (RMSE after an SE(3) alignment, livo-evaluate), the
ATE after a 4-DoF (yaw + translation) alignment, the vertical drift (the height error at the end and
per 100 m, heights anchored at the first pose), the roll and pitch RMSE, the end-point drift and the
ground-map thickness (livo-evaluate --ground-map: the RMS over 0.5 m cells of the spread of the
ground's estimated heights in the variant's registered scans, which a drifting height or pitch
thickens and the planar factors are meant to keep thin; REGISTERED_SCAN is recorded for it and the
recording deleted after the evaluation, as every run's is); then
per config the mean ± standard deviation of each over the seeds, and the bars (issue 44), on means:
  - the full variant (graph) has the lowest mean vertical drift (|z error at the end|) of the four
    graph variants, and the planar factors cut it by at least 30 % (graph against graph-wheel);
  - on bridge_deck and bridge_deck_graded (the LiDAR-degenerate deck) the wheels halve the mean ATE
    (graph against graph-planar);
  - on long_slope (a narrow vertical field of view that sees little ground ahead) the full variant's
    mean vertical drift is at most half of livo-lio's (lio: paper 1's filter, no planar factors).
Every run lasts its config's sim.duration_s unless --duration or --duration-of says.
A bar whose variants were not all run is missed, not skipped. Seed 1 was used for tuning; the defaults
are five seeds that were not. --resume reuses a run only when its key (config, seed, duration, the
log's key and the executables' hashes, written beside it) matches. Exit status 1 if a bar is missed
or a run failed. Runs one after the other (each run uses both cores).
"""
import argparse, sys

import sim_variants as sv

VARIANTS = [
    sv.Variant('graph', swaps={'lio': 'livo-lio-graph'}, ground_map=True),
    sv.Variant('graph-wheel', swaps={'lio': 'livo-lio-graph'}, overlay='lio_graph: {planar_factors: false}\n',
               ground_map=True),
    sv.Variant('graph-planar', swaps={'lio': 'livo-lio-graph'}, overlay='lio_graph: {wheel: false}\n', ground_map=True),
    sv.Variant('graph-bare', swaps={'lio': 'livo-lio-graph'}, overlay='lio_graph: {planar_factors: false, wheel: false}\n',
               ground_map=True),
    sv.Variant('lio', ground_map=True),
    sv.Variant('lio-nowheel', overlay='lio: {wheel: {enabled: false}}\n', ground_map=True),
]
GRAPH = [v.name for v in VARIANTS if v.swaps]


def check_bars(rows, chosen, failures):
    z = sv.per_config(rows, GRAPH, 'z_end', magnitude=True)
    ate = sv.per_config(rows, GRAPH, 'ate')
    for config in dict.fromkeys(r['config'] for r in rows):
        bar = '%s: the full variant has the lowest mean vertical drift' % config
        if sv.missing_variants(bar, GRAPH, chosen, failures):
            means = {v: sv.mean_sd(xs)[0] for v, xs in z.get(config, {}).items()}
            if len(means) < len(GRAPH):
                failures.append('%s: not checked, a graph variant has no run' % bar)
            else:
                best = min(means, key=means.get)
                if best != 'graph':
                    failures.append('%s: %s has it (%.3f m against %.3f m)' % (bar, best, means[best], means['graph']))
                if not means['graph'] <= 0.7 * means['graph-wheel']:
                    failures.append('%s: the planar factors cut the mean vertical drift from %.3f m to %.3f m, not by 30 %%'
                                    % (config, means['graph-wheel'], means['graph']))
        if config.startswith('long_slope'):
            bar = '%s: the full variant\'s mean vertical drift at most half of livo-lio\'s' % config
            if sv.missing_variants(bar, ('graph', 'lio'), chosen, failures):
                zs = sv.per_config(rows, ('graph', 'lio'), 'z_end', magnitude=True).get(config, {})
                if 'graph' not in zs or 'lio' not in zs:
                    failures.append('%s: not checked, a variant has no run' % bar)
                elif not sv.mean_sd(zs['graph'])[0] <= 0.5 * sv.mean_sd(zs['lio'])[0]:
                    failures.append('%s: %.3f m against %.3f m' % (bar, sv.mean_sd(zs['graph'])[0],
                                                                   sv.mean_sd(zs['lio'])[0]))
        if config.startswith('bridge'):
            bar = '%s: the wheels halve the mean ATE' % config
            if sv.missing_variants(bar, ('graph', 'graph-planar'), chosen, failures):
                g, p = ate.get(config, {}).get('graph'), ate.get(config, {}).get('graph-planar')
                if not g or not p:
                    failures.append('%s: not checked, a variant has no run' % bar)
                elif not sv.mean_sd(g)[0] <= 0.5 * sv.mean_sd(p)[0]:
                    failures.append('%s: %.4f m with them against %.4f m without, not half' % (
                        bar, sv.mean_sd(g)[0], sv.mean_sd(p)[0]))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    sv.add_arguments(ap, 'bridge_deck_graded,tree_campus_graded,long_slope', ','.join(v.name for v in VARIANTS),
                     images=False)
    a = ap.parse_args()
    chosen = sv.chosen_variants('planar_wheel_ablation.py', a, VARIANTS)
    variants = [v for v in VARIANTS if v.name in chosen]
    rows, failures = sv.sweep('planar_wheel_ablation.py', a.configs.split(','), a.seeds.split(','), a.duration,
                              variants, a.out, ('livo-lio', 'livo-lio-graph'), a.logs, a.keep_logs,
                              sv.parse_durations('planar_wheel_ablation.py', a.duration_of), a.resume,
                              images=False, sim_overlay=a.sim_overlay)  # no variant reads the camera
    check_bars(rows, chosen, failures)

    def best(row, v):
        return v in GRAPH and all(row[v]['ate'] <= row[w]['ate'] for w in GRAPH if w in row)

    shown = [v.name for v in variants]
    lines = sv.sim_overlay_line(a) + ['Per run:', '']
    lines += sv.markdown(rows, shown, best)
    lines += ['', 'Per config, mean ± standard deviation over the seeds (vertical errors as magnitudes):', '']
    lines += sv.summary(rows, shown)
    lines += ['', 'graph: planar factors + wheels; graph-wheel: no planar factors; graph-planar: no wheels; '
              'graph-bare: neither (livo-lio-graph). lio / lio-nowheel: livo-lio with / without its wheel update. '
              'Bold: the lowest ATE of the four graph variants.', '']
    return sv.finish(a.out, lines, failures)


if __name__ == '__main__':
    sys.exit(main())
