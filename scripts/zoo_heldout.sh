#!/bin/sh
# The task zoo's held-out section of docs/zoo.md, regenerated in batches (docs/zoo.md,
# "Regenerating the tables"): every family × cell is one `cargo xtask zoo` command on the eight
# held-out seeds and N = 2, 3, 4 (30 rounds), each well under 15 minutes on 2 idle cores, each
# saving its own zoo.json; `render` puts them together with `--from` and writes docs/zoo.md and
# docs/figures/zoo.png. A batch whose zoo.json exists is skipped, so an interrupted run resumes.
#
#   scripts/zoo_heldout.sh list                 # the batches, one per line
#   scripts/zoo_heldout.sh run [BATCH...]       # run the given batches (default: all missing)
#   scripts/zoo_heldout.sh align [FAMILY...]    # the alignment against the known warps: export
#                                               # (seconds), then gdtw per family in .venv
#                                               # (bench/peers/README.md; default: all missing)
#   scripts/zoo_heldout.sh render               # docs/zoo.md and the figure from the saved runs
#
# SEEDS (default held-out) and OUT (default results/zoo/heldout) override the seed set and the
# folder; with SEEDS=select, `render` writes the selection section instead.
set -eu
cd "$(dirname "$0")/.."
SEEDS=${SEEDS:-held-out}
OUT=${OUT:-results/zoo/heldout}
FAMILIES="dispensing peg_insertion screw_driving polishing pick_and_place painting deburring cable_routing"
PY=${PY:-.venv/bin/python}

batches() {
    for f in $FAMILIES; do
        echo "$f-rounds"
        echo "$f-continuous"
    done
}

run_batch() {
    b=$1
    f=${b%-*}
    c=${b##*-}
    if [ -f "$OUT/$b/zoo.json" ]; then
        echo "== $b: $OUT/$b/zoo.json exists, skipped"
        return
    fi
    # The reference-choice spread (one fit per demonstration, no rounds) is measured once per
    # task, with its rounds; `--from` keeps it for the continuous cell's fits.
    spread=""
    [ "$c" = continuous ] && spread="--no-spread"
    echo "== $b"
    start=$(date +%s)
    cargo xtask zoo --seeds "$SEEDS" --families "$f" --cell "$c" $spread --threads 2 \
        --out "$OUT/$b" >"$OUT/$b.log" 2>&1 || { tail -20 "$OUT/$b.log"; exit 1; }
    echo "   $(($(date +%s) - start)) s"
}

cmd=${1:-run}
[ $# -gt 0 ] && shift
mkdir -p "$OUT"
case $cmd in
list) batches ;;
run)
    if [ $# -eq 0 ]; then set -- $(batches); fi
    for b in "$@"; do run_batch "$b"; done
    ;;
align)
    [ -d "$OUT/align" ] || cargo xtask zoo --seeds "$SEEDS" --export-alignments "$OUT/align"
    if [ $# -eq 0 ]; then set -- $FAMILIES; fi
    for f in "$@"; do
        if [ -f "$OUT/gdtw-$f.json" ]; then
            echo "== gdtw $f: $OUT/gdtw-$f.json exists, skipped"
            continue
        fi
        echo "== gdtw $f"
        "$PY" bench/peers/zoo_gdtw.py "$OUT/align" --families "$f" --json "$OUT/gdtw-$f.json.part"
        mv "$OUT/gdtw-$f.json.part" "$OUT/gdtw-$f.json"
    done
    ;;
render)
    from=""
    for b in $(batches); do
        if [ -f "$OUT/$b/zoo.json" ]; then
            from="$from${from:+,}$OUT/$b/zoo.json"
        else
            echo "== $b not run yet: rendered without it" >&2
        fi
    done
    [ -n "$from" ] || { echo "no batch has run: $0 run" >&2; exit 1; }
    peer=""
    for f in $FAMILIES; do
        [ -f "$OUT/gdtw-$f.json" ] && peer="$peer${peer:+,}$OUT/gdtw-$f.json"
    done
    [ -n "$peer" ] && peer="--peer-warps $peer"
    cargo xtask zoo --from "$from" $peer --docs --out "$OUT/all"
    ;;
*)
    echo "usage: $0 list | run [BATCH...] | align | render" >&2
    exit 2
    ;;
esac
