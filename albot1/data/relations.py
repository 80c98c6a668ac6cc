"""Ground-truth relations files (Kuemmerle et al., Autonomous Robots 2009).

One relation per line: ``t1 t2 x y z roll pitch yaw`` -- the pose at time
``t2`` seen from the pose at time ``t1`` (``inv(T1) * T2``); the times are
the ipc timestamps of the dataset's scans (s), x and y in metres, the angles
in **radians** (the metricEvaluator's unit; every published file's yaw lies
in [-pi, pi], the largest |yaw| being 3.14157 in fr079's). A |yaw| beyond
pi is refused naming its line (:data:`MAX_YAW_RAD`): it is the sign of a
file written in degrees, which read as radians would score a wrong heading
for every relation turning more than a few degrees. Only the planar part (x, y, yaw)
is kept: z, roll and pitch are zero in every published 2D relations file,
and a non-zero value is reported rather than silently dropped. Blank lines
and ``#`` comments are allowed. A file without one relation is refused
(a wrong or truncated file would otherwise score as "0 relations"), except
where the caller reads a copy this project wrote (``empty_ok``): a run folder of
a dataset with an empty relation set round-trips.

A relation names its two poses by timestamp, and those are the timestamps
of scans, so :func:`match_stamps` is the one place where a relation end is
turned into a scan index: the nearest scan stamp, accepted within
:data:`STAMP_TOLERANCE_S`, and :func:`relations_in_run` the one place that
decides which relations a run on part of a log is scored on. Scan stamps need not be sorted: the Intel log's
ipc stamps go back by up to 0.9 s at 631 places, which is also why 6 of
``intel.relations``' lines have ``t2 < t1`` -- the scan stamped ``t1``
comes *first* in the log and the relation, read as written
(``inv(T(t1)) * T(t2)``), agrees with the odometry between those two scans
(docs/metrics.md has the check). Such pairs are therefore used as written:
neither swapped nor inverted.

A line that repeats an earlier line identically (same ``t1``, ``t2`` and
motion) is the same measurement listed twice. By default it is **counted
once** (``repeats="drop"``): counting it twice would weight that relation
double and overstate N (a file listed twice would narrow every confidence
interval). The published evaluator counts lines as listed, though, and
three published files hold such lines (aces 9, fr079 4, mit-csail 1):
dropping aces' nine changes raw odometry's error by -4.8 % (``docs/metrics.md``),
so a number scored that way could not stand beside a published one. A
dataset whose relations file is published declares ``repeats = "keep"`` in
its manifest (the published reading); anyone can choose with the
``relations_repeats=drop|keep`` option. Either way the reader says how many
lines repeat (a warning naming them, :attr:`Relations.repeats`) and the
relation metric's block records the count and the reading. The same pair
with two *different* motions is an error: which one is the measurement
cannot be decided.

A line that gives an earlier relation **in the other direction** (``t2 t1``
and the inverse motion, to the rounding of printed decimals:
:data:`REVERSE_TOLERANCE`) is the same measurement too, and is counted the
same way (once by default, as listed with ``keep``, said in the warning as
``line 7 (= 3 reversed)``): counted twice it weighted that relation double,
and its two errors differ (the translation error of ``inv(d)`` against
``inv(d*)`` is not that of ``d`` against ``d*``), so the metric depended on
how often the file's author wrote a pair. A reversed line whose motion is
not the inverse is the same pair with two different motions: an error. No
published file has such a line.
"""

from __future__ import annotations

import logging
import math
from pathlib import Path
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from albot1.atomic import atomic_write
from albot1.data.errors import DataError, ParseError
from albot1.data.model import MAX_TIMESTAMP_S, Relations
from albot1.data.text import TEXT_ENCODING
from albot1.data.tokens import parse_floats

log = logging.getLogger(__name__)

_FIELDS = "t1 t2 x y z roll pitch yaw"
_PLANAR_TOLERANCE = 1e-6

#: Largest accepted gap (s) between a relation's timestamp and the scan stamp it names. The published
#: relations files copy the scans' ipc stamps, except that ``mit-csail.relations`` prints 5 decimals where
#: its log prints 6 (8 stamps differ by up to 5 us); the closest two scans of the five logs are 0.51 ms
#: apart (Intel), so 0.1 ms accepts the rounding with a 20x margin and can never accept a neighbour scan.
STAMP_TOLERANCE_S = 1e-4
#: Largest accepted |x|, |y| (m) of a relation's motion.
MAX_MOTION_M = 1e8
#: Largest accepted |yaw| (rad) of a relation's motion: pi, with room for pi printed rounded up (3.1416, 3.141593).
MAX_YAW_RAD = math.pi + 1e-5
#: How far (m per metre of the relation's length, plus this much; and rad) a line giving an earlier relation in the
#: other direction may be from that relation's inverse and still be the same measurement: the inverse of a motion
#: printed to 5 decimals misses the printed inverse by about 1e-5 of that, so this is a tenfold margin.
REVERSE_TOLERANCE = 1e-4
#: How identical repeated lines are read: ``drop`` counts each relation once (the default), ``keep`` as listed.
RepeatPolicy = Literal["drop", "keep"]
REPEAT_POLICIES: tuple[RepeatPolicy, ...] = ("drop", "keep")
#: The comment with which :func:`write_relations` records its source's reading of repeated lines, so a run
#: folder's copy is read back as its source was: ``# albot1: relations_repeats=drop repeated_lines=9``.
_REPEATS_NOTE = "# albot1: relations_repeats="


def read_relations(
    path: str | Path, *, warn_repeats: bool = True, repeats: RepeatPolicy = "drop", empty_ok: bool = False
) -> Relations:
    """Parse a relations file; ParseError naming ``file:line`` on any malformed line.

    Identical repeated lines are left out (``repeats="drop"``) or kept as listed (``"keep"``); see the
    module docstring. A file without a relation is a ParseError unless ``empty_ok`` (a copy this project
    wrote of an empty relation set).

    ``warn_repeats=False`` for a copy this project wrote (a run folder's
    ``relations.txt``): its repeats were reported when the dataset's own file
    was read, and saying so again for the copy would double every warning.
    """
    p = Path(path)
    try:
        text = p.read_text(encoding=TEXT_ENCODING, errors="replace")  # a leading byte-order mark dropped
    except OSError as exc:
        raise ParseError(p, f"cannot read relations file ({exc.strerror or exc})") from None
    first_line = text.split("\n", 1)[0].strip()
    noted = 0
    if first_line.startswith(_REPEATS_NOTE):  # a copy this project wrote: read as its source was
        repeats, noted = _noted_repeats(p, first_line)
    rows: list[list[float]] = []
    seen: dict[tuple[float, float], tuple[int, list[float]]] = {}
    repeated: list[str] = []
    reversed_lines = 0
    for number, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip()
        if not line or line.startswith("#"):
            continue
        tokens = line.split()
        if len(tokens) != 8:
            raise ParseError(p, f"{len(tokens)} fields, expected 8 ({_FIELDS})", line=number)
        values = parse_floats(p, number, tokens, "field", _FIELDS).tolist()
        if not all(math.isfinite(v) for v in values):
            raise ParseError(p, f"non-finite value; expected finite numbers ({_FIELDS})", line=number)
        if max(abs(values[4]), abs(values[5]), abs(values[6])) > _PLANAR_TOLERANCE:
            raise ParseError(p, "z, roll and pitch must be 0 for a planar (2D) relation", line=number)
        _check_row(p, number, values)
        pair = (values[0], values[1])
        if pair in seen:
            first, kept = seen[pair]
            if kept != values:
                raise ParseError(
                    p,
                    f"the relation t1={values[0]!r} t2={values[1]!r} is listed twice with different motions "
                    f"(lines {first} and {number}); expected each relation once",
                    line=number,
                )
            repeated.append(f"{number} (= {first})")
            if repeats == "drop":
                continue
        elif (values[1], values[0]) in seen:
            first, kept = seen[(values[1], values[0])]
            _check_reverse(p, number, first, kept, values)
            seen[pair] = (number, values)
            repeated.append(f"{number} (= {first} reversed)")
            reversed_lines += 1
            if repeats == "drop":
                continue
        else:
            seen[pair] = (number, values)
        rows.append(values)
    if not rows and not repeated and not empty_ok:
        lines = text.splitlines()
        found = "the file is empty" if not lines else f"its {len(lines)} line(s) are all blank or '#' comments"
        raise ParseError(p, f"no relation: {found}; expected one relation per line ({_FIELDS})")
    if repeated and warn_repeats:
        log.warning(
            "%s: %d relation line(s) repeat an earlier line %s; %s: line %s",
            p,
            len(repeated),
            "identically or in the other direction" if reversed_lines else "identically",
            "each relation is counted once"
            if repeats == "drop"
            else "each is counted as listed (relations_repeats=keep)",
            ", ".join(repeated[:5]) + (", ..." if len(repeated) > 5 else ""),
        )
    arr = np.asarray(rows, dtype=np.float64).reshape(-1, 8)
    return Relations(
        t1=arr[:, 0].copy(),
        t2=arr[:, 1].copy(),
        poses=arr[:, [2, 3, 7]].copy(),
        repeats=len(repeated) if repeats == "keep" or not noted else noted,
        repeats_counted=repeats == "keep" and bool(repeated),  # without repeated lines both readings agree
    )


def repeat_policy(value: object, where: str) -> RepeatPolicy:
    """``value`` of a ``relations_repeats`` option or manifest field, checked; DataError naming ``where``."""
    for policy in REPEAT_POLICIES:
        if value == policy:
            return policy
    raise DataError(
        f"{where}: relations_repeats={value!r}; expected drop (count each relation once) or keep (as listed)"
    )


def _noted_repeats(path: Path, line: str) -> tuple[RepeatPolicy, int]:
    """The reading and count in a :data:`_REPEATS_NOTE` comment (a run folder's copy of a relations file)."""
    fields = dict(part.partition("=")[::2] for part in line[len("# albot1: ") :].split())
    count = fields.get("repeated_lines", "")
    if set(fields) != {"relations_repeats", "repeated_lines"} or not count.isdigit():
        raise ParseError(path, f"{line!r}; expected '{_REPEATS_NOTE}drop|keep repeated_lines=N'", line=1)
    return repeat_policy(fields["relations_repeats"], f"{path}:1"), int(count)


def _check_reverse(path: Path, number: int, first: int, kept: list[float], values: list[float]) -> None:
    """ParseError unless line ``number`` (``values``) is the inverse of line ``first``'s relation (``kept``).

    Both motions composed must give no motion, to :data:`REVERSE_TOLERANCE` (the rounding of printed decimals).
    """
    x, y, yaw = kept[2], kept[3], kept[7]
    c, s = math.cos(yaw), math.sin(yaw)
    # kept * values: the pose of t1 (of line `first`) seen from itself after going to t2 and back
    dx, dy = x + c * values[2] - s * values[3], y + s * values[2] + c * values[3]
    turn = math.remainder(yaw + values[7], math.tau)
    if math.hypot(dx, dy) <= REVERSE_TOLERANCE * (1.0 + math.hypot(x, y)) and abs(turn) <= REVERSE_TOLERANCE:
        return
    raise ParseError(
        path,
        f"the relation t1={kept[0]!r} t2={kept[1]!r} of line {first} is listed again in the other direction with "
        f"a motion that is not its inverse (composed they move {math.hypot(dx, dy):.6g} m and "
        f"{math.degrees(turn):.6g} deg); expected each relation once, or its exact inverse",
        line=number,
    )


def _check_row(path: Path, number: int, values: list[float]) -> None:
    """ParseError for an absurd or self-referencing relation (see the module docstring)."""
    t1, t2, x, y, yaw = values[0], values[1], values[2], values[3], values[7]
    if max(abs(t1), abs(t2)) > MAX_TIMESTAMP_S:
        raise ParseError(
            path, f"timestamp beyond {MAX_TIMESTAMP_S:g}; expected seconds (the scans' timestamps)", line=number
        )
    if max(abs(x), abs(y)) > MAX_MOTION_M:
        raise ParseError(
            path, f"motion ({x:.6g}, {y:.6g}) m is beyond {MAX_MOTION_M:g} m; expected metres", line=number
        )
    if abs(yaw) > MAX_YAW_RAD:
        raise ParseError(
            path,
            f"yaw {yaw:g} is beyond pi; expected radians in [-pi, pi] (a file written in degrees?)",
            line=number,
        )
    if t1 == t2:
        raise ParseError(
            path,
            f"t1 and t2 are both {t1!r}: a relation from a pose to itself (motion {x:g}, {y:g}, {values[7]:g}); "
            "expected two different scans",
            line=number,
        )


def write_relations(path: str | Path, relations: Relations) -> None:
    """Write ``relations`` in the same 8-column format, atomically (temp file + rename)."""
    p = Path(path)
    n = len(relations)
    zeros = np.zeros(n)
    rows = np.column_stack(
        [
            relations.t1,
            relations.t2,
            relations.poses[:, 0],
            relations.poses[:, 1],
            zeros,
            zeros,
            zeros,
            relations.poses[:, 2],
        ]
    )
    # The copy says how its source's repeated lines were read, so reading it back gives the same relations,
    # the same reading and the same count (a dropped line is no longer in the copy).
    policy = "keep" if relations.repeats_counted else "drop"
    header = f"{_REPEATS_NOTE}{policy} repeated_lines={relations.repeats}" if relations.repeats else ""
    atomic_write(p, lambda tmp: np.savetxt(tmp, rows, fmt="%.9f", header=header, comments=""))


def match_stamps(timestamps: ArrayLike, query: ArrayLike) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
    """For each ``query`` time: the index of the nearest of ``timestamps`` and the absolute gap (s).

    ``timestamps`` may be in any order (indices refer to the given order); among equal stamps the first
    in that order wins. Accepting or refusing a gap is the caller's decision (see
    :data:`STAMP_TOLERANCE_S`).
    """
    t = np.asarray(timestamps, dtype=float).reshape(-1)
    q = np.asarray(query, dtype=float).reshape(-1)
    if len(t) == 0:
        raise ValueError("match_stamps: no timestamps to match against")
    order = np.argsort(t, kind="stable")
    ts = t[order]
    right = np.clip(np.searchsorted(ts, q, side="left"), 0, len(ts) - 1)
    left = np.clip(right - 1, 0, len(ts) - 1)
    # searchsorted(side="left") lands on the first of equal stamps; the left neighbour wins ties of distance
    # only when it is strictly closer, so an exact match is always the first stamp of its run.
    pick = np.where(np.abs(ts[left] - q) < np.abs(ts[right] - q), left, right)
    return order[pick].astype(np.int64), np.abs(ts[pick] - q)


def relations_in_run(
    relations: Relations, timestamps: ArrayLike, tolerance_s: float = STAMP_TOLERANCE_S
) -> NDArray[np.bool_]:
    """Which of ``relations`` apply to a run that saw the scans stamped ``timestamps`` (a mask, one per relation).

    A relation applies when both its ends are within ``tolerance_s`` of one of the run's scan stamps: a run
    on part of a log (a prefix, every n-th scan) has no pose for a scan it did not see, so a relation naming
    one cannot be scored. This is the one rule for ``albot1 run`` + ``albot1 evaluate``, the bench's cells
    and external trajectories alike (the relation metric applies it when it excludes); its callers count
    what it leaves out and report it (``relations_outside_run`` in ``metrics.json``), never drop it silently.
    """
    t = np.asarray(timestamps, dtype=float).reshape(-1)
    if len(t) == 0 or len(relations) == 0:
        return np.zeros(len(relations), dtype=bool)
    _, gap1 = match_stamps(t, relations.t1)
    _, gap2 = match_stamps(t, relations.t2)
    return np.asarray((gap1 <= tolerance_s) & (gap2 <= tolerance_s), dtype=bool)
