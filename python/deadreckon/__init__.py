"""deadreckon: dead reckoning for cars and wheeled robots through GNSS outages.

The Rust crates of https://github.com/ (this repository) from Python: read a
drive from any source the ``deadreckon`` command line reads, or build one from
pandas DataFrames; calibrate the six parameters (gyro bias, speed scale, four
wheel circumferences); run the filter, smoother and dead reckoning; evaluate;
TedriS; the four-wheel filter one step at a time (:class:`Filter`) and the
online filter of ``deadreckon stream`` on JSON-line events (:class:`Online`). Arrays cross as numpy
arrays. The dicts returned by :func:`calibrate` and :func:`evaluate` have
exactly the keys and numbers of ``deadreckon calibrate --json`` and
``deadreckon evaluate --json`` (the same Rust code builds them).

Errors are :class:`DeadreckonError` with the command line's message (file,
line, column).

>>> import deadreckon
>>> r = deadreckon.calibrate("../shared/data/comma2k19-rav4")   # doctest: +SKIP
>>> r["speed_scale"], r["std"]["speed_scale"]                   # doctest: +SKIP

:mod:`deadreckon.fleet` maps calibrations over a Dask cluster.
"""

from __future__ import annotations

import json
import os
from typing import Any, Dict, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import pandas as pd

from . import _native
from ._native import DeadreckonError, Filter, Online, Update

__all__ = [
    "DeadreckonError",
    "Drive",
    "Filter",
    "Online",
    "TedrisModel",
    "Update",
    "calibrate",
    "evaluate",
    "read_drive",
    "run",
    "tedris_run",
    "tedris_train",
]

PathLike = Union[str, "os.PathLike[str]"]

#: The streams of a drive, named like the drive directory's files (docs/drive-format.md).
STREAMS = ("wheel_ticks", "wheel_speeds", "yaw_rate", "speed", "steering", "gnss", "truth")


class Drive:
    """A drive in memory: vehicle, wheels, gyro, CAN speed, steering, GNSS, truth.

    Read one with :func:`read_drive` (any source the command line reads) or
    build one from DataFrames with :meth:`from_frames`.
    """

    __slots__ = ("_native",)

    def __init__(self, native: "_native.Drive") -> None:
        self._native = native

    @classmethod
    def read(cls, path: PathLike, mapping: Optional[PathLike] = None) -> "Drive":
        """Reads a drive directory, comma2k19 segment, ROS bag, MCAP or tricycle log."""
        return cls(_native.read_drive(os.fspath(path), None if mapping is None else os.fspath(mapping)))

    @classmethod
    def from_frames(
        cls,
        vehicle: Union[Mapping[str, Any], PathLike],
        wheel_ticks: Optional[pd.DataFrame] = None,
        wheel_speeds: Optional[pd.DataFrame] = None,
        yaw_rate: Optional[pd.DataFrame] = None,
        speed: Optional[pd.DataFrame] = None,
        steering: Optional[pd.DataFrame] = None,
        gnss: Optional[pd.DataFrame] = None,
        truth: Optional[pd.DataFrame] = None,
    ) -> "Drive":
        """Builds a drive from DataFrames with the drive format's column names.

        ``vehicle`` is a dict of ``vehicle.toml``'s keys (``noise`` and
        ``origin`` as nested dicts) or the path of a ``vehicle.toml``. Each
        frame has the columns of its CSV file in docs/drive-format.md:
        ``wheel_ticks`` (``t_s, fl, fr, rl, rr``) or ``wheel_speeds``
        (``t_s, fl_mps, ...``), ``yaw_rate`` (``t_s, yaw_rate_rps``),
        ``speed`` (``t_s, speed_mps``), ``steering``
        (``t_s, steering_wheel_rad``), ``gnss`` (``t_s``, ``east_m, north_m``
        or ``lat_deg, lon_deg``, ``std_m``, optional ``course_deg``,
        ``speed_mps``), ``truth`` (``t_s``, positions, ``yaw_rad``, optional
        ``speed_mps``). Extra columns are ignored; NaN in an optional column
        means absent. The drive is checked as every drive is
        (``Drive::validate``: at least two wheel rows, strictly increasing
        times, finite values, ``std_m`` > 0, integer tick counts); the CSV
        readers' plausibility ranges of each unit (such as |speed| <= 100 m/s)
        are not applied.
        """
        frames = dict(
            wheel_ticks=wheel_ticks,
            wheel_speeds=wheel_speeds,
            yaw_rate=yaw_rate,
            speed=speed,
            steering=steering,
            gnss=gnss,
            truth=truth,
        )
        streams = {name: _frame_columns(name, f) for name, f in frames.items() if f is not None}
        if isinstance(vehicle, Mapping):
            native = _native.Drive._from_columns(streams, vehicle_json=json.dumps(dict(vehicle)))
        else:
            native = _native.Drive._from_columns(streams, vehicle_path=os.fspath(vehicle))
        return cls(native)

    def to_frames(self) -> Dict[str, pd.DataFrame]:
        """The drive's streams as DataFrames keyed like :meth:`from_frames`'s arguments."""
        out: Dict[str, pd.DataFrame] = {}
        for name, cols in self._native._columns().items():
            df = pd.DataFrame(cols)
            if name == "wheel_ticks":
                df = df.astype({c: "int64" for c in ("fl", "fr", "rl", "rr")})
            out[name] = df
        return out

    @property
    def vehicle(self) -> Dict[str, Any]:
        """The vehicle: ``vehicle.toml``'s keys as a dict."""
        return json.loads(self._native._vehicle_json())

    def __len__(self) -> int:
        return len(self._native)

    def __repr__(self) -> str:
        return repr(self._native)


def _frame_columns(name: str, frame: pd.DataFrame) -> Dict[str, np.ndarray]:
    if not isinstance(frame, pd.DataFrame):
        raise TypeError(f"{name}: expected a pandas DataFrame, got {type(frame).__name__}")
    cols: Dict[str, np.ndarray] = {}
    for c in frame.columns:
        try:
            cols[str(c)] = np.ascontiguousarray(frame[c].to_numpy(dtype=np.float64, na_value=np.nan))
        except (TypeError, ValueError):
            # Extra non-numeric columns are ignored, as in the CSV files; a
            # required one is reported missing by the reader.
            continue
    return cols


DriveLike = Union[Drive, PathLike]


def _source(d: DriveLike) -> Any:
    return d._native if isinstance(d, Drive) else os.fspath(d)


def _opt_path(p: Optional[PathLike]) -> Optional[str]:
    return None if p is None else os.fspath(p)


def read_drive(path: PathLike, mapping: Optional[PathLike] = None) -> Drive:
    """Reads a drive from any source the command line reads.

    A drive directory (CSV files + ``vehicle.toml``), a comma2k19 segment
    directory, a ROS1 ``.bag`` or ROS2 ``.mcap`` (``mapping``: a topic-mapping
    TOML file; default the built-in Husky, or Jackal when the file name says
    so) or a tricycle ``dataset.txt``.
    """
    return Drive.read(path, mapping)


def calibrate(
    drive: DriveLike,
    method: Optional[str] = None,
    *,
    state: Optional[str] = None,
    iteration: Optional[str] = None,
    max_iterations: Optional[int] = None,
    timing: Optional[str] = None,
    min_speed: Optional[float] = None,
    mapping: Optional[PathLike] = None,
    corrections: Optional[str] = None,
    skip_checks: bool = False,
) -> Dict[str, Any]:
    """Calibrates the six parameters; returns ``deadreckon calibrate --json``'s object.

    ``method``: ``rts`` (smoothed states, needs GNSS), ``zupt`` (standstill
    gyro bias) or ``truth``. The options are ``calibrate``'s, and an option
    not given (``None``) takes the command's default, held once in the
    library (``CalibrationRequest::default``): ``state`` (``augmented`` or
    ``paper``), ``iteration`` (``anderson`` or ``plain``),
    ``max_iterations``, ``timing`` (``wheel`` or ``each``), ``min_speed``
    (m/s), ``corrections`` (``auto``: each correction applied only when it
    lowers the held-back GNSS error; ``gnss``: estimate the streams' delays, the
    driven axle's slip, the IMU tilt and the gyro scale, apply the slip, the
    tilt, the GNSS delay and the scale;
    ``all``: apply every delay too; ``none``). Keys: the six parameters,
    ``std``, ``iterations``, ``converged``, ``corrections``,
    ``method``, ``samples``, ``history``, ``checks`` and, when the filter
    ran, ``gnss``, ``wheel_gaps``, ``gates``. The computation runs without
    the GIL.

    The drive is first checked across its streams, as the command does (units,
    clocks, signs: see docs/checks.md): a drive that
    cannot be right raises :class:`DeadreckonError` saying what disagrees; the
    warnings are under ``checks``. ``skip_checks=True`` skips the checks.
    """
    return _native.calibrate(
        _source(drive),
        method,
        state,
        iteration,
        max_iterations,
        timing,
        min_speed,
        _opt_path(mapping),
        corrections,
        skip_checks,
    )


Params = Union[str, PathLike, Mapping[str, float]]


def _params(p: Optional[Params]) -> Any:
    if p is None or isinstance(p, Mapping):
        return p
    return os.fspath(p)


def run(
    drive: DriveLike,
    params: Optional[Params] = None,
    *,
    timing: str = "wheel",
    init_pose: Optional[Tuple[float, float, float]] = None,
    mapping: Optional[PathLike] = None,
    corrections: str = "auto",
) -> Dict[str, pd.DataFrame]:
    """The drive's tracks as DataFrames: ``dead-reckoned``, and with GNSS
    ``filtered`` and ``smoothed``, and with truth ``truth``.

    ``params``: ``"nominal"``, a ``params.toml`` path (bound to its vehicle:
    another vehicle's file is refused, and the corrections it stores are
    applied), or a dict with the six parameters (such as :func:`calibrate`'s
    result). Without it the drive is calibrated on itself first (RTS after
    the ``corrections`` of :func:`calibrate`), as ``deadreckon run`` does. Columns: those of
    ``deadreckon run --out track.csv`` but ``track``: ``t_s, east_m, north_m,
    yaw_rad, speed_mps, yaw_rate_rps, std_east_m, std_north_m, std_yaw_rad,
    cov_en_m2, bound_95_m`` (the 95 % error bound of the dead-reckoned and
    filtered positions, NaN elsewhere: docs/bound.md). ``init_pose``: (east_m, north_m, yaw_rad) of the dead
    reckoning's start (default the truth, else the smoothed GNSS track).
    """
    tracks = _native.run_tracks(
        _source(drive), _params(params), timing, init_pose, _opt_path(mapping), corrections
    )
    return {name: pd.DataFrame(cols) for name, cols in tracks.items()}


def evaluate(
    drive: DriveLike,
    params: Optional[Params] = None,
    metric: str = "drift",
    *,
    outage: Optional[float] = None,
    step: Optional[float] = None,
    warmup: Optional[float] = None,
    segment_m: float = 100.0,
    threshold_m: float = 1.0,
    track: str = "dead-reckoned",
    reference: str = "truth",
    delta_m: float = 100.0,
    pairs_from: str = "estimate",
    max_diff_s: float = _native.EVO_DEFAULT_MAX_DIFF_S,
    timing: str = "wheel",
    mapping: Optional[PathLike] = None,
    corrections: str = "auto",
    skip_checks: bool = False,
    shape: Optional[str] = None,
) -> Dict[str, Any]:
    """Dead-reckoning accuracy; returns ``deadreckon evaluate --json``'s object.

    ``shape``: ``car``, ``diff-drive`` or ``tricycle``; by default found from
    the data as the command finds it (a tricycle or a differential drive is
    evaluated over sliding ``outage`` windows through its own kinematics,
    ``shape_found`` saying which and why). ``params_source`` says which
    parameters were applied.

    ``metric``: ``drift`` (per ``segment_m``), ``reset-1m`` (at
    ``threshold_m``), ``rpe`` (evo's relative pose error per ``delta_m`` of
    path) or ``ape``. With ``outage`` (s), sliding GNSS outages every
    ``step`` s (default half the outage) after ``warmup`` s (default the
    command's, 5) instead. Without
    ``params``, for every metric, the drive is calibrated with RTS first, as
    the command does (in-sample), with the ``corrections`` of
    :func:`calibrate`, or the nominal parameters are taken when it has no
    GNSS fix; the result's ``params`` says which. ``params`` as in
    :func:`run`; a ``params.toml`` path applies the corrections it stores, a
    dict carries the six parameters only. The drive
    is checked across its streams first, as by :func:`calibrate`
    (``skip_checks``); the warnings are under ``checks``.
    """
    return _native.evaluate(
        _source(drive),
        _params(params),
        metric,
        outage,
        step,
        warmup,
        segment_m,
        threshold_m,
        track,
        reference,
        delta_m,
        pairs_from,
        max_diff_s,
        timing,
        _opt_path(mapping),
        corrections,
        skip_checks,
        shape,
    )


class TedrisModel:
    """A trained TedriS model: its JSON (what ``tedris train --out`` writes)
    and the summary ``tedris train --json`` prints."""

    __slots__ = ("json", "summary")

    def __init__(self, json_text: str, summary: Optional[Dict[str, Any]] = None) -> None:
        self.json = json_text
        self.summary = summary if summary is not None else {}

    def save(self, path: PathLike) -> None:
        """Writes the model file (readable by ``deadreckon tedris run --model``)."""
        with open(path, "w", encoding="utf-8") as f:
            f.write(self.json)

    @classmethod
    def load(cls, path: PathLike) -> "TedrisModel":
        """Reads a model file written by ``deadreckon tedris train --out``."""
        with open(path, encoding="utf-8") as f:
            return cls(f.read())

    def __repr__(self) -> str:
        return f"<deadreckon.TedrisModel {self.summary.get('chosen', '?')}>"


def tedris_train(
    drive: DriveLike,
    *,
    reference: str = "auto",
    variant: Optional[str] = None,
    model: str = "auto",
    config: Optional[Mapping[str, Any]] = None,
    from_s: Optional[float] = None,
    until_s: Optional[float] = None,
    mapping: Optional[PathLike] = None,
    skip_checks: bool = False,
    params: Optional[PathLike] = None,
) -> TedrisModel:
    """Trains TedriS on a drive (``deadreckon tedris train``).

    ``reference``: ``auto``, ``course``, ``track`` or ``gyro``; ``variant``:
    ``paper`` or ``extended``; ``model``: ``auto``, ``paper``, ``distance``,
    ``arx``, ``baseline``, ``speed``; ``config``: TedriS settings (docs/tedris.md);
    ``from_s``/``until_s``: train on that part of the drive only. The drive
    is checked across its streams first, as by :func:`calibrate`
    (``skip_checks``); the summary's ``checks`` holds the warnings.
    ``params``: a params.toml whose stored corrections (delays, IMU tilt,
    gyro scale) are applied to the drive first; the model keeps them
    (``corrections``) and :func:`tedris_run` applies them too. The
    summary's calibrated values (``dcf_rad``, ``dcf_distance_rad_per_m``,
    ``turn_gain``) come with their standard errors (``dcf_std_rad``,
    ``dcf_distance_std_rad_per_m``, ``turn_gain_std``; ``None``: not
    estimated), as in ``tedris train --json``.
    """
    text, summary = _native.tedris_train(
        _source(drive),
        reference,
        variant,
        model,
        None if config is None else json.dumps(dict(config)),
        from_s,
        until_s,
        _opt_path(mapping),
        skip_checks,
        _opt_path(params),
    )
    return TedrisModel(text, summary)


def tedris_run(
    drive: DriveLike,
    model: TedrisModel,
    outages: Sequence[Tuple[float, float]],
    *,
    reference: str = "auto",
    threshold_m: float = 1.0,
    mapping: Optional[PathLike] = None,
    skip_checks: bool = False,
    params: Optional[PathLike] = None,
) -> Dict[str, Any]:
    """Runs TedriS with GNSS blanked in ``outages`` ((start_s, end_s), drive
    clock); returns ``tedris run --json``'s object (``outages``,
    ``reference``, ``source``, ``model``, ``calibrated``: the values the
    machine holds at the end with their standard errors, ``corrections``,
    ``tedris_checks``, ``checks``) with ``track``: the predicted track as a
    DataFrame (instead of the CSV's path). The drive gets the corrections
    stored in ``params`` (a params.toml), or else those the model was
    trained with."""
    r = _native.tedris_run(
        _source(drive),
        model.json,
        [tuple(o) for o in outages],
        reference,
        threshold_m,
        _opt_path(mapping),
        skip_checks,
        _opt_path(params),
    )
    r["track"] = pd.DataFrame(r["track"])
    return r
