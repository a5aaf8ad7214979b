#!/usr/bin/env python3
"""`ulam solve --method`: usage errors, the per-iteration report, --json history, --out, the
stall status, and the Krylov peers' iteration counts against SciPy's on the same matrices
(skipped, with a note, when SciPy is missing).

Run from the source root: mcsa_test.py path/to/ulam
"""
import json
import os
import re
import subprocess
import sys
import tempfile

M = "matrices/"
from ulam_status import code  # noqa: E402

ENOCONV, ESTALL, EINFVAR = code("ENOCONV"), code("ESTALL"), code("EINFVAR")
P20 = ["solve", M + "poisson20.mtx", "--rhs", M + "poisson20_b.mtx", "--jacobi"]
RS = ["solve", M + "randsub1000.mtx", "--rhs", M + "randsub1000_b.mtx"]

CASES = [  # arguments, exit code, stderr regex, stdout regex
    (P20 + ["--method", "mcsa", "--tol", "0"], 2, r"--tol expects a residual reduction strictly between 0 and 1", r"^$"),
    (P20 + ["--method", "mcsa", "--tol", "1"], 2, r"--tol expects .*strictly between 0 and 1.*got '1'", r"^$"),
    (P20 + ["--method", "mcsa", "--tol", "1.5"], 2, r"--tol expects", r"^$"),
    (P20 + ["--method", "mcsa", "--tol", "-1e-8"], 2, r"--tol expects", r"^$"),
    (P20 + ["--method", "mcsa", "--tol", "tiny"], 2, r"--tol expects", r"^$"),
    (P20 + ["--method", "mcsa", "--max-iter", "0"], 2, r"--max-iter expects an integer from 1", r"^$"),
    (P20 + ["--method", "gauss-seidel", "--index", "3"], 0, r"^$", r"^x\[3\]\s+[\d.]+ \(certified range [\d.e-]+ \.\. [\d.e-]+\)$"),  # x_I without --out, its certified range
    (P20 + ["--method", "mcsa", "--eps1", "0"], 2, r"--eps1 expects .*strictly between 0 and 1", r"^$"),
    (P20 + ["--method", "newton"], 2, r"--method expects auto, walks, bidirectional \(with --source or a sparse b\), richardson, gauss-seidel, sequential, mcsa, cg or gmres, got .newton.", r"^$"),
    (P20 + ["--method", "mcsa", "--walks", "10"], 2, r"--walks does not apply with --method mcsa", r"^$"),
    (["solve", M + "poisson20.mtx", "--method", "mcsa"], 2, r"needs --rhs", r"^$"),
    (P20 + ["--method", "mcsa", "--out", "/nonexistent/dir/x.mtx"], 13, r"x\.mtx.*writable output file", r"^$"),
    (RS + ["--method", "cg"], 2, r"--method cg needs a symmetric M.*gmres", r"^$"),
    (["solve", M + "divergent200.mtx", "--rhs", M + "divergent200_b.mtx", "--method", "mcsa"], 3,
     r"rho\(\|M\|\) is >= 1 \(certified: bounds \[1\.1, 1\.1\]\)", r"^$"),
    (P20 + ["--method", "richardson", "--max-iter", "5"], ENOCONV, r"residual 0\.86\d+ after --max-iter 5 iterations",
     r"capped after 5 iterations"),
    (RS + ["--method", "mcsa", "--continue", "0.3", "--estimator", "collision", "--max-histories", "20000"], EINFVAR,
     r"variance is infinite.*\n.*error: .*a finite variance for the correction walks: rho\(M\^\) .*\[2\.7, 2\.7\] "
     r"\(>= 1: infinite\)", r"^$"),
    (["solve", M + "poisson900.mtx", "--rhs", M + "poisson900_b.mtx", "--jacobi", "--method", "sequential",
      "--max-histories", "1000"], ESTALL, r"the residual stopped decreasing: expected a correction that lowers the "
     r"residual: iteration 1's made it \S+x with 1000 histories; its variance asks ~\S+ .*cannot make it contract",
     r"(?s)stalled after 1 iterations, residual 1\.0000e\+00.*corrections rejected 1"),
    (P20 + ["--method", "gauss-seidel", "--tol", "1e-6"], 0, r"^$", r"converged after \d+ iterations"),
    # the iterations' table under --verbose (newuser15: by default the answer, or the totals, come first)
    (RS + ["--method", "sequential", "--tol", "1e-4", "--seed", "3", "--verbose"], 0, r"^$",
     r"(?s)iter\s+residual\s+histories\s+rel_sd\s+seconds\s*\n1\s+\S+\s+\d+.*converged after \d+ iterations"),
    (RS + ["--method", "sequential", "--tol", "1e-4", "--seed", "3"], 0, r"^$", r"\Amethod +sequential(?s:.)*converged after"),
]


def run(ulam, args):
    p = subprocess.run([ulam] + args, capture_output=True, text=True, timeout=300)
    return p.returncode, p.stdout, p.stderr


def check_table(ulam):
    bad = 0
    for k, (args, want, err_re, out_re) in enumerate(CASES):
        rc, out, err = run(ulam, args)
        if rc != want or not re.search(err_re, err, re.M) or not re.search(out_re, out, re.M):
            bad += 1
            print(f"FAIL case {k}: ulam {' '.join(args)}: rc {rc} (want {want})\n  stderr: {err.strip()}\n"
                  f"  stdout: {out.strip()[:400]}")
    return bad


def check_json_out(ulam):
    """--json holds every iteration; the final residual is the last one's and <= tol; --out writes
    x, which agrees with LAPACK (--check) and with --index's x_I; threads do not change a bit."""
    with tempfile.TemporaryDirectory() as d:
        x = os.path.join(d, "x.mtx")
        runs = []
        for t in ("1", "2"):
            rc, out, err = run(ulam, RS + ["--method", "mcsa", "--tol", "1e-6", "--json", "--check", "--threads", t,
                                           "--out", x, "--index", "7"])
            assert rc == 0, err
            runs.append(json.loads(out))
        o = runs[0]
        assert o["converged"] is True and o["method"] == "mcsa" and o["estimator"] == "expected", o
        h = o["history"]
        assert len(h) == o["iterations"] >= 2 and h[-1]["residual"] == o["residual"] <= 1e-6, o
        assert all(s["histories"] >= 1024 and s["rel_sd"] < 0.1 for s in h), h
        assert sum(s["histories"] for s in h) == o["histories"]
        assert o["relative_error"] < 1e-5, o
        assert runs[0]["history"] == [dict(s, seconds=t["seconds"], walk_seconds=t["walk_seconds"])
                                      for s, t in zip(runs[1]["history"], runs[0]["history"])], "threads changed it"
        assert runs[0]["estimate"] == runs[1]["estimate"]
        vals = [float(v) for v in open(x).read().split("\n")[3:] if v.strip()]
        assert len(vals) == 1000 and abs(vals[6] - o["estimate"]) <= 1e-12 * abs(vals[6]), (vals[6], o["estimate"])
        assert sorted(os.listdir(d)) == ["x.mtx"]
        # a run that does not converge writes no file
        y = os.path.join(d, "y.mtx")
        rc, _, _ = run(ulam, RS + ["--method", "richardson", "--max-iter", "3", "--out", y])
        assert rc == ENOCONV and not os.path.exists(y) and sorted(os.listdir(d)) == ["x.mtx"]


def check_interrupt(ulam):
    """Ctrl-C during the walks ends the run after the current correction: exit 130, outcome
    'interrupted', no --out file (the solution has not converged)."""
    from cli_test import interrupt_when_ready, popen_walks  # beside this file
    with tempfile.TemporaryDirectory() as d:
        x = os.path.join(d, "x.mtx")
        p = popen_walks([ulam, "solve", M + "poisson900.mtx", "--rhs", M + "poisson900_b.mtx", "--jacobi",
                              "--method", "mcsa", "--json", "--out", x], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True)
        interrupt_when_ready(p)
        out, _ = p.communicate(timeout=120)
        o = json.loads(out)
        assert p.returncode == 130 and o["outcome"] == "interrupted" and o["converged"] is False, (p.returncode, o)
        assert o["iterations"] >= 1 and os.listdir(d) == [], os.listdir(d)


def scipy_counts():
    """SciPy's CG and GMRES iteration counts on the systems ulam sees (I - M, or D^-1 A with --jacobi)."""
    import numpy as np
    import scipy.io
    import scipy.sparse as sp
    import scipy.sparse.linalg as sl
    out = {}
    for name, jac in (("poisson20", True), ("randsub1000", False), ("radiosity100", False)):
        A = scipy.io.mmread(f"{M}{name}.mtx").tocsr()
        b = np.asarray(scipy.io.mmread(f"{M}{name}_b.mtx")).ravel()
        if jac:
            d = A.diagonal()
            A, b = sp.diags(1 / d) @ A, b / d
        else:
            A = sp.identity(A.shape[0]) - A
        A = sp.csr_matrix(A)
        if jac:
            k = [0]
            sl.cg(A, b, tol=1e-8, atol=0, maxiter=10000, callback=lambda x: k.__setitem__(0, k[0] + 1))
            out[(name, "cg", 0)] = k[0]
        for m in (5, 10, 30):
            k = [0]
            sl.gmres(A, b, tol=1e-8, atol=0, restart=m, maxiter=10000, callback_type="pr_norm",
                     callback=lambda r: k.__setitem__(0, k[0] + 1))
            out[(name, "gmres", m)] = k[0]
    return out


def check_krylov(ulam):
    """ulam's CG and GMRES(m) take SciPy's iteration counts (within 1) to the same 1e-8."""
    try:
        ref = scipy_counts()
    except ImportError:
        print("SKIP check_krylov: SciPy is not installed (python3-scipy)")
        return
    args = {"poisson20": P20, "randsub1000": RS,
            "radiosity100": ["solve", M + "radiosity100.mtx", "--rhs", M + "radiosity100_b.mtx"]}
    for (name, method, m), k in sorted(ref.items()):
        extra = ["--restart", str(m)] if method == "gmres" else []
        rc, out, err = run(ulam, args[name] + ["--method", method, "--tol", "1e-8", "--json"] + extra)
        assert rc == 0, err
        o = json.loads(out)
        print(f"{name} {method}({m}): ulam {o['iterations']}, SciPy {k}")
        assert abs(o["iterations"] - k) <= 1 and o["residual"] <= 1e-8, (name, method, m, o["iterations"], k)


def check_issue25_case8(ulam):
    """Issue 25 case 8, with generators of our own: a 100-state nonsymmetric system with rho(M) = 0.99
    and an infinite forward variance is refused before any walk (it used to walk its first correction
    for minutes); 2-D Poisson with Jacobi at n = 10^4 (b = 1) ends in one iteration, the residual
    never above 1 (it was 1 -> 22 -> 24), with the count the correction would need."""
    import random
    with tempfile.TemporaryDirectory() as d:
        rng, n = random.Random(8), 100
        rows = [(i, j, rng.random() ** 3) for i in range(n) for j in rng.sample(range(n), 10)]
        v = [1.0] * n
        for _ in range(3000):  # Perron root by power iteration
            w = [0.0] * n
            for i, j, a in rows:
                w[i] += a * v[j]
            lam, v = sum(w) / sum(v), [x * n / sum(w) for x in w]
        a_path, b_path = os.path.join(d, "a.mtx"), os.path.join(d, "a_b.mtx")
        with open(a_path, "w") as f:
            f.write(f"%%MatrixMarket matrix coordinate real general\n{n} {n} {len(rows)}\n")
            f.writelines(f"{i + 1} {j + 1} {a * 0.99 / lam:.17g}\n" for i, j, a in rows)
        with open(b_path, "w") as f:
            f.write(f"%%MatrixMarket matrix array real general\n{n} 1\n" + "".join(f"{rng.random()}\n" for _ in range(n)))
        for m in ("mcsa", "sequential"):
            rc, out, err = run(ulam, ["solve", a_path, "--rhs", b_path, "--method", m])
            assert rc == EINFVAR and out == "" and "a finite variance for the correction walks" in err, (m, rc, err)
        L = 100
        p_path, pb_path = os.path.join(d, "p.mtx"), os.path.join(d, "p_b.mtx")
        ent = [(i * L + j, (i + di) * L + j + dj, -1) for i in range(L) for j in range(L)
               for di, dj in ((1, 0), (-1, 0), (0, 1), (0, -1)) if 0 <= i + di < L and 0 <= j + dj < L]
        ent += [(k, k, 4) for k in range(L * L)]
        with open(p_path, "w") as f:
            f.write(f"%%MatrixMarket matrix coordinate real general\n{L * L} {L * L} {len(ent)}\n")
            f.writelines(f"{i + 1} {j + 1} {a}\n" for i, j, a in ent)
        with open(pb_path, "w") as f:
            f.write(f"%%MatrixMarket matrix array real general\n{L * L} 1\n" + "1\n" * (L * L))
        for m in ("mcsa", "sequential"):
            rc, out, err = run(ulam, ["solve", p_path, "--rhs", pb_path, "--jacobi", "--method", m, "--json"])
            o = json.loads(out)
            assert rc == ESTALL and o["outcome"] == "stalled" and o["iterations"] == 1, (m, rc, o)
            assert o["rejected"] == 1 and all(h["residual"] <= 1 for h in o["history"]), o
            assert "cannot make it contract" in err, err


def main():
    ulam = sys.argv[1]
    failures = check_table(ulam)
    for f in (check_json_out, check_interrupt, check_krylov, check_issue25_case8):
        try:
            f(ulam)
        except AssertionError as e:
            failures += 1
            print(f"FAIL {f.__name__}: {e}")
    print(f"{len(CASES) + 4 - failures} passed, {failures} failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
