#!/bin/sh
# The hall's floor by --mode final --patches (docs/radiosity.md, "Some patches of a big scene"):
# bench_radiosity's hall (103 804 patches, 40 000 on the floor), its floor gathered alone against
# every patch gathered, (1) at a fixed SAMPLES a patch (default 128; the floor's answers are the
# same bits in both: the rays and CPU seconds are the cost of the floor alone against the whole),
# and (2) the floor alone to --rel-err 0.05 within SECONDS (default 60).  Prints each run's lines,
# its CPU seconds, and the floor's 95% half-width / B quantiles from its --out rows.  Run from the
# source root: tests/bench/radiosity_hall_floor.sh [builddir [SAMPLES [SECONDS]]]
set -e
B=${1:-build}
N=${2:-128}
T=${3:-60}
"$B/tests/bench_radiosity" hall "$B/hall.obj"
floor() { # the floor rows of a --out CSV: lit count, unreached, half-width / B median, 10%, 90%
    python3 -c '
import csv, math, sys
rel, dark = [], 0
for r in csv.DictReader(open(sys.argv[1])):
    if r["label"] != "floor":
        continue
    if r["R"] and float(r["R"]) > 0:
        rel.append(float(r["R_half"]) / float(r["R"]))
    else:
        dark += 1
rel.sort()
q = lambda p: rel[math.ceil(p * len(rel)) - 1]
print("floor: %d lit, %d dark or not reached; half-width / B median %.4f, 10%% %.4f, 90%% %.4f; %d within 0.05"
      % (len(rel), dark, q(0.5), q(0.1), q(0.9), sum(x <= 0.05 for x in rel)))' "$1"
}
for W in alone whole; do
    P=""
    [ "$W" = alone ] && P="--patches floor"
    uptime
    /usr/bin/time -f "cpu %U s user, %S s sys, %e s wall" "$B/ulam" radiosity "$B/hall.obj" --mode final $P \
        --walks "$N" --threads 2 --out "$B/hall_floor.csv"
    floor "$B/hall_floor.csv"
    grep '"floor"' "$B/hall_floor.csv" > "$B/hall_floor_$W.csv"
done
cmp -s "$B/hall_floor_alone.csv" "$B/hall_floor_whole.csv" && echo "floor rows: the same bits alone and in the whole run"
uptime
/usr/bin/time -f "cpu %U s user, %S s sys, %e s wall" "$B/ulam" radiosity "$B/hall.obj" --mode final --patches floor \
    --rel-err 0.05 --time "$T" --threads 2 --out "$B/hall_floor.csv"
floor "$B/hall_floor.csv"
uptime
