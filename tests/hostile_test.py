#!/usr/bin/env python3
"""Hostile inputs to `ulam` (issue 39): no exit 0 with a wrong answer, no signal death, no write
outside the paths asked for, no input destroyed.  Each check builds its own inputs in a temporary
folder.  Run from the source root: hostile_test.py path/to/ulam [--no-radiosity] [--case NAME]...
"""
import json
import math
import os
import re
import subprocess
import sys
import tempfile

from cli_test import stopped  # noqa: E402  (waits for a process to stop itself)
from ulam_status import code  # noqa: E402  (the enum of include/ulam.h)


def run(ulam, args, **kw):
    # 300 s: a guard against a hang, not a speed check
    p = subprocess.run([ulam] + args, capture_output=True, text=True, timeout=300, **kw)
    return p.returncode, p.stdout, p.stderr


def write_mtx(path, n, entries):
    with open(path, "w") as f:
        f.write(f"%%MatrixMarket matrix coordinate real general\n{n} {n} {len(entries)}\n")
        for i, j, v in entries:
            f.write(f"{i} {j} {v}\n")


def write_vec(path, values):
    with open(path, "w") as f:
        f.write(f"%%MatrixMarket matrix array real general\n{len(values)} 1\n")
        f.write("".join(f"{v!r}\n" for v in values))


def direct(ulam, m, b, index):
    rc, out, err = run(ulam, ["direct", m, "--rhs", b, "--index", str(index)])
    assert rc == 0, err
    return float(re.search(rf"^x\[{index}\]\s+(\S+)", out, re.M).group(1))


def answer_or_refusal(ulam, args, index, exact, what):
    """One solve: either a refusal (non-zero exit, a message that is not 'success', nothing on
    stdout) or exit 0 with x[index] (never another unknown) whose printed interval holds exact."""
    rc, out, err = run(ulam, args + ["--json"])
    if rc != 0:
        assert "success" not in err and re.search(r"error: ", err), f"{what}: exit {rc} without a clear error: {err}"
        assert json.loads(out).get("exit") == rc, f"{what}: JSON {out}"
        rc2, out2, err2 = run(ulam, args)
        assert rc2 == rc and out2 == "" and "success" not in err2, f"{what}: text run: exit {rc2}, {out2} {err2}"
        return "refused"
    assert "error: success" not in err and "error:" not in err, f"{what}: exit 0 with an error: {err}"
    j = json.loads(out)
    assert j["index"] == index, f"{what}: answered x[{j['index']}] for --index {index}"
    lo, hi = j["ci95"] if j.get("ci95") else (None, None)
    if lo is not None:
        tol = 1e-12 * max(1.0, abs(exact))
        assert lo - tol <= exact <= hi + tol, f"{what}: x[{index}] = {exact} outside the printed interval [{lo}, {hi}]"
    rc2, out2, err2 = run(ulam, args)
    assert rc2 == 0 and re.search(rf"^x\[{index}\]", out2, re.M), f"{what}: text run labels another unknown: {out2}"
    return "answered"


def check_relabel(ulam):
    """Point 1: M = [[0, t], [1e-201, 0]], b = (1, 1), solve --index 2 answered x[1] = 0 +- 0 as
    'bidirectional' with 'error: success', exit 0, for t from 1e155 to 1e299; info printed
    rho(M) 0.000000.  Now: a refusal or x[2] within its interval, for every t."""
    with tempfile.TemporaryDirectory() as d:
        b = os.path.join(d, "b.mtx")
        write_vec(b, [1.0, 1.0])
        for t in ["1e100", "1e155", "1e200", "1e250", "1e299"]:
            m = os.path.join(d, f"m{t}.mtx")
            write_mtx(m, 2, [(1, 2, t), (2, 1, "1e-201")])
            exact = direct(ulam, m, b, 2)
            for extra in ([], ["--mode", "adjoint"], ["--mode", "forward"], ["--walks", "1000"]):
                answer_or_refusal(ulam, ["solve", m, "--rhs", b, "--index", "2"] + extra, 2, exact, f"t = {t} {extra}")
            rc, out, err = run(ulam, ["info", m])
            assert rc == 0, err
            rho = re.search(r"^rho\(M\)\s+(\S+)", out, re.M).group(1)
            assert float(rho) > 0, f"t = {t}: info prints rho(M) {rho} (it is sqrt({t} x 1e-201) > 0)"


def check_study_counts_every_run(ulam):
    """Point 2: study dropped the runs with no standard error (forward walks that never reached
    x_I) yet printed '5 runs a cell', and named a winner from a cell where 2 of 5 runs had no
    estimate (randsub1000, x[7], 100 walks: 'forward-collision-plain ... 3/3').  Every run is
    counted: a run with no estimate is a failure, in runs.csv, summary.csv and on stdout, and
    such a cell never wins."""
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "st")
        args = ["study", "matrices/randsub1000.mtx", "--rhs", "matrices/randsub1000_b.mtx", "--index", "7", "--methods",
                "forward-collision-plain,adjoint-collision-plain", "--budgets", "100,1000", "--repeats", "5",
                "--out", out, "--reference-time", "0"]
        for attempt in ("fresh", "resumed"):
            rc, stdout, err = run(ulam, args)
            assert rc == 0, f"{attempt}: {err}"
            runs = open(os.path.join(out, "runs.csv")).read().splitlines()[1:]
            assert len(runs) == 2 * 2 * 5, f"{attempt}: runs.csv holds {len(runs)} runs of 20"
            failed = [r for r in runs if r.split(",")[4] == ""]
            assert failed and all(r.startswith("forward-") for r in failed), f"{attempt}: failed runs {failed}"
            rows = [r.split(",") for r in open(os.path.join(out, "summary.csv")).read().splitlines()]
            col = {k: i for i, k in enumerate(rows[0])}
            for r in rows[1:]:
                assert r[col["runs"]] == "5", f"{attempt}: a cell of {r[col['runs']]} runs: {r}"
            nfail = sum(int(r[col["failed"]]) for r in rows[1:])
            assert nfail == len(failed), f"{attempt}: summary.csv counts {nfail} failures, runs.csv {len(failed)}"
            for line in stdout.splitlines():
                m = re.match(r"^(\d+)\s+(\S+)\s+\S+\s+\S+\s+(\d+)/(\d+)", line)
                if m:
                    assert m.group(4) == "5", f"{attempt}: winner over {m.group(4)} runs: {line}"
                    cell = [r for r in rows[1:] if r[0] == m.group(2) and float(r[1]) == float(m.group(1))][0]
                    assert cell[col["failed"]] == "0", f"{attempt}: winner with runs that failed: {line}"
            assert re.search(r"^no estimate: forward-collision-plain at 100: \d of 5 runs", stdout, re.M), stdout


CUBE_OBJ = """mtllib {mtl}
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0 0 1
v 1 0 1
v 1 1 1
v 0 1 1
usemtl white
o floor
f 1 5 6 2
{comment}usemtl lamp
o ceiling
f 4 3 7 8
"""
CUBE_MTL = "newmtl lamp\nKd 0 0 0\nKe 1 1 1\nnewmtl white\nKd 0.7 0.7 0.7\n"


def check_radiosity_obj_lines(ulam):
    """Point 3: the OBJ reader took a failed read (ENOMEM on a 600 MB comment line) for the end of
    the file and answered from the patches before it, exit 0.  Lines are bounded (1 MiB): a longer
    one is refused at its line, before anything after it is dropped; a NUL byte likewise."""
    with tempfile.TemporaryDirectory() as d:
        open(os.path.join(d, "c.mtl"), "w").write(CUBE_MTL)
        obj = os.path.join(d, "c.obj")
        open(obj, "w").write(CUBE_OBJ.format(mtl="c.mtl", comment=""))
        rc, out, err = run(ulam, ["radiosity", obj, "--list"])
        assert rc == 0 and len(re.findall(r"^\s*\d+\s", out, re.M)) == 2, f"the plain scene: {rc} {out} {err}"
        open(obj, "w").write(CUBE_OBJ.format(mtl="c.mtl", comment="# " + "x" * (3 << 20) + "\n"))
        rc, out, err = run(ulam, ["radiosity", obj, "--list"])
        assert rc == code("ESYNTAX") and re.search(rf"{re.escape(obj)}:13: error: .*line of at most 1048576 bytes", err), \
            f"a 3 MiB comment line: exit {rc}: {err.strip()[:300]}"
        assert out == "", out
        long_mtl = os.path.join(d, "long.mtl")
        open(long_mtl, "w").write("# " + "y" * (3 << 20) + "\n" + CUBE_MTL)
        open(obj, "w").write(CUBE_OBJ.format(mtl="long.mtl", comment=""))
        rc, out, err = run(ulam, ["radiosity", obj, "--list"])
        assert rc == code("ESYNTAX") and re.search(rf"{re.escape(long_mtl)}:1: error: .*line of at most", err), \
            f"a 3 MiB MTL line: exit {rc}: {err.strip()[:300]}"
        rc, out, err = run(ulam, ["radiosity", "/dev/zero", "--list"])  # said at the first NUL, not at the bound
        assert rc == code("ESYNTAX") and re.search(r"/dev/zero:1: error: .*NUL byte", err), f"/dev/zero: {rc} {err}"


def check_radiosity_mtllib_not_regular(ulam):
    """Point 5: 'mtllib /dev/zero' grew one line buffer to 4.2 GB; 'mtllib' naming a FIFO blocked
    forever.  An MTL file must be a regular file: a device, FIFO or directory is refused at the
    mtllib line without reading (or waiting on) it."""
    with tempfile.TemporaryDirectory() as d:
        obj = os.path.join(d, "c.obj")
        fifo = os.path.join(d, "fifo.mtl")
        os.mkfifo(fifo)
        os.mkdir(os.path.join(d, "dir.mtl"))
        for name, what in (("/dev/zero", "a device"), (fifo, "a FIFO"), ("dir.mtl", "a directory")):
            open(obj, "w").write(CUBE_OBJ.format(mtl=name, comment=""))
            rc, out, err = run(ulam, ["radiosity", obj, "--list"])  # a FIFO would block: run's timeout
            assert rc == code("EIO") and re.search(rf"{re.escape(obj)}:1: error: .*a regular MTL file: .* is {what}", err), \
                f"mtllib {name}: exit {rc}: {err.strip()[:300]}"


def check_matrix_zeros_streamed(ulam):
    """Point 5: a 5 GB sparse file of zeros given as a matrix was read whole (5.2 GB RSS) before
    the NUL check.  A 1 GiB one (sparse: no disk) is refused at line 1 with a few MB resident, as
    is a 2 MiB line with no newline."""
    with tempfile.TemporaryDirectory() as d:
        z = os.path.join(d, "zeros.mtx")
        with open(z, "wb") as f:
            f.truncate(1 << 30)
        probe = ("import resource, subprocess, sys\n"
                 "p = subprocess.run(sys.argv[1:], capture_output=True, text=True, timeout=300)\n"
                 "print(p.returncode, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)\n"
                 "sys.stderr.write(p.stderr)\n")
        p = subprocess.run([sys.executable, "-c", probe, ulam, "info", z], capture_output=True, text=True, timeout=300)
        rc, rss = map(int, p.stdout.split())
        assert rc == code("ESYNTAX") and re.search(rf"{re.escape(z)}:1: error: .*NUL byte", p.stderr), f"exit {rc}: {p.stderr}"
        assert rss < 200 * 1024, f"1 GiB of zeros: {rss} KiB resident (read whole?)"
        long = os.path.join(d, "long.mtx")
        open(long, "w").write("%%MatrixMarket matrix coordinate real general\n%" + "x" * (2 << 20))
        rc, out, err = run(ulam, ["info", long])
        assert rc == code("ESYNTAX") and re.search(rf"{re.escape(long)}:2: error: .*line of at most 1048576 bytes", err), \
            f"a 2 MiB line: exit {rc}: {err}"


def check_pipes(ulam):
    """Point 9: docs/input.md says pipes are read, but `info /dev/stdin` and `solve <(cat m.mtx)`
    exited 14 'empty file': the prepared-file sniff (and --cache's hash) consumed the pipe's first
    bytes.  Matrices and right-hand sides through pipes give what the files give; a gzip stream
    through a pipe is refused by name."""
    m, b = "matrices/chain4.mtx", "matrices/chain4_b.mtx"
    rc, want, err = run(ulam, ["info", m])
    assert rc == 0, err
    p = subprocess.run([ulam, "info", "/dev/stdin"], input=open(m).read(), capture_output=True, text=True, timeout=300)
    assert p.returncode == 0 and p.stdout.split("\n")[1:4] == want.split("\n")[1:4], \
        f"info /dev/stdin: exit {p.returncode}: {p.stderr}"
    solve = ["solve", "--method", "walks", "--walks", "2000", "--index", "2", "--json"]
    rc, ref, err = run(ulam, solve + [m, "--rhs", b])
    assert rc == 0, err
    ref = json.loads(ref)
    with tempfile.TemporaryDirectory() as d:
        for what, cmd in (("M", f"'{ulam}' {' '.join(solve)} <(cat {m}) --rhs {b}"),
                          ("b", f"'{ulam}' {' '.join(solve)} {m} --rhs <(cat {b})"),
                          ("both, --cache", f"'{ulam}' {' '.join(solve)} <(cat {m}) --rhs <(cat {b}) --cache"),
                          ("direct", f"'{ulam}' direct <(cat {m}) --rhs <(cat {b}) --index 2")):
            p = subprocess.run(["bash", "-c", cmd], capture_output=True, text=True, timeout=300, cwd=os.getcwd())
            assert p.returncode == 0, f"{what} through a pipe: exit {p.returncode}: {p.stderr}"
            if what != "direct":
                got = json.loads(p.stdout)
                assert got["estimate"] == ref["estimate"], f"{what}: {got['estimate']} != {ref['estimate']}"
        assert not [f for f in os.listdir("matrices") if f.endswith(".ulamcache")], "--cache wrote beside a file not asked"
        p = subprocess.run(["bash", "-c", f"'{ulam}' info <(gzip -c {m})"], capture_output=True, text=True, timeout=300)
        assert p.returncode == code("EUNSUPPORTED") and "gzip" in p.stderr, f"gzip pipe: {p.returncode} {p.stderr}"


def check_output_is_input(ulam):
    """Point 8: `solve m.mtx --out m.mtx`, `--out b.mtx`, `prepare m.mtx -o m.mtx` destroyed the
    input silently, and `radiosity --image x.png --out x.hdr` overwrote the CSV with the HDR
    image.  An output that is an input (the same file through any name, link or symlink) or
    another output of the run is refused (exit 2) before anything is written; every input stays
    byte for byte."""
    import shutil
    with tempfile.TemporaryDirectory() as d:
        m, b = os.path.join(d, "m.mtx"), os.path.join(d, "b.mtx")
        shutil.copy("matrices/chain4.mtx", m)
        shutil.copy("matrices/chain4_b.mtx", b)
        os.symlink("m.mtx", os.path.join(d, "link.mtx"))
        os.link(b, os.path.join(d, "hard.mtx"))
        fwd = ["solve", "--method", "walks", m, "--rhs", b, "--mode", "forward", "--walks", "100"]
        cases = [
            (fwd + ["--out", m], r"--out \S*m\.mtx is the matrix"),
            (fwd + ["--out", b], r"--out \S*b\.mtx is --rhs"),
            (fwd + ["--errors", os.path.join(d, "link.mtx")], r"--errors \S*link\.mtx is the matrix"),
            (fwd + ["--out", os.path.join(d, "x.mtx"), "--errors", os.path.join(d, ".", "x.mtx")], r"is also --out"),
            (["direct", m, "--rhs", b, "--out", os.path.join(d, "hard.mtx")], r"--out \S*hard\.mtx is --rhs"),
            (["prepare", m, "-o", m], r"-o \S*m\.mtx is the matrix"),
            (["prepare", m, "--rhs", b, "-o", os.path.join(d, "link.mtx")], r"is the matrix"),
            (["solve", "--method", "richardson", m, "--rhs", b, "--out", b], r"--out \S*b\.mtx is --rhs"),
        ]
        before = {f: open(os.path.join(d, f), "rb").read() for f in ("m.mtx", "b.mtx")}
        if run(ulam, ["radiosity", "--help"])[0] == 0 and os.path.exists("tests/data/rad/cube_black_lamp.obj"):
            for f in ("cube_black_lamp.obj", "cube_black_lamp.mtl"):
                shutil.copy("tests/data/rad/" + f, d)
                before[f] = open(os.path.join(d, f), "rb").read()
            scene = os.path.join(d, "cube_black_lamp.obj")
            rad = ["radiosity", scene, "--patch", "1", "--direct"]
            cases += [(rad + ["--image", os.path.join(d, "x.png"), "--out", os.path.join(d, "x.hdr")],
                       r"--out \S*x\.hdr is also --image's HDR"),
                      (rad + ["--out", scene], r"--out \S*cube_black_lamp\.obj is the scene")]
        for args, msg in cases:
            rc, out, err = run(ulam, args)
            assert rc == 2 and re.search(msg, err), f"ulam {' '.join(args)}: exit {rc}: {err.strip()}"
            for f, data in before.items():
                assert open(os.path.join(d, f), "rb").read() == data, f"ulam {' '.join(args)}: {f} changed"
            left = [f for f in os.listdir(d) if f.startswith("x.") or ".tmp." in f]
            assert not left, f"ulam {' '.join(args)}: wrote {left}"


def check_study_chart_symlinks(ulam):
    """Point 7: study's charts were drawn by gnuplot to the fixed name DIR/NAME.tmp.png; a symlink
    planted there made it overwrite a file outside the study folder, and the link was then renamed
    into the folder.  Charts are drawn into a temporary file ulam makes (mkstemp), through its
    descriptor: a planted link at any name is neither followed nor kept."""
    if subprocess.run(["sh", "-c", "command -v gnuplot"], capture_output=True).returncode != 0:
        return  # no gnuplot: no charts drawn
    with tempfile.TemporaryDirectory() as d:
        victim = os.path.join(d, "victim.txt")
        open(victim, "wb").write(b"precious\n")
        out = os.path.join(d, "st")
        os.mkdir(out)
        charts = ["rmse-collision", "work", "coverage"]
        for c in charts:
            os.symlink(victim, os.path.join(out, f"{c}.tmp.png"))
        rc, stdout, err = run(ulam, ["study", "matrices/chain4.mtx", "--rhs", "matrices/chain4_b.mtx", "--index", "1",
                                     "--methods", "adjoint-collision-plain", "--budgets", "100,1000", "--repeats", "3",
                                     "--out", out, "--reference-time", "0"])
        assert rc == 0, err
        assert open(victim, "rb").read() == b"precious\n", "a chart was drawn through the planted symlink"
        for c in charts:
            p = os.path.join(out, c + ".png")
            assert not os.path.islink(p) and open(p, "rb").read(8) == b"\x89PNG\r\n\x1a\n", f"{c}.png: a link or not a PNG"


def check_radiosity_early_exit_frees(ulam):
    """Point 10: ASan found 48 bytes leaked from parse_at (the --at list) when radiosity stopped early
    on an error (a scene that does not load, an output refused).  Every early exit frees it: under
    ASan's leak check (.ci/run step 2) a leak turns the exit code into LeakSanitizer's 23."""
    with tempfile.TemporaryDirectory() as d:
        bad = os.path.join(d, "bad.obj")
        open(bad, "w").write("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n")
        for scene, status in ((os.path.join(d, "missing.obj"), "EIO"), (bad, "ENOTFOUND")):
            rc, out, err = run(ulam, ["radiosity", scene, "--at", "0,0,0", "--at", "0.5,0.5,0,0,0,1"])
            assert rc == code(status) and "LeakSanitizer" not in err, f"{scene}: exit {rc}: {err.strip()[-400:]}"


def check_mapped_file_shrinks(ulam):
    """Point 4: SIGBUS (exit 135) when a prepared file was truncated during `info`, or replaced by
    `cp new.ulam sys.ulam` during a default `solve`.  Deterministic: the process stops itself once
    the file is mapped (ULAM_TEST_STOP_AT_MAP), the file shrinks, the process goes on and reads
    the lost pages: a clear error naming the file, exit 13, nothing on stdout, no signal death."""
    import shutil
    import signal
    with tempfile.TemporaryDirectory() as d:
        sysf, small = os.path.join(d, "sys.ulam"), os.path.join(d, "small.ulam")
        rc, out, err = run(ulam, ["prepare", "matrices/randsub1000.mtx", "--rhs", "matrices/randsub1000_b.mtx", "-o", sysf])
        assert rc == 0, err
        rc, out, err = run(ulam, ["prepare", "matrices/chain4.mtx", "--rhs", "matrices/chain4_b.mtx", "-o", small])
        assert rc == 0, err
        whole = open(sysf, "rb").read()
        cases = [("info, truncated", ["info", sysf], lambda: os.truncate(sysf, 4096)),
                 ("solve, cp over it", ["solve", sysf, "--index", "3", "--walks", "2000"], lambda: shutil.copyfile(small, sysf)),
                 ("direct, truncated to 0", ["direct", sysf], lambda: os.truncate(sysf, 0))]
        for name, args, shrink in cases:
            open(sysf, "wb").write(whole)
            env = dict(os.environ, ULAM_TEST_STOP_AT_MAP="1")
            p = subprocess.Popen([ulam] + args, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
            try:
                assert stopped(p), f"{name}: ended before the mapping: {p.communicate()}"
                shrink()
                p.send_signal(signal.SIGCONT)
                out, err = p.communicate(timeout=300)
            finally:
                if p.poll() is None:
                    p.kill()
                    p.wait()
            assert p.returncode == code("EIO"), f"{name}: exit {p.returncode}: {err.strip()[-300:]}"
            assert re.search(rf"^ulam: {re.escape(sysf)}: error: .*prepared file that stays whole while in use", err, re.M), \
                f"{name}: {err}"
            assert out == "", f"{name}: printed {out}"


CHECKS = [check_mapped_file_shrinks, check_radiosity_early_exit_frees, check_study_chart_symlinks, check_output_is_input, check_pipes, check_relabel, check_study_counts_every_run, check_radiosity_obj_lines,
          check_radiosity_mtllib_not_regular, check_matrix_zeros_streamed]


def main():
    ulam = sys.argv[1]
    flags = sys.argv[2:]
    radiosity = "--no-radiosity" not in flags
    cases = [flags[k + 1] for k in range(len(flags) - 1) if flags[k] == "--case"]
    checks = [c for c in CHECKS if radiosity or "radiosity" not in c.__name__]
    if cases:
        names = {c.__name__ for c in checks}
        unknown = [c for c in cases if c not in names and "check_" + c not in names]
        if unknown:
            print(f"unknown --case {', '.join(unknown)}: one of {', '.join(sorted(names))}")
            return 2
        checks = [c for c in checks if c.__name__ in cases or c.__name__[6:] in cases]
    failures = 0
    for f in checks:
        try:
            f(ulam)
        except AssertionError as e:
            failures += 1
            print(f"FAIL {f.__name__}: {e}\n  (rerun it alone: --case {f.__name__})")
    print(f"{len(checks) - failures} passed, {failures} failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
