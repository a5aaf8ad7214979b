"""PageRank from an edge list on the command line against SciPy's power iteration (issue 42 pt 2).

A seeded random directed graph (a Zipf-like out-degree, some dangling nodes, 0-based ids) is written
as SNAP writes it (# comments, tab-separated pairs) and as a 1-based Matrix Market file; ulam's
pi = (1 - alpha) x for a single source, a seed set, global PageRank (top K) and point queries
is compared with pi from the power iteration pi <- alpha P^T pi + (1 - alpha) s, where a
dangling node's row of P is zero (its rank leaks, as ulam documents).  Each printed pi_i must
hold the reference inside its printed 95% interval and within 4 standard errors; the top-K order
must be the reference's wherever the intervals separate, and no node left out may rank above the
last one printed.  Run: ULAM=path/to/ulam python3 -m pytest tests/pagerank_test.py
"""
import json
import os
import subprocess

import numpy as np
import pytest
import scipy.sparse as sp

ULAM = os.environ.get("ULAM", "build/ulam")
ALPHA = 0.85


def make_graph(n=400, seed=42):
    """Edges (u, v), 0-based: out-degrees Zipf-like (1..40), every 20th node dangling, no node above n-1."""
    rng = np.random.default_rng(seed)
    edges = set()
    for u in range(n):
        if u % 20 == 7:
            continue  # dangling
        deg = min(40, int(rng.zipf(2.0)))
        for v in rng.choice(n, size=deg, replace=False):
            if v != u:
                edges.add((u, int(v)))
    edges.add((0, n - 1))  # the largest id appears
    return n, sorted(edges)


def reference(n, edges, s):
    """pi of pi = alpha P^T pi + (1 - alpha) s by power iteration, dangling rows of P zero."""
    u = np.array([e[0] for e in edges])
    v = np.array([e[1] for e in edges])
    A = sp.csr_matrix((np.ones(len(edges)), (u, v)), shape=(n, n))
    out = np.asarray(A.sum(axis=1)).ravel()
    inv = np.where(out > 0, 1.0 / np.where(out > 0, out, 1.0), 0.0)
    PT = (sp.diags(inv) @ A).T.tocsr()
    pi = (1 - ALPHA) * s.copy()
    for _ in range(1000):
        nxt = ALPHA * (PT @ pi) + (1 - ALPHA) * s
        if np.abs(nxt - pi).sum() < 1e-15:
            pi = nxt
            break
        pi = nxt
    return pi


@pytest.fixture(scope="module")
def graph(tmp_path_factory):
    d = tmp_path_factory.mktemp("pagerank")
    n, edges = make_graph()
    txt = d / "graph.txt"
    with open(txt, "w") as f:
        f.write("# Directed graph: a seeded test graph\n# Nodes: %d Edges: %d\n# FromNodeId\tToNodeId\n" % (n, len(edges)))
        for u, v in edges:
            f.write("%d\t%d\n" % (u, v))
    mtx = d / "graph.mtx"
    with open(mtx, "w") as f:
        f.write("%%%%MatrixMarket matrix coordinate pattern general\n%d %d %d\n" % (n, n, len(edges)))
        for u, v in edges:
            f.write("%d %d\n" % (u + 1, v + 1))
    return {"n": n, "edges": edges, "txt": str(txt), "mtx": str(mtx), "dir": d}


def ulam(*args):
    p = subprocess.run([ULAM, *map(str, args)], capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, (args, p.returncode, p.stderr)
    return json.loads(p.stdout)


def check_top(out, ref, k, base=0):
    top = out["top"]
    assert out["quantity"] == "pi" and out["damping"] == ALPHA
    assert len(top) == k
    idx = [t["index"] - base for t in top]
    for t, i in zip(top, idx):
        lo, hi = t["ci95"]
        assert lo <= ref[i] <= hi, (i, ref[i], t)
        assert abs(t["estimate"] - ref[i]) <= 4 * t["stderr"] + 1e-12, (i, ref[i], t)
    for a, b in zip(top, top[1:]):  # the order is the reference's unless the intervals overlap
        ia, ib = a["index"] - base, b["index"] - base
        assert ref[ia] >= ref[ib] or a["ci95"][0] <= b["ci95"][1], (a, b, ref[ia], ref[ib])
    left = np.setdiff1d(np.arange(len(ref)), idx)
    assert ref[left].max() <= top[-1]["ci95"][1] + 1e-12, "a node ranked above the last one printed was left out"
    return idx


def test_single_source_top(graph):
    n = graph["n"]
    s = np.zeros(n)
    s[6] = 1.0
    ref = reference(n, graph["edges"], s)
    out = ulam("solve", graph["txt"], "--pagerank", ALPHA, "--source", 6, "--top", 10, "--json", "--seed", 3, "--walks", 200000)
    idx = check_top(out, ref, 10)
    assert idx[0] == 6  # the source keeps at least 1 - alpha
    # the same graph as a 1-based Matrix Market file: the same CSR, ids shifted by one
    out1 = ulam("solve", graph["mtx"], "--pagerank", ALPHA, "--source", 7, "--top", 10, "--json", "--seed", 3, "--walks", 200000)
    assert [t["index"] - 1 for t in out1["top"]] == idx
    assert [t["estimate"] for t in out1["top"]] == [t["estimate"] for t in out["top"]]


def test_seed_set_top(graph):
    n = graph["n"]
    s = np.zeros(n)
    s[[3, 7, 9]] = 1.0 / 3
    ref = reference(n, graph["edges"], s)
    check_top(ulam("solve", graph["txt"], "--pagerank", ALPHA, "--source", "3,7,9", "--top", 10, "--json", "--walks", 200000), ref, 10)
    seeds = graph["dir"] / "seeds.txt"
    seeds.write_text("# node weight\n3 2\n9 1\n")
    s = np.zeros(n)
    s[3], s[9] = 2 / 3, 1 / 3
    ref = reference(n, graph["edges"], s)
    check_top(ulam("solve", graph["txt"], "--pagerank", ALPHA, "--source", seeds, "--top", 8, "--json", "--walks", 200000), ref, 8)


def test_global_top(graph):
    n = graph["n"]
    ref = reference(n, graph["edges"], np.full(n, 1.0 / n))
    check_top(ulam("solve", graph["txt"], "--damping", ALPHA, "--top", 10, "--json"), ref, 10)


def test_point_queries(graph):
    n = graph["n"]
    s = np.zeros(n)
    s[6] = 1.0
    ref = reference(n, graph["edges"], s)
    target = int(np.argsort(ref)[-3])  # a node the source reaches
    out = ulam("solve", graph["txt"], "--pagerank", ALPHA, "--source", 6, "--index", target, "--rel-err", 0.02,
               "--json", "--check")
    assert out["index"] == target and out["quantity"] == "pi"
    assert out["ci95"][0] <= ref[target] <= out["ci95"][1], (out, ref[target])
    assert abs(out["direct"] - ref[target]) <= 1e-9 * ref[target]
    g = reference(n, graph["edges"], np.full(n, 1.0 / n))
    t = int(np.argmax(g))
    out = ulam("solve", graph["txt"], "--pagerank", ALPHA, "--index", t, "--rel-err", 0.02, "--json")
    assert out["index"] == t and out["quantity"] == "pi"
    assert abs(out["estimate"] - g[t]) <= 4 * out["stderr"], (out, g[t])


def test_top_coverage(graph):
    """The printed 95% intervals over 20 seeds (200 intervals each: single source, seed set, global): misses
    counted against a binomial bound (mean 10 at 95%; 22 is about 4 sigma above it)."""
    n = graph["n"]
    for seeds in ("6", "3,7,9", None):
        s = np.full(n, 1.0 / n)  # None: global PageRank
        if seeds:
            s = np.zeros(n)
            ids = [int(t) for t in seeds.split(",")]
            s[ids] = 1.0 / len(ids)
        ref = reference(n, graph["edges"], s)
        miss = total = 0
        for seed in range(1, 21):
            out = ulam("solve", graph["txt"], "--pagerank", ALPHA, *(["--source", seeds] if seeds else []), "--top", 10,
                       "--json", "--seed", seed, "--walks", 20000)
            for t in out["top"]:
                total += 1
                miss += not (t["ci95"][0] <= ref[t["index"]] <= t["ci95"][1])
        print(f"coverage {seeds}: {miss} of {total} intervals missed")
        assert total == 200 and miss <= 22, (seeds, miss, total)
