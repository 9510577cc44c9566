"""Type stubs of the native module (Rust, pyo3). Use the package ``deadreckon``."""

from typing import Any, Dict, List, Mapping, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

EVO_DEFAULT_MAX_DIFF_S: float

class DeadreckonError(Exception):
    """An error of deadreckon, with the command line's message (file, line, column)."""

Columns = Dict[str, npt.NDArray[np.float64]]

class Drive:
    @staticmethod
    def read(path: str, mapping: Optional[str] = None) -> Drive: ...
    @staticmethod
    def _from_columns(
        streams: Mapping[str, Columns],
        vehicle_json: Optional[str] = None,
        vehicle_path: Optional[str] = None,
    ) -> Drive: ...
    def _columns(self) -> Dict[str, Columns]: ...
    def _vehicle_json(self) -> str: ...
    def __len__(self) -> int: ...

class Update:
    """The outcome of one measurement update."""

    sensor: str
    innovation: float
    variance: float
    nis: float
    accepted: bool

class Filter:
    """The four-wheel EKF, one step at a time (``deadreckon_core::filter``)."""

    def __init__(
        self,
        vehicle: Any,
        t0_s: float,
        x0: npt.ArrayLike,
        p0: npt.ArrayLike,
        params: Optional[Mapping[str, float]] = None,
        augmented: bool = False,
        prior_std: Optional[Mapping[str, float]] = None,
    ) -> None: ...
    @staticmethod
    def from_drive(
        drive: Any,
        params: Optional[Union[str, Mapping[str, float]]] = None,
        augmented: bool = False,
        prior_std: Optional[Mapping[str, float]] = None,
    ) -> Filter: ...
    def predict_to(self, t_s: float) -> None: ...
    def update_wheel_ticks(self, i: int, ticks: float, interval_s: float) -> Optional[Update]: ...
    def update_wheel_speed(self, i: int, speed_mps: float) -> Optional[Update]: ...
    def update_gyro(self, yaw_rate_rps: float) -> Update: ...
    def update_speed(self, speed_mps: float) -> Update: ...
    def update_steering(self, steering_wheel_rad: float) -> Update: ...
    def update_gnss(self, east_m: float, north_m: float, std_m: float) -> Update: ...
    def update_course(self, course_yaw_rad: float, speed_mps: Optional[float] = None) -> Optional[Update]: ...
    @property
    def time_s(self) -> float: ...
    @property
    def state(self) -> npt.NDArray[np.float64]: ...
    @property
    def covariance(self) -> npt.NDArray[np.float64]: ...
    @property
    def params(self) -> Dict[str, float]: ...
    @property
    def params_std(self) -> Optional[Dict[str, float]]: ...
    @property
    def gates(self) -> Dict[str, Dict[str, int]]: ...

class Online:
    """The online filter of ``deadreckon stream`` (``deadreckon_core::online``)."""

    def __init__(
        self,
        vehicle: Any,
        params: Optional[Union[str, Mapping[str, float]]] = None,
        timing: str = "wheel",
        learn: bool = False,
        prior_std: Optional[Mapping[str, float]] = None,
    ) -> None: ...
    def push_lines(self, lines: List[str]) -> Columns: ...
    def finish(self) -> Columns: ...
    @property
    def is_started(self) -> bool: ...
    def learned(self) -> Optional[Dict[str, Any]]: ...
    def to_json(self) -> str: ...
    @staticmethod
    def from_json(text: str) -> Online: ...

def read_drive(path: str, mapping: Optional[str] = None) -> Drive: ...
def calibrate(
    source: Union[Drive, str],
    method: Optional[str] = None,
    state: Optional[str] = None,
    iteration: Optional[str] = None,
    max_iterations: Optional[int] = None,
    timing: Optional[str] = None,
    min_speed: Optional[float] = None,
    mapping: Optional[str] = None,
    corrections: Optional[str] = None,
    skip_checks: bool = False,
) -> Dict[str, Any]: ...
def run_tracks(
    source: Union[Drive, str],
    params: Any = None,
    timing: str = "wheel",
    init_pose: Optional[Tuple[float, float, float]] = None,
    mapping: Optional[str] = None,
    corrections: str = "auto",
) -> Dict[str, Columns]: ...
def evaluate(
    source: Union[Drive, str],
    params: Any = None,
    metric: str = "drift",
    outage: Optional[float] = None,
    step: Optional[float] = None,
    warmup: Optional[float] = None,
    segment_m: float = 100.0,
    threshold_m: float = 1.0,
    track: str = "dead-reckoned",
    reference: str = "truth",
    delta_m: float = 100.0,
    pairs_from: str = "estimate",
    max_diff_s: float = ...,
    timing: str = "wheel",
    mapping: Optional[str] = None,
    corrections: str = "auto",
    skip_checks: bool = False,
    shape: Optional[str] = None,
) -> Dict[str, Any]: ...
def tedris_train(
    source: Union[Drive, str],
    reference: str = "auto",
    variant: Optional[str] = None,
    model: str = "auto",
    config_json: Optional[str] = None,
    from_s: Optional[float] = None,
    until_s: Optional[float] = None,
    mapping: Optional[str] = None,
    skip_checks: bool = False,
    params: Optional[str] = None,
) -> Tuple[str, Dict[str, Any]]: ...
def tedris_run(
    source: Union[Drive, str],
    model_json: str,
    outages: List[Tuple[float, float]],
    reference: str = "auto",
    threshold_m: float = 1.0,
    mapping: Optional[str] = None,
    skip_checks: bool = False,
    params: Optional[str] = None,
) -> Dict[str, Any]: ...
