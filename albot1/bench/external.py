"""Cells of a suite's external methods: another system's trajectory files, scored beside the methods run.

A method entry with ``trajectories = "runs/carto/{dataset}.tum"`` names one
file per dataset (relative to the suite file; ``{dataset}`` is the dataset's
name, or a path's file name without its suffixes). Such a cell runs
nothing: :func:`albot1.runs.external_run.write_external_run` scores the file
through the external-trajectory path (:mod:`albot1.runs.external`) and
stores it as a run folder, so every table, plot and page shows it beside
the methods run. It exists only for the dataset's own odometry (degradation
``none``, the first seed): the file is what the other system made of the
log, not of our degraded copies. The file's sha256 is part of the cell's
key, so an edited file is scored again, and a dataset without its file is
an error of the suite naming the path it expected (restrict the entry with
``datasets = [...]``). Two datasets of different logs whose ``{dataset}`` is one
file (``d1/run.clf`` and ``d2/run.clf`` both give ``run``) are an error of the
suite too (:func:`one_log_per_file`): the one file would be scored against
both logs.

The rest of its key is what the scoring reads and computes with: the
dataset's files and manifest loader options (its reference poses and
relations), and the versions block of any run
(:func:`albot1.versions.run_versions`: the code and the recorded libraries,
which read the log and compute the metrics). It runs no method, so no
program's or plugin's version is in it.
"""

from __future__ import annotations

import re
from pathlib import Path

from albot1 import versions
from albot1.bench.errors import SuiteError
from albot1.bench.grid import Cell
from albot1.bench.suite import DatasetOptions, MethodEntry, Suite
from albot1.data.fetch import sha256_of
from albot1.data.model import SequenceMetadata
from albot1.runs.external_run import external_config
from albot1.runs.folder import run_key

#: Loader options (``?key=value``) and a trailing slice (``[:N]``) are not part of a dataset's file name.
_OPTIONS_OR_SLICE = re.compile(r"(\?.*|\[[^\[\]]*\])+$")


def dataset_stem(name: str) -> str:
    """What ``{dataset}`` stands for: ``aces`` for ``aces[:500]``, ``run`` for ``bags/run.mcap`` or ``run.clf.gz``."""
    plain = _OPTIONS_OR_SLICE.sub("", name)
    if "/" in plain or "\\" in plain or Path(plain).suffix in {".bag", ".mcap", ".db3", ".clf", ".log", ".gz", ".bz2"}:
        return Path(plain).name.split(".")[0]
    return plain


def trajectory_path(suite: Suite, entry: MethodEntry, dataset: str) -> Path:
    """The entry's file for ``dataset`` (relative paths from the suite file's folder)."""
    assert entry.trajectories is not None
    path = Path(entry.trajectories.replace("{dataset}", dataset_stem(dataset))).expanduser()
    if not path.is_absolute() and suite.path is not None:
        path = suite.path.parent / path
    return path


def one_log_per_file(
    suite: Suite, entry: MethodEntry, cell: Cell, metadata: SequenceMetadata, seen: dict[str, tuple[str, str]]
) -> None:
    """SuiteError when ``cell``'s file was already given to a dataset read from another log.

    ``seen`` maps each external cell's file to (its dataset, the log it was read from) and is filled here.
    Slices and loader options of one log (``aces[:500]``, ``robot.mcap?reference=gt.tum``) share its file, as
    ``{dataset}`` says; two logs of one file name in two folders used to share it too, and the file made on
    one was scored against the other without a word (where their times overlapped).
    """
    assert cell.trajectory is not None
    log = str(Path(metadata.source).resolve()) if metadata.source else dataset_stem(cell.dataset)
    first = seen.setdefault(cell.trajectory, (cell.dataset, log))
    if first[1] != log:
        raise SuiteError(
            f"{suite.path or suite.name}: method {cell.method_label!r}: datasets {first[0]!r} and {cell.dataset!r} "
            f"are two logs ({first[1]}, {log}) but trajectories = {entry.trajectories!r} gives both "
            f"the file {cell.trajectory}; expected one file per log: rename one log, or restrict the entry with "
            f"datasets = [...]"
        )


def external_cell(
    suite: Suite, entry: MethodEntry, dataset: str, opts: DatasetOptions, seed: int, metadata: SequenceMetadata
) -> Cell:
    """The one cell scoring ``entry``'s file for ``dataset``; SuiteError when the file is missing.

    ``metadata``: the dataset's, whose checksums and loader options go into the key (the run records them).
    """
    path = trajectory_path(suite, entry, dataset)
    if not path.is_file():
        raise SuiteError(
            f"{suite.path or suite.name}: method {entry.display!r}: no trajectory file for dataset {dataset!r}: "
            f"expected {path} (trajectories = {entry.trajectories!r}); give the file or restrict the entry with "
            f"datasets = [...]"
        )
    config = external_config(path, entry.trajectory_format, sha256_of(path))
    planned = versions.run_versions()  # what albot1.runs.external_run records
    key = run_key(opts.label, entry.name, config, "none", seed, planned, metadata.checksums, metadata.manifest_loader)
    return Cell(
        suite=suite.name,
        dataset=dataset,
        dataset_label=opts.label,
        method=entry.name,
        method_label=entry.display,
        preset="external",
        degradation="none",
        seed=seed,
        key=key,
        code_version=str(planned["code"]),
        time_s=opts.time_s or suite.limits.time_s,
        memory_mb=opts.memory_mb or suite.limits.memory_mb,
        limit=opts.limit,
        stride=opts.stride,
        config=config,
        trajectory=str(path),
        trajectory_format=entry.trajectory_format,
        versions=versions.key_versions(planned),
    )
