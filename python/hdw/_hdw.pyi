# Type stubs of the compiled extension hdw._hdw (python/src/*.rs). The public API is in
# hdw/__init__.py and its modules, which are annotated; these are the raw bindings.
from os import PathLike
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

class SimulationError(RuntimeError):
    """The integrator could not finish a run."""

Columns = Dict[str, Union[np.ndarray, List[Any]]]

def parameters() -> Columns: ...
def metric_names() -> List[str]: ...
def column_doc(name: str) -> Optional[Tuple[str, str]]: ...
def simulate(
    options: Dict[str, Any], params: Optional[Dict[str, float]] = None, trace: bool = True
) -> Dict[str, Any]: ...
def simulate_dicts(
    options: Dict[str, Any],
    sets: Sequence[Dict[str, float]],
    base: Optional[Dict[str, float]] = None,
    threads: Optional[int] = None,
    metrics: Optional[Sequence[str]] = None,
) -> Columns: ...
def simulate_array(
    options: Dict[str, Any],
    values: npt.NDArray[np.float64],
    names: Sequence[str],
    base: Optional[Dict[str, float]] = None,
    threads: Optional[int] = None,
    metrics: Optional[Sequence[str]] = None,
) -> Columns: ...
def run_study(
    path: Union[str, PathLike[str]],
    read_profile: Callable[[str], Tuple[np.ndarray, np.ndarray]],
    threads: Optional[int] = None,
    parts: Optional[Sequence[str]] = None,
) -> Dict[str, Any]: ...
def fit_hysteresis(
    t: npt.ArrayLike,
    theta: npt.ArrayLike,
    torque: npt.ArrayLike,
    law: str = "memory",
    elements: Optional[int] = None,
    offset: bool = False,
    fix: Optional[Dict[str, float]] = None,
) -> Dict[str, Any]: ...
def fit_friction(
    t: Optional[npt.ArrayLike] = None,
    omega: Optional[npt.ArrayLike] = None,
    torque: Optional[npt.ArrayLike] = None,
    steady_omega: Optional[npt.ArrayLike] = None,
    steady_torque: Optional[npt.ArrayLike] = None,
    steady_load: Optional[npt.ArrayLike] = None,
    fix: Optional[Dict[str, float]] = None,
    asymmetric: bool = False,
    offset: bool = False,
) -> Dict[str, Any]: ...
def sobol_indices(
    y: npt.ArrayLike, dims: int, bootstrap: int = 1000, confidence: float = 0.95, seed: int = 0
) -> Dict[str, Any]: ...
