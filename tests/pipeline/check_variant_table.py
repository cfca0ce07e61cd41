#!/usr/bin/env python3
"""Checks the table.md of a sim_variants.py script (planar_wheel_ablation.py, visual_coupling_table.py):
    check_variant_table.py TABLE CONFIG SEED VARIANTS
a line per run and variant with every metric a number (ATE, 4-DoF ATE, z at the end, z per 100 m,
roll, pitch, end-point drift, the end-point rotation when the table has that column, and the
ground-map thickness when it has that one: planar_wheel_ablation.py's variants measure it), and a
mean ± sd line per variant. Prints the run's lines."""
import re, sys

table, config, seed, variants = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
lines = open(table).read().splitlines()
rows = [l for l in lines if l.startswith('| %s | %s |' % (config, seed))]
assert len(rows) == variants, rows
header = next(l for l in lines if l.startswith('| config | seed |'))
metrics = 7 + ('end-point rotation deg' in header) + ('ground-map thickness m' in header)
for row in rows:
    cells = [c.strip().strip('*') for c in row.strip().strip('|').split('|')][5:]
    assert len(cells) == metrics and all(re.fullmatch(r'-?\d+\.\d{3,4}', c) for c in cells), cells
summary = [l for l in lines if l.startswith('| %s | ' % config) and ' ± ' in l]
assert len(summary) == variants, summary
print(*rows, sep='\n')
