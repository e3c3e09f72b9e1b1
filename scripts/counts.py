#!/usr/bin/env python3
"""Structure counts of the workspace, the same script before and after a restructuring
(issue 40, "Counts before and after, same script"):

- public items per crate: `pub fn|struct|enum|trait|type|const|static|mod|use` at any depth,
  not `pub(crate)`/`pub(super)`, outside `#[cfg(test)]` files (tests.rs, tests/);
- functions longer than 100 lines (from the `fn` line to its closing brace, by brace depth);
- duplicated blocks of 6+ lines between tandem-realtime, tandem-sim and tandem-py (the
  `duplicates` command of the tool library, pairs whose two sides lie in two of those crates);
- owners of concepts: how many places define each (a definition counted by a pattern).

Usage: python3 scripts/counts.py [--json]   (run from the repository root; reads files only)
"""
import json, os, re, shutil, subprocess, sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PUB = re.compile(r'^\s*pub\s+(?:unsafe\s+|async\s+|const\s+)*(fn|struct|enum|trait|type|const|static|mod|use)\b')
FN = re.compile(r'^\s*(?:pub(?:\([^)]*\))?\s+)?(?:const\s+|async\s+|unsafe\s+)*fn\s+(\w+)')


def rust_files(crate_dir):
    for base, dirs, files in os.walk(os.path.join(crate_dir, 'src')):
        for f in files:
            if f.endswith('.rs') and f != 'tests.rs':
                yield os.path.join(base, f)


def crates():
    out = {}
    for name in sorted(os.listdir(os.path.join(ROOT, 'crates'))):
        d = os.path.join(ROOT, 'crates', name)
        if os.path.isfile(os.path.join(d, 'Cargo.toml')):
            out[name] = d
    out['xtask'] = os.path.join(ROOT, 'xtask')
    return out


def strip_test_modules(lines):
    """Drop `#[cfg(test)] mod … { … }` blocks (by brace depth)."""
    out, i = [], 0
    while i < len(lines):
        if lines[i].strip() == '#[cfg(test)]' and i + 1 < len(lines) and re.match(r'\s*mod\s+\w+\s*\{', lines[i + 1]):
            depth, j = 0, i + 1
            while j < len(lines):
                depth += lines[j].count('{') - lines[j].count('}')
                j += 1
                if depth <= 0:
                    break
            i = j
            continue
        out.append(lines[i])
        i += 1
    return out


def long_functions(path, lines, limit=100):
    found = []
    for i, line in enumerate(lines):
        m = FN.match(line)
        if not m or line.rstrip().endswith(';'):
            continue
        depth, started, j = 0, False, i
        while j < len(lines):
            depth += lines[j].count('{') - lines[j].count('}')
            started = started or '{' in lines[j]
            if started and depth <= 0:
                break
            j += 1
        n = j - i + 1
        if n > limit:
            found.append((os.path.relpath(path, ROOT), i + 1, m.group(1), n))
    return found


def duplicates_between(names):
    exe = shutil.which('duplicates')
    if not exe:
        return None
    res = subprocess.run([exe, '--repo', os.path.join(ROOT, 'crates'), '--most', '200', '--seconds', '120'],
                         capture_output=True, text=True)
    pairs = []
    for line in res.stdout.splitlines():
        m = re.match(r'\s*D\d+\s+(\S+):\d+-\d+\s+~\s+(\S+):\d+-\d+', line)
        if not m:
            continue
        a, b = m.group(1).split('/')[0], m.group(2).split('/')[0]
        if a in names and b in names and a != b:
            pairs.append(line.strip())
    return pairs


CONCEPTS = {
    'fault latch (hold the later robot)': r'fn\s+(latch_fault|raise_fault|on_overlap)\b|fault\s*=\s*Some\(',
    'a Cell enum (rounds | continuous)': r'\benum\s+(\w*Cell|Cell(Arg|Kind|Mode)?)\b',
    'resampling onto a grid': r'fn\s+resample\w*\s*[<(]',
    'robot count checked (an error made)': r'RobotCount\s*[{(]|(>|<|>=|<=)\s*MAX_ROBOTS\b',
    'the cyclic plan built from a planner': r'cyclic_plan(_for_order)?\s*\(',
}


def main():
    report = {'public_items': {}, 'long_functions': [], 'concepts': {}}
    for name, d in crates().items():
        count = 0
        for path in rust_files(d):
            lines = strip_test_modules(open(path, encoding='utf-8').read().split('\n'))
            count += sum(1 for l in lines if PUB.match(l))
            report['long_functions'] += long_functions(path, lines)
        report['public_items'][name] = count
    for concept, pat in CONCEPTS.items():
        rx = re.compile(pat)
        places = []
        for name, d in crates().items():
            for path in rust_files(d):
                for i, l in enumerate(strip_test_modules(open(path, encoding='utf-8').read().split('\n'))):
                    if rx.search(l):
                        places.append(f'{os.path.relpath(path, ROOT)}:{i + 1}')
        report['concepts'][concept] = places
    report['duplicates_realtime_sim_py'] = duplicates_between({'tandem-realtime', 'tandem-sim', 'tandem-py'})
    if '--json' in sys.argv:
        json.dump(report, sys.stdout, indent=1, ensure_ascii=False)
        print()
        return
    total = sum(report['public_items'].values())
    print(f'public items: {total}')
    for k, v in report['public_items'].items():
        print(f'  {k:20} {v}')
    print(f"functions over 100 lines: {len(report['long_functions'])}")
    for path, line, name, n in sorted(report['long_functions'], key=lambda x: -x[3]):
        print(f'  {n:4}  {name}  {path}:{line}')
    print('owners of concepts (places matching each definition pattern):')
    for k, v in report['concepts'].items():
        print(f'  {len(v):3}  {k}')
    d = report['duplicates_realtime_sim_py']
    print('duplicated 6+-line blocks between realtime, sim and py:', 'duplicates not on PATH' if d is None else len(d))
    for row in d or []:
        print('  ' + row)


if __name__ == '__main__':
    main()
