#!/bin/sh
# Every performance figure the README quotes, from one script (issue 29 point 6): each table is
# printed under a line naming the machine, its cores, its load and the date, and the whole output
# is written to docs/benchmarks.md (a README figure that does not reproduce within 1.5x here is
# replaced by this file's).  Run from the source root after `meson compile -C build`:
#
#   tests/bench/readme.sh [build-dir] [--quick] [--only NAME ...]
#
# Tables: walk (steps/s in cache and at n = 1e7, 1 and 2 threads: bench_walk), mmio (Matrix Market
# parse MB/s and peak RSS / CSR: bench_mmio), prepared (one unknown to 1% from a prepared file,
# n = 1e6 and 1e7, against the same query at a fixed walk count and SciPy: bench_prepared),
# threads (a small query's walk phase, default threads vs --threads 1, with two busy loops on the
# machine: the spin-wait check), queries (point-source pairs on R-MAT 2^20 from a prepared file
# in one process against bench_bidir's in-process figure: bench_queries).  --quick runs the
# smaller sizes (prepared to 1e6, queries on 2^16) for a check that the script works; its figures
# are not the README's.  Nothing here is a test: no figure is asserted.
set -u
BUILD=build
QUICK=0
ONLY=""
while [ $# -gt 0 ]; do
    case "$1" in
    --quick) QUICK=1 ;;
    --only) shift; ONLY="$ONLY ${1:-}" ;;
    -*) echo "usage: tests/bench/readme.sh [build-dir] [--quick] [--only walk|mmio|prepared|threads|queries]" >&2; exit 2 ;;
    *) BUILD="$1" ;;
    esac
    shift
done
ULAM="$BUILD/ulam"
T="$BUILD/tests"
OUT=docs/benchmarks.md
[ -x "$ULAM" ] || { echo "readme.sh: $ULAM not built (meson compile -C $BUILD)" >&2; exit 2; }
TMP=$(mktemp -d /tmp/ulam_readme.XXXXXX)
trap 'rm -rf "$TMP"' EXIT INT TERM

# One line: machine, cores, load, date, commit.
stamp() {
    printf 'machine %s, %s cores (%s), load %s, %s UTC, commit %s\n' "$(hostname)" "$(nproc)" \
        "$(grep -m1 'model name' /proc/cpuinfo | sed 's/.*: //')" "$(cut -d' ' -f1-3 /proc/loadavg)" \
        "$(date -u '+%Y-%m-%d %H:%M')" "$(git rev-parse --short HEAD 2>/dev/null || echo unknown)"
}

# Run table NAME (title, command...) unless --only leaves it out; its output in a code block.
table() {
    name=$1 title=$2
    shift 2
    if [ -n "$ONLY" ] && ! echo " $ONLY " | grep -q " $name "; then return 0; fi
    {
        printf '\n## %s\n\n```\n' "$title"
        stamp
        "$@" 2>&1
        printf '```\n'
    } | tee -a "$TMP/out.md"
}

# The spin-wait check: 4096 and 131072 walks of one 1e6 screened query, default threads and --threads 1, each
# 5 times, with two busy loops running (the README's "busy machine").
threads_check() {
    "$T/bench_prepared" --write-only "$TMP/s6.ulam" 1e6 >/dev/null 2>&1 || { echo "could not write the system"; return 0; }
    ( while :; do :; done ) & b1=$!
    ( while :; do :; done ) & b2=$!
    for w in 4096 131072; do
        for t in default 1; do
            set -- ; [ "$t" = 1 ] && set -- --threads 1
            printf '%6d walks, threads %-8s walk seconds:' "$w" "$t"
            for k in 1 2 3 4 5; do
                env -u OMP_WAIT_POLICY "$ULAM" solve "$TMP/s6.ulam" --method walks --index 500001 --walks "$w" "$@" \
                    --json | sed -n 's/.*"seconds": \([0-9.e-]*\), "steps_per_second".*/ \1/p' | cut -c1-8 | tr '\n' ' '
            done
            echo
        done
    done
    kill "$b1" "$b2" 2>/dev/null
    wait "$b1" "$b2" 2>/dev/null
    echo "(two busy loops on the machine's cores; the walk phase as ulam solve --json reports it)"
}

{
    printf '# Benchmarks\n\nWritten by `tests/bench/readme.sh` (do not edit by hand: run it again).\n'
    printf 'Each table names the machine, cores, load and date it was measured at; the README quotes these.\n'
} > "$TMP/out.md"
table walk "Walk rate (bench_walk)" "$T/bench_walk"
table mmio "Matrix Market parse speed and peak memory (bench_mmio)" "$T/bench_mmio"
if [ "$QUICK" = 1 ]; then
    table prepared "One unknown to 1% from a prepared file (bench_prepared, quick: n = 1e6)" "$T/bench_prepared" "$ULAM" "" 1e6
    table queries "Point-source queries in one process (bench_queries, quick: 2^16)" "$T/bench_queries" "$ULAM" 16 4
else
    table prepared "One unknown to 1% from a prepared file (bench_prepared)" "$T/bench_prepared" "$ULAM" "" 1e7
    table queries "Point-source queries in one process (bench_queries)" "$T/bench_queries" "$ULAM" 20 20
fi
table threads "Default threads on a busy machine (passive waiting)" threads_check
if [ -z "$ONLY" ] && [ "$QUICK" = 0 ]; then
    cp "$TMP/out.md" "$OUT"
    echo "readme.sh: wrote $OUT"
else
    echo "readme.sh: --only or --quick: $OUT left as it was"
fi
