#!/usr/bin/env python3
"""Walks across MPI ranks (built with -Dmpi=enabled): `mpirun -np 2 ulam ...` must give, bit for
bit, what one process gives with the same seed and walk count, for solve (adjoint and forward,
whose --out file must match byte for byte), study (runs.csv estimates) and radiosity.
Run from the source root: mpi_test.py path/to/ulam path/to/mpirun"""
import json
import os
import re
import subprocess
import sys
import tempfile

ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
           OMPI_MCA_rmaps_base_oversubscribe="1", OMPI_MCA_btl="self,vader", OMPI_MCA_btl_vader_single_copy_mechanism="none",
           OMPI_MCA_plm_rsh_agent="")


def answer(line):
    """estimate, standard error, 95% interval of an answer line 'x[i] E +- H (95% CI lo .. hi[; standard error se])':
    H is the standard error, or the interval's wider side past 10 of them, the standard error then named."""
    m = re.match(r"\S+\s+(\S+) \+- (\S+) \(95% CI (\S+) \.\. ([^;)\s]+)(?:; standard error (\S+))?\)", line)
    assert m, line
    est, pm, lo, hi, se = m.groups()
    return float(est), float(se if se is not None else pm), float(lo), float(hi)


def run(cmd, rc=0):
    """cmd's stdout, once it exited rc (5: a --rel-err target not met, the answer printed)."""
    p = subprocess.run(cmd, capture_output=True, text=True, env=ENV, timeout=300)
    assert p.returncode == rc, (cmd, p.returncode, p.stderr)
    return p.stdout


def check_interrupt(ulam, mpirun):
    """Ctrl-C under mpirun (issue 26, point 8): mpirun sends every rank SIGTERM, which the walks take
    as their first Ctrl-C: every rank stops at the same round and rank 0 prints the estimate so far,
    marked interrupted.  No clock: the signal is sent once both ranks have stopped themselves with the
    walks' handler installed (the ULAM_TEST_STOP_AT_WALKS hook; mpirun sends SIGCONT before SIGTERM)."""
    import signal
    p = subprocess.Popen([mpirun, "--oversubscribe", "-np", "2", ulam, "solve", "--method", "walks", "matrices/chain4.mtx",
                          "--rhs", "matrices/chain4_b.mtx", "--index", "2", "--walks", "100000000000", "--json"],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         # mpirun's SIGKILL follows its SIGTERM after odls_base_sigkill_timeout (1 s by
                         # default): under load the ranks' last round and rank 0's print can take longer
                         env=dict(ENV, ULAM_TEST_STOP_AT_WALKS="1", OMPI_MCA_odls_base_sigkill_timeout="60"))
    try:
        ready = 0
        while ready < 2 and p.poll() is None:  # both ranks stopped themselves with the walks' handler set
            ready = 0
            kids = subprocess.run(["pgrep", "-P", str(p.pid)], capture_output=True, text=True).stdout.split()
            for k in kids:
                try:
                    state = [l for l in open(f"/proc/{k}/status") if l.startswith("State:")][0].split()[1]
                    ready += state == "T" and open(f"/proc/{k}/comm").read().startswith("ulam")
                except (OSError, IndexError):
                    pass
        p.send_signal(signal.SIGINT)
        out, err = p.communicate(timeout=120)
    finally:
        if p.poll() is None:
            p.kill()
    o = json.loads(out)
    assert o["interrupted"] is True and o["walks"] >= 0 and o["ranks"] == 2, (out, err)


def write_system(d, n, seed):
    """A random sparse signed M (row and column sums of |M| below 0.6: finite variance both ways, a
    long cycle i -> i+1 so walks cross ranks) and b as Matrix Market files, prepared with M'."""
    import random
    rnd = random.Random(seed)
    ent = {}
    for i in range(n):
        deg = rnd.randint(1, 5)
        for q in range(deg):
            j = (i + 1) % n if q == 0 else rnd.randrange(n)
            ent[(i, j)] = ent.get((i, j), 0.0) + 0.4 / deg * (-1 if rnd.random() < 0.2 else 1)
    with open(f"{d}/pm.mtx", "w") as f:
        f.write("%%%%MatrixMarket matrix coordinate real general\n%d %d %d\n" % (n, n, len(ent)))
        f.writelines("%d %d %.17g\n" % (i + 1, j + 1, v) for (i, j), v in sorted(ent.items()))
    with open(f"{d}/pb.mtx", "w") as f:
        f.write("%%%%MatrixMarket matrix array real general\n%d 1\n" % n)
        f.writelines("%.17g\n" % rnd.random() for _ in range(n))
    return f"{d}/pm.mtx", f"{d}/pb.mtx"


def check_partition(ulam, mpirun, d):
    """Issue 43: the rows split across 1, 2 and 3 ranks (oversubscribed; and 4 in 2 sets), walks that
    migrate: the adjoint answer line and the forward --out file byte for byte the same at every rank count, no
    rank holding every row, walks crossing ranks; x within 4 standard errors of the direct solve; a
    rank that dies ends the job with a non-zero exit, not a hang."""
    import re
    n = 3000
    m, b = write_system(d, n, 5)
    sysf = f"{d}/p.ulam"
    run([ulam, "prepare", m, "--rhs", b, "--transpose", "-o", sysf])
    direct = f"{d}/pd.mtx"
    run([ulam, "direct", m, "--rhs", b, "--out", direct])
    exact = [float(v) for v in open(direct).read().split("\n")[3:] if v.strip()]
    lines, files = [], []
    for k in (1, 2, 3):
        out = run([mpirun, "--oversubscribe", "-np", str(k), ulam, "solve", sysf, "--partition", "--index", "1234",
                   "--walks", "40000", "--seed", "3", "-v"])
        lines.append(out.splitlines()[0])
        rows = [l for l in out.splitlines() if l.startswith("ranks")][0].split(";")[0].split()[2:]
        assert len(rows) == k and sum(map(int, rows)) == n and (k == 1 or max(map(int, rows)) < n), out
        mig = float([l for l in out.splitlines() if l.startswith("migration")][0].split()[1])
        assert (mig > 0) == (k > 1), out
        x = f"{d}/px{k}.mtx"
        run([mpirun, "--oversubscribe", "-np", str(k), ulam, "solve", sysf, "--partition", "--mode", "forward",
             "--walks", "200000", "--seed", "3", "--out", x, "-q"])
        files.append(open(x, "rb").read())
    x = f"{d}/pxs.mtx"  # 4 ranks in 2 sets (replication x partition): the same file again
    run([mpirun, "--oversubscribe", "-np", "4", ulam, "solve", sysf, "--partition", "--sets", "2", "--mode", "forward",
         "--walks", "200000", "--seed", "3", "--out", x, "-q"])
    files.append(open(x, "rb").read())
    assert lines[0] == lines[1] == lines[2], lines
    assert files[0] == files[1] == files[2] == files[3], "forward --out files differ across rank counts or sets"
    est, se = answer(lines[0])[:2]
    assert abs(est - exact[1233]) < 4 * se, (lines[0], exact[1233])
    outer = []  # MCSA (x file) and single source (top-10 table) at 1 and 3 ranks: byte for byte
    for k in (1, 3):
        x = f"{d}/pm{k}.mtx"
        run([mpirun, "--oversubscribe", "-np", str(k), ulam, "solve", sysf, "--partition", "--method", "mcsa", "--walks",
             "20000", "--out", x, "-q"])
        top = run([mpirun, "--oversubscribe", "-np", str(k), ulam, "solve", sysf, "--partition", "--source", "77",
                   "--top", "10", "--walks", "20000", "-q"])
        outer.append((open(x).read(), top))
    x = f"{d}/pms.mtx"  # 4 ranks in 2 sets: MCSA's x file and single source's table again, byte for byte
    run([mpirun, "--oversubscribe", "-np", "4", ulam, "solve", sysf, "--partition", "--sets", "2", "--method", "mcsa",
         "--walks", "20000", "--out", x, "-q"])
    top = run([mpirun, "--oversubscribe", "-np", "4", ulam, "solve", sysf, "--partition", "--sets", "2", "--source", "77",
               "--top", "10", "--walks", "20000", "-q"])
    outer.append((open(x).read(), top))
    assert outer[0] == outer[1] == outer[2], "MCSA or single source differ across rank counts or sets"
    # the migration line of every mode at 3 ranks: walks cross, and each crossing sends one walk's
    # bytes (the same record whatever the mode), so bytes a step over the share crossing is one
    # size; single source and MCSA once printed "0 bytes a step, 0 rounds" (issue 43)
    per = {}
    for name, mode in (("forward", ["--mode", "forward"]), ("source", ["--source", "77"]), ("mcsa", ["--method", "mcsa"])):
        out = run([mpirun, "--oversubscribe", "-np", "3", ulam, "solve", sysf, "--partition", *mode, "--walks", "20000"])
        mig = re.search(r"^migration +(\S+) of steps crossed ranks, (\S+) bytes a step, (\d+) rounds", out, re.M)
        share, step, rounds = float(mig.group(1)), float(mig.group(2)), int(mig.group(3))
        assert share > 0 and step > 0 and rounds > 0, (name, out)
        per[name] = step / share
    assert all(abs(v / per["forward"] - 1) < 0.01 for v in per.values()), per
    xm = [float(v) for v in outer[0][0].split("\n")[3:] if v.strip()]
    assert max(abs(a - b) for a, b in zip(xm, exact)) < 1e-6 * max(abs(b) for b in exact), "MCSA's x is off"
    assert len(outer[0][1].splitlines()) == 10 and outer[0][1].startswith("x[77]"), outer[0][1]
    # certified ranges from the residual (point 2): MCSA's bound, single source's top 10, forward --bound
    out = run([mpirun, "--oversubscribe", "-np", "3", ulam, "solve", sysf, "--partition", "--method", "mcsa", "--walks",
               "20000", "--out", f"{d}/pmb.mtx", "-q"])
    worst = float(re.search(r"^bound +every \|x_i - x\*_i\| <= (\S+)", out, re.M).group(1))
    xm = [float(v) for v in open(f"{d}/pmb.mtx").read().split("\n")[3:] if v.strip()]
    assert max(abs(a - b) for a, b in zip(xm, exact)) <= worst < 1e-6, (out, worst)
    with open(f"{d}/e77.mtx", "w") as f:
        f.write("%%%%MatrixMarket matrix array real general\n%d 1\n" % n + "".join("1\n" if i == 76 else "0\n" for i in range(n)))
    run([ulam, "direct", m, "--rhs", f"{d}/e77.mtx", "--out", f"{d}/c77.mtx"])
    col = [float(v) for v in open(f"{d}/c77.mtx").read().split("\n")[3:] if v.strip()]
    for line in outer[0][1].splitlines():
        i = int(re.match(r"x\[(\d+)\]", line).group(1))
        lo, hi = (float(v) for v in re.search(r"CI (\S+) \.\. ([^;)\s]+)", line).groups())
        assert lo <= col[i - 1] <= hi and hi - lo < 1e-4, (line, col[i - 1])
    out = run([mpirun, "--oversubscribe", "-np", "2", ulam, "solve", sysf, "--partition", "--mode", "forward", "--bound",
               "--walks", "50000", "--seed", "3", "--out", f"{d}/pfb.mtx", "-q"])
    worst = float(re.search(r"^bound +every \|x_i - x\*_i\| <= (\S+)", out, re.M).group(1))
    xf = [float(v) for v in open(f"{d}/pfb.mtx").read().split("\n")[3:] if v.strip()]
    assert max(abs(a - b) for a, b in zip(xf, exact)) <= worst, (out, worst)
    qf = f"{d}/pq.txt"  # many queries at once: each line the lone run's with the seed it prints, at 1 and 3 ranks
    open(qf, "w").write("1234\n# a comment\n7\n1234\n")
    qs = [run([mpirun, "--oversubscribe", "-np", str(k), ulam, "solve", sysf, "--partition", "--queries", qf, "--walks",
               "40000", "--seed", "3", "-q"]) for k in (1, 3)]
    first, own = qs[0].splitlines()[0].split("  line 1, seed ")  # query 1's seed: docs/streams.md
    lone = run([mpirun, "--oversubscribe", "-np", "3", ulam, "solve", sysf, "--partition", "--index", "1234", "--walks",
                "40000", "--seed", own, "-q"])
    assert qs[0] == qs[1] and own != "3" and first == lone.splitlines()[0], (qs, lone)
    est, _, lo, hi = answer(lines[0])  # the certified 95% interval holds x
    assert lo <= exact[1233] <= hi and lo <= est <= hi, (lines[0], exact[1233])
    rel = [run([mpirun, "--oversubscribe", "-np", str(k), ulam, "solve", sysf, "--partition", "--index", "1234",
                "--rel-err", "0.01", "--batch", "8192", "--seed", "3", "-q"]) for k in (1, 3)]
    assert rel[0] == rel[1] and "rel-err         met" in rel[0], rel  # --rel-err on a partition: the same bits
    est, _, lo, hi = answer(rel[0])
    assert lo <= exact[1233] <= hi and hi - lo <= 0.02 * abs(est), rel[0]
    p = subprocess.run([mpirun, "--oversubscribe", "-np", "3", ulam, "solve", sysf, "--partition", "--index", "5"],
                       capture_output=True, text=True, env=dict(ENV, ULAM_TEST_PARTITION_DIE="1"), timeout=120)
    assert p.returncode != 0 and not p.stdout, (p.returncode, p.stdout)


def check_partition_growing(ulam, mpirun, d):
    """Issue 43: adjoint intervals on a partition when rows of |M| sum above 1 (a tenth of the rows
    at 1.5, the rest 0.4: weights that grow, rho(M^) < 1).  The line said "no certified interval"
    before; now the weights' certified second moment bounds the clipping: a 95% CI at 1, 2 and 3
    ranks, byte for byte the same line, holding x from the direct solve, for queries at 3 seeds."""
    import random
    rnd = random.Random(5)
    n, ent = 3000, {}
    for i in range(n):
        deg = rnd.randint(1, 5)
        tot = 1.5 if rnd.random() < 0.1 else 0.4
        for q in range(deg):
            j = (i + 1) % n if q == 0 else rnd.randrange(n)
            ent[(i, j)] = ent.get((i, j), 0.0) + tot / deg * (-1 if rnd.random() < 0.2 else 1)
    m, b = f"{d}/gm.mtx", f"{d}/gb.mtx"
    with open(m, "w") as f:
        f.write("%%%%MatrixMarket matrix coordinate real general\n%d %d %d\n" % (n, n, len(ent)))
        f.writelines("%d %d %.17g\n" % (i + 1, j + 1, v) for (i, j), v in sorted(ent.items()))
    with open(b, "w") as f:
        f.write("%%%%MatrixMarket matrix array real general\n%d 1\n" % n)
        f.writelines("%.17g\n" % rnd.random() for _ in range(n))
    sysf = f"{d}/g3.ulam"
    prep = run([ulam, "prepare", m, "--rhs", b, "--transpose", "-o", sysf])
    assert "0.4 .. 1.5" in prep, prep  # rows above 1
    run([ulam, "direct", m, "--rhs", b, "--out", f"{d}/gd.mtx"])
    exact = [float(v) for v in open(f"{d}/gd.mtx").read().split("\n")[3:] if v.strip()]
    for idx, seed in ((1234, 3), (7, 4), (2999, 5)):
        lines = [run([mpirun, "--oversubscribe", "-np", str(k), ulam, "solve", sysf, "--partition", "--index", str(idx),
                      "--walks", "100000", "--seed", str(seed), "-q"]).splitlines()[0] for k in (1, 2, 3)]
        assert lines[0] == lines[1] == lines[2], lines
        assert "95% CI" in lines[0], lines[0]
        est, se, lo, hi = answer(lines[0])
        x = exact[idx - 1]
        assert abs(est - x) < 4 * se and lo <= x <= hi and lo <= est <= hi, (lines[0], x)


def check_partition_forward_index(ulam, mpirun, d):
    """Issue 43: forward mode on a partition with --index I prints x_I's line with a certified 95%
    interval (its histories' tallies in the confidence sequence adjoint queries use; --index with
    --mode forward was a usage error before): at 1, 2, 3 ranks and 4 in 2 sets the line and the
    --out file byte for byte the same, the file the same as without --index, the interval holding
    x_I from the direct solve and the estimate within 4 standard errors.  Two systems: M' rows of
    |M'| at most 0.4 (the length tail) and write_system's own (columns of |M| above 1: the
    weights' second moment, honest and wide)."""
    n = 3000
    m, b = write_system(d, n, 5)
    t = f"{d}/ft.mtx"
    with open(m) as f, open(t, "w") as g:
        for k, l in enumerate(f):
            g.write(l if k < 2 else "%s %s %s\n" % tuple(l.split()[i] for i in (1, 0, 2)))
    for mm in (t, m):
        sysf = f"{d}/fi.ulam"
        run([ulam, "prepare", mm, "--rhs", b, "--transpose", "-o", sysf])
        run([ulam, "direct", mm, "--rhs", b, "--out", f"{d}/fd.mtx"])
        exact = [float(v) for v in open(f"{d}/fd.mtx").read().split("\n")[3:] if v.strip()]
        base = [mpirun, "--oversubscribe", "-np"]
        run(base + ["1", ulam, "solve", sysf, "--partition", "--mode", "forward", "--walks", "200000", "--seed", "3",
                    "--out", f"{d}/f0.mtx", "-q"])
        lines, files = [], [open(f"{d}/f0.mtx").read()]
        for k, extra in (("1", []), ("2", []), ("3", []), ("4", ["--sets", "2"])):
            out = run(base + [k, ulam, "solve", sysf, "--partition", "--mode", "forward", "--index", "1234", "--walks",
                              "200000", "--seed", "3", "--out", f"{d}/f{k}.mtx", "-q"] + extra)
            lines.append(out.splitlines()[0])
            files.append(open(f"{d}/f{k}.mtx").read())
        assert len(set(lines)) == 1 and len(set(files)) == 1, (mm, lines)
        assert lines[0].startswith("x[1234]") and "95% CI" in lines[0], lines[0]
        est, se, lo, hi = answer(lines[0])
        x = exact[1233]
        assert abs(est - x) < 4 * se and lo <= x <= hi and lo <= est <= hi, (mm, lines[0], x)
        if mm == t:
            assert hi - lo < 3.0 * abs(x), lines[0]  # the length tail's: within +-150% of x (the second moment's: +-1e4)


def check_partition_forward_rel_err(ulam, mpirun, d):
    """exit17: --mode forward --index I --rel-err E on a partition.  Forward walks there have no stop
    rule, yet --rel-err raised the default walks to 2^30 (chain4 at 2 ranks: still running at 120 s)
    and the report said 'NOT met ... (no certified interval ...)' and exited 5 whatever the interval
    (chain4 at 10^5 walks: 2.938 +- 0.0095, 95% CI 2.900 .. 3.004, within 0.05 |x|).  Now --rel-err
    there needs --walks (a usage error naming the adjoint --index route, which stops at the target),
    and the target is judged on x_I's printed interval after the walks: met (exit 0) or NOT met (exit 5),
    the line saying the forward walks have no stop rule."""
    sysf = f"{d}/c4f.ulam"
    run([ulam, "prepare", "matrices/chain4.mtx", "--rhs", "matrices/chain4_b.mtx", "--transpose", "-o", sysf])
    base = [mpirun, "--oversubscribe", "-np", "2", ulam, "solve", sysf, "--partition", "--mode", "forward", "--index", "1",
            "--rel-err", "0.05"]
    p = subprocess.run(base, capture_output=True, text=True, env=ENV, timeout=60)
    assert p.returncode == 2 and "forward walks on a partition have no stop rule" in p.stderr and \
        "--index I without --mode forward" in p.stderr, (p.returncode, p.stderr)
    out = run(base + ["--walks", "100000"])
    m = re.match(r"x\[1\] +(\S+) \+- \S+ \(95% CI (\S+) \.\. ([^;)\s]+)(?:; standard error \S+)?\)\n", out)
    assert m, out
    est, lo, hi = (float(v) for v in m.groups())
    assert (hi - lo) / 2 <= 0.05 * abs(est) and lo <= 2.932917317 <= hi, out
    assert re.search(r"^rel-err +met \(target 0\.05; judged on the interval after --walks 100000: forward walks have no "
                     r"stop rule\)$", out, re.M), out
    out = run(base + ["--walks", "1000"], rc=5)
    assert re.search(r"^rel-err +NOT met \(target 0\.05\) in --walks 1000 \(judged on the interval after them: forward "
                     r"walks have no stop rule\)$", out, re.M), out


def check_partition_forward_top(ulam, mpirun, d):
    """Issue 43: `--mode forward --top K` on a partition printed no table (--top ignored, exit 0).
    Now the K largest forward components, each with its certified range from x's residual (as
    --bound's): the table byte for byte the same at 1, 2 and 3 ranks, its rows the K largest of the
    --out file's x in order, each range holding x_i from the direct solve and each estimate within 4
    standard errors.  --top where it has no meaning (--index, --queries, MCSA, forward in sets) is
    a usage error with nothing on stdout, not an answer that ignores it."""
    n, k = 3000, 5
    m, b = write_system(d, n, 5)
    sysf = f"{d}/ftop.ulam"
    run([ulam, "prepare", m, "--rhs", b, "--transpose", "-o", sysf])
    run([ulam, "direct", m, "--rhs", b, "--out", f"{d}/ftd.mtx"])
    exact = [float(v) for v in open(f"{d}/ftd.mtx").read().split("\n")[3:] if v.strip()]
    tops = []
    for r in ("1", "2", "3"):
        out = run([mpirun, "--oversubscribe", "-np", r, ulam, "solve", sysf, "--partition", "--mode", "forward", "--top",
                   str(k), "--walks", "100000", "--seed", "3", "--out", f"{d}/ftx{r}.mtx", "-q"])
        tops.append([l for l in out.splitlines() if l.startswith("x[")])
        assert open(f"{d}/ftx{r}.mtx").read() == open(f"{d}/ftx1.mtx").read()
    assert tops[0] == tops[1] == tops[2] and len(tops[0]) == k, tops
    x = [float(v) for v in open(f"{d}/ftx1.mtx").read().split("\n")[3:] if v.strip()]
    want = sorted(range(n), key=lambda i: (-x[i], i))[:k]
    for line, i in zip(tops[0], want):
        assert line.startswith(f"x[{i + 1}]") and "95% CI" in line, (line, i)
        est, se, lo, hi = answer(line)
        assert est == float("%.10g" % x[i]) and abs(est - exact[i]) < 4 * se and lo <= exact[i] <= hi, (line, exact[i])
    for extra in (["--index", "7", "--top", "3"], ["--mode", "forward", "--index", "7", "--top", "3"],
                  ["--method", "mcsa", "--top", "3"], ["--mode", "forward", "--top", "3", "--sets", "2"]):
        p = subprocess.run([mpirun, "--oversubscribe", "-np", "2", ulam, "solve", sysf, "--partition", "--walks", "1000"]
                           + extra, capture_output=True, text=True, env=ENV, timeout=300)
        assert p.returncode != 0 and not p.stdout and "--top" in p.stderr, (extra, p.returncode, p.stdout, p.stderr)


def three_rank_query(ulam, mpirun, d):
    """The failure checks' run: write_system's 3000 rows prepared, x[1234] by 40000 walks on 3 ranks;
    its command and what it prints undisturbed."""
    m, b = write_system(d, 3000, 5)
    sysf = f"{d}/k.ulam"
    run([ulam, "prepare", m, "--rhs", b, "--transpose", "-o", sysf])
    cmd = [mpirun, "--oversubscribe", "-np", "3", ulam, "solve", sysf, "--partition", "--index", "1234", "--walks", "40000",
           "--seed", "3"]
    return cmd, run(cmd)


def check_partition_kill(ulam, mpirun, d):
    """Issue 43: a rank killed mid-run (SIGKILL, no word to the others, while they wait in an
    exchange: the ULAM_TEST_PARTITION_KILL=rank:exchange hook of src/cli/mpi.c) ends the job with
    a non-zero exit, mpirun's message naming the rank and the signal, and no stdout, not a hang.
    Rank 1 of 3 makes 31 exchanges on this query (a kill at the 32nd is never reached: the run
    ends normally); the walks' 7 rounds are exchanges 23-29, so 26 kills it among the walks and 31
    at the last (rank 0 holds the answer, unprinted).  A quiet run takes about 1.5 s here; the
    timeout is 120 s."""
    cmd, quiet = three_rank_query(ulam, mpirun, d)
    for at in (26, 31, 32):
        p = subprocess.run(cmd, capture_output=True, text=True, env=dict(ENV, ULAM_TEST_PARTITION_KILL=f"1:{at}"), timeout=120)
        if at == 32:
            assert p.returncode == 0 and p.stdout.splitlines()[0] == quiet.splitlines()[0], (at, p.returncode, p.stderr)
        else:
            assert p.returncode != 0 and not p.stdout and "rank 1" in p.stderr and "signal 9" in p.stderr, (at, p.returncode, p.stdout, p.stderr)


def check_partition_stall(ulam, mpirun, d):
    """Issue 43: a message delayed without end (rank 1 of 3 stops for good, alive and silent, as it
    enters its 26th exchange, among the walks: the ULAM_TEST_PARTITION_STALL=rank:exchange hook of
    src/cli/mpi.c) ends the job once the others have waited ULAM_EXCHANGE_TIMEOUT (1 s here): a
    non-zero exit, the waiting rank's message naming what it waited for, no stdout, not a hang.  A
    timeout that is not a number is named and the default kept (the run then ends normally).  No
    clock in the test: the wait is the program's; the timeout here is 120 s."""
    cmd, quiet = three_rank_query(ulam, mpirun, d)
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=120,
                       env=dict(ENV, ULAM_TEST_PARTITION_STALL="1:26", ULAM_EXCHANGE_TIMEOUT="1"))
    assert p.returncode != 0 and not p.stdout and re.search(r"rank [02] of 3: no message sizes from the other ranks in 1 s",
                                                            p.stderr), (p.returncode, p.stdout, p.stderr)
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=120, env=dict(ENV, ULAM_EXCHANGE_TIMEOUT="soon"))
    assert p.returncode == 0 and p.stdout.splitlines()[0] == quiet.splitlines()[0] and \
        "ULAM_EXCHANGE_TIMEOUT=soon is not a number of seconds" in p.stderr, (p.returncode, p.stderr)


def check_partition_mtx(ulam, mpirun, d):
    """Issue 43: Matrix Market read by byte ranges on a partition (--rhs): each rank parses its share
    of the lines.  A file with shuffled rows, split duplicates, an explicit zero, a comment and a blank
    line gives, at 1, 2 and 3 ranks (and 4 in 2 sets), byte for byte what the prepared file gives:
    the adjoint line, the forward, MCSA and --errors files, the single-source table.  A symmetric
    4-row system (one block: ranks 2 and 3 hold no rows) likewise.  A malformed line in the first,
    middle or last rank's range, and too many or too few entries, are reported at the file's line as
    `ulam prepare` reports them, once, at every rank count, with a non-zero exit and no stdout."""
    import random
    rnd = random.Random(11)
    n = 3000
    m, b = write_system(d, n, 5)
    body = open(m).read().splitlines(True)
    head, lines = body[:2], body[2:]
    rnd.shuffle(lines)
    out = []
    for l in lines:  # a tenth of the entries split in two lines (summed in file order)
        i, j, v = l.split()
        if rnd.random() < 0.1:
            out += ["%s %s %.17g\n" % (i, j, float(v) * 0.25), "%s %s %.17g\n" % (i, j, float(v) * 0.75)]
        else:
            out.append(l)
    out.insert(100, "% a comment\n")
    out.insert(200, "\n")
    out.append("1 5 0\n")
    count = sum(1 for l in out if l.strip() and not l.startswith("%"))
    mm = f"{d}/mm.mtx"
    with open(mm, "w") as f:
        f.write("%%%%MatrixMarket matrix coordinate real general\n%% shuffled\n%d %d %d\n" % (n, n, count))
        f.writelines(out)
    sysf = f"{d}/mm.ulam"
    run([ulam, "prepare", mm, "--rhs", b, "--transpose", "-o", sysf])

    def answers(k, src, extra=()):
        pre = [mpirun, "--oversubscribe", "-np", str(k), ulam, "solve"] + src + ["--partition"] + list(extra)
        res = [run(pre + ["--index", "1234", "--walks", "20000", "--seed", "3", "-q"]).splitlines()[0]]
        run(pre + ["--mode", "forward", "--walks", "50000", "--seed", "3", "--out", f"{d}/mf.mtx", "--errors", f"{d}/me.mtx", "-q"])
        run(pre + ["--method", "mcsa", "--walks", "20000", "--out", f"{d}/mc.mtx", "-q"])
        res += [open(f"{d}/mf.mtx").read(), open(f"{d}/me.mtx").read(), open(f"{d}/mc.mtx").read()]
        res.append(run(pre + ["--source", "77", "--top", "10", "--walks", "20000", "-q"]))
        return res

    want = answers(1, [sysf])
    for k in (1, 2, 3):
        assert answers(k, [mm, "--rhs", b]) == want, f"Matrix Market by byte ranges at {k} ranks differs from the prepared file"
    assert answers(4, [mm, "--rhs", b], ["--sets", "2"]) == want, "Matrix Market in 2 sets differs"
    sym, sb = f"{d}/sym.mtx", f"{d}/symb.mtx"
    open(sym, "w").write("%%MatrixMarket matrix coordinate real symmetric\n4 4 5\n1 1 0.1\n2 1 0.2\n3 2 -0.3\n4 3 0.1\n4 4 0.2\n")
    open(sb, "w").write("%%MatrixMarket matrix array real general\n4 1\n1\n2\n3\n4\n")
    run([ulam, "prepare", sym, "--rhs", sb, "--transpose", "-o", f"{d}/sym.ulam"])
    xs = []
    for k in (1, 2, 3):
        for src in ([f"{d}/sym.ulam"], [sym, "--rhs", sb]):
            run([mpirun, "--oversubscribe", "-np", str(k), ulam, "solve"] + src + ["--partition", "--mode", "forward",
                 "--walks", "10000", "--out", f"{d}/sx.mtx", "-q"])
            xs.append(open(f"{d}/sx.mtx").read())
    assert len(set(xs)) == 1, "ranks without rows change the answer"
    total = len(open(mm).read().splitlines())
    bad = []
    for at in (10, total // 2, total - 3):  # a malformed line in the first, a middle and the last rank's range
        t = open(mm).read().splitlines(True)
        t[at - 1] = "12 x 0.5\n"
        bad.append(("".join(t), f"{at}:"))
    t = open(mm).read()
    bad.append((t + "1 2 0.1\n", f"{total + 1}:"))  # one entry more than the size line says
    t = t.splitlines(True)
    bad.append(("".join(t[:500] + t[505:]), f"{total - 5}:"))  # five fewer
    for text, where in bad:
        f = f"{d}/bad.mtx"
        open(f, "w").write(text)
        p = subprocess.run([ulam, "prepare", f, "--rhs", b, "-o", f"{d}/bad.ulam"], capture_output=True, text=True, env=ENV, timeout=120)
        ref = [l for l in p.stderr.splitlines() if l.startswith("ulam:")]
        assert p.returncode != 0 and len(ref) == 1 and f"bad.mtx:{where}" in ref[0], (where, p.stderr)
        for k in (1, 2, 3):
            p = subprocess.run([mpirun, "--oversubscribe", "-np", str(k), ulam, "solve", f, "--rhs", b, "--partition", "--index",
                                "3"], capture_output=True, text=True, env=ENV, timeout=120)
            got = [l for l in p.stderr.splitlines() if l.startswith("ulam:")]
            assert p.returncode != 0 and not p.stdout and got == ref, (k, where, got, ref)


def check_partition_source_graph(ulam, mpirun, d):
    """Single source on a PageRank graph prepared without b (M = 0.85 P' of a digraph whose heads
    favour low-numbered nodes, so rows reach every rank): runs on a partition (it needed a b in the
    file before), the top-10 table byte for byte the same at 1, 2 and 3 ranks and in 2 sets, each line within 4
    standard errors of the direct column and inside its certified range (from ||M||_1 < 1: the power
    iteration certifies no u < 1 on such a graph, and no range was printed before); an adjoint query on the same file ends with a
    clear error, not a wrong answer."""
    import random
    rnd = random.Random(11)
    n, edges = 2000, {}
    for u in range(n):
        for _ in range(1 + int(rnd.paretovariate(1.5))):
            v = min(int(rnd.paretovariate(0.7)) - 1, n - 1) if rnd.random() < 0.5 else rnd.randrange(n)
            if v != u:
                edges[(u, v)] = edges.get((u, v), 0) + 1
    out = {}
    for (u, v), c in edges.items():
        out[u] = out.get(u, 0) + c
    m = f"{d}/g.mtx"
    with open(m, "w") as f:
        f.write("%%%%MatrixMarket matrix coordinate real general\n%d %d %d\n" % (n, n, len(edges)))
        f.writelines("%d %d %.17g\n" % (v + 1, u + 1, 0.85 * c / out[u]) for (u, v), c in sorted(edges.items()))
    sysf, e = f"{d}/g.ulam", f"{d}/ge.mtx"
    run([ulam, "prepare", m, "--transpose", "-o", sysf])
    with open(e, "w") as f:
        f.write("%%%%MatrixMarket matrix array real general\n%d 1\n" % n)
        f.writelines("%d\n" % (i == 4) for i in range(n))
    run([ulam, "direct", m, "--rhs", e, "--out", f"{d}/gx.mtx"])
    exact = [float(v) for v in open(f"{d}/gx.mtx").read().split("\n")[3:] if v.strip()]
    tops = [run([mpirun, "--oversubscribe", "-np", str(k), ulam, "solve", sysf, "--partition", "--source", "5", "--top",
                 "10", "--walks", "20000", "-q"]) for k in (1, 2, 3)]
    tops.append(run([mpirun, "--oversubscribe", "-np", "4", ulam, "solve", sysf, "--partition", "--sets", "2",
                     "--source", "5", "--top", "10", "--walks", "20000", "-q"]))  # 2 sets: ||r||_1 over one set's rows
    assert tops[0] == tops[1] == tops[2] == tops[3], tops
    import re
    for line in tops[0].splitlines():  # within 4 standard errors, or 1e-3 of it where no walk reached it
        i, est = int(re.match(r"x\[(\d+)\]", line).group(1)) - 1, float(line.split()[1])
        se = re.search(r"standard error (\S+)\)", line) or re.search(r"\+- (\S+)", line)
        assert abs(est - exact[i]) < (4 * float(se.group(1)) if se else 1e-3 * exact[i]), (line, exact[i])
        ci = re.search(r"CI (\S+) \.\. ([^;)\s]+)", line)  # the l1 range (||M||_1 = 0.85): none was certified before
        assert ci and float(ci.group(1)) <= exact[i] <= float(ci.group(2)), (line, exact[i])
    p = subprocess.run([mpirun, "--oversubscribe", "-np", "2", ulam, "solve", sysf, "--partition", "--index", "3"],
                       capture_output=True, text=True, env=ENV, timeout=300)
    assert p.returncode != 0 and "a b in the prepared file" in p.stderr, (p.returncode, p.stderr)


def check_partition_memory(ulam, mpirun, d):
    """Issue 43's memory test: forward mode on a 10^6-row system (8 entries a row, a band around the
    diagonal, |row sums| 0.4), 3 ranks: each rank's peak RSS at most half of one rank's alone (MPI's
    own memory included), and the same x file."""
    n, width = 1000000, 8
    with open(f"{d}/big.mtx", "w") as f:
        f.write("%%%%MatrixMarket matrix coordinate real general\n%d %d %d\n" % (n, n, n * width))
        for i in range(1, n + 1):
            f.write("".join("%d %d %s\n" % (i, (i + k - 1) % n + 1, "-0.05" if k == 3 else "0.05") for k in range(1, width + 1)))
    with open(f"{d}/bigb.mtx", "w") as f:
        f.write("%%%%MatrixMarket matrix array real general\n%d 1\n" % n)
        f.write("1\n" * n)
    run([ulam, "prepare", f"{d}/big.mtx", "--rhs", f"{d}/bigb.mtx", "--transpose", "-o", f"{d}/big.ulam"])
    rss, files = [], []
    for k, src in ((1, [f"{d}/big.ulam"]), (3, [f"{d}/big.ulam"]), (1, [f"{d}/big.mtx", "--rhs", f"{d}/bigb.mtx"]),
                   (3, [f"{d}/big.mtx", "--rhs", f"{d}/bigb.mtx"])):  # prepared, then Matrix Market by byte ranges
        out = run([mpirun, "--oversubscribe", "-np", str(k), ulam, "solve"] + src + ["--partition", "--mode",
                   "forward", "--walks", "100000", "--out", f"{d}/bx{k}.mtx", "-v"])
        line = [l for l in out.splitlines() if l.startswith("ranks")][0]
        rss.append([float(v) for v in line.split("peak RSS MiB")[1].split()])
        files.append(open(f"{d}/bx{k}.mtx").read())
    os.unlink(f"{d}/big.mtx")
    assert files[0] == files[1] == files[2] == files[3], "x differs"
    assert len(rss[1]) == 3 and max(rss[1]) <= 0.5 * rss[0][0], rss
    assert len(rss[3]) == 3 and max(rss[3]) <= 0.5 * rss[2][0], rss  # no rank holds the whole matrix
    return rss


PARTITION_CHECKS = (("partition", check_partition), ("partition rows above 1", check_partition_growing),
                    ("partition forward index", check_partition_forward_index),
                    ("partition forward rel-err", check_partition_forward_rel_err),
                    ("partition forward top", check_partition_forward_top),
                    ("partition rank killed", check_partition_kill),
                    ("partition rank stalled", check_partition_stall),
                    ("partition matrix market", check_partition_mtx),
                    ("partition source without b", check_partition_source_graph))


def main():
    ulam, mpirun = sys.argv[1], sys.argv[2]
    par = [mpirun, "--oversubscribe", "-np", "2", ulam]
    failures = 0
    with tempfile.TemporaryDirectory() as d:
        cases = [
            ("solve adjoint", ["solve", "--method", "walks", "matrices/signed200.mtx", "--rhs", "matrices/signed200_b.mtx", "--index", "7",
                               "--walks", "50000", "--seed", "9", "--json"], None),
            # chain4 at alpha 0.5: rho(M4) < 0.96, a quick rel-err stop (signed200's certified second
            # moment asks for 1.7e7 walks at this target)
            ("solve adjoint alpha", ["solve", "--method", "walks", "matrices/chain4.mtx", "--rhs", "matrices/chain4_b.mtx",
                                     "--index", "2", "--alpha", "0.5", "--rel-err", "0.02", "--json"], None),
            ("solve adjoint alpha walks", ["solve", "--method", "walks", "matrices/signed200.mtx", "--rhs", "matrices/signed200_b.mtx",
                                           "--index", "7", "--alpha", "0.5", "--rel-err", "0.02", "--walks", "100000",
                                           "--json"], None),
            ("solve forward alpha", ["solve", "--method", "walks", "matrices/radiosity100.mtx", "--rhs", "matrices/radiosity100_b.mtx", "--index",
                                     "1", "--mode", "forward", "--alpha", "2", "--walks", "30000", "--json", "--out",
                                     "{d}/xa.mtx"], "xa.mtx"),
            ("solve adjoint rel-err", ["solve", "--method", "walks", "matrices/randsub1000.mtx", "--rhs", "matrices/randsub1000_b.mtx",
                                       "--index", "3", "--rel-err", "0.005", "--json"], None),
            ("solve bidirectional", ["solve", "matrices/randsub1000.mtx", "--index", "7", "--source", "3",
                                     "--rel-err", "0.01", "--json"], None),
            ("solve bidirectional sparse b", ["solve", "matrices/randsub1000.mtx", "--index", "7", "--rhs",
                                              "tests/data/sparse3_b.mtx", "--method", "bidirectional",
                                              "--rel-err", "0.02", "--json"], None),
            ("solve auto", ["solve", "matrices/randsub1000.mtx", "--rhs", "matrices/randsub1000_b.mtx",
                            "--index", "3", "--rel-err", "0.01", "--json"], None),
            # auto with a sparse b on which it chooses bidirectional (its plan seeded, not timed)
            ("solve auto bidirectional", ["solve", "matrices/randsub1000.mtx", "--index", "7", "--rhs",
                                          "tests/data/sparse3_b.mtx", "--rel-err", "0.02", "--json"], None),
            ("solve forward", ["solve", "--method", "walks", "matrices/radiosity100.mtx", "--rhs", "matrices/radiosity100_b.mtx", "--index",
                               "1", "--mode", "forward", "--walks", "30000", "--json", "--out", "{d}/x.mtx"], "x.mtx"),
            ("solve mcsa", ["solve", "matrices/randsub1000.mtx", "--rhs", "matrices/randsub1000_b.mtx", "--method",
                            "mcsa", "--tol", "1e-6", "--json", "--out", "{d}/m.mtx"], "m.mtx"),
            ("radiosity", ["radiosity", "examples/scenes/cornell_box.obj", "--patch", "floor", "--subdivide", "300",
                           "--walks", "20000", "--json"], None),
            ("radiosity next-event", ["radiosity", "examples/scenes/cornell_box.obj", "--patch", "floor", "--subdivide",
                                      "300", "--estimator", "next-event", "--rel-err", "0.02", "--json"], None),
            ("radiosity view", ["radiosity", "examples/scenes/cornell_box.obj", "--subdivide", "150", "--view-gather",
                                "--rel-err", "0.1", "--size", "12x12", "--json", "--image", "{d}/v.png"], "v.png"),
            ("radiosity shoot", ["radiosity", "tests/data/rad/cornell_black_light.obj", "--subdivide", "300", "--mode",
                                 "shoot", "--walks", "20000", "--json", "--out", "{d}/p.csv"], "p.csv"),
            ("study", ["study", "matrices/chain4.mtx", "--rhs", "matrices/chain4_b.mtx", "--index", "2", "--methods",
                       "adjoint-collision-plain,forward-collision-plain", "--budgets", "1000,5000", "--repeats", "3",
                       "--out", "{d}/s"], "s/runs.csv"),
        ]
        for name, args, outfile in cases:
            try:
                res = []
                for launcher in ([ulam], par):
                    # --walks 100000 stops "alpha walks" before its target: exit 5 (rel_err_met false), on both
                    out = run(launcher + [a.format(d=d) for a in args], 5 if name == "solve adjoint alpha walks" else 0)
                    if outfile and outfile.endswith("runs.csv"):  # drop the seconds column (wall time)
                        rows = open(os.path.join(d, outfile)).read().splitlines()
                        res.append([",".join(r.split(",")[:9]) for r in rows])
                    elif outfile:
                        mode = "rb" if outfile.endswith(".png") else "r"
                        res.append((json.loads(out), open(os.path.join(d, outfile), mode).read()))
                    else:
                        res.append(json.loads(out))
                one, two = res
                if name == "solve mcsa":  # the same iterations, walks and residuals; the same x file
                    strip = lambda o: [dict(h, seconds=0, walk_seconds=0) for h in o["history"]]
                    assert strip(one[0]) == strip(two[0]) and one[0]["residual"] == two[0]["residual"], (one, two)
                    assert two[0]["ranks"] == 2 and one[1] == two[1], "not distributed, or x files differ"
                elif name.startswith("solve"):
                    for k in ("estimate", "stderr", "walks", "steps", "variance"):
                        a, b = (one[0] if outfile else one)[k], (two[0] if outfile else two)[k]
                        assert a == b, (name, k, a, b)
                    assert (two[0] if outfile else two)["ranks"] == 2, "not distributed"
                    if name == "solve auto bidirectional":
                        assert one["method"] == two["method"] == "bidirectional", (one, two)
                        assert one["auto"] == dict(two["auto"], seconds=one["auto"]["seconds"]), (one, two)
                    if outfile:
                        assert one[1] == two[1], "forward --out files differ"
                elif name in ("radiosity", "radiosity next-event"):
                    assert one["radiosity"] == two["radiosity"] and one["stderr"] == two["stderr"], (one, two)
                    assert one["rays"] == two["rays"], (one, two)
                elif name == "radiosity view":  # the seen patches gathered across ranks: the picture byte for byte
                    assert one[0]["view"]["rays"] == two[0]["view"]["rays"] and one[1] == two[1], "differ"
                elif name == "radiosity shoot":  # every patch, black light: the CSV byte for byte
                    assert one[0]["walks"] == two[0]["walks"] and one[1] == two[1] and one[1].count("\n") == 50, "differ"
                else:
                    assert one == two and len(one) == 13, (one, two)
                print(f"ok {name}")
            except AssertionError as e:
                failures += 1
                print(f"FAIL {name}: {e}")
        for name, check in PARTITION_CHECKS:
            try:
                check(ulam, mpirun, d)
                print(f"ok {name}")
            except AssertionError as e:
                failures += 1
                print(f"FAIL {name}: {e}")
        try:
            rss = check_partition_memory(ulam, mpirun, d)
            print(f"ok partition memory (peak RSS MiB: prepared 1 rank {rss[0][0]}, 3 ranks {rss[1]}; Matrix Market "
                  f"1 rank {rss[2][0]}, 3 ranks {rss[3]})")
        except AssertionError as e:
            failures += 1
            print(f"FAIL partition memory: {e}")
    try:
        check_interrupt(ulam, mpirun)
        print("ok interrupt")
    except AssertionError as e:
        failures += 1
        print(f"FAIL interrupt: {e}")
    print(f"{len(cases) + len(PARTITION_CHECKS) + 2 - failures} passed, {failures} failed")  # + memory, interrupt
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
