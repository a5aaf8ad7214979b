"""The library's status codes, read from enum ulam_status in include/ulam.h (the one list), and
the CLI's exit code for each: 10 + the status (see the README's exit-code table)."""
import os
import re

_HEADER = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "include", "ulam.h")


def _statuses():
    text = open(_HEADER).read()
    body = re.search(r"enum ulam_status \{(.*?)\};", text, re.S).group(1)
    names = re.findall(r"^\s*ULAM_([A-Z0-9_]+)\s*(?:=\s*0)?\s*,", body, re.M)
    return [n for n in names if n != "NSTATUS"]


STATUS = _statuses()

# The 95% normal quantile, the library's ULAM_Z95 (one home).
Z95 = float(re.search(r"#define ULAM_Z95 ([0-9.]+)", open(_HEADER).read()).group(1))


def code(name):
    """The exit code of a run that failed with status ULAM_<name>."""
    return 10 + STATUS.index(name)
