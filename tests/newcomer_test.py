#!/usr/bin/env python3
"""The README's and docs/'s shell blocks, verbatim.  Every fenced block of README.md and docs/*.md
that holds shell commands (```sh, or a transcript whose first line is `$ ulam ...`) is run, or is
marked `<!-- newcomer: skip: WHY -->` on the line before it; an unmarked shell block fails.  The
line before a block says how it runs:
  <!-- newcomer: KIND -->  KIND solve, study, radiosity or python (README): each `build/ulam ...`
      command in it (a line, or a part of a `&&` chain) is run with build/ulam replaced by the ulam
      under test, from a scratch directory that sees the source tree's matrices/ and examples/, and
      its output must have the shape KIND promises; a ```text block after one carries the date it
      was printed on.
  <!-- newcomer: run -->  each command (backslash continuations joined) runs in the scratch
      directory, `ulam` and `build/ulam` being the ulam under test, and must exit 0.
  <!-- newcomer: rerun -->  each line runs from the source root with build/ the build directory
      under test; `meson test -C build NAME... [--test-args=ARGS]` runs those tests' commands from
      the build's meson-info (meson test itself is not run inside meson test), and must exit 0
      and not report "0 passed".
  <!-- newcomer: pydoc -->  ```python blocks of one file, run in order in one interpreter (Debian's
      python3, PYTHONPATH the built binding).
  A `$ ulam ...` transcript runs its command in the scratch directory: exit 0, and its first output
  line has the shape of the transcript's.
Run from the source root: newcomer_test.py path/to/ulam [--wheel]
--wheel instead builds a wheel with pip (meson-python, --no-build-isolation, in a temporary build
directory: meson-python 0.12 cannot start a build directory it is given), installs it with pip into a temporary directory and imports it there with Debian's
python3 (no meson install, no ldconfig), as docs/python.md says.
"""
import glob
import json
import os
import re
import shlex
import subprocess
import sys
import tempfile

NUM = r"-?[\d.]+(?:e[-+]?\d+)?"
SHAPES = {  # KIND: regexes the stdout must match, each on a line of its own
    "solve": [rf"^x\[\d+\]\s+{NUM} \+- {NUM} \(95% CI {NUM} \.\. {NUM}\)$",
              r"^method\s+(\S.*random walks|bidirectional)", r"^walks\s+\d+", r"^seconds\s+",
              rf"^direct\s+{NUM} \((dense|sparse) LU(, {NUM} s)?\), z = {NUM}$"],
    "study": [r"^study of x\[\d+\]: exact ", r"^walks\s+winner",
              rf"^\d+\s+\S+-\S+-\S+\s+{NUM}\s+{NUM}\s+\d+/\d+ \({NUM} \.\. {NUM}\)$"],
    "radiosity": [r"^scene\s+", r"^patch\s+\d+ \(floor", rf"^radiosity R\s+{NUM} \+- {NUM} \(95% CI {NUM} \.\. {NUM}\)$",
                  rf"^radiosity B\s+{NUM} \+- {NUM} \(95% CI {NUM} \.\. {NUM}\)$", r"^rel-err\s+met"],
    "python": [rf"^{NUM} \+- {NUM} \({NUM}, {NUM}\) \d+ \w+$"],  # estimate +- stderr ci95 walks method
}
MAX_LINES = {"solve": 10}  # the default solve output is read in one glance
DEBIAN_PYTHON = "/usr/bin/python3" if os.path.exists("/usr/bin/python3") else sys.executable


def fences(path):
    """(marker, lang, body, line, next_lang, text_before_next) of each fenced block of a Markdown file;
    marker is the `<!-- newcomer: ... -->` text on the line before the fence (or the line before
    that, past one blank line), else None."""
    lines = open(path).read().split("\n")
    out, k = [], 0
    while k < len(lines):
        m = re.match(r"^```(\w*)\s*$", lines[k])
        if not m:
            k += 1
            continue
        start, lang = k, m.group(1)
        k += 1
        while k < len(lines) and not lines[k].startswith("```"):
            k += 1
        body = "\n".join(lines[start + 1:k])
        before = [ln for ln in lines[max(0, start - 2):start] if ln.strip()]
        mk = re.match(r"^<!-- newcomer: (.*?) -->$", before[-1]) if before else None
        out.append([mk.group(1) if mk else None, lang, body, start + 1, None, ""])
        k += 1
    for a, b in zip(out, out[1:]):  # what the next block is, and the prose line(s) before it
        a[4] = b[1]
        a[5] = "\n".join(lines[a[3]:b[3] - 1])
    return out


def is_shell(lang, body):
    """A block of shell commands: ```sh / ```shell / ```console, or a `$ ` transcript."""
    return lang in ("sh", "shell", "bash", "console") or (lang == "" and body.lstrip().startswith("$ "))


def commands(body):
    """The commands of a shell block: backslash continuations joined, comments and blanks dropped."""
    text = re.sub(r"\\\n\s*", " ", body)
    return [ln.strip() for ln in text.split("\n") if ln.strip() and not ln.strip().startswith("#")]


def readme_commands(kind, body):
    """The README's marked block: its build/ulam commands (each part of a && chain)."""
    cmds = []
    for line in body.splitlines():
        for part in line.split("&&"):
            part = part.strip()
            if part.startswith("build/ulam ") or kind == "python":
                cmds.append(part)
    return cmds


def with_ulam(cmd, ulam):
    """cmd with build/ulam and a leading ulam replaced by the ulam under test."""
    cmd = re.sub(r"(^|\s)build/ulam(?=\s|$)", lambda m: m.group(1) + shlex.quote(ulam), cmd)
    return re.sub(r"^ulam(?=\s)", shlex.quote(ulam), cmd)


def shape_of(line):
    """A line's shape as a regex: its numbers as NUM, runs of blanks as \\s+, the rest literal."""
    out = []
    for k, part in enumerate(re.split(r"(-?\d[\d.]*(?:e[-+]?\d+)?)", line.strip())):
        out.append(NUM if k % 2 else "".join(r"\s+" if w.isspace() else re.escape(w) for w in re.split(r"(\s+)", part) if w))
    return "^" + "".join(out) + r"\s*$"


class Runner:
    """Runs the blocks; counts failures."""

    def __init__(self, ulam, root, scratch):
        self.ulam, self.root, self.scratch = ulam, root, scratch
        self.build = os.path.dirname(ulam)
        self.failures = self.ran = 0

    def report(self, ok, what, p=None, why=""):
        self.ran += 1
        if ok:
            print(f"ok   {what}")
            return
        self.failures += 1
        print(f"FAIL {what}\n  {why}")
        if p is not None:
            print(f"  rc {p.returncode}\n  stdout: {p.stdout[-3000:]}\n  stderr: {p.stderr[-3000:]}")

    def sh(self, line, cwd, env=None):
        return subprocess.run(["sh", "-c", line], cwd=cwd, capture_output=True, text=True, timeout=600,
                              env=dict(os.environ, **(env or {})))

    def readme(self, kind, body, next_lang, between, where):
        cmds = readme_commands(kind, body)
        if not cmds:
            self.report(False, where, why=f"a '{kind}' block without a build/ulam command")
        if next_lang == "text" and not re.search(r"\b(?:Printed|run|printed) on \d{4}-\d\d-\d\d|\b\d{4}-\d\d-\d\d\b", between):
            self.report(False, where, why="the sample output after it carries no date (say when and where it was printed)")
        for cmd in cmds:
            if kind == "python":  # a shell line run from the source root, build/ being ulam's build directory
                pydir = os.path.join(self.build, "python")
                if not os.path.isfile(os.path.join(pydir, "ulam", "__init__.py")):
                    print(f"skip (no Python binding built): {cmd}")
                    continue
                line = cmd.replace("PYTHONPATH=build/python", "PYTHONPATH=" + shlex.quote(pydir))
                p = self.sh(line, self.root)
            else:
                args = shlex.split(cmd)
                if kind == "radiosity" and not self.radiosity():
                    print(f"skip (no radiosity front end): {cmd}")
                    continue
                p = subprocess.run([self.ulam] + args[1:], cwd=self.scratch, capture_output=True, text=True, timeout=600)
            bad = [rx for rx in SHAPES[kind] if not re.search(rx, p.stdout, re.M)]
            lines = len(p.stdout.splitlines())
            ok = not p.returncode and not bad and lines <= MAX_LINES.get(kind, 1000)
            self.report(ok, f"{where}: {cmd}", p, f"{lines} lines; shapes not found: {bad}")

    def radiosity(self):
        return subprocess.run([self.ulam, "radiosity", "--help"], capture_output=True).returncode == 0

    def run(self, body, where):
        for cmd in commands(body):
            if " radiosity " in f" {cmd} " and not self.radiosity():
                print(f"skip (no radiosity front end): {cmd}")
                continue
            p = self.sh(with_ulam(cmd, self.ulam), self.scratch)
            self.report(p.returncode == 0, f"{where}: {cmd}", p, "exit status not 0")

    def transcript(self, body, where):
        lines = body.split("\n")
        cmd = lines[0].lstrip()[2:]
        want = next((ln for ln in lines[1:] if ln.strip()), "")
        if " radiosity " in f" {cmd} " and not self.radiosity():
            print(f"skip (no radiosity front end): {cmd}")
            return
        p = self.sh(with_ulam(cmd, self.ulam), self.scratch)
        first = p.stdout.split("\n")[0]
        ok = p.returncode == 0 and re.match(shape_of(want), first) is not None
        self.report(ok, f"{where}: {cmd}", p, f"first line {first!r} is not shaped like {want!r}")

    def rerun(self, body, where):
        tests = json.load(open(os.path.join(self.build, "meson-info", "intro-tests.json")))
        for cmd in commands(body):
            env = {}
            words = shlex.split(cmd)
            while words and re.match(r"^[A-Z_]+=", words[0]):
                k, v = words.pop(0).split("=", 1)
                env[k] = v
            if words[:2] == ["meson", "test"]:
                rest = words[2:]
                extra = [w.split("=", 1)[1] for w in rest if w.startswith("--test-args=")]
                names = [w for w in rest[2:] if not w.startswith("-")] if rest[:2] == ["-C", "build"] else None
                if not names:
                    self.report(False, f"{where}: {cmd}", why="expected `meson test -C build NAME...`")
                    continue
                for name in names:
                    t = [t for t in tests if t["name"] == name]
                    if not t:
                        self.report(False, f"{where}: {cmd}", why=f"no test named {name}")
                        continue
                    t = t[0]
                    args = t["cmd"] + (shlex.split(extra[0]) if extra else [])
                    p = subprocess.run(args, cwd=t["workdir"] or self.root, capture_output=True, text=True, timeout=900,
                                       env=dict(os.environ, **t["env"], **env))
                    ok = p.returncode in (0, 77) and not re.search(r"^0 passed", p.stdout, re.M)
                    self.report(ok, f"{where}: {cmd} [{name}]", p, "failed, or ran no case")
            else:
                line = re.sub(r"(^|\s)build/", lambda m: m.group(1) + self.build + "/", cmd)
                p = self.sh(line, self.root)
                ok = p.returncode == 0 and not re.search(r"^0 passed", p.stdout, re.M)
                self.report(ok, f"{where}: {cmd}", p, "failed, or ran no case")

    def pydoc(self, bodies, where):
        pydir = os.path.join(self.build, "python")
        if not os.path.isfile(os.path.join(pydir, "ulam", "__init__.py")):
            print(f"skip (no Python binding built): {where}")
            return
        p = subprocess.run([DEBIAN_PYTHON, "-c", "\n".join(bodies)], cwd=self.scratch, capture_output=True, text=True,
                           timeout=600, env=dict(os.environ, PYTHONPATH=pydir))
        self.report(p.returncode == 0, f"{where}: its {len(bodies)} python blocks", p, "the program failed")


def docs_blocks(root):
    """(file, blocks) for README.md and every docs/*.md."""
    for path in [os.path.join(root, "README.md")] + sorted(glob.glob(os.path.join(root, "docs", "*.md"))):
        yield os.path.relpath(path, root), fences(path)


def main_docs(ulam):
    root = os.getcwd()
    with tempfile.TemporaryDirectory() as d:
        for sub in ("matrices", "examples", "tests"):
            os.symlink(os.path.join(root, sub), os.path.join(d, sub))
        r = Runner(ulam, root, d)
        kinds = set()
        for rel, blocks in docs_blocks(root):
            pyblocks = []
            for marker, lang, body, line, next_lang, between in blocks:
                where = f"{rel}:{line}"
                if marker == "pydoc" and lang == "python":
                    pyblocks.append(body)
                    continue
                if not is_shell(lang, body):
                    if marker and not marker.startswith("skip"):
                        r.report(False, where, why=f"a newcomer: {marker} mark on a block that is not shell")
                    continue
                if marker is None and lang == "" and body.lstrip().startswith("$ "):
                    r.transcript(body, where)
                elif marker is None:
                    r.report(False, where, why="a shell block neither run nor marked "
                             "<!-- newcomer: skip: WHY --> (tests/newcomer_test.py says how)")
                elif marker.startswith("skip:"):
                    print(f"skip {where}: {marker[5:].strip()}")
                elif marker in SHAPES and rel == "README.md":
                    kinds.add(marker)
                    r.readme(marker, body, next_lang, between, where)
                elif marker == "run":
                    r.run(body, where)
                elif marker == "rerun":
                    r.rerun(body, where)
                elif marker == "transcript" or (lang == "" and body.lstrip().startswith("$ ")):
                    r.transcript(body, where)
                else:
                    r.report(False, where, why=f"unknown mark 'newcomer: {marker}'")
            if pyblocks:
                r.pydoc(pyblocks, rel)
        if not {"solve", "study", "radiosity"} <= kinds:
            r.report(False, "README.md", why=f"the README lost a marked example: {sorted(kinds)}")
    print(f"{r.failures} of {r.ran} blocks failed" if r.failures else f"every one of {r.ran} shell blocks ran as documented")
    return 1 if r.failures else 0


def main_wheel(ulam):
    """pip wheel, pip install --target into a temporary directory, import there with Debian's python3."""
    root = os.getcwd()
    py = DEBIAN_PYTHON
    need = subprocess.run([py, "-c", "import mesonpy, pip, numpy, scipy"], capture_output=True)
    if need.returncode:
        print("skip: Debian's python3 lacks meson-python, pip, NumPy or SciPy (sh .ci/setup-tests)")
        return 77
    doc = open(os.path.join(root, "docs", "python.md")).read()
    assert "pip wheel --no-build-isolation" in doc and "pip install --no-build-isolation" in doc, \
        "docs/python.md no longer says how to build the wheel offline"
    with tempfile.TemporaryDirectory() as d:
        dist, site, elsewhere = (os.path.join(d, x) for x in ("dist", "site", "elsewhere"))
        os.mkdir(elsewhere)
        env = dict(os.environ, PIP_NO_INDEX="1", PIP_DISABLE_PIP_VERSION_CHECK="1")
        p = subprocess.run([py, "-m", "pip", "wheel", "--no-build-isolation", "--no-deps", "-w", dist, "."],
                           cwd=root, capture_output=True, text=True, timeout=1200, env=env)
        wheels = glob.glob(os.path.join(dist, "ulam-*.whl"))
        if p.returncode or len(wheels) != 1:
            print(f"FAIL pip wheel: rc {p.returncode}\n{p.stdout[-4000:]}\n{p.stderr[-4000:]}")
            return 1
        names = subprocess.run([py, "-m", "zipfile", "-l", wheels[0]], capture_output=True, text=True).stdout
        for want in ("ulam/__init__.py", "ulam/__init__.pyi", "ulam/py.typed", "ulam/_ulam."):
            if want not in names:
                print(f"FAIL the wheel lacks {want}:\n{names}")
                return 1
        if re.search(r"libulam|\.mesonpy\.libs|bin/ulam|include/", names):
            print(f"FAIL the wheel carries more than the binding:\n{names}")
            return 1
        p = subprocess.run([py, "-m", "pip", "install", "--no-deps", "--no-build-isolation", "--target", site, wheels[0]],
                           capture_output=True, text=True, timeout=600, env=env)
        if p.returncode:
            print(f"FAIL pip install --target: {p.stdout[-2000:]}\n{p.stderr[-2000:]}")
            return 1
        prog = ("import numpy as np, scipy.sparse as sp, scipy.sparse.linalg as sla, ulam, os, sys\n"
                f"assert os.path.dirname(os.path.dirname(ulam.__file__)) == {site!r}, ulam.__file__\n"
                "M = sp.random(300, 300, density=0.02, format='csr', random_state=1)\n"
                "M = sp.diags(0.8 / np.maximum(abs(M).sum(axis=1).A1, 1e-300)) @ M\n"
                "b = np.ones(300)\n"
                "x = sla.spsolve((sp.identity(300) - M).tocsc(), b)\n"
                "r = ulam.solve(M=M, b=b, index=7, rel_err=0.02, seed=3)\n"
                "assert abs(r.estimate - x[7]) < 4 * r.stderr, (r, x[7])\n"
                "v = ulam.solve(M=M, source=4)\n"
                "print('wheel ok', ulam.__version__, r)\n")
        # a clean environment: no build tree on the path, no library path, no libulam installed needed
        clean = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "LD_LIBRARY_PATH")}
        p = subprocess.run([py, "-c", prog], cwd=elsewhere, capture_output=True, text=True, timeout=600,
                           env=dict(clean, PYTHONPATH=site))
        print(p.stdout, p.stderr)
        if p.returncode:
            print("FAIL the installed wheel does not import and answer")
            return 1
    print("the pip-built wheel installs into a temporary directory and answers there")
    return 0


if __name__ == "__main__":
    exe = os.path.abspath(sys.argv[1])
    sys.exit(main_wheel(exe) if "--wheel" in sys.argv[2:] else main_docs(exe))
