"""ulam: (I - M) x = b by von Neumann-Ulam random walks, with an honest error bar.

    import ulam
    r = ulam.solve(M=M, b=b, index=3, rel_err=0.01)      # (I - M) x = b: one entry, x_3
    print(r.estimate, "+-", r.stderr, r.ci95, r.walks, r.method)
    r = ulam.solve(A=A, b=b, index=3, rtol=0.01)          # A x = b (Jacobi: M = I - D^-1 A)
    v = ulam.solve(M=M, b=b, mode="forward")             # every x_i: NumPy arrays
    v = ulam.solve(M=M, source=5)                        # every x_i of (I - M) x = e_5
    p = ulam.pagerank(adj)                               # global PageRank, every node

The system is named in the call: M= for (I - M) x = b, A= for A x = b (a matrix passed by
position is refused: scipy's solve(A, b) means A x = b, ulam's walks (I - M) x = b).  A matrix is
any scipy.sparse matrix or array, or a dense NumPy array (square); b a NumPy vector; indices are
0-based.  An answer for one entry is a ulam.Result (floats); for every entry (mode="forward",
source= without index, pagerank without target) a ulam.VectorResult (NumPy arrays).  The answer
comes from the C library's method table, as `ulam solve` gives it.  ulam.System(M=M) answers many
queries of one matrix, reusing its set-up.  Errors raise ulam.Error subclasses carrying the
library's status and message; Ctrl-C raises ulam.Interrupted (a KeyboardInterrupt) with the
estimate so far in its .result.
"""
import json
import math
import re
import threading
import warnings
import zlib

import numpy as np

from . import _ulam

__all__ = ["solve", "pagerank", "study", "System", "Result", "VectorResult", "methods", "Error", "InputError", "DivergenceError",
           "InfiniteVarianceError", "ConvergenceError", "OutOfMemoryError", "Interrupted"]
__version__ = _ulam.version

MODES = ("adjoint", "forward")
ESTIMATORS = ("collision", "absorption", "expected")
_ROWS = [name for name, _ in _ulam.methods()]
_METHOD_WALKS, _METHOD_BIDIR = _ROWS.index("walks"), _ROWS.index("bidirectional")


class Error(Exception):
    """A refusal or failure of the library: .status (the library's ULAM_E* code), .message (the
    sentence saying what was expected), .index (the row or index it concerns, or None)."""

    def __init__(self, status, message, index=None):
        self.status, self.message, self.index = status, message, index
        text = _ulam.strerror(status) + (": expected " + message if message else "")
        super().__init__(text if index is None or index < 0 else f"{text} (index {index})")


class InputError(Error, ValueError):
    """Bad input: an option out of range, a non-square M, a b of the wrong length, an index out
    of range, NaN or infinite entries, a zero diagonal for jacobi, ..."""


class DivergenceError(Error):
    """rho(|M|) is not certified below 1: the walks may diverge (pass force=True to walk anyway)."""


class InfiniteVarianceError(Error):
    """A rel_err target with a variance not certified finite: no walk count can meet it honestly
    (bound the run with walks= or time= instead)."""


class ConvergenceError(Error):
    """An iteration did not converge within its cap, or its residual stalled."""


class OutOfMemoryError(Error, MemoryError):
    """The library ran out of memory."""


class Interrupted(KeyboardInterrupt):
    """Ctrl-C during a solve: .result is the Result so far (its estimate from the walks made)."""

    def __init__(self, result):
        self.result = result
        if isinstance(result, VectorResult):
            super().__init__(f"interrupted after {result.walks} walks: the estimates so far are in .result")
        else:
            super().__init__(f"interrupted after {result.walks} walks: estimate so far {result.estimate:.10g} "
                             f"+- {result.stderr:.3g}")


_INPUT = {"EINVAL", "EZERODIAG", "ENONFINITE", "EUNDEFINED"}


def _raise(status, message, index=-1):
    """Raise the exception of a library status."""
    names = {getattr(_ulam, k): k for k in ("EINVAL", "ENOMEM", "EDIVERGE", "EINFVAR", "ENOCONV", "ESTALL",
                                            "EUNDEFINED", "EZERODIAG", "ENONFINITE")}
    name = names.get(status, "")
    cls = (DivergenceError if name == "EDIVERGE" else InfiniteVarianceError if name == "EINFVAR"
           else ConvergenceError if name in ("ENOCONV", "ESTALL") else OutOfMemoryError if name == "ENOMEM"
           else InputError if name in _INPUT or 11 <= status <= 16 else Error)
    raise cls(status, message, index if index is not None and index >= 0 else None)


def _input(message):
    """Raise an InputError (ULAM_EINVAL) with message (what was expected)."""
    raise InputError(_ulam.EINVAL, message)


def methods():
    """The library's method table: a list of (name, what it answers), what answers is "entry"
    (one x_i with an error bar: walks, bidirectional) or "all" (every unknown to a residual
    tolerance: richardson, gauss-seidel, sequential, mcsa, cg, gmres).  solve(method=NAME) pins a
    row; method="auto" (the default) chooses among them."""
    return [(name, "entry" if answers == 1 else "all") for name, answers in _ulam.methods()]


def _csr(M, what="M"):
    """M as the library's CSR arrays (indptr int64, indices int32, data float64, n): taken without
    a copy where they already are of those types and canonical (sorted, no duplicates, no stored
    zeros); converted otherwise (scipy's own int32 indptr: its n + 1 entries)."""
    import scipy.sparse as sp
    import scipy.sparse.linalg as sla
    if isinstance(M, sla.LinearOperator):
        raise TypeError(f"{what}: a matrix with its entries (scipy.sparse or NumPy), got a LinearOperator: the walks "
                        "sample M's entries row by row, which a LinearOperator's products do not give (pass the "
                        "sparse matrix behind it)")
    if sp.issparse(M):
        if M.format != "csr":
            M = M.tocsr()
    else:
        a = np.asarray(M)
        if a.dtype == object or a.dtype.kind not in "biufc":
            raise TypeError(f"{what}: a matrix of numbers (scipy.sparse or NumPy), got {type(M).__name__}")
        if a.ndim != 2:
            _input(f"{what}: a 2-d matrix (scipy.sparse or NumPy), got {a.ndim} dimensions")
        M = sp.csr_matrix(a)
    if M.shape[0] != M.shape[1]:
        raise InputError(14, f"{what}: a square matrix, got {M.shape[0]} x {M.shape[1]}")
    if M.shape[0] < 1 or M.shape[0] > 2**31 - 1:
        _input(f"{what}: between 1 and 2^31 - 1 rows, got {M.shape[0]}")
    if np.iscomplexobj(M.data):
        _input(f"{what}: real entries (complex systems are not supported)")
    if not M.has_canonical_format:
        M = M.copy()
        M.sum_duplicates()
    data = M.data if M.data.dtype == np.float64 else M.data.astype(np.float64)
    if not np.isfinite(data).all():
        k = int(np.flatnonzero(~np.isfinite(data))[0])
        row = int(np.searchsorted(M.indptr, k, side="right") - 1)
        raise InputError(_ulam.ENONFINITE, f"{what}: finite entries (row {row} holds a NaN or infinity)", row)
    indices, indptr = M.indices, M.indptr
    if (data == 0).any():
        keep = data != 0
        counts = np.add.reduceat(keep.astype(np.int64), indptr[:-1]) if len(data) else np.zeros(M.shape[0], np.int64)
        counts[np.diff(indptr) == 0] = 0
        indptr = np.concatenate(([0], np.cumsum(counts)))
        data, indices = data[keep], indices[keep]
    indices = indices if indices.dtype == np.int32 else indices.astype(np.int32)
    indptr = indptr if indptr.dtype == np.int64 else indptr.astype(np.int64)
    return (np.ascontiguousarray(indptr), np.ascontiguousarray(indices), np.ascontiguousarray(data), M.shape[0])


def _vector(b, n, what="b"):
    """b as a float64 C-contiguous vector of n entries."""
    import scipy.sparse as sp
    if sp.issparse(b):
        b = b.toarray()
    if np.iscomplexobj(b):
        _input(f"{what}: real entries (complex systems are not supported)")
    if np.asarray(b).dtype == object:
        raise TypeError(f"{what}: a vector of numbers, got {type(b).__name__}")
    v = np.ascontiguousarray(np.asarray(b, dtype=np.float64).reshape(-1) if np.ndim(b) == 2 and 1 in np.shape(b)
                             else np.asarray(b, dtype=np.float64))
    if v.ndim != 1 or v.shape[0] != n:
        raise InputError(15, f"{what}: a vector of {n} entries (M's size), got shape {np.shape(b)}")
    if not np.isfinite(v).all():
        raise InputError(_ulam.ENONFINITE, f"{what}: finite entries (entry {int(np.flatnonzero(~np.isfinite(v))[0])} "
                         "is NaN or infinite)")
    return v


def _number(name, v, lo, hi, integer=False):
    """v checked to lie in [lo, hi] (the CLI's ranges), as int or float (True and False are not numbers
    here: index=True was index 1)."""
    if isinstance(v, (bool, np.bool_)):
        _input(f"{name}: {'an integer' if integer else 'a number'} from {lo:g} to {hi:g}, got {v!r}")
    try:
        x = int(v) if integer else float(v)
    except (TypeError, ValueError):
        _input(f"{name}: a number from {lo} to {hi}, got {v!r}")
    if integer and x != v:
        _input(f"{name}: an integer from {lo} to {hi}, got {v!r}")
    if not (lo <= x <= hi):
        _input(f"{name}: a number from {lo:g} to {hi:g}, got {v!r}")
    return x


class Result:
    """One answer.  Attributes:
      estimate   the estimate of x_index
      stderr     its standard error (NaN for the rows without an error bar)
      ci95       (low, high): the 95% confidence interval, or None when the variance is not
                 certified finite (or cut walks may have moved it more than its standard error)
      walks      walks made (for the outer iterations: their walk histories)
      method     the table row that ran: "walks", "bidirectional", "mcsa", ...
      mode, estimator, continue_q, kernel_alpha   the walks' kernel (walks row)
      variance_finite  True, False or None (unknown)
      interrupted  True when Ctrl-C stopped it
      report     the JSON object `ulam solve --json` prints for this run, as a dict (the CLI's keys;
                 its "index" is 1-based there, as on the command line; the process keys load_seconds,
                 guard_seconds, kernel_seconds, transpose_seconds and peak_rss_mib are absent, and a
                 bidirectional run's rho_abs and rho_hat are None: the CLI computes them beside it)
      choice     the library's choice: every row's verdict and the walks' candidates (raw)
    """

    def __init__(self, d, index, b_nonzeros, source, scale=1.0):
        w = d["walk"]
        self.method = d["method"]
        self.estimate = d["estimate"] * scale
        self.stderr = d["std_error"] * scale
        lo, hi = d["ci95"]
        self.ci95 = (lo * scale, hi * scale) if math.isfinite(lo) and math.isfinite(hi) else None
        if scale < 0 and self.ci95:
            self.ci95 = (self.ci95[1], self.ci95[0])
        self.walks = w["walks"]
        o = d["opts"]
        self.mode, self.estimator = MODES[o["mode"]], ESTIMATORS[o["estimator"]]
        self.continue_q = o["continue_q"] if o["continue_q"] > 0 else "analog"
        self.kernel_alpha = o["kernel_alpha"]
        self.seed = o["seed"]
        self.index = index
        fin = w["variance_finite"]
        self.variance_finite = True if fin == 1 else False if fin == 0 else None
        if self.method == "bidirectional":
            self.variance_finite = self.ci95 is not None
        self.interrupted = bool(d["interrupted"] or w["interrupted"])
        self.choice = d.get("choice")
        self.iterations, self.residual = d["iterations"], d["residual"]
        self.report = _report(d, index, b_nonzeros, source, scale)

    def __repr__(self):
        # the CLI's answer line (src/report.c ulam__report_pm_fprint): where a side of the interval passes
        # 10 standard errors (ULAM__REPORT_PM_WIDE), the +- is that side and the standard error is named
        pm, ci = self.stderr, "no confidence interval"
        if self.ci95:
            ci = f"95% CI {self.ci95[0]:.10g} .. {self.ci95[1]:.10g}"
            side = max(self.ci95[1] - self.estimate, self.estimate - self.ci95[0])
            if side > 10.0 * self.stderr:
                pm, ci = side, ci + f"; standard error {self.stderr:.3g}"
        return (f"<ulam.Result x[{self.index}] = {self.estimate:.10g} +- {pm:.3g} ({ci}), "
                f"{self.walks} walks, method {self.method}>")


class VectorResult:
    """An answer for every unknown (mode="forward", source= without index, pagerank without
    target).  Attributes (NumPy arrays of n unless said):
      estimate   the estimates of every x_i
      stderr     their standard errors (NaN where no walk reached x_i: no estimate)
      ci95       (low, high): two arrays, each component's 95% interval.  Single source and
                 PageRank from a source: the library's interval of each component (the walks'
                 empirical-Bernstein interval around the push, clipped to what the push leaves).
                 Forward walks: estimate -+ 1.96 stderr, a normal interval (NaN where stderr is),
                 except at the watched index, which carries the run's anytime interval (watched_ci95)
      watched, watched_ci95  forward walks: the index the stopping rule watched and its interval
                 (None when the variance is not certified finite)
      walks      walks made;  method  "walks" (forward) or "single-source";  interrupted
      report     the run's details as a dict
    len(r) is n and np.asarray(r) the estimates."""

    def __init__(self, method, estimate, stderr, lo, hi, walks, report, watched=None, watched_ci95=None,
                 interrupted=False):
        self.method, self.estimate, self.stderr, self.ci95 = method, estimate, stderr, (lo, hi)
        self.walks, self.report, self.watched, self.watched_ci95 = walks, report, watched, watched_ci95
        self.interrupted = interrupted

    def __len__(self):
        return len(self.estimate)

    def __array__(self, dtype=None):
        return self.estimate if dtype is None else self.estimate.astype(dtype)

    def __repr__(self):
        return (f"<ulam.VectorResult of {len(self.estimate)} unknowns (max {np.nanmax(self.estimate):.6g}, "
                f"median stderr {np.nanmedian(self.stderr) if np.isfinite(self.stderr).any() else float('nan'):.3g}), "
                f"{self.walks} walks, method {self.method}>")


def _num(v):
    """A JSON number as the CLI prints it: None when not finite."""
    return v if isinstance(v, (int, bool)) or (v is not None and math.isfinite(v)) else None


def _report(d, index, b_nonzeros, source, scale):
    """The JSON object `ulam solve --json` prints, from the library's answer (the CLI's keys)."""
    w, o = d["walk"], d["opts"]
    ch = d.get("choice")
    auto = ch is not None and not ch["pinned"]
    rep = {"index": index + 1}
    if d["method"] in ("walks", "bidirectional"):  # the library's JSON, as `ulam solve --json` prints it
        rep.update(json.loads(d["report_json"]))
        if d["method"] == "walks":  # ulam_walk_result_json's members, and the CLI's own keys around them
            rep.update({"ranks": 1, "kernel_rows": w["rows"]})  # (ranks: MPI; kernel_rows)
        else:  # ulam_report_fprint's bidirectional object, less the process's keys; source and b as given
            for k in ("transpose_seconds", "load_seconds", "guard_seconds"):
                del rep[k]
            rep.update({"source": source + 1 if source is not None else None, "b_nonzeros": b_nonzeros})
        if scale != 1.0:  # pagerank's scale (1 - alpha)
            rep["estimate"], rep["stderr"] = rep["estimate"] * scale, rep["stderr"] * abs(scale)
            if rep["ci95"]:
                rep["ci95"] = sorted(c * scale for c in rep["ci95"])
    else:
        rep.update({"method": d["method"], "estimate": d["estimate"] * scale, "iterations": d["iterations"],
                    "residual": _num(d["residual"]), "histories": w["walks"], "seed": o["seed"]})
    if auto:  # the library's "auto" member (ulam_choice_fprint), as the CLI prints it
        rep["auto"] = json.loads(d["auto_json"])["auto"]
        why = ch["rows"][_METHOD_BIDIR]["why"]
        if rep["auto"]["bidirectional"] is not None and why == "not considered: --jacobi":
            rep["auto"]["bidirectional"] = why  # the CLI's wording for its --jacobi (set by _solve)
    rep["interrupted"] = bool(d["interrupted"] or w["interrupted"])
    return rep


def _option_message(message):
    """The options table's refusal named as Python names it ("--rel-err expects a real ..." ->
    "rel_err: a real ..."); other messages as they are."""
    return re.sub(r"^--([a-z-]+) expects ", lambda m: m.group(1).replace("-", "_") + ": ", message)


def _method_error(name):
    """The CLI's usage error for an unknown method."""
    names = ["walks", "bidirectional (with source= or a sparse b)"] + _ROWS[2:]
    _input(f"method: one of auto, {', '.join(names[:-1])} or {names[-1]}, got {name!r}")


class System:
    """A matrix of (I - M) x = b (System(M=M)) or A x = b (System(A=A), walked as
    M = I - omega D^-1 A with b scaled per query) to answer many queries of:
    System(M=M).solve(b, index=i, ...) as many times as needed (keyword arguments: those of
    ulam.solve).  The set-up the queries share (the guards of the analog kernel, computed by the
    first query; M's transpose, by the first single-source query) is paid once; each query's
    answer is as honest as a fresh solve's, though its choice may differ where the pilots' budget
    counted a fresh solve's guard pass.  M's arrays are taken without a copy where they are
    float64 CSR with int32 indices (an int32 indptr is converted: n + 1 entries); a checksum of
    them is kept, and a query after they changed (M.data *= 3) raises InputError: make a new
    System for a changed matrix."""

    def __init__(self, *args, M=None, A=None, jacobi=False, omega=1.0):
        if args:
            _positional("System")
        if (M is None) == (A is None):
            _input("the system: System(M=M) for (I - M) x = b, or System(A=A) for A x = b")
        if jacobi and A is None:
            _input("jacobi=True goes with A= (System(A=A): A x = b)")
        self._jacobi, self._omega = A is not None, _number("omega", omega, 1e-6, 2.0)
        arrays = _csr(A if self._jacobi else M, "A" if self._jacobi else "M")
        self.n = arrays[3]
        self._held = arrays  # the arrays borrowed (the caller's own, where not converted)
        if self._jacobi:
            self._A = arrays
            st, msg, idx, *rest = _ulam.jacobi(*arrays, np.zeros(self.n), self._omega)
            if st:
                _raise(st, msg, idx)
            arrays = (rest[0], rest[1], rest[2], self.n)
        self._arrays = arrays
        self._sum = self._checksum()
        try:
            self._sys = _ulam.System(*arrays)
        except ValueError as e:
            st = int(str(e).split(":")[0])
            raise InputError(st, "a valid CSR matrix (sorted unique columns, finite nonzero values)") from None

    def _checksum(self):
        """Adler-32 of the borrowed arrays' bytes (the matrix the queries walk on)."""
        c = 1
        for a in self._held[:3]:
            c = zlib.adler32(memoryview(a).cast("B"), c)
        return c

    def _check(self):
        """Refuse a query once the borrowed matrix changed under this System."""
        if self._checksum() != self._sum:
            _input(f"{'A' if self._jacobi else 'M'} unchanged since System(): its entries or structure changed "
                   "after it was made (make a new System for a changed matrix)")

    def _rhs(self, b):
        """b of the walks: omega D^-1 b under jacobi."""
        if not self._jacobi:
            return b
        st, msg, idx, *rest = _ulam.jacobi(*self._A, b, self._omega)
        if st:
            _raise(st, msg, idx)
        return rest[3]

    def solve(self, b=None, index=None, **kw):
        """As ulam.solve(M=..., b=b, index=..., ...) on this system's matrix (see help(ulam.solve))."""
        return _solve(self, b, index, reuse=True, **kw)


def _positional(name):
    """The refusal of a matrix passed by position."""
    raise TypeError(f"ulam.{name}: name the system: M=M for (I - M) x = b (the walks' form), or A=A for A x = b "
                    f"(scipy's spsolve(A, b); walked as M = I - D^-1 A) -- a matrix passed by position is "
                    f"ambiguous and is not accepted")


def _vectors(system, d, index, scale, rel_err):
    """The VectorResult of a forward-walks query."""
    x, se, st = d["vectors"]
    if st:
        _raise(st, "finite estimates (a component's estimate overflowed)")
    x, se = x * scale, se * abs(scale)
    lo, hi = x - 1.96 * se, x + 1.96 * se
    if scale < 0:
        lo, hi = hi, lo
    w = d["walk"]
    ci = d["ci95"]
    watched_ci = ((ci[0] * scale, ci[1] * scale) if scale > 0 else (ci[1] * scale, ci[0] * scale)) \
        if w["variance_finite"] == 1 and all(math.isfinite(c) for c in ci) else None
    if watched_ci is not None:
        lo[index], hi[index] = watched_ci
    rep = {"method": "walks", "mode": "forward", "walks": w["walks"], "steps": w["steps"], "seconds": w["seconds"],
           "watched": index, "unreached": w["unreached"], "variance_finite": watched_ci is not None,
           "seed": d["opts"]["seed"], "push_sweeps": w["push_sweeps"], "push_ops": w["push_ops"],
           "push_residual": w["push_residual"]}
    if rel_err is not None:
        rep["rel_err_met"] = bool(w["rel_err_met"])
    return VectorResult("walks", x, se, lo, hi, w["walks"], rep, index, watched_ci,
                        bool(d["interrupted"] or w["interrupted"]))


def _single_source(system, source, *, walks=None, rel_err=None, seed=1, threads=None, force=False, _scale=1.0,
                   method="auto", **rest):
    """Every x_i of (I - M) x = e_source (b' = omega D^-1 e_source under A=): ulam_fpush_solve."""
    if method not in ("auto", "single-source"):
        _input(f"source=S without index answers every unknown (method 'single-source'), got method={method!r}")
    given = {k: v for k, v in rest.items() if v not in (None, False)}
    if given:
        _input(f"source=S without index (single source, every unknown): it takes walks=, rel_err=, seed=, threads= "
               f"and force=, got {', '.join(sorted(given))}")
    n = system.n
    source = _number("source", source, 0, n - 1, integer=True)
    e = np.zeros(n)
    e[source] = 1.0
    scale = _scale * float(system._rhs(e)[source])
    opts = {"seed": _number("seed", seed, 0, 2**63 - 1, integer=True), "force": int(bool(force)),
            "catch_sigint": int(threading.current_thread() is threading.main_thread())}
    if threads is not None:
        opts["threads"] = _number("threads", threads, 1, 1024, True)
    if rel_err is not None:
        opts["fpush_rel_err"] = _number("rel_err", rel_err, 1e-12, 1.0)
    if walks is not None:
        opts["fpush_walks"] = opts["max_walks"] = _number("walks", walks, 1, 2**62, True)
    system._check()
    d = system._sys.fpush(source, opts)
    if d["status"]:
        _divergence(d, force)
        _raise(d["status"], d["message"], d["error_index"])
    x, se, lo, hi = d["x"] * scale, d["std_error"] * abs(scale), d["lo"] * scale, d["hi"] * scale
    if scale < 0:
        lo, hi = hi, lo
    rep = {k: d[k] for k in ("walks", "steps", "rmax", "push_ops", "residual_bound", "dense", "seconds")}
    rep.update({"method": "single-source", "source": source, "n": n})
    r = VectorResult("single-source", x, se, lo, hi, d["walks"], rep, interrupted=bool(d["interrupted"]))
    if r.interrupted:
        raise Interrupted(r)
    return r


def _divergence(d, force):
    """force=True on a matrix whose walks overflow: a DivergenceError that says so (the library's
    status is ULAM_ENONFINITE: a walk's weight or score became infinite or NaN)."""
    if force and d["status"] == _ulam.ENONFINITE:
        raise DivergenceError(_ulam.EDIVERGE, "walks that stay finite: force=True walked a matrix whose rho(|M|) "
                              "is not certified below 1, and a walk's weight overflowed to infinity or NaN (the "
                              "Neumann series of M diverges here: x has no walk estimate; solve it directly)")


def _unknown_keyword(name):
    """The TypeError for keyword name that solve does not take, naming the closest it does (the
    CLI's "did you mean" for an option): its keywords are _solve's and solve's own."""
    import difflib
    import inspect
    names = [k for k in inspect.signature(_solve).parameters if not k.startswith("_") and k not in
             ("system", "unknown", "reuse")] + ["M", "A", "jacobi", "omega"]
    near = difflib.get_close_matches(name, names, 1, 0.6)
    raise TypeError(f"unexpected keyword argument {name!r}" + (f" (did you mean {near[0]!r}?)" if near else ""))


def _solve(system, b, index, *, source=None, method="auto", mode=None, estimator=None, walks=None, rel_err=None,
           rtol=None, time=None, seed=1, threads=None, continue_q=None, kernel_alpha=None, roulette=None, split=None,
           max_steps=None, force=False, assume_finite_variance=False, whole_kernel=False, progress=None, reuse=False,
           _scale=1.0, **unknown):
    """The query behind solve, System.solve and pagerank."""
    if "alpha" in unknown:
        raise TypeError("alpha: the walk kernel's exponent is kernel_alpha= (--alpha); in ulam, alpha is "
                        "PageRank's damping (ulam.pagerank(adj, alpha=0.85))")
    if unknown:
        _unknown_keyword(next(iter(unknown)))
    if rtol is not None:
        if rel_err is not None:
            _input("rel_err= or rtol= (scipy's name for it), not both")
        rel_err = rtol
    n = system.n
    if source is not None and index is None and mode in (None, "forward"):  # single source: forward by nature
        if b is not None:
            _input("source=S sets b = e_S: it cannot go with b")
        return _single_source(system, source, walks=walks, rel_err=rel_err, seed=seed, threads=threads, force=force,
                              _scale=_scale, method=method, estimator=estimator, time=time, continue_q=continue_q,
                              kernel_alpha=kernel_alpha, roulette=roulette, split=split, max_steps=max_steps,
                              assume_finite_variance=assume_finite_variance, whole_kernel=whole_kernel,
                              progress=progress)
    if method != "auto" and method not in _ROWS:
        _method_error(method)
    if source is not None:
        source = _number("source", source, 0, n - 1, integer=True)
        if b is not None:
            _input("source=S sets b = e_S: it cannot go with b")
        if mode is not None:
            _input("source=S with index answers x_index bidirectionally (mode cannot be pinned); without index, "
                   "every unknown")
        if method not in ("auto", "bidirectional"):
            _input(f"source=S goes with method='bidirectional', got {method!r}")
        method = "bidirectional"
        b = np.zeros(n)
        b[source] = 1.0
    if b is None:
        _input("b (or source= for b = e_S)")
    b = _vector(b, n)
    b = system._rhs(b)
    opts = {"seed": _number("seed", seed, 0, 2**63 - 1, integer=True)}
    if mode is not None:
        if mode not in MODES:
            _input(f"mode: adjoint or forward, got {mode!r}")
        opts["mode"], opts["pin_mode"] = MODES.index(mode), 1
    if estimator is not None:
        if estimator not in ESTIMATORS:
            _input(f"estimator: collision, absorption or expected, got {estimator!r}")
        opts["estimator"], opts["pin_estimator"] = ESTIMATORS.index(estimator), 1
    if continue_q is not None:
        opts["continue_q"] = 0.0 if continue_q == "analog" else _number("continue_q", continue_q, 1e-9, 1 - 1e-12)
        opts["pin_continue"] = 1
    if kernel_alpha is not None:
        opts["kernel_alpha"], opts["pin_alpha"] = _number("kernel_alpha", kernel_alpha, 0.0, 1000.0), 1
    given = {"walks": walks, "rel_err": rel_err, "time": time, "threads": threads, "max_steps": max_steps,
             "roulette": roulette, "split": split}
    # the numeric options, set and checked by the library's options table (ulam_options_set)
    opts["set"] = {name: str(v) for name, v in given.items() if v is not None}
    if walks is None:
        opts["max_walks"] = 100000 if rel_err is None and time is None else 0  # the CLI's default budget
    try:
        if roulette is not None and split is not None and float(split) <= float(roulette):
            _input("split: a weight above roulette's")
    except (TypeError, ValueError):
        pass  # not numbers: the options table refuses them
    mode_forward = opts.get("mode") == 1
    if index is None:
        if not mode_forward:
            _input("index (adjoint walks and bidirectional answer x_index; mode='forward' or source= without index "
                   "answer every unknown)")
        index = 0
    index = _number("index", index, 0, n - 1, integer=True)
    opts.update({"force": int(bool(force)), "assume_finite": int(bool(assume_finite_variance)),
                 "whole_kernel": int(bool(whole_kernel)), "reuse": int(bool(reuse)),
                 "catch_sigint": int(threading.current_thread() is threading.main_thread())})
    if mode_forward:  # every unknown: the forward walks' vectors (no bidirectional: it answers one entry)
        if method not in ("auto", "walks"):
            _input(f"mode='forward' answers every unknown by walks: method 'walks' or 'auto', got {method!r}")
        opts["vectors"] = 1
        method = "walks"
    if all(opts.get(k) for k in ("pin_mode", "pin_estimator", "pin_continue", "pin_alpha")) and method == "auto":
        method = "walks"  # nothing to choose: the CLI's pinned run
    opts["method"] = -1 if method == "auto" else _ROWS.index(method)
    if method == "auto" and system._jacobi:
        opts["exclude"] = 1 << _METHOD_BIDIR  # as the CLI: not with --jacobi
    if progress is not None and not callable(progress):
        _input("progress: a callable (walks, estimate, stderr) or None")
    system._check()
    d = system._sys.query(b, index, opts, progress)
    if "choice" in d and method == "auto" and system._jacobi:
        d["choice"]["rows"][_METHOD_BIDIR]["why"] = "not considered: --jacobi"
    d["rel_err"] = rel_err
    if d["status"]:
        _divergence(d, force)
        _raise(d["status"], _option_message(d["message"]), d["error_index"])
    ch = d.get("choice")
    if method == "auto" and ch and ch["walks"]["chosen"] < 0:
        w = ch["walks"]
        c = w["candidates"][w["closest"]]
        diverge = not (w["abs_upper"] < 1)
        text = (f"no walk candidate has a certified finite variance"
                f"{' (rho(|M|) is not certified below 1)' if diverge else ''}; the closest is "
                f"{MODES[c['mode']]} {ESTIMATORS[c['estimator']]} (continuation "
                f"{'' if c['continue_q'] > 0 else 'analog, '}{max(c['continue_q'], 0):.3g}, kernel exponent "
                f"{c['kernel_alpha']:g}) with rho(M^) = {c['rho_hat']:.6g} (upper bound {c['rho_hat_upper']:.6g})")
        if rel_err is not None:
            raise (DivergenceError if diverge else InfiniteVarianceError)(
                _ulam.EDIVERGE if diverge else _ulam.EINFVAR, text + ": a rel_err target cannot be met honestly")
        warnings.warn("ulam: " + text + "; running it", RuntimeWarning, stacklevel=3)
    if "vectors" in d:
        r = _vectors(system, d, index, _scale, rel_err)
        if r.interrupted:
            raise Interrupted(r)
        return r
    nb = int(np.count_nonzero(b))
    r = Result(d, index, nb, source, _scale)
    if d["interrupted"]:  # Ctrl-C (the walks' interrupt flag): the estimate so far rides on the exception
        raise Interrupted(r)
    return r


def solve(*args, M=None, A=None, b=None, index=None, jacobi=False, omega=1.0, source=None, method="auto",
          mode=None, estimator=None, walks=None, rel_err=None, rtol=None, time=None, seed=1, threads=None,
          continue_q=None, kernel_alpha=None, roulette=None, split=None, max_steps=None, force=False,
          assume_finite_variance=False, whole_kernel=False, progress=None, **unknown):
    """Estimate x of (I - M) x = b (M=) or A x = b (A=) with an error bar: `ulam solve` from Python.

    Returns a ulam.Result for one unknown x_index (r.estimate, r.stderr, r.ci95, r.walks, r.method,
    r.report), or a ulam.VectorResult for every unknown (NumPy arrays r.estimate, r.stderr and
    r.ci95 = (low, high)): mode="forward", or source= without index.

    Arguments (all by keyword; they mirror `ulam solve`'s long options):
      M           the matrix of (I - M) x = b: any scipy.sparse matrix or array, or a dense NumPy
                  array, square.  Float64 CSR with int32 indices is used without a copy (scipy's
                  int32 indptr, n + 1 entries, is converted); other formats and types are
                  converted.  A LinearOperator is refused (TypeError): the walks need M's entries.
      A           instead of M: the matrix of A x = b (scipy's spsolve(A, b)), walked as
                  M = I - omega D^-1 A with b' = omega D^-1 b (--jacobi); needs a nonzero diagonal.
                  A matrix passed by position is refused (TypeError): name the system.
      b           the right-hand side, a real NumPy vector of M's size (or source= instead).
      index       0-based: the unknown x_index to estimate (needed unless mode="forward" or
                  source= answers every unknown; with mode="forward", the one its rule watches).
      jacobi      accepted with A= (redundant: A= is walked by Jacobi).
      omega       the Jacobi damping, in [1e-6, 2] (--omega, default 1).
      source      0-based S: b = e_S, a point source (--source).  With index: x_index by a
                  bidirectional solve (a reverse push from index, walks from S).  Without: every
                  x_i (a forward push from S and walks from its residual: single source), a
                  VectorResult whose intervals are the library's, per component.
      method      "auto" (the default: the library's choice among the table's rows, as the CLI's
                  --method auto: the walks' candidates raced by pilots, and bidirectional for a
                  sparse b with a rel_err target when predicted cheaper), or a row of the table
                  pinned: "walks" (the walks the options name, defaults for the rest),
                  "bidirectional", or "richardson", "gauss-seidel", "sequential", "mcsa", "cg",
                  "gmres" (every unknown to a residual of 1e-8; r.estimate is x_index, with no
                  error bar).  ulam.methods() lists the rows.
      mode        "adjoint" (walks start at index) or "forward" (walks from b: every unknown, a
                  VectorResult); pins it for auto.
      estimator   "collision", "absorption" or "expected"; pins it for auto.
      walks       stop after this many walks (--walks; default 100000 when no rule is given).
      rel_err     stop once the printed 95% interval's half-width is at most rel_err |estimate|
                  (matrix walks), after at least 1000 walks (--rel-err, in [1e-12, 1]); refused
                  (InfiniteVarianceError) when the variance is not certified finite, unless
                  walks= or time= bounds the run.  Single source: every component whose interval
                  reaches 1/n within -+ rel_err of it (default 0.1).
      rtol        scipy's name for rel_err (one or the other).
      time        stop after this many seconds (--time); the first rule reached wins.
      seed        block q of walks uses stream (seed, q) (--seed, default 1): the same answer for
                  any thread count, and the CLI's answer for the same seed and options.
      threads     threads (--threads, default all cores).
      continue_q  --continue: "analog" (min(1, row sum), the default) or a fixed continuation
                  probability in (0, 1); pins it for auto.
      kernel_alpha  the walk kernel's exponent (--alpha, in [0, 1000], default 1: p_ij in
                  proportion to |M_ij|^kernel_alpha); pins it for auto.  (alpha= is refused here:
                  in ulam, alpha is PageRank's damping.)
      roulette    Russian roulette below this weight (--roulette).
      split       split particles above this weight (--split; above roulette's).
      max_steps   cut walks longer than this (--max-steps, default 10^6).
      force       walk even when rho(|M|) is not certified below 1 (--force; else
                  DivergenceError; walks that then overflow raise DivergenceError too).
      assume_finite_variance  treat a variance the guards cannot decide as finite
                  (--assume-finite-variance).
      whole_kernel  build every row of the walk kernel first (--whole-kernel).
      progress    None, or a callable progress(walks, estimate, stderr) called after each round of
                  walks (an exception it raises stops the walks and propagates).

    Raises TypeError (a matrix by position, a LinearOperator, an unknown keyword),
    ulam.InputError (bad arguments: the CLI's refusals; a ValueError), ulam.DivergenceError,
    ulam.InfiniteVarianceError, ulam.ConvergenceError, ulam.OutOfMemoryError (all ulam.Error:
    .status, .message), and ulam.Interrupted (a KeyboardInterrupt; .result holds the estimate so
    far) on Ctrl-C.  The GIL is released while the library works.
    """
    if args:
        _positional("solve")
    if M is not None and A is not None:
        _input("M= or A=, not both")
    if jacobi and A is None:
        _input("jacobi=True goes with A= (solve(A=A, b=b): A x = b)")
    if M is None and A is None:
        _input("a matrix: M= for (I - M) x = b, or A= for A x = b")
    system = System(M=M, A=A, omega=omega)
    return _solve(system, b, index, source=source, method=method, mode=mode, estimator=estimator, walks=walks,
                  rel_err=rel_err, rtol=rtol, time=time, seed=seed, threads=threads, continue_q=continue_q,
                  kernel_alpha=kernel_alpha, roulette=roulette, split=split, max_steps=max_steps, force=force,
                  assume_finite_variance=assume_finite_variance, whole_kernel=whole_kernel, progress=progress,
                  **unknown)


def pagerank(adj, alpha=None, source=None, target=None, *, damping=None, **kw):
    """PageRank with an error bar, pi = (1 - alpha) x with (I - alpha P') x = s, P = D^-1 adj the
    out-link transition matrix and s the restart distribution: e_source (personalized PageRank
    from source) or, with no source, uniform 1/n (global PageRank).  A node without out-links ends
    the walk (its mass is lost: the substochastic convention).

      adj      the adjacency (weights >= 0), any scipy.sparse or dense square matrix; adj[i, j] is
               the link i -> j.
      alpha    the damping: the probability of following a link each step, in (0, 1), default
               0.85 (networkx's name; damping= is the same, the CLI's --damping).
      source   0-based node the surfer restarts at (personalized), or None: global PageRank.
      target   0-based node: pi(target) alone, a ulam.Result (from a source: bidirectionally, a
               reverse push from target and walks from source, as `ulam solve --index t
               --source s`); None: every node, a ulam.VectorResult (from a source: a forward push
               and walks, the library's interval per node; global: forward walks).
      **kw     as ulam.solve (rel_err= or rtol=, walks=, seed=, threads=, ...).
    Returns a ulam.Result or ulam.VectorResult whose estimates, stderr and intervals are of pi."""
    import scipy.sparse as sp
    if alpha is not None and damping is not None:
        _input("alpha= or damping= (the same), not both")
    alpha = damping if alpha is None else alpha
    alpha = 0.85 if alpha is None else alpha
    try:
        a = float(alpha)
    except (TypeError, ValueError):
        a = float("nan")
    if isinstance(alpha, (bool, np.bool_)) or not (0 < a < 1):
        _input(f"alpha: the damping, a number strictly between 0 and 1 (at 1 the surfer never restarts: no "
               f"PageRank, and walks that never end), got {alpha!r}")
    alpha = a
    G = _csr_input(adj, "adj")
    G = sp.csr_matrix(G, dtype=np.float64) if not sp.issparse(G) else G.tocsr().astype(np.float64)
    if G.shape[0] != G.shape[1]:
        raise InputError(14, f"adj: a square adjacency, got {G.shape[0]} x {G.shape[1]}")
    if (G.data < 0).any():
        _input("adj: nonnegative link weights")
    out = np.asarray(G.sum(axis=1)).reshape(-1)
    inv = np.divide(alpha, out, out=np.zeros_like(out), where=out > 0)
    M = (sp.diags(inv) @ G).T.tocsr()
    system = System(M=M)
    n = system.n
    if target is not None:
        target = _number("target", target, 0, n - 1, integer=True)
    if source is not None:
        return _solve(system, None, target, source=source, _scale=1.0 - alpha, **kw)
    b = np.full(n, 1.0 / n)
    if target is None:
        kw.setdefault("mode", "forward")
    return _solve(system, b, target, _scale=1.0 - alpha, **kw)


def study(*args, M=None, b=None, index=None, methods=None, budgets=(100, 1000, 10000, 100000, 1000000),
          time_budgets=False, repeats=30, seed=1, threads=None):
    """A variance study of x_index (0-based) of (I - M) x = b, as `ulam study` runs it (the
    library's ulam_study_*): every method of the grid named in methods (names like
    "adjoint-collision-plain"; None: all 18) at every budget (walks a run, or seconds with
    time_budgets=True), repeats runs each, run k walking with seed
    ulam_rng_substream(seed, STUDY, k), each scored against the exact x_index (LAPACK up to n =
    8000, else Gauss-Seidel).  Returns a dict: exact, direct (LAPACK's), done, interrupted,
    runs (a dict a run: method, budget, repeat, seed, status, estimate, std_error, abs_error,
    walks, steps, seconds, covered; a run with no estimate has NaN there), cells (a dict per
    method and budget: runs, failed, rmse, mean_stderr, honesty, coverage, seconds, work) and
    screens (a dict per method: infinite, refused: why, or "")."""
    if args:
        _positional("study")
    if M is None or b is None or index is None:
        _input("study(M=M, b=b, index=i): the matrix, b and the unknown")
    system = System(M=M)
    n = system.n
    index = _number("index", index, 0, n - 1, integer=True)
    names = [m[0] for m in _ulam.study_methods()]
    if methods is not None:
        methods = [methods] if isinstance(methods, str) else list(methods)
        for m in methods:
            if m not in names:
                _input(f"methods: names of the study's grid ({', '.join(names[:2])}, ...), got {m!r}")
        methods = [names.index(m) for m in methods]
    budgets = [_number("budgets", v, 1e-6 if time_budgets else 1, 1e6 if time_budgets else 2**62,
                       integer=not time_budgets) for v in budgets]
    if not 1 <= len(budgets) <= 16:
        _input(f"budgets: 1 to 16 budgets, got {len(budgets)}")
    repeats = _number("repeats", repeats, 2, 4096, integer=True)
    seed = _number("seed", seed, 0, 2**64 - 1, integer=True)
    threads = 0 if threads is None else _number("threads", threads, 1, 1024, integer=True)
    d = system._sys.study(_vector(b, n), index, methods, [float(v) for v in budgets], int(bool(time_budgets)),
                          repeats, seed, threads)
    if d["status"]:
        _raise(d["status"], d["message"])
    return d


def _csr_input(m, what):
    """m checked to be a matrix with entries (not a LinearOperator): the TypeError of _csr."""
    import scipy.sparse.linalg as sla
    if isinstance(m, sla.LinearOperator):
        _csr(m, what)
    return m
