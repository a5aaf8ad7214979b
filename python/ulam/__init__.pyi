# Type hints of the ulam package (PEP 561: py.typed beside it).
from typing import Any, Callable, Dict, List, Literal, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str
MODES: Tuple[str, ...]
ESTIMATORS: Tuple[str, ...]

Matrix = Any  # a scipy.sparse matrix or array, or a 2-d NumPy array (not a LinearOperator)
Vector = npt.ArrayLike
Array = npt.NDArray[np.float64]
Method = Literal["auto", "walks", "bidirectional", "richardson", "gauss-seidel", "sequential", "mcsa", "cg", "gmres"]
Progress = Callable[[int, float, float], object]

class Error(Exception):
    status: int
    message: str
    index: Optional[int]
    def __init__(self, status: int, message: str, index: Optional[int] = ...) -> None: ...

class InputError(Error, ValueError): ...
class DivergenceError(Error): ...
class InfiniteVarianceError(Error): ...
class ConvergenceError(Error): ...
class OutOfMemoryError(Error, MemoryError): ...

class Result:
    method: str
    estimate: float
    stderr: float
    ci95: Optional[Tuple[float, float]]
    walks: int
    mode: str
    estimator: str
    continue_q: Union[float, str]
    kernel_alpha: float
    seed: int
    index: int
    variance_finite: Optional[bool]
    interrupted: bool
    iterations: int
    residual: float
    report: Dict[str, Any]
    choice: Optional[Dict[str, Any]]

class VectorResult:
    method: str
    estimate: Array
    stderr: Array
    ci95: Tuple[Array, Array]
    walks: int
    report: Dict[str, Any]
    watched: Optional[int]
    watched_ci95: Optional[Tuple[float, float]]
    interrupted: bool
    def __len__(self) -> int: ...
    def __array__(self, dtype: Any = ...) -> Array: ...

class Interrupted(KeyboardInterrupt):
    result: Union[Result, VectorResult]
    def __init__(self, result: Union[Result, VectorResult]) -> None: ...

def methods() -> List[Tuple[str, Literal["entry", "all"]]]: ...

class System:
    n: int
    def __init__(self, *, M: Optional[Matrix] = ..., A: Optional[Matrix] = ..., jacobi: bool = ...,
                 omega: float = ...) -> None: ...
    def solve(self, b: Optional[Vector] = ..., index: Optional[int] = ..., *, source: Optional[int] = ...,
              method: Method = ..., mode: Optional[Literal["adjoint", "forward"]] = ...,
              estimator: Optional[Literal["collision", "absorption", "expected"]] = ..., walks: Optional[int] = ...,
              rel_err: Optional[float] = ..., rtol: Optional[float] = ..., time: Optional[float] = ...,
              seed: int = ..., threads: Optional[int] = ..., continue_q: Union[None, float, Literal["analog"]] = ...,
              kernel_alpha: Optional[float] = ..., roulette: Optional[float] = ..., split: Optional[float] = ...,
              max_steps: Optional[int] = ..., force: bool = ..., assume_finite_variance: bool = ...,
              whole_kernel: bool = ..., progress: Optional[Progress] = ...) -> Union[Result, VectorResult]: ...

def solve(*, M: Optional[Matrix] = ..., A: Optional[Matrix] = ..., b: Optional[Vector] = ...,
          index: Optional[int] = ..., jacobi: bool = ..., omega: float = ..., source: Optional[int] = ...,
          method: Method = ..., mode: Optional[Literal["adjoint", "forward"]] = ...,
          estimator: Optional[Literal["collision", "absorption", "expected"]] = ..., walks: Optional[int] = ...,
          rel_err: Optional[float] = ..., rtol: Optional[float] = ..., time: Optional[float] = ..., seed: int = ...,
          threads: Optional[int] = ..., continue_q: Union[None, float, Literal["analog"]] = ...,
          kernel_alpha: Optional[float] = ..., roulette: Optional[float] = ..., split: Optional[float] = ...,
          max_steps: Optional[int] = ..., force: bool = ..., assume_finite_variance: bool = ...,
          whole_kernel: bool = ..., progress: Optional[Progress] = ...) -> Union[Result, VectorResult]: ...

def pagerank(adj: Matrix, alpha: Optional[float] = ..., source: Optional[int] = ..., target: Optional[int] = ...,
             *, damping: Optional[float] = ..., **kw: Any) -> Union[Result, VectorResult]: ...

def study(*, M: Optional[Matrix] = ..., b: Optional[Vector] = ..., index: Optional[int] = ...,
          methods: Union[None, str, List[str]] = ..., budgets: Any = ..., time_budgets: bool = ...,
          repeats: int = ..., seed: int = ..., threads: Optional[int] = ...) -> Dict[str, Any]: ...
