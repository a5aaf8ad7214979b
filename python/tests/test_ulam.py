"""The Python binding (import ulam): answers within 4 sigma of scipy's spsolve, coverage counted
over seeds against a binomial bound, the CLI's choice and estimate on the same seed, the CLI's
refusals as exceptions, many queries of one System, Ctrl-C as KeyboardInterrupt with the estimate
so far, M taken without a copy.  Run by meson test (python): PYTHONPATH=<build>/python and
ULAM_EXE=<build>/ulam; from the source root."""
import inspect
import json
import os
import signal
import subprocess
import tempfile

import numpy as np
import pytest
import scipy.io
import scipy.sparse as sp
import scipy.sparse.linalg as sla
from scipy.stats import binom

import ulam

ULAM = os.environ.get("ULAM_EXE", "build/ulam")
ROOT = os.environ.get("ULAM_ROOT", ".")


def random_system(n, nnz_row, radius, seed, signed=False):
    """A random sparse M with every |row| sum = radius (so rho(|M|) <= radius) and a dense b."""
    rng = np.random.default_rng(seed)
    rows = np.repeat(np.arange(n), nnz_row)
    cols = np.concatenate([rng.choice(n, nnz_row, replace=False) for _ in range(n)])
    vals = rng.random(n * nnz_row) + 0.1
    if signed:
        vals *= rng.choice([-1.0, 1.0], n * nnz_row)
    M = sp.csr_matrix((vals, (rows, cols)), shape=(n, n))
    M = sp.diags(radius / np.asarray(abs(M).sum(axis=1)).reshape(-1)) @ M
    return M.tocsr(), rng.random(n) + 0.5


def exact(M, b):
    return sla.spsolve((sp.identity(M.shape[0], format="csc") - M).tocsc(), b)


def test_spsolve_4sigma():
    """Every answer is within 4 of its standard errors of spsolve's, on three systems, with the
    default choice (auto) and a rel_err target met."""
    for seed, signed, radius in ((1, False, 0.9), (2, True, 0.8), (3, False, 0.99)):
        M, b = random_system(300, 6, radius, seed, signed)
        x = exact(M, b)
        for i in (7, 123):
            r = ulam.solve(M=M, b=b, index=i, rel_err=0.02, seed=seed, threads=2)
            assert r.ci95 is not None and r.variance_finite, r
            assert abs(r.estimate - x[i]) < 4 * r.stderr, (seed, i, r, x[i])
            assert r.stderr <= 0.02 * abs(r.estimate) and r.report["rel_err_met"], r.report
            assert r.ci95[0] < r.estimate < r.ci95[1] and r.walks >= 256  # a rel_err run's first round


def test_repr_pm_not_narrower():
    """A Result's repr, as the CLI's answer line: its +- is never under a tenth of the interval's wider
    side (a signed system at 64 walks: the interval's side is 13.8 standard errors; the repr printed
    the standard error beside it)."""
    M, b = random_system(200, 6, 0.9, 4, signed=True)
    wide = 0
    for seed in range(1, 6):
        r = ulam.solve(M=M, b=b, index=5, walks=64, seed=seed, method="walks")
        assert r.ci95 is not None, r
        side = max(r.ci95[1] - r.estimate, r.estimate - r.ci95[0])
        pm = float(repr(r).split(" +- ")[1].split(" ")[0])
        assert pm >= side / 10.0 * (1 - 1e-3), (repr(r), side)
        wide += side > 10.0 * r.stderr
        assert ("standard error" in repr(r)) == (side > 10.0 * r.stderr), repr(r)
    assert wide >= 1  # the case this asserts happens here


def coverage_bound(n):
    """The least number of covering 95% intervals of n that is not rejected at 1e-6."""
    return int(binom.ppf(1e-6, n, 0.95))


@pytest.mark.parametrize("rule", ["walks", "rel_err"])
def test_coverage(rule):
    """95% intervals over 100 seeds on a hard small system (signed; radius 0.97 and a small budget of
    1000 walks, or radius 0.9 under the rel_err 0.1 rule) cover x_i at least the binomial bound's count (the walks
    row pinned: auto's choice, made from pilots independent of the walks, is tested above)."""
    M, b = random_system(40, 3, 0.97 if rule == "walks" else 0.9, 11, signed=True)
    x = exact(M, b)
    covered, n = 0, 100
    for seed in range(1, n + 1):
        kw = {"walks": 1000} if rule == "walks" else {"rel_err": 0.1}
        r = ulam.solve(M=M, b=b, index=5, seed=seed, threads=1, method="walks", **kw)
        assert r.ci95 is not None, r
        covered += r.ci95[0] <= x[5] <= r.ci95[1]
    assert covered >= coverage_bound(n), (covered, coverage_bound(n))


def cli_json(args):
    p = subprocess.run([ULAM] + args + ["--json"], capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr
    return json.loads(p.stdout)


@pytest.mark.parametrize("case", ["dense_b", "sparse_b"])
def test_same_as_cli(case):
    """ulam.solve with defaults gives `ulam solve`'s choice and estimate on the same seed (the
    library's table: walks for a dense b, bidirectional for a sparse one), and its report holds
    the CLI's keys (less the process's)."""
    M = scipy.io.mmread(os.path.join(ROOT, "matrices/randsub1000.mtx")).tocsr()
    if case == "dense_b":
        bpath = os.path.join(ROOT, "matrices/randsub1000_b.mtx")
        index = 0
    else:
        bpath = os.path.join(ROOT, "tests/data/sparse3_b.mtx")
        index = 6
    b = np.asarray(scipy.io.mmread(bpath).todense() if sp.issparse(scipy.io.mmread(bpath))
                   else scipy.io.mmread(bpath)).reshape(-1)
    o = cli_json(["solve", os.path.join(ROOT, "matrices/randsub1000.mtx"), "--rhs", bpath, "--index", str(index + 1),
                  "--rel-err", "0.02", "--seed", "3"])
    r = ulam.solve(M=M, b=b, index=index, rel_err=0.02, seed=3)
    assert r.estimate == o["estimate"] and r.stderr == o["stderr"] and r.walks == o["walks"], (r.report, o)
    assert r.method == ("bidirectional" if case == "sparse_b" else "walks") == o.get("method", "walks"), o
    assert r.report["auto"]["chosen"] == o["auto"]["chosen"], (r.report["auto"], o["auto"])
    assert r.report["auto"]["bidirectional"] == o["auto"]["bidirectional"]
    process = {"load_seconds", "guard_seconds", "kernel_seconds", "peak_rss_mib", "transpose_seconds"}
    assert set(o) - process <= set(r.report), set(o) - process - set(r.report)
    for k in ("estimate", "stderr", "ci95", "walks", "steps", "variance_finite", "seed"):
        assert r.report[k] == o[k], k


def test_source_same_as_cli():
    """source=S is `ulam solve --source S`: the same push, walks and estimate on the same seed."""
    M = scipy.io.mmread(os.path.join(ROOT, "matrices/randsub1000.mtx")).tocsr()
    o = cli_json(["solve", os.path.join(ROOT, "matrices/randsub1000.mtx"), "--index", "7", "--source", "3",
                  "--rel-err", "0.05", "--seed", "5"])
    r = ulam.solve(M=M, index=6, source=2, rel_err=0.05, seed=5)
    assert (r.estimate, r.stderr, r.walks, r.report["rmax"]) == (o["estimate"], o["stderr"], o["walks"], o["rmax"]), o
    assert r.report["source"] == o["source"] == 3 and r.method == o["method"] == "bidirectional"


def test_refusals():
    """The CLI's refusals raise the library's status as ulam.Error subclasses; the interpreter lives."""
    M, b = random_system(50, 4, 0.9, 5)
    with pytest.raises(ulam.InputError):
        ulam.solve(M=sp.random(5, 6, density=0.5, format="csr"), b=np.ones(5), index=0)
    with pytest.raises(ulam.InputError):
        ulam.solve(M=M, b=np.ones(49), index=0)
    with pytest.raises(ulam.InputError):
        ulam.solve(M=M, b=b, index=50)
    with pytest.raises(ulam.InputError):
        ulam.solve(M=M, b=b)  # adjoint walks need an index
    with pytest.raises(ulam.InputError):
        ulam.solve(M=M, b=b, index=0, method="sideways")
    with pytest.raises(ulam.InputError):
        ulam.solve(M=M, b=b, index=0, rel_err=2.0)
    with pytest.raises(ulam.InputError):
        ulam.solve(M=M, b=b, index=0, source=3)  # source= sets b
    with pytest.raises(ulam.InputError):
        ulam.solve(M=M, b=b, index=0, jacobi=True)  # jacobi=True goes with A=
    with pytest.raises(ulam.InputError):
        ulam.solve(M=M, b=b, index=0, roulette=0.5, split=0.4)
    with pytest.raises(TypeError):
        ulam.solve(M=M, b=b, index=0, sideways=1)
    bad = M.copy()
    bad.data[3] = np.nan
    with pytest.raises(ulam.InputError) as e:
        ulam.solve(M=bad, b=b, index=0)
    assert e.value.status == ulam._ulam.ENONFINITE
    A = sp.identity(50, format="csr") - M
    A = A.tolil()
    A[7, 7] = 0.0
    with pytest.raises(ulam.InputError) as e:
        ulam.solve(A=A.tocsr(), b=b, jacobi=True, index=0)
    assert e.value.status == ulam._ulam.EZERODIAG and e.value.index == 7
    # rho(|M|) above 1: refused unless force=True (the CLI's exit 3)
    with pytest.raises(ulam.DivergenceError) as e:
        ulam.solve(M=1.5 * M, b=b, index=0, method="walks")
    assert e.value.status == ulam._ulam.EDIVERGE and "rho" in str(e.value)
    with pytest.raises(ulam.DivergenceError):
        ulam.solve(M=1.5 * M, b=b, index=0, rel_err=0.01)  # auto: no candidate certified
    # the variance not certified finite and a rel_err target alone: no walk count meets it
    S, c = random_system(40, 3, 0.995, 8, signed=True)
    with pytest.raises(ulam.InfiniteVarianceError) as e:
        ulam.solve(M=S, b=c, index=0, rel_err=0.01, method="walks", estimator="absorption", continue_q=0.05)
    assert e.value.status == ulam._ulam.EINFVAR


def test_many_queries():
    """A System answers 12 queries, each within 4 sigma of spsolve, paying the guards once: its
    queries' choices spend less set-up work than a fresh solve's."""
    M, b = random_system(400, 5, 0.9, 21)
    x = exact(M, b)
    system = ulam.System(M=M)
    fresh = ulam.solve(M=M, b=b, index=0, rel_err=0.05, seed=4)
    for i in range(12):
        r = system.solve(b, index=31 * i, rel_err=0.05, seed=4 + i)
        assert abs(r.estimate - x[31 * i]) < 4 * r.stderr, (i, r, x[31 * i])
    again = system.solve(b, index=0, rel_err=0.05, seed=4)
    assert again.report["auto"]["pilot_work"] < fresh.report["auto"]["pilot_work"], (again.report["auto"],
                                                                                     fresh.report["auto"])


def test_no_copy():
    """Canonical float64 CSR with int32 indices is taken without a copy (an int32 indptr is converted)."""
    M0, _ = random_system(100, 4, 0.9, 2)
    M0.sum_duplicates()
    M = M0.copy()  # canonical: sorted columns, no duplicates (else a canonical copy is made)
    M.indices = M.indices.astype(np.int32)
    s = ulam.System(M=M)
    assert np.shares_memory(s._arrays[1], M.indices) and np.shares_memory(s._arrays[2], M.data)
    M.indptr = M.indptr.astype(np.int64)
    s = ulam.System(M=M)
    assert all(np.shares_memory(a, m) for a, m in zip(s._arrays[:3], (M.indptr, M.indices, M.data)))
    # other formats and dense arrays are converted, and answer the same
    b = np.ones(100)
    r1 = ulam.solve(M=M, b=b, index=3, walks=5000, method="walks")
    for other in (M0.tocoo(), M0.tocsc(), M0.toarray(), sp.csr_array(M0), M0.astype(np.float32).astype(np.float64)):
        r2 = ulam.solve(M=other, b=b, index=3, walks=5000, method="walks")
        assert r2.estimate == r1.estimate


def test_interrupt():
    """Ctrl-C (SIGINT sent by the progress callback after the first round: deterministic) stops the
    walks at the next block and raises ulam.Interrupted, a KeyboardInterrupt, with the estimate so far."""
    M, b = random_system(200, 4, 0.9, 6)
    x = exact(M, b)
    rounds = []

    def progress(walks, estimate, stderr):
        rounds.append(walks)
        if len(rounds) == 1:
            os.kill(os.getpid(), signal.SIGINT)

    with pytest.raises(KeyboardInterrupt) as e:
        ulam.solve(M=M, b=b, index=2, walks=10**9, method="walks", progress=progress)
    r = e.value.result
    assert isinstance(e.value, ulam.Interrupted) and r.interrupted and r.report["interrupted"]
    assert 0 < r.walks < 10**9 and abs(r.estimate - x[2]) < 4 * r.stderr, r
    # Python's own handler is back: the next SIGINT is Python's KeyboardInterrupt
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_progress_exception():
    """An exception raised by progress stops the walks and propagates."""
    M, b = random_system(50, 4, 0.9, 6)

    def progress(walks, estimate, stderr):
        raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        ulam.solve(M=M, b=b, index=2, walks=10**8, method="walks", progress=progress)


def test_rows_and_sources():
    """Pinned rows of the library's table: bidirectional for a point source, the outer iterations
    and Krylov peers to their residual (no standard error; a certified range from the residual that
    holds the exact x), Jacobi from A."""
    M, b = random_system(120, 4, 0.8, 9)
    Ms = ((M + M.T) / 2).tocsr()
    x = exact(Ms, b)
    for name, kind in ulam.methods():
        if kind == "all":
            r = ulam.solve(M=Ms, b=b, index=4, method=name, seed=2)
            assert r.method == name and np.isnan(r.stderr) and abs(r.estimate - x[4]) < 1e-6 * abs(x[4])
            assert r.ci95[0] <= x[4] <= r.ci95[1] and r.ci95[1] - r.ci95[0] < 1e-6 * abs(x[4])
    e = np.zeros(120)
    e[17] = 1.0
    xs = exact(M, e)
    r = ulam.solve(M=M, index=3, source=17, walks=20000)
    assert r.method == "bidirectional" and abs(r.estimate - xs[3]) < 4 * r.stderr + 1e-12, r
    A = (sp.identity(120) - M).tocsr() * 3.0
    r = ulam.solve(A=A, b=b, jacobi=True, index=5, rel_err=0.02)
    assert abs(r.estimate - sla.spsolve(A.tocsc(), b)[5]) < 4 * r.stderr
    assert r.report["auto"]["bidirectional"] == "not considered: --jacobi"


def test_pagerank():
    """Personalized PageRank pi_s(t) within 4 sigma of (1 - alpha) (I - alpha P')^-1 e_s."""
    rng = np.random.default_rng(3)
    n = 300
    adj = sp.random(n, n, density=0.02, format="csr", random_state=4)
    adj.data[:] = 1.0
    out = np.asarray(adj.sum(axis=1)).reshape(-1)
    P = sp.diags(np.divide(1.0, out, out=np.zeros(n), where=out > 0)) @ adj
    alpha, s = 0.85, int(rng.integers(n))
    e = np.zeros(n)
    e[s] = 1.0
    pi = (1 - alpha) * sla.spsolve((sp.identity(n) - alpha * P.T).tocsc(), e)
    t = int(np.argsort(pi)[-3])  # a node the walks from s reach
    r = ulam.pagerank(adj, alpha, s, t, rel_err=0.05)
    assert r.method == "bidirectional" and abs(r.estimate - pi[t]) < 4 * r.stderr, (r, pi[t])


def test_help_documents_every_argument():
    """help(ulam.solve) names every argument."""
    doc = ulam.solve.__doc__
    for name, p in inspect.signature(ulam.solve).parameters.items():
        if p.kind in (p.VAR_POSITIONAL, p.VAR_KEYWORD):
            continue
        assert f"  {name} " in doc or f"  {name}," in doc or f", {name} " in doc or f" {name}  " in doc, name


# --- Python as SciPy users expect it (issue 42, point 4) and hostile arguments (issue 39, point 6)

def small_graph(n=200, seed=4):
    """A random 0/1 adjacency and its out-link transition matrix P (dangling rows zero)."""
    adj = sp.random(n, n, density=0.03, format="csr", random_state=seed)
    adj.data[:] = 1.0
    out = np.asarray(adj.sum(axis=1)).reshape(-1)
    return adj, (sp.diags(np.divide(1.0, out, out=np.zeros(n), where=out > 0)) @ adj).tocsr()


def test_system_named():
    """A SciPy user's solve(A, b, index=...) (A x = b; diagonal 0.8, spsolve 1.25) no longer answers
    (I - A) x = b (5) silently: a matrix by position is a TypeError naming M= and A=; A= answers
    A x = b, M= answers (I - M) x = b."""
    n = 20
    A = sp.diags(np.full(n, 0.8)).tocsr()
    b = np.ones(n)
    with pytest.raises(TypeError, match="M=M .*A=A"):
        ulam.solve(A, b, index=10)
    with pytest.raises(TypeError, match="M=M .*A=A"):
        ulam.System(A)
    r = ulam.solve(A=A, b=b, index=10, walks=1000)
    assert abs(r.estimate - sla.spsolve(A.tocsc(), b)[10]) <= 1e-12, r  # 1.25: one step of Jacobi is exact
    r = ulam.solve(M=A, b=b, index=10, walks=20000)
    assert abs(r.estimate - 5.0) < 4 * r.stderr + 1e-9, r
    with pytest.raises(ulam.InputError):
        ulam.solve(M=A, A=A, b=b, index=0)
    with pytest.raises(ulam.InputError):
        ulam.solve(b=b, index=0)


def test_forward_arrays():
    """mode="forward" answers every unknown: NumPy arrays of estimates, standard errors and interval
    ends (not x[0] = 0 +- 0), within 4 sigma of spsolve, the watched index with the run's interval."""
    M, b = random_system(60, 4, 0.8, 31)
    x = exact(M, b)
    r = ulam.solve(M=M, b=b, mode="forward", walks=40000, seed=2)
    assert isinstance(r, ulam.VectorResult) and r.method == "walks" and len(r) == 60
    for a in (r.estimate, r.stderr, r.ci95[0], r.ci95[1]):
        assert isinstance(a, np.ndarray) and a.shape == (60,) and a.dtype == np.float64
    assert (r.stderr > 0).all() and (np.abs(r.estimate - x) < 4 * r.stderr).all(), np.abs(r.estimate - x) / r.stderr
    assert (r.ci95[0] < r.estimate).all() and (r.estimate < r.ci95[1]).all() and r.walks == 40000
    assert r.watched == 0 and r.watched_ci95 is not None and (r.ci95[0][0], r.ci95[1][0]) == r.watched_ci95
    assert np.array_equal(np.asarray(r), r.estimate)
    # System.solve too, and an index names the component the rule watches
    r2 = ulam.System(M=M).solve(b, index=7, mode="forward", rtol=0.05, seed=2)
    assert r2.watched == 7 and r2.report["rel_err_met"] and abs(r2.estimate[7] - x[7]) < 4 * r2.stderr[7]


def test_single_source_arrays():
    """source=S without index answers every x_i of (I - M) x = e_S (single source: push + walks) as
    arrays: the CLI's `solve --source S` estimates, each within 4 sigma of spsolve's."""
    M, _ = random_system(80, 4, 0.8, 32)
    e = np.zeros(80)
    e[9] = 1.0
    x = exact(M, e)
    r = ulam.solve(M=M, source=9, walks=20000, seed=3)
    assert isinstance(r, ulam.VectorResult) and r.method == "single-source"
    assert r.estimate.shape == r.stderr.shape == r.ci95[0].shape == r.ci95[1].shape == (80,)
    assert (np.abs(r.estimate - x) <= 4 * r.stderr + 1e-12).all(), np.max(np.abs(r.estimate - x) / r.stderr)
    # the intervals printed bracket the estimates; with ||M||_1 >= 1 (the queue path) only the
    # source's is certified, the others are none (NaN), not the CLT's x -+ 1.96 stderr
    shown = ~np.isnan(r.ci95[0])
    assert shown[9] and (r.ci95[0][shown] <= r.estimate[shown]).all() and (r.estimate[shown] <= r.ci95[1][shown]).all()
    # the call, source= with mode="forward": the same (it printed x[0] = 0 +- 0, 0 walks)
    r2 = ulam.solve(M=M, source=9, mode="forward", walks=20000, seed=3)
    assert np.array_equal(r2.estimate, r.estimate) and r2.walks == r.walks > 0
    with pytest.raises(ulam.InputError):
        ulam.solve(M=M, source=9, estimator="absorption")  # single source takes only its own options


def test_pagerank_global_and_from_source():
    """pagerank() with no source is global PageRank (uniform restart), not source 0; with no target
    it answers every node; alpha is the damping (damping= the same), both against SciPy's power
    iteration and spsolve."""
    n, a = 200, 0.85
    adj, P = small_graph(n)
    pi = np.full(n, 1.0 / n)
    for _ in range(300):  # the power iteration (substochastic: dangling mass lost, as ulam's)
        pi = (1 - a) / n + a * (P.T @ pi)
    r = ulam.pagerank(adj, walks=200000, seed=5)
    assert isinstance(r, ulam.VectorResult)
    assert (np.abs(r.estimate - pi) < 4 * r.stderr + 1e-12).all(), np.max(np.abs(r.estimate - pi) / r.stderr)
    t = int(np.argmax(pi))
    r1 = ulam.pagerank(adj, target=t, rel_err=0.02)
    assert abs(r1.estimate - pi[t]) < 4 * r1.stderr, (r1, pi[t])
    r2 = ulam.pagerank(adj, damping=a, target=t, rel_err=0.02)
    assert r2.estimate == r1.estimate
    e = np.zeros(n)
    e[5] = 1.0
    ps = (1 - a) * sla.spsolve((sp.identity(n) - a * P.T).tocsc(), e)
    r3 = ulam.pagerank(adj, source=5, walks=20000)
    assert isinstance(r3, ulam.VectorResult) and (np.abs(r3.estimate - ps) <= 4 * r3.stderr + 1e-12).all()
    with pytest.raises(ulam.InputError, match="strictly between 0 and 1"):
        ulam.pagerank(adj, alpha=1.0)
    with pytest.raises(ulam.InputError):
        ulam.pagerank(adj, alpha=0.5, damping=0.5)


def test_alpha_is_damping_only():
    """alpha means PageRank's damping; the walk kernel's exponent is kernel_alpha= (alpha= there is a
    TypeError saying so)."""
    M, b = random_system(40, 3, 0.8, 33)
    with pytest.raises(TypeError, match="kernel_alpha"):
        ulam.solve(M=M, b=b, index=0, alpha=0.5)
    r = ulam.solve(M=M, b=b, index=0, kernel_alpha=0.5, walks=2000, method="walks")
    assert r.kernel_alpha == 0.5


def test_keyword_typo_did_you_mean():
    """A misspelt keyword is a TypeError naming the closest one solve takes, as the CLI's "did you
    mean" names the closest option (newuser15: it named the typo alone)."""
    M, b = random_system(40, 3, 0.8, 33)
    with pytest.raises(TypeError, match=r"'rel_er' \(did you mean 'rel_err'\?\)"):
        ulam.solve(M=M, b=b, index=0, rel_er=0.1)
    with pytest.raises(TypeError, match=r"'wlaks' \(did you mean 'walks'\?\)"):
        ulam.System(M=M).solve(b, index=0, wlaks=100)
    with pytest.raises(TypeError, match=r"'sideways'$"):
        ulam.solve(M=M, b=b, index=0, sideways=1)


def test_clear_type_errors():
    """A LinearOperator gets a TypeError saying the walks need M's entries (not "got 0
    dimensions"); rtol= is rel_err (scipy's name)."""
    M, b = random_system(40, 3, 0.8, 34)
    with pytest.raises(TypeError, match="LinearOperator"):
        ulam.solve(M=sla.aslinearoperator(M), b=b, index=0)
    with pytest.raises(TypeError, match="LinearOperator"):
        ulam.pagerank(sla.aslinearoperator(M))
    r1 = ulam.solve(M=M, b=b, index=3, rtol=0.05, seed=9)
    r2 = ulam.solve(M=M, b=b, index=3, rel_err=0.05, seed=9)
    assert r1.estimate == r2.estimate and r1.report["rel_err_met"]
    with pytest.raises(ulam.InputError):
        ulam.solve(M=M, b=b, index=3, rtol=0.05, rel_err=0.05)


def test_force_divergent():
    """force=True on a divergent M (rho(|M|) = 1.5): a DivergenceError saying the walks overflowed,
    not an InputError "a walk produced NaN"."""
    M, b = random_system(50, 5, 1.5, 35)
    with pytest.raises(ulam.DivergenceError, match="force=True"):
        ulam.solve(M=M, b=b, index=0, force=True, walks=1000, method="walks")


def test_hostile_arguments():
    """Issue 39.6: a complex b is refused (was cast to its real part), index=True is not index 1, and a
    matrix changed after System(M=M) (M.data *= 3, taken without a copy) is refused, not walked
    (it answered 5.9e24 +- 5.4e24)."""
    M, b = random_system(60, 4, 0.9, 36)
    M.sum_duplicates()  # canonical (sorted columns): taken without a copy
    M.indices = M.indices.astype(np.int32)
    with pytest.raises(ulam.InputError, match="real entries"):
        ulam.solve(M=M, b=b + 1j, index=0)
    with pytest.raises(ulam.InputError):
        ulam.solve(M=M, b=b, index=True)
    with pytest.raises(ulam.InputError):
        ulam.solve(M=M, b=b, index=0, walks=True)
    s = ulam.System(M=M)
    assert np.shares_memory(s._arrays[2], M.data)  # borrowed: the case a change reaches
    r = s.solve(b, index=0, walks=2000)
    saved = M.data.copy()
    M.data *= 3
    with pytest.raises(ulam.InputError, match="changed"):
        s.solve(b, index=0, walks=2000)
    M.data[:] = saved  # the same matrix again: answered as before
    assert s.solve(b, index=0, walks=2000).estimate == r.estimate
    A = (sp.identity(60, format="csr") - M).tocsr()
    A.sum_duplicates()
    A.indices = A.indices.astype(np.int32)
    sa = ulam.System(A=A)
    A.data[0] *= 2
    with pytest.raises(ulam.InputError, match="changed"):
        sa.solve(b, index=0, walks=100)


def test_type_hints():
    """The package is typed (PEP 561): py.typed and __init__.pyi beside it, the stub naming every
    public name and each keyword of solve, System.solve and pagerank."""
    import ast
    pkg = os.path.dirname(ulam.__file__)
    assert os.path.isfile(os.path.join(pkg, "py.typed"))
    tree = ast.parse(open(os.path.join(pkg, "__init__.pyi")).read())
    defined = {n.name for n in ast.walk(tree) if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
    assert set(ulam.__all__) <= defined, set(ulam.__all__) - defined
    stubs = {n.name: n for n in tree.body if isinstance(n, ast.FunctionDef)}
    system = next(n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == "System")
    stubs["System.solve"] = next(n for n in system.body if isinstance(n, ast.FunctionDef) and n.name == "solve")
    for name, f in (("solve", ulam.solve), ("pagerank", ulam.pagerank), ("System.solve", None)):
        a = stubs[name].args
        hinted = {x.arg for x in a.args + a.kwonlyargs} - {"self"}
        if f is None:  # System.solve takes solve's keywords through **kw
            real = {p for p in inspect.signature(ulam.solve).parameters} - {"args", "unknown", "M", "A", "jacobi", "omega"}
            real |= {"b", "index"}
        else:
            real = {p.name for p in inspect.signature(f).parameters.values() if p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)}
        assert hinted == real, (name, hinted ^ real)


def test_study_same_as_cli():
    """ulam.study runs the library's study engine: the same runs as `ulam study` for the same seed
    (run k's seed is ulam_rng_substream(seed, STUDY, k) in both, its estimate the same to the last
    bit), each run within 4 of its stderr of spsolve's x_2, a cell per method and budget."""
    M = scipy.io.mmread(os.path.join(ROOT, "matrices/chain4.mtx")).tocsr()
    b = scipy.io.mmread(os.path.join(ROOT, "matrices/chain4_b.mtx"))
    b = np.asarray(b.toarray() if sp.issparse(b) else b).reshape(-1)
    methods = ["adjoint-collision-plain", "forward-expected-split"]
    d = ulam.study(M=M, b=b, index=1, methods=methods, budgets=[100, 1000], repeats=4, seed=5)
    assert d["done"] and not d["interrupted"] and d["direct"]
    assert abs(d["exact"] - exact(M, b)[1]) <= 1e-12 * abs(d["exact"])
    assert len(d["runs"]) == 2 * 2 * 4 and len(d["cells"]) == 2 * 2
    assert all(abs(r["estimate"] - d["exact"]) < 4 * r["std_error"] for r in d["runs"])
    assert {c["method"] for c in d["cells"]} == set(methods) and all(c["runs"] == 4 for c in d["cells"])
    with tempfile.TemporaryDirectory() as out:
        p = subprocess.run([ULAM, "study", os.path.join(ROOT, "matrices/chain4.mtx"), "--rhs",
                            os.path.join(ROOT, "matrices/chain4_b.mtx"), "--index", "2", "--methods", ",".join(methods),
                            "--budgets", "100,1000", "--repeats", "4", "--seed", "5", "--reference-time", "0",
                            "--out", out + "/s"], capture_output=True, text=True, timeout=600)
        assert p.returncode == 0, p.stderr
        with open(out + "/s/runs.csv") as f:
            rows = [line.rstrip("\n").split(",") for line in f][1:]
    cli = {(r[0], float(r[1]), int(r[2])): (int(r[3]), float(r[4])) for r in rows}
    assert len(cli) == len(d["runs"])
    for r in d["runs"]:
        assert cli[(r["method"], r["budget"], r["repeat"])] == (r["seed"], r["estimate"])


def test_study_bad_input():
    """ulam.study refuses an unknown method, too few repeats and an index out of range."""
    M, b = random_system(20, 3, 0.5, 1)
    with pytest.raises(ulam.InputError):
        ulam.study(M=M, b=b, index=0, methods=["adjoint-nothing-plain"], budgets=[10], repeats=2)
    with pytest.raises(ulam.InputError):
        ulam.study(M=M, b=b, index=0, budgets=[10], repeats=1)
    with pytest.raises(ulam.InputError):
        ulam.study(M=M, b=b, index=20, budgets=[10], repeats=2)
