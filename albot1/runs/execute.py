"""Run one method on one sequence with the measurements every result carries.

Per-scan time is ``perf_counter_ns`` around ``Mapper.process`` only (decoding
and degradation happen outside it); ``finish`` is timed separately and added
to ``total_s``. A method's start-up before the first scan (``Mapper.warm_up``,
e.g. numba compiling or loading its kernels) is ``startup_s``, outside the
per-scan times and ``total_s`` and inside ``wall_s``, so the per-scan
statistics describe the steady state. ``peak_mb`` is the process's resident-set high-water mark
(its own ``VmHWM``, not the ``ru_maxrss`` it inherits across ``exec``) at the end of the run: the
benchmark runs each cell in a fresh process, so there it is the cell's peak. ``cpu_s`` is the CPU time of the
same span as ``wall_s`` (:func:`cpu_time_s`).
"""

from __future__ import annotations

import logging
import numbers
import resource
import sys
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from albot1 import versions
from albot1.contract import MapData, MapperOutput, RunResult
from albot1.data.degrade import degrade
from albot1.data.model import MAX_COORDINATE_M, Frame, Scan, Sequence
from albot1.data.transforms import robot_frame, sensor_frame
from albot1.errors import Albot1Error
from albot1.geometry.types import FloatArray
from albot1.methods.registry import MethodRegistry, get_method, resolve_config
from albot1.processes import high_water_mb
from albot1.runs.errors import RunError

log = logging.getLogger(__name__)


def peak_rss_mb() -> float:
    """Resident-set high-water mark of this process, MiB: its own ``VmHWM``, ``ru_maxrss`` where there is none.

    ``ru_maxrss`` alone is at least the peak of the process that started this one (the kernel keeps it across
    ``exec``): a cell run as ``python -m albot1.bench.cell_main`` by a 400 MB process recorded 400 MB whatever its
    method used (:func:`albot1.processes.high_water_mb`).
    """
    own = high_water_mb()
    if own is not None:
        return own
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return peak / (1024.0 * 1024.0) if sys.platform == "darwin" else peak / 1024.0


def cpu_time_s() -> float:
    """CPU seconds (user + system) of this process's threads and of the children it has waited for.

    A wall-clock time on a shared machine says as much about the other jobs as
    about the method; the CPU time is the method's own cost (an external
    program such as MRPT's counts once it has been waited for).
    """
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    return time.process_time() + children.ru_utime + children.ru_stime


def run_method(
    method: str,
    sequence: Sequence,
    *,
    preset: str = "default",
    overrides: dict[str, Any] | None = None,
    degradation: str = "none",
    seed: int = 0,
    dataset_name: str | None = None,
    on_frame: Callable[[int], None] | None = None,
    announce: Callable[[str], None] | None = None,
    registry: MethodRegistry | None = None,
) -> RunResult:
    """Degrade (seeded), run and check one method; raises the method's error class on failure.

    A mapper with a ``warm_up`` method (``Mapper.warm_up``) gets it called
    before the timed loop, with ``announce`` for what it has to say (e.g.
    that it compiles); its time is the run's ``startup_s``. ``registry``: where
    ``method`` is looked up (default: this process's :func:`method_registry`).
    """
    spec = get_method(method, registry)
    config = resolve_config(method, preset, overrides, registry)
    error_class = spec.load_error_class()
    dataset = dataset_name or sequence.name
    seq = degrade(sequence, degradation, seed=seed)
    # Methods see the laser's trajectory (mounting offset applied once, here, for every method); their poses and
    # the recorded odometry/reference are mapped back to the robot below (albot1.data.transforms.sensor_frame).
    offset = seq.metadata.sensor_offset
    seen = sensor_frame(seq)
    mapper_class = spec.load_class()
    # where the method was, for the message of its failure; None while the runner reads the next scan or reports
    # progress: a failure there (a loader's OSError) is not the method's and leaves as raised
    where: str | None = "while starting"
    try:
        mapper = mapper_class(config, seed=seed)
        # The versions of the libraries the mapper has imported by now are kept from here on (the record below
        # names what ran, not what another install put in place during the run: albot1.versions.library_versions);
        # read before the run's clock starts, so the metadata search is not in its timings.
        versions.library_versions()

        wall_start, cpu_start = time.perf_counter(), cpu_time_s()
        warm_up = getattr(mapper, "warm_up", None)
        if callable(warm_up):
            warm_up(announce)
        startup_s = time.perf_counter() - wall_start
        where = None
        per_scan: list[int] = []
        blind_scans = 0
        stamps: list[float] = []
        odometry: list[np.ndarray] = []
        reference: list[np.ndarray] | None = []
        for frame in seen.frames():
            # What the runner keeps of the frame is read before the method sees it, and the method is handed
            # arrays of its own: a method that writes into its input alters neither the run's record (odometry,
            # the blind-scan count) nor the sequence's frames (an in-memory sequence, the degraded odometry chain).
            stamps.append(frame.scan.timestamp)
            odometry.append(np.array(frame.odometry, dtype=float))
            if not frame.scan.valid().any():
                blind_scans += 1
            if reference is not None:
                # A reference counts only when every frame has one.
                if frame.reference is None:
                    reference = None
                else:
                    reference.append(frame.reference)
            blind = withhold_ground_truth(frame)
            where = f"at scan {frame.index}"
            start = time.perf_counter_ns()
            mapper.process(blind)
            per_scan.append(time.perf_counter_ns() - start)
            where = None
            if on_frame is not None:
                on_frame(frame.index)
        where = "in finish"
        finish_start = time.perf_counter()
        output = mapper.finish()
        finish_s = time.perf_counter() - finish_start
    except Albot1Error as exc:
        if type(exc) is not error_class:
            raise
        # A mapper never sees the dataset's name: add it ("kiss-icp diverged ..." -> "kiss-icp on intel diverged ...").
        text = str(exc)
        rest = text[len(method) :] if text.startswith(method) else f": {text}"
        raise error_class(f"{method} on {dataset}{rest}") from exc
    except Exception as exc:  # a library failed deep inside: name method, dataset and scan
        if where is None:
            raise
        raise error_class(f"{method} on {dataset} failed {where}: {type(exc).__name__}: {exc}") from exc
    except KeyboardInterrupt:
        raise  # Ctrl-C: the command stops (a bench cell records it as interrupted)
    except BaseException as exc:  # sys.exit() or a bare BaseException: a method may not end the run
        if where is None:
            raise
        raise error_class(
            f"{method} on {dataset} failed {where}: it raised {_exit_text(exc)}; expected it to return, or to "
            "raise an exception for a failure (a method may not end the process)"
        ) from exc

    output = _check_output(output, len(per_scan), method, dataset, error_class)
    note = blind_note(blind_scans, len(per_scan), method, dataset)
    if note is not None:
        log.warning(note)
    per_scan_ns = np.asarray(per_scan, dtype=np.int64)
    poses = robot_frame(np.asarray(output.poses, dtype=float), offset)
    reference_poses = robot_frame(np.asarray(reference, dtype=float).reshape(-1, 3), offset) if reference else None
    # A method's own claims (e.g. re-visits in places.json) are scored against the reference poses, which the
    # mapper never saw, when the run is evaluated (the `places` metric, albot1.metrics.measures.places).
    counters, files = dict(output.counters), dict(output.files)
    return RunResult(
        method=method,
        dataset=dataset,
        preset=preset,
        degradation=degradation,
        seed=seed,
        config=config.model_dump(mode="json"),
        timestamps=np.asarray(stamps, dtype=float),
        poses=poses,
        odometry=robot_frame(np.asarray(odometry, dtype=float).reshape(-1, 3), offset),
        reference=reference_poses,
        relations=seq.relations,
        map=output.map,
        counters=counters,
        extras=dict(output.extras),
        files=files,
        per_scan_ns=per_scan_ns,
        finish_s=finish_s,
        startup_s=startup_s,
        per_scan_reason=batch_reason(method) if spec.batch else None,
        total_s=float(per_scan_ns.sum()) / 1e9 + finish_s,
        wall_s=time.perf_counter() - wall_start,
        cpu_s=cpu_time_s() - cpu_start,
        peak_mb=peak_rss_mb(),
        # a plugin's own code is not in the code version (this package's digest): its distribution and version
        versions=versions.run_versions(programs=output.versions, plugin=spec.plugin),
        dataset_info={
            "source": seq.metadata.source,
            "format": seq.metadata.format,
            "odometry_source": seq.metadata.odometry_source,
            "reference_source": seq.metadata.reference_source,
            "sensor_offset": [float(v) for v in offset],
            "data_sha256": dict(seq.metadata.checksums),
            "manifest_loader": dict(seq.metadata.manifest_loader),
        },
    )


def batch_reason(method: str) -> str:
    """Why a batch method's per-scan statistics are not applicable (``MethodSpec.batch``).

    Its ``process`` only keeps the frame and its work runs in ``finish``, so the
    per-scan times are microseconds of bookkeeping: shown as a cost they made
    MRPT's ``icp-slam`` the fastest method of the cost table (0.002 ms per scan)
    while it took longer than KISS-ICP over the whole log.
    """
    return (
        f"{method} does its work in finish() (a batch program given the whole log): its per-scan times are the "
        "bookkeeping of process(), not its cost (see total)"
    )


def blind_note(blind: int, scans: int, method: str, dataset: str) -> str | None:
    """The warning for a run where at least half the scans had no return (None below that).

    A scan whose every range is NaN (beyond the scanner's range, ``+inf`` or
    ``-inf`` under REP 117, NaN) gives a method nothing to match, so it can
    only follow the odometry there; the run still succeeds, which without
    this line would read as a scan matcher that agreed with the odometry (a
    driver's ``range_max`` set below every reading does exactly that).
    """
    if scans == 0 or 2 * blind < scans:
        return None
    which = (
        f"none of the {scans} scans had a return" if blind == scans else f"{blind} of the {scans} scans had no return"
    )
    return (
        f"{method} on {dataset}: {which} (every range NaN, infinite or outside the scanner's limits); "
        f"in those the method had only the odometry to go by"
    )


def withhold_ground_truth(frame: Frame) -> Frame:
    """What a method is given of ``frame``: the scan and the odometry, never the reference pose.

    The one place where ground truth is kept from the methods (relations
    never reach them: a mapper is given frames only). The runner keeps the
    reference for evaluation and for the method's judge (``MethodSpec.judge``),
    which run after the mapper has finished.

    The arrays are the method's own: a writeable one is a copy, so a method
    that writes into its input (a plugin clipping ranges in place) cannot
    alter the runner's frame or the sequence the frame came from; a read-only
    one (the beam angles a loader shares between scans) cannot be written and
    is handed as it is (a copy would cost per scan and change its type for
    numba's kernels).
    """
    scan = frame.scan
    own = Scan(_own(scan.ranges), _own(scan.angles), scan.timestamp, scan.max_range)
    return Frame(frame.index, own, _own(frame.odometry))


def _own(array: FloatArray) -> FloatArray:
    """``array`` itself when it is read-only, else a copy."""
    return array.copy() if array.flags.writeable else array


def _exit_text(exc: BaseException) -> str:
    """How a BaseException that is not an Exception reads in a method's failure (``sys.exit(0)`` -> SystemExit(0))."""
    if isinstance(exc, SystemExit):
        return f"SystemExit({exc.code!r}) (sys.exit)"
    return f"{type(exc).__name__}: {exc}" if str(exc) else type(exc).__name__


def map_problem(data: MapData) -> str | None:
    """Why a method's map cannot be kept (rows of another shape, not real numbers, non-finite or absurd), or None.

    The run boundary's own check: whatever a method did with its inputs, no
    run ends with a map that a report or a metric cannot draw or measure.
    Points of three columns were stored as ``(-1, 2)`` rows (three points made
    of two), complex ones lost their imaginary part, flat or text arrays
    ended the run in a numpy traceback.
    """
    for name, array, form in (
        ("segment", data.segments, "(M, 4) rows (x1, y1, x2, y2)"),
        ("point", data.points, "(K, 2) rows (x, y)"),
    ):
        if array is None or not len(array):
            continue
        try:
            given = np.asarray(array)
        except (TypeError, ValueError):  # ragged rows
            return f"the map's {name}s do not form an array (rows of unequal length?); expected {form} of real numbers"
        if given.dtype.kind not in "iuf":
            return f"the map's {name}s are of dtype {given.dtype}; expected {form} of real numbers"
        if given.ndim != 2 or given.shape[1] != (4 if name == "segment" else 2):
            return f"the map's {name}s are of shape {given.shape}; expected {form} of real numbers"
        values = given.astype(float)
        bad = np.flatnonzero(~(np.isfinite(values).all(axis=1) & (np.abs(values).max(axis=1) <= MAX_COORDINATE_M)))
        if len(bad):
            return (
                f"the map has {len(bad)} {name}(s) with non-finite or absurd coordinates (first: {name} {bad[0]}, "
                f"{values[bad[0]].tolist()}); expected finite metres within {MAX_COORDINATE_M:g} m"
            )
    return _properties_problem(data)


def _properties_problem(data: MapData) -> str | None:
    """Why ``segment_properties`` do not go with the segments, or None (map.geojson pairs them one to one)."""
    props = data.segment_properties
    if props is None:
        return None
    expected = "expected one dict per segment (or none)"
    if not isinstance(props, list):
        return f"the map's segment properties are a {type(props).__name__}; {expected}"
    odd = next((i for i, p in enumerate(props) if not isinstance(p, dict)), None)
    if odd is not None:
        return f"the map's segment property {odd} is a {type(props[odd]).__name__}; {expected}"
    count = 0 if data.segments is None else len(data.segments)
    if len(props) != count:
        return f"the map has {len(props)} segment properties for {count} segments; {expected}"
    return None


def _check_output(output: object, n: int, method: str, dataset: str, error_class: type[Exception]) -> MapperOutput:
    """``output`` when it is what :meth:`Mapper.finish` must return, else the method's error (one line).

    The run boundary checks whatever a method hands back (a third-party
    plugin's included): a pose that a metric could not score (non-finite,
    beyond :data:`MAX_COORDINATE_M`, complex or text) fails the run here, naming
    the method and the scan, rather than later in an evaluation or never.
    """
    run = f"{method} on {dataset}"
    if not isinstance(output, MapperOutput):
        raise error_class(
            f"{run}: finish() returned {type(output).__name__}; expected a MapperOutput (albot1.contract)"
        )
    expected = f"expected {n} poses (one per scan) of (x, y, theta) as real numbers"
    try:
        poses = np.asarray(output.poses)
    except (TypeError, ValueError):  # ragged rows
        raise error_class(f"{run}: the poses do not form an array (rows of unequal length?); {expected}") from None
    if poses.dtype.kind not in "iuf":
        raise error_class(f"{run}: the poses are of dtype {poses.dtype}; {expected}")
    if poses.shape != (n, 3):
        raise error_class(f"{run}: {expected}, got shape {poses.shape}")
    poses = poses.astype(float)
    bad = np.flatnonzero(~np.isfinite(poses).all(axis=1))
    if len(bad):
        raise error_class(f"{run}: {len(bad)} non-finite poses, first at scan {bad[0]} (diverged)")
    far = np.flatnonzero(np.abs(poses[:, :2]).max(axis=1) > MAX_COORDINATE_M)
    if len(far):
        raise error_class(
            f"{run}: {len(far)} poses beyond {MAX_COORDINATE_M:g} m, first at scan {far[0]} "
            f"({poses[far[0]].tolist()}); expected positions of a map in metres (diverged)"
        )
    if not isinstance(output.map, MapData):
        raise error_class(f"{run}: the map is {type(output.map).__name__}; expected a MapData (albot1.contract)")
    problem = map_problem(output.map)
    if problem is not None:
        raise error_class(f"{run}: {problem}")
    for name in ("counters", "extras", "files", "versions"):
        if not isinstance(getattr(output, name), dict):
            raise error_class(f"{run}: {name} is {type(getattr(output, name)).__name__}; expected a dict")
    problem = versions.program_versions_problem(output.versions)
    if problem is not None:
        raise error_class(f"{run}: MapperOutput.versions: {problem}")
    for key in ("views", "updates"):
        if key not in output.counters:
            raise RunError(f"{run}: counters lack the required key {key!r}")
    for key, value in output.counters.items():
        if isinstance(value, bool) or not isinstance(value, numbers.Real) or not np.isfinite(float(value)):
            raise error_class(f"{run}: counter {key!r} is {value!r}; expected a finite number")
    return output
