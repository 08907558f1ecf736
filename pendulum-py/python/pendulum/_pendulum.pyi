"""Type stubs of the native module (checked against it by mypy.stubtest)."""

from os import PathLike
from pathlib import Path
from typing import Any, Optional, Sequence, Union, final

import numpy as np
import numpy.typing as npt

__all__ = [
    "AtlasPlan",
    "Chain",
    "Circle",
    "Harmonic",
    "HeavyString",
    "Run",
    "RunResult",
    "Sampled",
    "__version__",
    "check_claims",
    "page",
    "run_sweep",
    "steady",
    "whirls",
]
__version__: str

_Array = npt.NDArray[np.float64]

def page(directory: Union[str, PathLike[str]], frames: int = ...) -> str: ...
def steady(
    chain: Chain,
    *,
    radius: float = ...,
    omega: Union[float, Sequence[float], None] = ...,
    omega_max: Optional[float] = ...,
    branches: Optional[int] = ...,
    damping: Optional[_PerLink] = ...,
) -> dict[str, Any]: ...
def whirls(
    chain: Chain,
    *,
    radius: Union[float, Sequence[float], npt.ArrayLike],
    omega: Union[float, Sequence[float], npt.ArrayLike],
    ramp_time: Union[float, Sequence[float], npt.ArrayLike, None] = ...,
    duration: Optional[float] = ...,
    step: Optional[float] = ...,
) -> dict[str, Any]: ...
def check_claims(
    path: Union[str, PathLike[str], None] = None,
    *,
    text: Optional[str] = None,
    states: int = ...,
    seed: int = ...,
) -> tuple[list[dict[str, Any]], str]: ...
def run_sweep(
    chain: Chain,
    omega: str,
    radius: float,
    kinds: Sequence[str],
    scaled: bool,
    duration: Optional[float],
    ramp_time: Optional[float],
    step: Optional[float],
    jobs: Optional[int],
    out: Union[str, PathLike[str], None],
) -> str: ...
_PerLink = Union[float, Sequence[float], npt.ArrayLike]

@final
class AtlasPlan:
    def __new__(
        cls,
        chain: Chain,
        *,
        omega: Union[float, Sequence[float]],
        radius: Union[float, Sequence[float]],
        damping: Union[float, Sequence[float], None] = ...,
        ramp_time: Union[float, Sequence[float], None] = ...,
        kinds: Sequence[str] = ...,
        scaled: bool = ...,
        duration: Optional[float] = ...,
        step: Optional[float] = ...,
    ) -> AtlasPlan: ...
    @staticmethod
    def from_json(text: str) -> AtlasPlan: ...
    def to_json(self) -> str: ...
    def __reduce__(self) -> tuple[Any, tuple[str]]: ...
    def __len__(self) -> int: ...
    def derived_json(self) -> str: ...
    def run(self, indices: Sequence[int], threads: Optional[int] = None) -> str: ...
    def save(self, directory: Union[str, PathLike[str]], points: str) -> None: ...

@final
class Chain:
    def __new__(
        cls,
        masses: _PerLink,
        lengths: _PerLink,
        gravity: float = 9.81,
        damping: Optional[_PerLink] = None,
    ) -> Chain: ...
    @property
    def n(self) -> int: ...
    @property
    def masses(self) -> _Array: ...
    @property
    def lengths(self) -> _Array: ...
    @property
    def gravity(self) -> float: ...
    @property
    def damping(self) -> _Array: ...
    def __eq__(self, other: object, /) -> bool: ...
    def __reduce__(self) -> tuple[Any, tuple[Any, ...]]: ...
    def accelerations(
        self,
        q: npt.ArrayLike,
        qd: Optional[npt.ArrayLike] = None,
        torque: Optional[npt.ArrayLike] = None,
        pivot_acceleration: Optional[npt.ArrayLike] = None,
        *,
        model: str = "planar",
        precision: str = "float64",
    ) -> _Array: ...
    def integrate(
        self,
        q: npt.ArrayLike,
        qd: Optional[npt.ArrayLike] = None,
        torque: Optional[npt.ArrayLike] = None,
        pivot_acceleration: Optional[npt.ArrayLike] = None,
        *,
        h: float,
        steps: int = 1,
        model: str = "planar",
        precision: str = "float64",
        drive: Union[Harmonic, Circle, Sampled, None] = None,
        t0: float = 0.0,
        method: str = "rk4",
    ) -> tuple[_Array, _Array]: ...
    def trajectory(
        self,
        q: npt.ArrayLike,
        qd: Optional[npt.ArrayLike] = None,
        torque: Optional[npt.ArrayLike] = None,
        pivot_acceleration: Optional[npt.ArrayLike] = None,
        *,
        h: float,
        steps: int,
        every: int = 1,
        model: str = "planar",
        precision: str = "float64",
        drive: Union[Harmonic, Circle, Sampled, None] = None,
        t0: float = 0.0,
        method: str = "rk4",
    ) -> tuple[_Array, _Array, _Array]: ...
    def jacobians(
        self,
        q: npt.ArrayLike,
        qd: Optional[npt.ArrayLike] = None,
        torque: Optional[npt.ArrayLike] = None,
        pivot_acceleration: Optional[npt.ArrayLike] = None,
        *,
        model: str = "planar",
        precision: str = "float64",
    ) -> tuple[_Array, _Array, _Array]: ...
    def terms(
        self,
        q: npt.ArrayLike,
        qd: Optional[npt.ArrayLike] = None,
        torque: Optional[npt.ArrayLike] = None,
        pivot_acceleration: Optional[npt.ArrayLike] = None,
        *,
        model: str = "planar",
    ) -> dict[str, Any]: ...
    def energy(
        self, q: npt.ArrayLike, qd: Optional[npt.ArrayLike] = None, *, model: str = "planar"
    ) -> tuple[_Array, _Array]: ...
    def modes(self) -> tuple[_Array, _Array]: ...
    def linearize(
        self,
        q: npt.ArrayLike,
        qd: Optional[npt.ArrayLike] = None,
        torque: Optional[npt.ArrayLike] = None,
        pivot_acceleration: Optional[npt.ArrayLike] = None,
        *,
        model: str = "planar",
        force: bool = False,
        tolerance: float = ...,
    ) -> dict[str, Any]: ...

_PerState = Union[float, Sequence[float], npt.ArrayLike]

@final
class Harmonic:
    def __new__(
        cls,
        amplitude: _PerState,
        omega: _PerState,
        phase: Optional[_PerState] = None,
        direction: Optional[npt.ArrayLike] = None,
    ) -> Harmonic: ...
    @property
    def amplitude(self) -> Union[float, _Array]: ...
    @property
    def omega(self) -> Union[float, _Array]: ...
    @property
    def phase(self) -> Union[float, _Array]: ...
    @property
    def direction(self) -> Optional[Union[float, _Array]]: ...
    def __reduce__(self) -> tuple[Any, tuple[Any, ...]]: ...

@final
class Circle:
    def __new__(
        cls,
        radius: _PerState,
        omega: _PerState,
        ramp_time: Optional[_PerState] = None,
        ramp_from: Optional[_PerState] = None,
    ) -> Circle: ...
    @property
    def radius(self) -> Union[float, _Array]: ...
    @property
    def omega(self) -> Union[float, _Array]: ...
    @property
    def ramp_time(self) -> Optional[Union[float, _Array]]: ...
    @property
    def ramp_from(self) -> Optional[Union[float, _Array]]: ...
    def __reduce__(self) -> tuple[Any, tuple[Any, ...]]: ...

@final
class Sampled:
    def __new__(
        cls,
        times: npt.ArrayLike,
        positions: npt.ArrayLike,
        end_velocities: Optional[npt.ArrayLike] = None,
    ) -> Sampled: ...
    @property
    def times(self) -> _Array: ...
    @property
    def positions(self) -> _Array: ...
    @property
    def end_velocities(self) -> Optional[_Array]: ...
    def __reduce__(self) -> tuple[Any, tuple[Any, ...]]: ...

@final
class Run:
    def __new__(
        cls,
        *,
        dim: int = 2,
        n: Optional[int] = None,
        masses: Optional[_PerLink] = None,
        lengths: Optional[_PerLink] = None,
        gravity: float = 9.81,
        damping: Optional[_PerLink] = None,
        torque: Optional[_PerLink] = None,
        drive: str = "fixed",
        amplitude: float = 0.05,
        omega: float = 10.0,
        phase: float = 0.0,
        direction: Optional[Sequence[float]] = None,
        radius: float = 0.1,
        ramp_time: Optional[float] = None,
        ramp_from: Optional[float] = None,
        path: Union[str, PathLike[str], npt.ArrayLike, None] = None,
        path_at_rest: bool = False,
        initial: str = "tilted:1.0",
        spin: Optional[float] = None,
        integrator: Optional[str] = None,
        solver: str = "fixed-point",
        tolerance: Optional[float] = None,
        step: Optional[float] = None,
        end: float = 10.0,
        every: Optional[int] = None,
    ) -> Run: ...
    @staticmethod
    def load(path: Union[str, PathLike[str]]) -> Run: ...
    @staticmethod
    def from_json(text: str) -> Run: ...
    def to_json(self) -> str: ...
    @property
    def n(self) -> int: ...
    @property
    def step(self) -> float: ...
    @property
    def end(self) -> float: ...
    @property
    def chosen(self) -> Optional[str]: ...
    def __reduce__(self) -> tuple[Any, tuple[Any, ...]]: ...
    def run(self, out: Optional[Union[str, PathLike[str]]] = None) -> RunResult: ...

@final
class RunResult:
    @property
    def status(self) -> str: ...
    @property
    def error(self) -> Optional[str]: ...
    @property
    def t_end(self) -> float: ...
    @property
    def steps(self) -> int: ...
    @property
    def t(self) -> _Array: ...
    @property
    def states(self) -> _Array: ...
    @property
    def positions(self) -> _Array: ...
    @property
    def ledger(self) -> dict[str, _Array]: ...
    @property
    def final_state(self) -> _Array: ...
    @property
    def shape(self) -> Optional[dict[str, Any]]: ...
    @property
    def directory(self) -> Optional[Path]: ...
    @property
    def balance_residual(self) -> float: ...
    @property
    def energy_scale(self) -> float: ...
    @property
    def warnings(self) -> list[str]: ...
    def _repr_html_(self) -> Optional[str]: ...

@final
class HeavyString:
    def __new__(cls, length: float = ..., gravity: float = ..., radius: float = ...) -> HeavyString: ...
    @property
    def length(self) -> float: ...
    @property
    def gravity(self) -> float: ...
    @property
    def radius(self) -> float: ...
    def critical_speeds(self, count: int = ...) -> _Array: ...
    def shapes_at(self, omega: float) -> list[dict[str, Any]]: ...
