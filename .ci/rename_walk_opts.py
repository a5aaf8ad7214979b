#!/usr/bin/env python3
"""Move every use of a ulam_walk_opts field into its concern (issue 31 point 4, soname 3).

    python3 .ci/rename_walk_opts.py [BUILD]      (from the repository root, after the header change)

ulam_walk_opts's fields were grouped by concern into nested structs (include/ulam.h):
kernel (continue_q, kernel_alpha, whole_kernel, roulette, split), stop (max_walks, rel_err,
max_seconds, max_steps, interrupt, rel_err_offset), exec (seed, threads, share), query (index,
nstarts, starts, start_weights) and policy (force, assume_finite, guard, system); mode and
estimator stay at the top.  A textual sed cannot do the rename: index, seed, threads, mode,
guard ... are fields of other structs too.  So the compiler finds the uses: every C file the
repository tracks is compiled with -fsyntax-only (with the build's flags when
BUILD/compile_commands.json has it, else the include paths), and at each error
"'ulam_walk_opts' has no member named F" or "unknown field 'F' specified in initializer" the
concern's name is inserted before F (o.max_walks -> o.stop.max_walks, .seed = 1 ->
.exec.seed = 1); repeated until no such error is left.  Files the script cannot compile
(README.md's copy of examples/embed.c) are the lead's to copy over.  Idempotent: a tree already
renamed has no such error."""
import json
import os
import re
import shlex
import subprocess
import sys

GROUP = {}
for g, fields in {
    "kernel": "continue_q kernel_alpha whole_kernel roulette split",
    "stop": "max_walks rel_err max_seconds max_steps interrupt rel_err_offset",
    "exec": "seed threads share",
    "query": "index nstarts starts start_weights",
    "policy": "force assume_finite guard system",
}.items():
    for f in fields.split():
        GROUP[f] = g

NO_MEMBER = re.compile(r"^(.*?):(\d+):(\d+): error: '(?:const )?(?:volatile )?ulam_walk_opts'.*has no member named '(\w+)'")
UNKNOWN = re.compile(r"^(.*?):(\d+):(\d+): error: unknown field '(\w+)' specified in initializer")


def commands(build):
    """Each tracked .c file's compile command (argument list, cwd)."""
    known = {}
    path = os.path.join(build, "compile_commands.json")
    if os.path.exists(path):
        for e in json.load(open(path)):
            f = os.path.realpath(os.path.join(e["directory"], e["file"]))
            args = e.get("arguments") or shlex.split(e["command"])
            known.setdefault(f, (args, e["directory"], e["file"]))
    files = subprocess.run(["git", "ls-files", "*.c"], capture_output=True, text=True, check=True).stdout.split()
    out = []
    for f in files:
        real = os.path.realpath(f)
        if real in known:
            args, cwd, src = known[real]
            keep, skip = [], False
            for a in args[1:]:
                if skip:
                    skip = False
                    continue
                if a in ("-o", "-MF", "-MQ", "-MT"):
                    skip = True
                    continue
                if a in ("-c", "-MD", src):
                    continue
                keep.append(a)
            out.append(([args[0]] + keep + ["-fsyntax-only", "-fmax-errors=0", "-fdiagnostics-color=never", real], cwd))
        else:
            out.append((["cc", "-std=gnu11", "-fsyntax-only", "-fmax-errors=0", "-fdiagnostics-color=never", "-Iinclude", "-I" + build + "/include",
                         "-Isrc", "-Iexamples", "-Itests", f], "."))
    return out


def fix(path, line, col, field, done):
    """Insert field's concern before it at path:line:col (col 1-based, on the name or its '.')."""
    key = (os.path.realpath(path), line, col)
    if key in done:
        return False
    done.add(key)
    text = open(path).read().split("\n")
    s = text[line - 1]
    at = s.find(field, col - 1)
    if s.startswith("offsetof", col - 1):  # the caret is on the macro: the field is its second argument
        m = re.compile(r"offsetof\(\s*\w+\s*,\s*(" + field + r")\b").match(s, col - 1)
        at = m.start(1) if m else -1
    elif at > col + 1:
        at = -1
    if at < 0:
        return False
    text[line - 1] = s[:at] + GROUP[field] + "." + s[at:]
    open(path, "w").write("\n".join(text))
    return True


def main():
    build = sys.argv[1] if len(sys.argv) > 1 else "build"
    cmds = commands(build)
    for rnd in range(8):
        changed = 0
        for args, cwd in cmds:
            r = subprocess.run(args, cwd=cwd, capture_output=True, text=True, env=dict(os.environ, LC_ALL="C"))
            done = set()
            hits = []
            for ln in r.stderr.splitlines():
                m = NO_MEMBER.match(ln) or UNKNOWN.match(ln)
                if m and m.group(4) in GROUP:
                    p = m.group(1) if os.path.isabs(m.group(1)) else os.path.join(cwd, m.group(1))
                    hits.append((p, int(m.group(2)), int(m.group(3)), m.group(4)))
            # right to left within a line, so earlier columns stay valid
            for p, line, col, field in sorted(set(hits), key=lambda h: (h[0], h[1], -h[2])):
                changed += fix(p, line, col, field, done)
        print(f"round {rnd + 1}: {changed} uses moved")
        if not changed:
            return 0
    return 1


if __name__ == "__main__":
    sys.exit(main())
