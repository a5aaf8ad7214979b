#!/usr/bin/env python3
"""Single source beside igraph (issue 43): `ulam solve G.ulam --source S --top 100 --json` on the
prepared graph beside igraph's personalized_pagerank (PRPACK, machine precision) with the same
source, in one run, on an R-MAT digraph of 2^L nodes and 8 2^L edges (tests/bench/bench_fpush.py's
draw: a = 0.57, b = c = 0.19, d = 0.05, random relabelling, multi-edges kept as weights), each node
without an out-edge given one to a random node (so PRPACK's dangling rule does not enter and its
pi is 0.15 (I - M)^-1 e_s with M = 0.85 P', the column ulam estimates).

Per source: igraph's call (wall and CPU seconds of personalized_pagerank alone; building its
graph is reported apart), ulam's query (JSON "seconds" and "cpu_seconds": push and walks) and
its whole process on the prepared file (wall; CPU of the child), the ratios ulam / igraph, and
coverage: how many of ulam's top-100 95% intervals hold igraph's pi / 0.15, and how many of
igraph's top 100 are in ulam's.  Dated, with the machine, cores and load average.

Usage: bench_igraph.py path/to/ulam [L [SOURCES]] (default 20 and 3).  Needs NumPy, SciPy and
python3-igraph (skipped with a note when missing: the peer is optional).

At scale (issue 43's 2^24 nodes and 2^28 edges, beyond igraph and SciPy in this machine's memory):
bench_igraph.py path/to/ulam --prepared G.ulam [SOURCES], G.ulam written once by
build/tests/bench_rmat_write G.ulam 24 (no Matrix Market text): ulam alone, each query's whole
process under /usr/bin/time (wall, CPU, peak RSS) with its JSON's walks, push operations and
seconds, and how many top-100 lines carry an interval."""
import json
import os
import resource
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))


def edges(L, seed=1):
    """bench_fpush.rmat's draw as edge arrays, every node given an out-edge."""
    import numpy as np
    from bench_fpush import rmat_edges
    n = 1 << L
    src, dst, rng = rmat_edges(L, seed)
    dangling = np.flatnonzero(np.bincount(src, minlength=n) == 0)
    src = np.concatenate([src, dangling])
    dst = np.concatenate([dst, rng.integers(0, n, dangling.size)])
    return n, src, dst


def prepared(ulam, path, nsrc):
    """ulam alone on a prepared graph (no peer): wall, CPU and peak RSS of each query's process."""
    import random
    with open(path, "rb") as f:
        head = f.read(48)
    n = int.from_bytes(head[24:32], "little")
    print(f"prepared {path}: n = {n}, nnz = {int.from_bytes(head[40:48], 'little')}; machine: {os.uname().nodename}, "
          f"{os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}, {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}")
    rng = random.Random(7)
    print(f"{'source':>9} {'wall':>7} {'cpu':>7} {'maxrss_MiB':>10} {'query_s':>8} {'push_s':>7} {'push_ops':>11} "
          f"{'walks':>9} {'with_ci':>7}")
    for _ in range(nsrc):
        s = rng.randrange(n)
        with tempfile.NamedTemporaryFile("r") as t:
            p = subprocess.run(["/usr/bin/time", "-f", "%e %U %S %M", "-o", t.name, ulam, "solve", path, "--source",
                                str(s + 1), "--top", "100", "--json", "--threads", "1", "--seed", str(s + 1)],
                               capture_output=True, text=True)
            wall, u, sy, rss = t.read().split()[-4:]
        if p.returncode:
            print(p.stderr)
            return 1
        o = json.loads(p.stdout)
        ci = sum(c["ci95"][0] is not None for c in o["top"])
        print(f"{s + 1:>9} {float(wall):>7.2f} {float(u) + float(sy):>7.2f} {int(rss) / 1024:>10.0f} {o['seconds']:>8.3f} "
              f"{o['push_seconds']:>7.3f} {o['push_ops']:>11} {o['walks']:>9} {ci:>4}/{len(o['top'])}")
    print(f"load now {os.getloadavg()[0]:.1f} (timings under load are upper bounds)")
    return 0


def main():
    args = sys.argv[1:]
    ulam = args.pop(0)
    if args and args[0] == "--prepared":
        return prepared(ulam, args[1], int(args[2]) if len(args) > 2 else 3)
    L = int(args[0]) if args else 20
    nsrc = int(args[1]) if len(args) > 1 else 3
    try:
        import numpy as np
        import scipy.sparse as sp
        import igraph
    except ImportError as e:
        print(f"SKIP bench_igraph: {e.name} not installed (apt-get install python3-igraph python3-scipy): no peer")
        return 0
    from bench_fpush import write_mtx
    t0 = time.time()
    n, src, dst = edges(L)
    out = np.bincount(src, minlength=n).astype(float)
    M = sp.csr_matrix((0.85 / out[src], (dst, src)), shape=(n, n))  # M_ji = 0.85 P_ij, multi-edges summed
    M.sum_duplicates()
    print(f"R-MAT 2^{L}: n = {n}, edges = {src.size}, nnz(M) = {M.nnz}; drawn in {time.time() - t0:.1f} s")
    print(f"machine: {os.uname().nodename}, {os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}, "
          f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}; igraph {igraph.__version__}")
    t0 = time.time()
    g = igraph.Graph(n=n, edges=np.column_stack([src, dst]), directed=True)
    build = time.time() - t0
    rows = []
    with tempfile.TemporaryDirectory() as d:
        mtx, sysf = os.path.join(d, "g.mtx"), os.path.join(d, "g.ulam")
        write_mtx(mtx, M)
        t0 = time.time()
        subprocess.run([ulam, "prepare", mtx, "--transpose", "-o", sysf, "-q"], check=True, capture_output=True)
        prep = time.time() - t0
        os.unlink(mtx)
        print(f"igraph graph built in {build:.2f} s; ulam prepare {prep:.2f} s (once; the queries below read the "
              f"prepared file)")
        rng = np.random.default_rng(7)
        for s in rng.choice(n, size=nsrc, replace=False):
            c0, w0 = time.process_time(), time.perf_counter()
            pi = np.array(g.personalized_pagerank(reset_vertices=[int(s)], damping=0.85, directed=True,
                                                  implementation="prpack"))
            ig_w, ig_c = time.perf_counter() - w0, time.process_time() - c0
            exact = pi / 0.15
            r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
            w0 = time.perf_counter()
            p = subprocess.run([ulam, "solve", sysf, "--source", str(s + 1), "--top", "100", "--json", "--threads", "1",
                                "--seed", str(s + 1)], capture_output=True, text=True)
            proc_w = time.perf_counter() - w0
            r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
            if p.returncode:
                print(p.stderr)
                return 1
            o = json.loads(p.stdout)
            cover = held = 0
            for c in o["top"]:
                i, lo, hi = c["index"] - 1, c["ci95"][0], c["ci95"][1]
                if lo is None:  # the push's part alone, exact: compare the estimate
                    cover += abs(c["estimate"] - exact[i]) <= 1e-9 * exact[i]
                else:
                    cover += lo <= exact[i] <= hi
            mine = {c["index"] - 1 for c in o["top"]}
            held = len(mine & set(np.argsort(-pi, kind="stable")[:100].tolist()))
            rows.append((s + 1, ig_w, ig_c, o["seconds"], o["cpu_seconds"], proc_w,
                         r1.ru_utime + r1.ru_stime - r0.ru_utime - r0.ru_stime, o["walks"], cover, held, len(o["top"])))
    print(f"\n{'source':>8} {'igraph_w':>9} {'igraph_c':>9} {'query_w':>8} {'query_c':>8} {'q/ig':>6} {'process_w':>9} "
          f"{'proc_c':>7} {'p/ig':>6} {'cpu q/ig':>8} {'walks':>8} {'covered':>8} {'top100':>7}")
    for r in rows:
        print(f"{r[0]:>8} {r[1]:>9.3f} {r[2]:>9.3f} {r[3]:>8.3f} {r[4]:>8.3f} {r[3] / r[1]:>5.3f}x {r[5]:>9.3f} {r[6]:>7.3f} "
              f"{r[5] / r[1]:>5.2f}x {r[4] / r[2]:>7.3f}x {r[7]:>8} {r[8]:>4}/{r[10]:<3} {r[9]:>4}/100")
    med = [sorted(r[a] / r[b] for r in rows)[len(rows) // 2] for a, b in ((3, 1), (5, 1), (4, 2))]
    print(f"\nulam / igraph (wall): median {med[0]:.3f}x for the query (push and walks), {med[1]:.2f}x for ulam's whole "
          f"process on the prepared file, {med[2]:.3f}x CPU for the query; covered: ulam's top-100 intervals holding "
          f"igraph's pi / 0.15; top100: igraph's top 100 in ulam's; load now {os.getloadavg()[0]:.1f} (timings under "
          f"load are upper bounds)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
