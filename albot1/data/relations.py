"""Ground-truth relations files (Kuemmerle et al., Autonomous Robots 2009).

One relation per line: ``t1 t2 x y z roll pitch yaw`` -- the pose at time
``t2`` seen from the pose at time ``t1`` (``inv(T1) * T2``); the times are
the ipc timestamps of the dataset's scans. Only the planar part (x, y, yaw)
is kept: z, roll and pitch are zero in every published 2D relations file,
and a non-zero value is reported rather than silently dropped. Blank lines
and ``#`` comments are allowed; a file without relations gives zero relations
(a run folder of a dataset with an empty relation set round-trips).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from albot1.atomic import atomic_write
from albot1.data.errors import ParseError
from albot1.data.model import Relations
from albot1.data.tokens import parse_floats

_FIELDS = "t1 t2 x y z roll pitch yaw"
_PLANAR_TOLERANCE = 1e-6


def read_relations(path: str | Path) -> Relations:
    """Parse a relations file; ParseError naming ``file:line`` on any malformed line."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8", errors="replace")
    except OSError as exc:
        raise ParseError(p, f"cannot read relations file ({exc.strerror or exc})") from None
    rows: list[list[float]] = []
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
        rows.append(values)
    arr = np.asarray(rows, dtype=np.float64).reshape(-1, 8)
    return Relations(t1=arr[:, 0].copy(), t2=arr[:, 1].copy(), poses=arr[:, [2, 3, 7]].copy())


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
    atomic_write(p, lambda tmp: np.savetxt(tmp, rows, fmt="%.9f"))
