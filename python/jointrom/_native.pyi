"""Type stubs of the extension module jointrom._native (re-exported by jointrom)."""

import os
from typing import Any, Callable, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

PathLike = Union[str, "os.PathLike[str]"]
Vector = npt.NDArray[np.float64]
Matrix = npt.NDArray[np.float64]
Progress = Callable[[float, float], Any]
"""progress(t_reached_s, end_time_s), called about every 50 ms from the calling thread."""

class Error(Exception):
    """Every failure jointrom reports; the message is the command line's."""

class InputError(Error):
    """A bad case, deck, matrix map or reduced-model file, or a bad option (named as the flag)."""

class SolverError(Error):
    """Linear algebra, SUNDIALS (function, flag, time), a failed callback, chattering events."""

class IoError(Error):
    """A file could not be read or written."""

def load(case: PathLike) -> Model:
    """A built-in name (friction_bar, multilayer_sheet), a case file, a NASTRAN deck or a
    matrix map."""

def load_rom(path: PathLike, model: Optional[Model] = None) -> Rom:
    """A reduced-model file; with `model`, checked to be exported from it."""

class Model:
    @property
    def name(self) -> str: ...
    @property
    def dofs(self) -> int: ...
    @property
    def pairs(self) -> int: ...
    @property
    def info(self) -> dict[str, Any]:
        """The `jointrom info --json` document."""
    def modes(self, count: int = 10, interface: str = "fixed") -> Vector:
        """The lowest eigenfrequencies, Hz; interface "fixed" or "free"."""
    def static(
        self,
        scale: float = 1.0,
        load: Optional[Union[Sequence[float], Vector]] = None,
        linear: bool = False,
    ) -> dict[str, Any]:
        """Contact (or linear) statics: master_displacement, contact_force_norm,
        pairs_in_contact, pair_forces (k × 4: x, y, z, p), forces, gaps, displacement."""
    def stiffness(self) -> Any:
        """K (N/mm): scipy.sparse.csc_matrix, or (data, indices, indptr, shape) without scipy."""
    def mass(self) -> Any:
        """M (t): scipy.sparse.csc_matrix, or (data, indices, indptr, shape) without scipy."""
    def transient(
        self,
        *,
        end_time: Optional[float] = None,
        output_step: float = 1e-4,
        friction: bool = True,
        events: bool = False,
        rtol: Optional[float] = None,
        atol: Optional[float] = None,
        iteration: str = "newton",
        max_order: Optional[int] = None,
        max_wall: float = 3600.0,
        progress: Optional[Progress] = None,
    ) -> RunResult:
        """The full FE model's transient run (`jointrom transient CASE --model full`)."""
    def reduce(
        self,
        *,
        tolerance: Optional[float] = None,
        basis: Optional[str] = None,
        g: Optional[int] = None,
        nu: int = 10,
        end_time: Optional[float] = None,
        output_step: float = 1e-4,
        friction: bool = True,
        events: bool = False,
        max_wall: float = 3600.0,
        progress: Optional[Progress] = None,
    ) -> Rom:
        """A reduced model: tolerance=TOL (adaptive) or basis=KIND (tvd, tvd-plain, modes, jim,
        alldof) with g vectors and nu fixed-interface modes. Default: tvd."""

class Rom:
    @property
    def dimension(self) -> int: ...
    @property
    def phi(self) -> Optional[Matrix]:
        """Φ (n × r); None for a reduced model read from a file."""
    @property
    def k(self) -> Matrix:
        """Φᵀ K Φ (r × r), N/mm."""
    @property
    def m(self) -> Matrix:
        """Φᵀ M Φ (r × r), t."""
    @property
    def b_phi(self) -> Matrix:
        """BΦ (3·pairs × r)."""
    @property
    def info(self) -> dict[str, Any]: ...
    def transient(
        self,
        *,
        end_time: Optional[float] = None,
        output_step: float = 1e-4,
        friction: bool = True,
        events: bool = False,
        rtol: Optional[float] = None,
        atol: Optional[float] = None,
        iteration: str = "newton",
        max_order: Optional[int] = None,
        max_wall: float = 3600.0,
        progress: Optional[Progress] = None,
    ) -> RunResult: ...
    def save(self, path: PathLike) -> None: ...
    def export_fmu(self, path: PathLike, binary: Optional[PathLike] = None) -> None: ...

class RunResult:
    model: str
    case: str
    basis_size: int
    g: Optional[int]
    t: Vector
    contact_force_norm: Vector
    friction_force_norm: Vector
    master_uy: Vector
    kinetic: Vector
    strain: Vector
    pair: Vector
    external_work: Vector
    dissipated: Vector
    stats: dict[str, Any]
    error_estimate: Optional[dict[str, Any]]
    energy_check: dict[str, Any]
    options: dict[str, Any]
    tolerance: Optional[dict[str, Any]]
    wall_s: float
    cpu_s: float
    offline_s: Optional[float]
    events: int
    total_s: float
    def curves(self) -> dict[str, Vector]: ...
