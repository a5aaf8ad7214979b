#!/bin/sh
# Regenerate docs/radiosity_grid.png and docs/radiosity_grid.csv (docs/radiosity.md): the office
# scene of bench_radiosity (about 10^4 triangles) and its 10 x 10 work-plane grid at 0.8 m,
# every sensor to 2%.  Run from the source root: tests/bench/radiosity_grid.sh [builddir]
set -e
B=${1:-build}
"$B/tests/bench_radiosity" office "$B/office.obj"
"$B/ulam" radiosity "$B/office.obj" --grid 0.3,0.8,0.3:5.7,0.8,3.7:10x10 --rel-err 0.02 --threads 2 \
    --out docs/radiosity_grid.csv --image docs/radiosity_grid.png
