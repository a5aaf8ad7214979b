#!/usr/bin/env python3
"""The README's examples, verbatim: every `sh` block marked `<!-- newcomer: KIND -->` is read from
README.md, each `build/ulam ...` command in it (a line, or a part of a `&&` chain) is run with
build/ulam replaced by the ulam under test, from a scratch directory that sees the source tree's
matrices/ and examples/, and its output must have the shape KIND promises.
Run from the source root: newcomer_test.py path/to/ulam
"""
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


def blocks(readme):
    """(KIND, commands) for each marked sh block."""
    text = open(readme).read()
    for kind, body in re.findall(r"<!-- newcomer: (\w+) -->\n```sh\n(.*?)```", text, re.S):
        cmds = []
        for line in body.splitlines():
            for part in line.split("&&"):
                part = part.strip()
                if part.startswith("build/ulam ") or kind == "python":
                    cmds.append(part)
        yield kind, cmds


def main():
    ulam = os.path.abspath(sys.argv[1])
    root = os.getcwd()
    found = list(blocks(os.path.join(root, "README.md")))
    kinds = {k for k, _ in found}
    assert {"solve", "study", "radiosity"} <= kinds, f"README lost a marked example: {sorted(kinds)}"
    failures = 0
    with tempfile.TemporaryDirectory() as d:
        for sub in ("matrices", "examples"):
            os.symlink(os.path.join(root, sub), os.path.join(d, sub))
        for kind, cmds in found:
            assert cmds, f"a '{kind}' block without a build/ulam command"
            for cmd in cmds:
                if kind == "python":  # a shell line run from the source root, build/ being ulam's build directory
                    pydir = os.path.join(os.path.dirname(ulam), "python")
                    if not os.path.isfile(os.path.join(pydir, "ulam", "__init__.py")):
                        print(f"skip (no Python binding built): {cmd}")
                        continue
                    line = cmd.replace("PYTHONPATH=build/python", "PYTHONPATH=" + shlex.quote(pydir))
                    p = subprocess.run(["sh", "-c", line], cwd=root, capture_output=True, text=True, timeout=600)
                else:
                    args = shlex.split(cmd)
                    if kind == "radiosity" and subprocess.run([ulam, "radiosity", "--help"], capture_output=True).returncode:
                        print(f"skip (no radiosity front end): {cmd}")
                        continue
                    p = subprocess.run([ulam] + args[1:], cwd=d, capture_output=True, text=True, timeout=600)
                bad = [rx for rx in SHAPES[kind] if not re.search(rx, p.stdout, re.M)]
                lines = len(p.stdout.splitlines())
                if p.returncode or bad or lines > MAX_LINES.get(kind, 1000):
                    failures += 1
                    print(f"FAIL {cmd}\n  rc {p.returncode}, {lines} lines; shapes not found: {bad}\n"
                          f"  stdout: {p.stdout}\n  stderr: {p.stderr}")
                else:
                    print(f"ok   {cmd}")
    print(f"{failures} of the README's examples failed" if failures else "every README example ran and has its shape")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
