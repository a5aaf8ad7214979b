#!/usr/bin/env python3
"""Command-line behaviour of `ulam`: exit codes, located error messages, output files.

A table of cases, each (arguments, expected exit code, regex the stderr must match,
regex the stdout must match).  Exit codes are 10 + the library status (see README).
Run from the source root: cli_test.py path/to/ulam
"""
import json
import os
import re
import subprocess
import sys
import tempfile

STATUS = ["OK", "EINVAL", "ENOMEM", "EIO", "EEMPTY", "EBANNER", "EUNSUPPORTED", "ESIZELINE",
          "EOVERFLOW", "ETOOFEW", "ETOOMANY", "EINDEX", "ESYNTAX", "ENONFINITE", "ENOTSQUARE",
          "EDIM", "EZERODIAG", "ESINGULAR", "EMEMLIMIT", "ENOCONV", "EUNDEFINED", "EGEOMETRY",
          "ENOTFOUND", "ERANGE", "EDEVICE"]


def code(name):
    return 10 + STATUS.index(name)


D = "tests/data/"
M = "matrices/"
BAD_FILES = [
    ("empty.mtx", "EEMPTY", 1), ("no_banner.mtx", "EBANNER", 1), ("bad_format.mtx", "EBANNER", 1),
    ("complex.mtx", "EUNSUPPORTED", 1), ("hermitian.mtx", "EUNSUPPORTED", 1),
    ("no_size.mtx", "ESIZELINE", 3), ("bad_size.mtx", "ESIZELINE", 3),
    ("too_few.mtx", "ETOOFEW", 4), ("too_many.mtx", "ETOOMANY", 5),
    ("index_zero.mtx", "EINDEX", 4), ("row_too_big.mtx", "EINDEX", 4),
    ("not_a_number.mtx", "ESYNTAX", 4), ("nan.mtx", "ENONFINITE", 3), ("inf.mtx", "ENONFINITE", 4),
    ("missing_value.mtx", "ESYNTAX", 4), ("huge_dims.mtx", "EOVERFLOW", 2),
    ("huge_nnz.mtx", "ETOOFEW", 2), ("skew_diagonal.mtx", "EINDEX", 4),
]

CASES = []
for f, status, line in BAD_FILES:
    CASES.append((["info", D + f], code(status), rf"^ulam: {re.escape(D + f)}:{line}: error: .*expected ", ""))
CASES += [
    (["info", D + "does_not_exist.mtx"], code("EIO"), r"does_not_exist.mtx: error: .*No such file", ""),
    (["info", D + "nonsquare.mtx"], code("ENOTSQUARE"), r"nonsquare.mtx: error: .*square", ""),
    (["direct", M + "chain4.mtx", "--rhs", D + "ones3.mtx"], code("EDIM"),
     r"ones3.mtx: error: .*expected 4 entries", ""),
    (["direct", M + "chain4.mtx", "--rhs", D + "vector_not_column.mtx"], code("EDIM"),
     r"vector_not_column.mtx: error: .*column vector", ""),
    (["direct", D + "singular.mtx", "--rhs", D + "ones3.mtx"], code("ESINGULAR"), r"singular", ""),
    (["direct", D + "zero_diagonal.mtx", "--rhs", D + "ones3.mtx", "--jacobi"], code("EZERODIAG"),
     r"diagonal entry in row 2", ""),
    (["direct", M + "randsub1000.mtx", "--rhs", M + "randsub1000_b.mtx", "--max-mem", "1M"],
     code("EMEMLIMIT"), r"memory limit.*needs", ""),
    (["direct", M + "chain4.mtx", "--rhs", M + "chain4_b.mtx", "--index", "5"], 2, r"--index 5 is out of range 1..4", ""),
    (["direct", M + "chain4.mtx", "--rhs", M + "chain4_b.mtx", "--index", "0"], 2, r"--index expects an integer", ""),
    (["direct", M + "chain4.mtx", "--rhs", M + "chain4_b.mtx", "--max-mem", "lots"], 2, r"--max-mem expects a size", ""),
    (["direct", M + "chain4.mtx"], 2, r"needs --rhs", ""),
    (["direct", M + "chain4.mtx", "--rhs", M + "chain4_b.mtx", "--bogus"], 2, r"unrecognized option", ""),
    (["info"], 2, r"exactly one matrix", ""),
    (["frobnicate"], 2, r"unknown command 'frobnicate'", ""),
    ([], 2, r"usage: ulam", ""),
    (["--help"], 0, r"^$", r"1-based"),
    (["direct", "--help"], 0, r"^$", r"1-based"),
    (["info", M + "chain4.mtx"], 0, r"^$", r"walks\s+converge"),
    (["info", M + "poisson20.mtx", "--jacobi"], 0, r"^$", r"rho\(M\)\s+0\.98883"),
    (["info", M + "poisson20.mtx", "--jacobi"], 0, r"^$", r"rho\(\|M\|\)\s+0\.988[78]"),
    (["info", M + "poisson20.mtx", "--jacobi"], 0, r"^$", r"0\.50\s+0\.9944\d+\s+0\.994[34]\d+\s+converges"),
    (["info", M + "randsub1000.mtx", "--continue", "0.5"], 0, r"^$", r"variance adjoint infinite"),
    (["info", M + "signed_edge200.mtx"], 0, r"^$", r"walks\s+diverge"),
    (["direct", M + "chain4.mtx", "--rhs", M + "chain4_b.mtx", "--index", "4"], 0, r"^$", r"x\[4\]\s+3\.68174"),
]
SOLVE = ["solve", M + "chain4.mtx", "--rhs", M + "chain4_b.mtx"]
DIV = ["solve", M + "divergent200.mtx", "--rhs", M + "divergent200_b.mtx", "--index", "1"]
RS = ["solve", M + "randsub1000.mtx", "--rhs", M + "randsub1000_b.mtx", "--index", "1"]
CASES += [
    # the guards: refusal, --force, the walk cap, the non-finite stop, infinite variance, the edge
    (DIV, 3, r"rho\(\|M\|\) = 1\.1 .*>= 1.*divergent series.*ulam direct.*--jacobi.*--force", r"^$"),
    (["solve", M + "signed_edge200.mtx", "--rhs", M + "signed_edge200_b.mtx", "--index", "1"], 3,
     r"rho\(\|M\|\) = 1\.3 ", r"^$"),
    (DIV + ["--force", "--max-steps", "50", "--walks", "1000"], 0, r"Running anyway \(--force\)",
     r"1000 cut at 50 steps: the estimate is biased by the cut"),
    (DIV + ["--force", "--walks", "100"], code("ENONFINITE"), r"non-finite weight or score", r"^$"),
    (RS + ["--continue", "0.5"], 0, r"rho\(M\^\) = 1\.62 >= 1 .* variance is infinite",
     r"no confidence interval: the variance is infinite"),
    (["solve", M + "poisson20.mtx", "--rhs", M + "poisson20_b.mtx", "--index", "1", "--jacobi", "--omega", "0.5",
      "--walks", "2000"], 0, r"rho\(\|M\|\) = 0\.99\d+ is within 1% of 1", r"\+-"),
    (SOLVE + ["--index", "1", "--walks", "-5"], 2, r"--walks expects an integer", ""),
    (SOLVE + ["--index", "1", "--rel-err", "0"], 2, r"--rel-err expects a number", ""),
    (SOLVE + ["--index", "1", "--threads", "0"], 2, r"--threads expects an integer", ""),
    (SOLVE + ["--index", "1", "--seed", "twelve"], 2, r"--seed expects an integer from 0", ""),
    (SOLVE + ["--index", "1", "--seed", "-1"], 2, r"--seed expects an integer from 0", ""),
    (SOLVE + ["--index", "5"], 2, r"--index 5 is out of range 1..4", ""),
    (SOLVE + ["--index", "1", "--walks", "10", "--frobnicate"], 2, r"unrecognized option '--frobnicate'", ""),
    (SOLVE + ["--index", "1", "--seed", "12x"], 2, r"--seed expects an integer", ""),
    (SOLVE + ["--index", "1", "--mode", "sideways"], 2, r"--mode expects adjoint or forward", ""),
    (SOLVE + ["--index", "1", "--estimator", "psychic"], 2, r"--estimator expects", ""),
    (SOLVE + ["--index", "1", "--continue", "1"], 2, r"--continue expects a number", ""),
    (SOLVE + ["--index", "1", "--roulette", "2", "--split", "1"], 2, r"--split W must exceed", ""),
    (SOLVE + ["--index", "9"], 2, r"--index 9 is out of range 1..4", ""),
    (SOLVE, 2, r"adjoint walks need --index", ""),
    (SOLVE + ["--index", "1", "--out", "/tmp/x.mtx"], 2, r"--out and --errors need --mode forward", ""),
    (["solve", D + "absorb_undefined.mtx", "--rhs", D + "ones3.mtx", "--index", "1", "--estimator", "absorption"],
     code("EUNDEFINED"), r"state 2 \(1-based\) is reachable and never terminates", ""),
    (SOLVE + ["--index", "2", "--walks", "20000", "--check"], 0, r"^$", r"direct\s+2\.34009.*z = "),
    (SOLVE + ["--index", "2", "--walks", "20000", "--mode", "forward", "--estimator", "expected"], 0, r"^$",
     r"forward walks, expected estimator"),
]


O = D + "obj/"
SC = "examples/scenes/"
BAD_SCENES = [  # file, status, the file:line the message must name
    ("missing_mtl.obj", "EIO", O + "missing_mtl.obj:1"), ("unknown_material.obj", "ENOTFOUND", O + "unknown_material.obj:2"),
    ("kd_range.obj", "ERANGE", O + "kd_range.mtl:4"), ("ke_negative.obj", "ERANGE", O + "ke_negative.mtl:2"),
    ("nonplanar.obj", "EGEOMETRY", O + "nonplanar.obj:8"), ("degenerate.obj", "EGEOMETRY", O + "degenerate.obj:8"),
    ("nonconvex.obj", "EGEOMETRY", O + "nonconvex.obj:8"), ("index_range.obj", "EINDEX", O + "index_range.obj:7"),
    ("no_usemtl.obj", "ENOTFOUND", O + "no_usemtl.obj:6"), ("bad_vertex.obj", "ESYNTAX", O + "bad_vertex.obj:3"),
    ("unknown_statement.obj", "ESYNTAX", O + "unknown_statement.obj:7"), ("empty.obj", "EEMPTY", O + "empty.obj:2"),
]
for f, status, where in BAD_SCENES:
    CASES.append((["radiosity", O + f, "--patch", "1"], code(status), rf"^ulam: {re.escape(where)}: error: .*expected ", ""))
CASES += [
    (["radiosity", SC + "cube.obj"], 2, r"needs --patch K", ""),
    (["radiosity", SC + "cube.obj", "--patch", "7"], 2, r"--patch 7 is out of range 1..6", ""),
    (["radiosity", SC + "cube.obj", "--patch", "attic"], 2, r"neither a patch number nor a label; labels: floor ceiling", ""),
    (["radiosity", SC + "cube.obj", "--patch", "1", "--image", "x.png"], 2, r"--image needs --mode shoot or --direct", ""),
    (["radiosity", SC + "cube.obj", "--patch", "1", "--walks", "-5"], 2, r"--walks expects an integer", ""),
    (["radiosity", SC + "cube.obj", "--patch", "1", "--subdivide", "0"], 2, r"--subdivide expects a number", ""),
    (["radiosity", SC + "cube.obj", "--patch", "1", "--mode", "sideways"], 2, r"--mode expects gather or shoot", ""),
    (["radiosity", SC + "cube.obj", "--patch", "1", "--size", "0x5"], 2, r"--size expects WxH", ""),
    (["radiosity", SC + "cube.obj", "--patch", "1", "--walks", "1000", "--estimator", "absorption"], 0, r"^$", r"radiosity R  2 \+- 0"),
    (["radiosity", SC + "cube.obj", "--direct", "--max-mem", "10"], code("EMEMLIMIT"), r"memory limit", ""),
]


def run(ulam, args):
    p = subprocess.run([ulam] + args, capture_output=True, text=True, timeout=120)
    return p.returncode, p.stdout, p.stderr


def check_table(ulam):
    failures = 0
    for args, want_rc, err_re, out_re in CASES:
        rc, out, err = run(ulam, args)
        ok = rc == want_rc and re.search(err_re, err, re.M) and re.search(out_re, out, re.M)
        if not ok:
            failures += 1
            print(f"FAIL ulam {' '.join(args)}: rc {rc} (want {want_rc})\n  stderr: {err.strip()}\n  stdout: {out.strip()[:300]}")
    return failures, len(CASES)


def check_json(ulam):
    """--json prints one object with the documented keys; values match the text output."""
    rc, out, _ = run(ulam, ["info", M + "signed_edge200.mtx", "--json"])
    o = json.loads(out)
    assert rc == 0
    for k in ["n", "nnz", "nonnegative", "substochastic", "rho", "rho_abs", "neumann_converges", "walks_converge"]:
        assert k in o, k
    assert o["neumann_converges"] is True and o["walks_converge"] is False
    assert abs(o["rho_abs"] - 1.3) < 1e-6 and o["rho"] < 1 and o["rho_abs_lower"] >= 1
    assert o["variance_finite_adjoint"] is False and abs(o["rho_hat_adjoint"] - 1.69) < 1e-6
    rc, out, _ = run(ulam, ["direct", M + "chain4.mtx", "--rhs", M + "chain4_b.mtx", "--index", "1", "--json"])
    o = json.loads(out)
    for k in ["n", "index", "value", "rcond", "residual", "seconds"]:
        assert k in o, k
    assert o["index"] == 1 and abs(o["value"] - 2.9329173166926679) < 1e-12 and o["residual"] < 1e-14


def check_solve_json(ulam):
    """solve --json has the documented keys; --check adds direct and z; threads do not matter."""
    base = SOLVE + ["--index", "3", "--walks", "50000", "--seed", "5", "--json", "--check"]
    outs = []
    for t in ("1", "2"):
        rc, out, _ = run(ulam, base + ["--threads", t])
        assert rc == 0
        outs.append(json.loads(out))
    o = outs[0]
    for k in ["index", "estimate", "stderr", "ci95", "variance", "walks", "steps", "seconds", "mode",
              "estimator", "seed", "threads", "interrupted", "direct", "direct_seconds", "z"]:
        assert k in o, k
    assert o["index"] == 3 and o["walks"] == 50000 and o["interrupted"] is False
    assert abs(o["estimate"] - o["direct"]) < 4 * o["stderr"], o
    assert o["ci95"][0] < o["estimate"] < o["ci95"][1]
    assert outs[0]["estimate"] == outs[1]["estimate"] and outs[0]["variance"] == outs[1]["variance"]
    assert o["variance_finite"] is True and o["heavy_tail"] is False and 0 < o["max_share"] < 0.01
    assert abs(o["rho_abs"] - 0.748408) < 1e-4
    # infinite variance: no interval, and one walk dominates the sum of squares
    rc, out, _ = run(ulam, RS + ["--continue", "0.5", "--json", "--seed", "3"])
    o = json.loads(out)
    assert rc == 0 and o["variance_finite"] is False and o["ci95"] is None, o
    assert abs(o["rho_hat"] - 1.62) < 1e-6 and o["heavy_tail"] is True and o["max_share"] > 0.05, o


def check_forward_files(ulam):
    """forward --out and --errors write every component; each within 5 sigma of LAPACK, and
    about 95% within their 95% interval (binomial: 1000 components, 4 sigma band)."""
    with tempfile.TemporaryDirectory() as d:
        x, e, ref = (os.path.join(d, f) for f in ("x.mtx", "e.mtx", "ref.mtx"))
        rc, _, err = run(ulam, ["solve", M + "randsub1000.mtx", "--rhs", M + "randsub1000_b.mtx",
                                "--mode", "forward", "--walks", "200000", "--out", x, "--errors", e])
        assert rc == 0, err
        rc, _, _ = run(ulam, ["direct", M + "randsub1000.mtx", "--rhs", M + "randsub1000_b.mtx", "--out", ref])
        assert rc == 0
        read = lambda p: [float(v) for v in open(p).read().split("\n")[3:] if v]
        xs, es, rs = read(x), read(e), read(ref)
        assert len(xs) == len(es) == len(rs) == 1000
        assert all(abs(a - b) < 5 * s for a, b, s in zip(xs, rs, es))
        covered = sum(abs(a - b) < 1.959964 * s for a, b, s in zip(xs, rs, es))
        assert 922 <= covered <= 978, covered


def interrupt_when_ready(p):
    """Send SIGINT once process p has installed its handler (polled in /proc, no sleeps)."""
    import signal
    import time
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        try:
            caught = [l for l in open(f"/proc/{p.pid}/status") if l.startswith("SigCgt:")]
        except OSError:
            break
        if caught and int(caught[0].split()[1], 16) & (1 << (signal.SIGINT - 1)):
            break
    p.send_signal(signal.SIGINT)


def check_interrupt(ulam):
    """Ctrl-C prints the estimate so far, marked interrupted, with exit code 130 (no sleeps:
    wait until the process has installed its SIGINT handler, then send it)."""
    import signal
    import time
    p = subprocess.Popen([ulam] + SOLVE + ["--index", "1", "--walks", "100000000000", "--json"],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    interrupt_when_ready(p)
    out, _ = p.communicate(timeout=60)
    assert p.returncode == 130, p.returncode
    o = json.loads(out)  # valid JSON even when no block had finished (ci95 then null)
    assert o["interrupted"] is True and o["walks"] >= 0
    if o["walks"] == 0:
        assert o["ci95"] == [None, None] and o["stderr"] is None


def check_second_interrupt(ulam):
    """A second Ctrl-C exits at once.  solve's stdout is a pipe the test has filled, so the
    process cannot finish its output: after the first Ctrl-C (the walks stop, or the blocked
    write is restarted) it would wait forever; the second must end it with 130, and none of its
    output may have got through."""
    import signal
    r, w = os.pipe()
    os.set_blocking(w, False)
    filled = 0
    for chunk in (4096, 1):  # whole pages, then single bytes up to the last free byte
        try:
            while True:
                filled += os.write(w, b"x" * chunk)
        except BlockingIOError:
            pass
    os.set_blocking(w, True)  # O_NONBLOCK belongs to the shared file description: undo it
    p = subprocess.Popen([ulam] + SOLVE + ["--index", "1", "--walks", "100000", "--json"], stdout=w,
                         stderr=subprocess.DEVNULL)
    os.close(w)
    interrupt_when_ready(p)
    pending = True
    while pending and p.poll() is None:  # the first must be taken before the second is sent
        try:
            st = {l.split(":")[0]: int(l.split()[1], 16) for l in open(f"/proc/{p.pid}/status")
                  if l.startswith(("SigPnd:", "ShdPnd:"))}
        except OSError:
            break
        pending = any(v & (1 << (signal.SIGINT - 1)) for v in st.values())
    assert p.poll() is None, "solve finished its output into a full pipe?"
    p.send_signal(signal.SIGINT)
    try:
        p.wait(timeout=60)
    finally:
        if p.poll() is None:
            p.kill()
    os.set_blocking(r, False)
    got = b""
    try:
        while True:
            block = os.read(r, 65536)
            if not block:
                break
            got += block
    except BlockingIOError:
        pass
    os.close(r)
    assert p.returncode == 130, p.returncode
    assert got == b"x" * filled, "output got through after the second Ctrl-C"


def check_cache(ulam):
    """--cache: the first run parses and writes FILE.ulamcache, the second reads it and gives the
    same answer, a changed file is parsed again."""
    import shutil
    with tempfile.TemporaryDirectory() as d:
        for f in ("signed200.mtx", "signed200_b.mtx"):
            shutil.copy(M + f, d)
        args = ["solve", d + "/signed200.mtx", "--rhs", d + "/signed200_b.mtx", "--index", "5", "--walks", "20000",
                "--json", "--cache"]
        rc, out1, err = run(ulam, args)
        assert rc == 0 and err.count("cache written") == 2, err
        assert sorted(os.listdir(d)) == ["signed200.mtx", "signed200.mtx.ulamcache", "signed200_b.mtx",
                                         "signed200_b.mtx.ulamcache"], os.listdir(d)
        rc, out2, err = run(ulam, args)
        assert rc == 0 and err.count("loaded from its cache") == 2, err
        assert json.loads(out1)["estimate"] == json.loads(out2)["estimate"]
        with open(d + "/signed200_b.mtx", "a") as fh:
            fh.write("% changed\n")
        rc, _, err = run(ulam, args)
        assert rc == 0 and err.count("loaded from its cache") == 1 and err.count("cache written") == 1, err


def check_prepare(ulam):
    """ulam prepare writes a prepared system; solve, info and study take it where they take a
    matrix, with the same answer as from text and no guard pass; a truncated, damaged or
    foreign file is refused with a located message; nothing is written when the output path
    cannot be written or the input is bad."""
    with tempfile.TemporaryDirectory() as d:
        sysf = d + "/s.ulam"
        rc, out, err = run(ulam, ["prepare", M + "signed200.mtx", "--rhs", M + "signed200_b.mtx", "-o", sysf])
        assert rc == 0 and "prepared" in out and os.listdir(d) == ["s.ulam"], (rc, out, err, os.listdir(d))
        common = ["--index", "5", "--walks", "20000", "--json", "--threads", "2"]
        rc, text, err = run(ulam, ["solve", M + "signed200.mtx", "--rhs", M + "signed200_b.mtx"] + common)
        assert rc == 0, err
        rc, prep, err = run(ulam, ["solve", sysf] + common)
        assert rc == 0, err
        a, b = json.loads(text), json.loads(prep)
        assert a["estimate"] == b["estimate"] and a["stderr"] == b["stderr"], (a, b)
        assert b["guard_seconds"] == 0 and b["rho_abs"] == a["rho_abs"], b
        rc, fwd, err = run(ulam, ["solve", sysf, "--mode", "forward", "--walks", "2000", "--json"])
        assert rc == 0, err
        rc, info, err = run(ulam, ["info", sysf, "--json"])
        assert rc == 0 and json.loads(info)["n"] == 200, err
        rc, _, err = run(ulam, ["study", sysf, "--index", "2", "--methods", "adjoint-collision-plain", "--budgets",
                                "100", "--repeats", "2", "--out", d + "/study"])
        assert rc == 0 and os.path.exists(d + "/study/runs.csv"), err
        import shutil
        shutil.rmtree(d + "/study")
        rc, _, err = run(ulam, ["solve", sysf, "--index", "5", "--jacobi"])
        assert rc == 2 and "prepared system" in err, err
        # Jacobi splitting stored, no b: solve needs --rhs
        rc, _, err = run(ulam, ["prepare", M + "poisson20.mtx", "--jacobi", "-o", d + "/p.ulam"])
        assert rc == 0, err
        rc, _, err = run(ulam, ["solve", d + "/p.ulam", "--index", "3"])
        assert rc == 2 and "holds no b" in err, err
        rc, _, err = run(ulam, ["solve", M + "poisson20.mtx", "--jacobi", "--rhs", M + "poisson20_b.mtx", "--index",
                                "3", "--walks", "5000", "--json"])
        rc2, out2, err2 = run(ulam, ["solve", d + "/p.ulam", "--rhs", M + "poisson20_b.mtx", "--index", "3",
                                     "--walks", "5000", "--json"])
        assert rc == 0 and rc2 == 0, err2
        raw = open(sysf, "rb").read()
        damaged = [(raw[:-1], "ESYNTAX", "truncated"), (raw[:100], "ESYNTAX", "truncated"),
                   (b"ulamSYS2" + raw[8:], "EBANNER", "prepared system"),
                   (raw[:40] + bytes([raw[40] ^ 1]) + raw[41:], "ESYNTAX", "checksum")]
        for k, (data, status, word) in enumerate(damaged):
            bad = d + f"/bad{k}.ulam"
            with open(bad, "wb") as fh:
                fh.write(data)
            rc, out, err = run(ulam, ["solve", bad, "--index", "5", "--walks", "100"])
            if status == "EBANNER":  # no longer a prepared file: parsed as Matrix Market
                assert rc != 0 and out == "", (k, rc, err)
            else:
                assert rc == code(status) and re.search(rf"^ulam: {re.escape(bad)}: error: .*{word}", err), (k, rc, err)
            os.remove(bad)
        # a damaged row behind a sound header: refused when a walk reaches it, or by the check
        data = bytearray(raw)
        colidx = int.from_bytes(raw[56:64], "little")
        data[colidx:colidx + 4] = (999).to_bytes(4, "little")
        with open(d + "/rows.ulam", "wb") as fh:
            fh.write(bytes(data))
        rc, out, err = run(ulam, ["solve", d + "/rows.ulam", "--index", "1", "--walks", "1000"])
        assert rc == code("ESYNTAX") and "corrupt" in err and out == "", (rc, err)
        rc, out, err = run(ulam, ["info", d + "/rows.ulam"])
        assert rc != 0 and "corrupt" in err and out == "", (rc, err)
        os.remove(d + "/rows.ulam")
        # the output is checked before the work, and a failed prepare leaves nothing
        rc, _, err = run(ulam, ["prepare", M + "signed200.mtx", "-o", d + "/no/such/dir/s.ulam"])
        assert rc == code("EIO"), err
        rc, _, err = run(ulam, ["prepare", D + "nan.mtx", "-o", d + "/x.ulam"])
        assert rc == code("ENONFINITE") and sorted(os.listdir(d)) == ["p.ulam", "s.ulam"], os.listdir(d)


def check_study_nonfinite(ulam):
    """M = 0: every walk scores 1 exactly, so the standard error is 0 and honesty (RMSE / mean
    standard error) is 0/0.  The CSVs carry an empty field there, never inf or nan; no
    temporary file is left in the output directory."""
    with tempfile.TemporaryDirectory() as d:
        rc, _, err = run(ulam, ["study", D + "zero1.mtx", "--rhs", D + "one1.mtx", "--index", "1", "--methods",
                                "adjoint-collision-plain,adjoint-absorption-plain", "--budgets", "100",
                                "--repeats", "3", "--out", d])
        assert rc == 0, (rc, err)
        for name in ("runs.csv", "summary.csv", "bars.csv", "reference.csv"):
            text = open(os.path.join(d, name)).read().lower()
            assert "inf" not in text and "nan" not in text, (name, text)
        summary = open(os.path.join(d, "summary.csv")).read().splitlines()
        assert len(summary) == 3 and all(l.split(",")[5] == "" for l in summary[1:]), summary
        assert all(".tmp." not in f for f in os.listdir(d)), os.listdir(d)


def check_study(ulam):
    """study: rows per run, a summary per cell, resume without duplicates, a torn last line cut,
    refusals listed, Ctrl-C keeps finished rows."""
    import signal
    import tempfile
    import time
    d = tempfile.mkdtemp()
    args = ["study", M + "chain4.mtx", "--rhs", M + "chain4_b.mtx", "--index", "2", "--methods",
            "adjoint-collision-plain,forward-expected-split", "--budgets", "100,1000", "--repeats", "5", "--out", d]
    rc, _, err = run(ulam, args)
    rows = open(f"{d}/runs.csv").read().splitlines()
    assert rc == 0 and len(rows) == 21 and rows[0].startswith("method,budget,repeat"), (rc, err, len(rows))
    summary = open(f"{d}/summary.csv").read().splitlines()
    assert len(summary) == 5, summary
    for line in summary[1:]:
        f = line.split(",")
        assert int(f[2]) == 5 and 0 <= float(f[6]) <= 1 and float(f[3]) > 0, line
    rc, _, err = run(ulam, args)
    assert rc == 0 and "resuming: 20 runs" in err, err
    assert open(f"{d}/runs.csv").read().splitlines() == rows  # nothing run twice
    with open(f"{d}/runs.csv", "w") as fh:  # lose three rows and tear the last line
        fh.write("\n".join(rows[:-3]) + "\n" + rows[-3][:20])
    rc, _, err = run(ulam, args)
    again = open(f"{d}/runs.csv").read().splitlines()
    assert rc == 0 and "resuming: 17 runs" in err and len(again) == 21, (err, again[-4:])
    assert all(len(l.split(",")) == 11 for l in again), again
    rc, _, err = run(ulam, ["study", M + "signed200.mtx", "--rhs", M + "signed200_b.mtx", "--index", "3", "--methods",
                            "forward-absorption-plain,adjoint-collision-plain", "--budgets", "100", "--repeats", "2",
                            "--out", d + "/s"])
    assert rc == 0 and re.search(r"forward-absorption-plain refused: .*p\* > 0", err), err
    rc, _, err = run(ulam, args[:6] + ["--methods", "adjoint-expected-plain", "--time-budgets", "0.001,0.002",
                                       "--repeats", "3", "--out", d + "/t"])
    timed = open(f"{d}/t/runs.csv").read().splitlines()
    assert rc == 0 and len(timed) == 7 and all(int(l.split(",")[7]) > 0 for l in timed[1:]), (err, timed)
    rc, _, err = run(ulam, ["study", M + "divergent200.mtx", "--rhs", M + "divergent200_b.mtx", "--index", "1",
                            "--out", d + "/x"])
    assert rc == 3 and "rho(|M|) = 1.1 >= 1" in err, (rc, err)
    p = subprocess.Popen([ulam] + args[:6] + ["--methods", "adjoint-collision-plain", "--budgets", "100000000000",
                                              "--repeats", "3", "--out", d + "/i"],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    interrupt_when_ready(p)
    p.communicate(timeout=60)
    assert p.returncode == 130, p.returncode
    assert open(f"{d}/i/runs.csv").read() == "method,budget,repeat,seed,estimate,stderr,abs_error,walks,steps,seconds,covered\n"


def check_outputs(ulam):
    """--out writes a readable solution; a failed run leaves an old file intact and no temp files."""
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "x.mtx")
        rc, _, _ = run(ulam, ["direct", M + "chain4.mtx", "--rhs", M + "chain4_b.mtx", "--out", out])
        assert rc == 0
        lines = open(out).read().split("\n")
        assert lines[0] == "%%MatrixMarket matrix array real general" and "4 1" in lines
        with open(out, "w") as f:
            f.write("old\n")
        rc, _, _ = run(ulam, ["direct", D + "singular.mtx", "--rhs", D + "ones3.mtx", "--out", out])
        assert rc == code("ESINGULAR")
        assert open(out).read() == "old\n", "failed run clobbered the old output"
        assert os.listdir(d) == ["x.mtx"], os.listdir(d)
        rc, _, err = run(ulam, ["direct", M + "chain4.mtx", "--rhs", M + "chain4_b.mtx", "--out", d + "/no/such/dir/x.mtx"])
        assert rc == code("EIO") and "error" in err


def check_radiosity(ulam):
    """ulam radiosity: JSON fields, --check agreement, matrix walks, shooting images, atomic PNG."""
    rc, out, err = run(ulam, ["radiosity", SC + "cornell_box.obj", "--subdivide", "300", "--patch", "back_wall",
                              "--check", "--ff-rays", "50000", "--walks", "200000", "--json"])
    assert rc == 0, err
    j = json.loads(out)
    assert j["label"] == "back_wall" and j["patches"] == 49 and j["mode"] == "gather"
    for key in ("radiosity", "stderr", "direct", "direct_stderr", "z"):
        assert len(j[key]) == 3, key
    assert all(abs(z) < 4 for z in j["z"]), j["z"]
    assert all(0 < s < 0.1 * b for s, b in zip(j["stderr"], j["radiosity"])), j
    rc, out, err = run(ulam, ["radiosity", SC + "cornell_box.obj", "--subdivide", "300", "--patch", "10",
                              "--check", "--matrix-walk", "--estimator", "absorption", "--ff-rays", "2000",
                              "--walks", "100000", "--json"])
    assert rc == 0, err
    j = json.loads(out)
    assert j["matrix_walk"] and j["patch"] == 10 and all(abs(z) < 4 for z in j["z"]), j
    with tempfile.TemporaryDirectory() as d:
        png = d + "/box.png"
        rc, out, err = run(ulam, ["radiosity", SC + "cornell_box.obj", "--mode", "shoot", "--walks", "20000",
                                  "--image", png, "--size", "64x48"])
        assert rc == 0, err
        data = open(png, "rb").read()
        assert data[:8] == b"\x89PNG\r\n\x1a\n" and data[16:24] == bytes([0, 0, 0, 64, 0, 0, 0, 48])
        rc, _, err = run(ulam, ["radiosity", SC + "cube.obj", "--mode", "shoot", "--walks", "1000",
                                "--image", d + "/no/such/dir/x.png"])
        assert rc == code("EIO") and "x.png" in err, err
        assert sorted(os.listdir(d)) == ["box.png"], os.listdir(d)


def check_genmat(genmat):
    """examples/genmat reproduces every generated file in matrices/ byte for byte."""
    with tempfile.TemporaryDirectory() as d:
        assert subprocess.run([genmat, d], timeout=120).returncode == 0
        made = sorted(os.listdir(d))
        assert len(made) == 12, made
        for f in made:
            assert open(os.path.join(d, f), "rb").read() == open(M + f, "rb").read(), f


def main():
    ulam, genmat = sys.argv[1], sys.argv[2]
    failures, n = check_table(ulam)
    extra = [(check_json, ulam), (check_outputs, ulam), (check_genmat, genmat), (check_solve_json, ulam),
             (check_forward_files, ulam), (check_interrupt, ulam), (check_second_interrupt, ulam),
             (check_study, ulam), (check_study_nonfinite, ulam), (check_cache, ulam), (check_prepare, ulam),
             (check_radiosity, ulam)]
    for f, arg in extra:
        try:
            f(arg)
        except AssertionError as e:
            failures += 1
            print(f"FAIL {f.__name__}: {e}")
    total = n + len(extra)
    print(f"{total - failures} passed, {failures} failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
