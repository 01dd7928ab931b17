# Type hints for the jetfit module (docs/python.md is the manual).
from os import PathLike
from typing import Dict, List, NamedTuple, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str
STATUS: Dict[str, int]
OPENMP_RUNTIME: str  # "libgomp", the command's runtime

_Path = Union[str, bytes, PathLike]
_Points = npt.ArrayLike            # (N, 3) numbers; float64 C order is not copied
_Faces = Union[npt.ArrayLike, Sequence[Sequence[int]]]  # (M, k) or polygons

class FileError(OSError): ...

class Result:
    normal: npt.NDArray[np.float64]        # (N, 3)
    k1: npt.NDArray[np.float64]            # (N,)
    k2: npt.NDArray[np.float64]            # (N,)
    d1: npt.NDArray[np.float64]            # (N, 3)
    d2: npt.NDArray[np.float64]            # (N, 3)
    b: Optional[npt.NDArray[np.float64]]   # (N, 4) if monge_degree >= 3
    c: Optional[npt.NDArray[np.float64]]   # (N, 5) if monge_degree >= 4
    degree: npt.NDArray[np.int32]          # (N,)
    neighbors: npt.NDArray[np.int32]       # (N,)
    status: npt.NDArray[np.int32]          # (N,) flags, see STATUS
    cond: npt.NDArray[np.float64]          # (N,)
    residual: npt.NDArray[np.float64]      # (N,)
    sigma: npt.NDArray[np.float64]         # (N,) neighbors="auto": noise seen; else NaN
    auto_step0: Optional[str]              # neighbors="auto": step 0's decision; else None
    points: object
    faces: Optional[object]
    monge_degree: int
    def __len__(self) -> int: ...
    def as_structured(self, points: Optional[_Points] = ...) -> np.ndarray: ...

class Jet(NamedTuple):
    normal: npt.NDArray[np.float64]
    k1: float
    k2: float
    d1: npt.NDArray[np.float64]
    d2: npt.NDArray[np.float64]
    b: Optional[npt.NDArray[np.float64]]
    c: Optional[npt.NDArray[np.float64]]
    degree: int
    neighbors: int
    cond: float
    residual: float
    status: int

def estimate(points: _Points, *, neighbors: Optional[str] = "knn:32",
             degree: Optional[int] = 2, monge_degree: Optional[int] = None,
             fit: Optional[str] = "approx", frame: Optional[str] = "pca",
             max_cond: Optional[float] = 1000, orient: Optional[str] = None,
             normals: Optional[_Points] = None, normal: Optional[str] = None,
             robust: Optional[str] = None,
             scales: Optional[Union[int, Sequence[int]]] = None,
             degree_select: Optional[int] = None,
             dist_weight: Optional[float] = None,
             robust_normals: bool = False,
             threads: Optional[int] = None,
             scanners: Optional[_Points] = None) -> Result: ...

def estimate_mesh(vertices: _Points, faces: _Faces, rings: Optional[int] = None, *,
                  neighbors: Optional[str] = None,
                  degree: Optional[int] = 2, monge_degree: Optional[int] = None,
                  fit: Optional[str] = "approx", frame: Optional[str] = "pca",
                  max_cond: Optional[float] = 1000, orient: Optional[str] = None,
                  normals: Optional[_Points] = None, normal: Optional[str] = None,
                  robust: Optional[str] = None,
                  scales: Optional[Union[int, Sequence[int]]] = None,
                  degree_select: Optional[int] = None,
                  dist_weight: Optional[float] = None,
                  robust_normals: bool = False,
                  threads: Optional[int] = None,
                  scanners: Optional[_Points] = None) -> Result: ...

def fit_jet(neighbors: _Points, degree: Optional[int] = 2, *,
            monge_degree: Optional[int] = None, fit: Optional[str] = "approx",
            frame: Optional[str] = "pca", max_cond: Optional[float] = 1000,
            point: Optional[npt.ArrayLike] = None,
            weights: Optional[npt.ArrayLike] = None) -> Jet: ...

def read(path: _Path, *, columns: Optional[Sequence[int]] = None,
         bad_rows: Optional[str] = None) -> Tuple[
        npt.NDArray[np.float64], Optional[npt.NDArray[np.float64]],
        Optional[Union[npt.NDArray[np.int32], List[npt.NDArray[np.int32]]]],
        Dict[str, np.ndarray]]: ...

def write(path: _Path, result: Result, *, points: Optional[_Points] = None,
          faces: Optional[_Faces] = None, ascii: bool = False,
          threads: Optional[int] = None) -> None: ...

def status_names(status: int) -> str: ...
