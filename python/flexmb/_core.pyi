"""Type stubs of the Rust extension flexmb._core (the public API is in flexmb/__init__.py)."""

from typing import Dict, List, Optional, Tuple

import numpy as np
import numpy.typing as npt

__version__: str

class FlexmbError(Exception): ...

class CaseError(FlexmbError):
    field: Optional[str]
    file: Optional[str]

class RunError(FlexmbError):
    formulation: str
    run: str
    result: Dict[str, npt.NDArray[np.generic]]

_Columns = Dict[str, npt.NDArray[np.generic]]
_PerFormulation = Dict[str, Tuple[_Columns, Optional[str]]]

def run(
    case: str, from_path: bool, base_dir: str, formulations: List[str], overrides: List[str]
) -> List[Tuple[str, _PerFormulation]]: ...
def static_sweep(
    case: str, from_path: bool, base_dir: str, formulations: List[str], overrides: List[str]
) -> List[Tuple[str, _PerFormulation]]: ...
def stability(
    case: str, from_path: bool, base_dir: str, formulations: List[str], overrides: List[str]
) -> List[Tuple[str, _PerFormulation]]: ...
def trim(
    case: str, from_path: bool, base_dir: str, formulations: List[str], overrides: List[str]
) -> List[Tuple[str, Dict[str, Tuple[str, Optional[str]]]]]: ...
def to_csv(columns: Dict[str, npt.NDArray[np.generic]]) -> str: ...
def tip_difference(
    a: Dict[str, npt.NDArray[np.generic]], b: Dict[str, npt.NDArray[np.generic]]
) -> Tuple[List[float], List[float]]: ...
def native_seconds(
    case: str, from_path: bool, base_dir: str, formulations: List[str], overrides: List[str]
) -> float: ...
