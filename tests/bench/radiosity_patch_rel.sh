#!/bin/sh
# The table of docs/radiosity.md (patch gathering's --rel-err cost): the Cornell floor at
# --rel-err 0.01 by next-event and collision, its walks and rays, and the oracle (the walks the
# variance needs: max over channels of var / (0.01 B)^2, var = stderr^2 * walks from a fixed
# 10^5-walk run).  Run from the source root: tests/bench/radiosity_patch_rel.sh [builddir]
set -e
B=${1:-build}
S=examples/scenes/cornell_box.obj
date -u; uptime
for e in next-event collision; do
    rel=$("$B/ulam" radiosity $S --patch floor --rel-err 0.01 --estimator $e --threads 2 --json)
    fix=$("$B/ulam" radiosity $S --patch floor --walks 100000 --estimator $e --threads 2 --json)
    /usr/bin/python3 -c '
import json, sys
rel, fix = json.loads(sys.argv[2]), json.loads(sys.argv[3])
oracle = max(se * se * fix["walks"] / (0.01 * x) ** 2 for se, x in zip(fix["stderr"], fix["radiosity"]))
print("%-10s walks %9d rays %9d oracle %10.0f ratio %.2f" % (sys.argv[1], rel["walks"], rel["rays"], oracle,
                                                            rel["walks"] / oracle))
' $e "$rel" "$fix"
done
