#!/bin/sh
# Radiosity's printed 95% intervals, one build beside another (issue 38 point 5): per scene and
# mode, at --rel-err E and at a fixed --walks N, the walks to the stop and the worst channel's
# half-width over 1.96 stderr and over |B| (median of 3 seeds; shooting's whole-scene rule: its
# largest relative half-width and, beside it, the largest relative stderr 1.96 times).  Run from
# the source root: tests/bench/radiosity_intervals.sh BEFORE_BUILDDIR AFTER_BUILDDIR
set -e
A=${1:?before build dir}
B=${2:?after build dir}
date -u; uptime
run() { # scene, label, budget, options...
    s=$1 l=$2 b=$3
    shift 3
    for bd in "$A" "$B"; do
        for seed in 1 2 3; do
            "$bd/ulam" radiosity "$s" $b "$@" --seed $seed --threads 2 --no-mesh-error --json
            echo
        done | /usr/bin/python3 -c '
import json, sys, statistics as st
rows = []
for line in sys.stdin:
    if not line.strip(): continue
    j = json.loads(line)
    if "points" in j: j = j["points"][0]
    if "scene_rule" in j:
        q = j["scene_rule"]
        rows.append((j["walks"], q["worst_half"] / (1.96 * q["worst_se"]), q["worst_half"]))
        continue
    lo, hi = j.get("irradiance_ci95_lo", j.get("ci95_lo")), j.get("irradiance_ci95_hi", j.get("ci95_hi"))
    x, se = j.get("irradiance", j.get("radiosity")), j.get("irradiance_stderr", j.get("stderr"))
    r = [((h - l) / 2 / (1.96 * e), (h - l) / 2 / m) for l, h, m, e in zip(lo, hi, x, se) if m and e and l is not None]
    rows.append((j["walks"], max(a for a, _ in r), max(b for _, b in r)) if r else (j["walks"], float("nan"), float("nan")))
w, a, b = (st.median(c) for c in zip(*rows))
print("%-16s %-22s %-14s %-6s walks %9d  half/1.96se %6.2f  half/B %7.4f" % tuple(sys.argv[1:5] + [w, a, b]))
' "$(basename "$s" .obj)" "$l" "$b" "$([ "$bd" = "$A" ] && echo before || echo after)"
    done
}
C=examples/scenes/cornell_box.obj P=examples/scenes/parallel_squares.obj
for budget in "--rel-err 0.05" "--walks 10000"; do
    run $C "gather next-event" "$budget" --patch floor
    run $C "gather absorption" "$budget" --patch floor --estimator absorption
    run $C "point next-event" "$budget" --at 278,0,279
    run $C "shoot collision" "$budget" --patch floor --mode shoot
    run $C "shoot absorption" "$budget" --patch floor --mode shoot --estimator absorption
    run $P "gather next-event" "$budget" --patch top
    run $P "point next-event" "$budget" --at 0.5,0.5,1
    run $P "shoot collision" "$budget" --patch top --mode shoot
done
run $C "shoot whole scene" "--rel-err 0.1" --mode shoot
run $P "shoot whole scene" "--rel-err 0.05" --mode shoot
