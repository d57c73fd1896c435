"""Type stubs of flexmb (docstrings in flexmb/__init__.py)."""

import os
from typing import Any, Dict, Mapping, Optional, Tuple, Union, overload, Literal

import numpy as np
import numpy.typing as npt

from ._core import CaseError as CaseError, FlexmbError as FlexmbError, RunError as RunError

__version__: str

CaseLike = Union[str, os.PathLike[str], Mapping[str, Any]]
Columns = Dict[str, npt.NDArray[np.generic]]

@overload
def run(
    case: CaseLike,
    formulation: Literal["ancf", "gebf"] = ...,
    set: Optional[Mapping[str, Any]] = ...,
    *,
    base_dir: Optional[Union[str, os.PathLike[str]]] = ...,
    check: bool = ...,
) -> Columns: ...
@overload
def run(
    case: CaseLike,
    formulation: Literal["both"],
    set: Optional[Mapping[str, Any]] = ...,
    *,
    base_dir: Optional[Union[str, os.PathLike[str]]] = ...,
    check: bool = ...,
) -> Dict[str, Columns]: ...
def sweep(
    case: CaseLike,
    formulation: str = ...,
    set: Optional[Mapping[str, Any]] = ...,
    *,
    base_dir: Optional[Union[str, os.PathLike[str]]] = ...,
    check: bool = ...,
) -> Dict[str, Any]: ...
def trim(
    case: CaseLike,
    formulation: str = ...,
    set: Optional[Mapping[str, Any]] = ...,
    *,
    base_dir: Optional[Union[str, "os.PathLike[str]"]] = ...,
) -> Dict[str, Any]: ...
def static(
    case: CaseLike,
    formulation: str = ...,
    set: Optional[Mapping[str, Any]] = ...,
    *,
    base_dir: Optional[Union[str, os.PathLike[str]]] = ...,
) -> Dict[str, Any]: ...
def stability(
    case: CaseLike,
    formulation: str = ...,
    set: Optional[Mapping[str, Any]] = ...,
    *,
    base_dir: Optional[Union[str, os.PathLike[str]]] = ...,
) -> Dict[str, Any]: ...
def tip_difference(
    a: Mapping[str, npt.NDArray[np.generic]], b: Mapping[str, npt.NDArray[np.generic]]
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
def to_csv(result: Mapping[str, npt.NDArray[np.generic]]) -> str: ...
