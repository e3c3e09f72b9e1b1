#!/usr/bin/env python3
"""Reference-choice criteria compared offline on `cargo xtask fit-defaults`' output
(docs/decisions.md, "The medoid reference by default: labels follow the reference").

Each first-file fit (`first[i]`) is the model with that demonstration as the reference, so a
criterion that reads a fit (its median or mean σ²_D, its length, its high confidence without
the rate term) picks one of them; the table gives the best single first file's high
confidence minus the pick's, mean over seeds / worst seed, per family (percentage points).

    python3 scripts/reference_criteria.py results/fit_defaults.json
"""
import json, sys, collections
d = json.load(open(sys.argv[1]))
crit = {
 'median s2 (min)': lambda v: v['sigma2_median'],
 'mean s2 (min)': lambda v: v['sigma2_mean'],
 'n_ref (shortest)': lambda v: v['n_ref'],
 'n_ref (longest)': lambda v: -v['n_ref'],
 'HC without rate (max)': lambda v: -v['high_without_rate_pct'],
 'median n_ref (closest)': None,
}
rows = collections.defaultdict(lambda: collections.defaultdict(list))
for t in d:
    if t['family'].startswith('sanding'): continue
    firsts = t['first']; best = max(v['high_pct'] for v in firsts)
    rows[t['family']]['default (medoid)'].append(best - t['default']['high_pct'])
    for name, f in crit.items():
        if f is None:
            ns = sorted(v['n_ref'] for v in firsts); med = ns[len(ns)//2]
            pick = min(firsts, key=lambda v: (abs(v['n_ref'] - med), v['reference_demo']))
        else:
            pick = min(firsts, key=lambda v: (f(v), v['reference_demo']))
        rows[t['family']][name].append(best - pick['high_pct'])
names = ['default (medoid)'] + list(crit)
print('| family | ' + ' | '.join(names) + ' |')
print('|---|' + '---|' * len(names))
allv = collections.defaultdict(list)
for fam, r in rows.items():
    cells = []
    for n in names:
        v = r[n]; allv[n] += v
        cells.append(f'{sum(v)/len(v):.2f} / {max(v):.2f}')
    print(f'| {fam} | ' + ' | '.join(cells) + ' |')
print('| **all** | ' + ' | '.join(f'{sum(allv[n])/len(allv[n]):.2f} / {max(allv[n]):.2f}' for n in names) + ' |')
