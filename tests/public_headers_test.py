#!/usr/bin/env python3
"""The tests' include rule (tests/meson.build): every test program under tests/ (tests/*.c, *.h,
tests/fuzz/) includes only public headers -- include/, the generated ulam_version.h, headers of
tests/ itself and examples/ -- and never a header of src/.  A test of a private piece is a module
unit, src/MODULE_test.c beside its module, and each of those is built by tests/meson.build.

Usage: public_headers_test.py ROOT.  Exit 0 when the rule holds; 1 with each offending line
(file:line: the include and where it resolves) or each unit that is not built."""
import pathlib
import re
import sys

INCLUDE = re.compile(r'^\s*#\s*include\s*"([^"]+)"')


def resolve(root, src, name):
    """Where a quoted include of src resolves: its own directory first, then the include paths
    the tests are given (include/, examples/); None when nowhere."""
    for d in (src.parent, root / 'include', root / 'examples'):
        p = (d / name).resolve()
        if p.is_file():
            return p
    return None


def main():
    root = pathlib.Path(sys.argv[1]).resolve()
    tests = root / 'tests'
    allowed = [tests, root / 'include', root / 'examples']
    bad = []
    files = sorted([*tests.glob('*.c'), *tests.glob('*.h'), *tests.glob('fuzz/*.c'), *tests.glob('fuzz/*.h')])
    for f in files:
        for n, line in enumerate(f.read_text().splitlines(), 1):
            m = INCLUDE.match(line)
            if not m:
                continue
            name = m.group(1)
            if name == 'ulam_version.h':  # generated from include/ulam_version.h.in
                continue
            p = resolve(root, f, name)
            if p is None or not any(p.is_relative_to(a) for a in allowed):
                where = p.relative_to(root) if p is not None and p.is_relative_to(root) else p
                bad.append(f'{f.relative_to(root)}:{n}: #include "{name}" ({where or "not found"}): not a public header')
    # Every module unit beside its module is built (and so run) by tests/meson.build.
    build = (tests / 'meson.build').read_text()
    for u in sorted(root.glob('src/**/*_test.c')):
        rel = u.relative_to(root / 'src').as_posix()
        if f"'{rel}'" not in build:
            bad.append(f'src/{rel}: a module unit that tests/meson.build does not build')
    for b in bad:
        print(b)
    print(f'{len(files)} test files checked, {len(bad)} problems')
    return 1 if bad else 0


if __name__ == '__main__':
    sys.exit(main())
