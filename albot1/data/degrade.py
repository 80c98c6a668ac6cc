"""Seeded odometry degradation, applied identically for every method.

Degradation acts on the *relative* motion between consecutive scans (the
odometry increment ``inv(o[i-1]) * o[i]``), then re-integrates from the first
pose, which is how odometry error arises physically. SPEC strings
(the README, "Running methods", lists the same):

``none``
    unchanged.
``thesis``
    the thesis's Experiment 3: "0.1 meter and 1 degree added to translation
    and rotation data of two consecutive robot locations". The step's
    translation grows by 0.1 m along its own direction (along the robot's
    forward axis when the step does not translate) and its rotation by +1 deg.
    It is meant for start-stop data (one view per ~1 m): on a high-rate log
    it adds 0.1 m per scan, so thin such logs first.
``gauss:SIGMA_XY_M:SIGMA_THETA_DEG``
    zero-mean Gaussian noise on each step's dx, dy (step frame) and dtheta.
``bias:DX_M:DTHETA_DEG``
    a constant forward offset and rotation added to every step.
``offset:DX_M:DY_M:DTHETA_DEG``
    a wrong laser offset: the odometry is reported for a frame displaced by
    (dx, dy, dtheta) from where the scans are taken (a mounting the method
    does not know). Each step of the scanner becomes ``inv(D) * step * D``
    (D in the scanner's frame: on a robot whose scanner sits at a
    ``sensor_offset`` S, the robot's odometry steps are conjugated by
    ``S * D * inv(S)``, so the methods, which see the scanner's trajectory,
    get exactly that), so a turn in place reads as a small arc and a straight
    step keeps its length but not its direction when dtheta is not 0.
    Deterministic.
``dropout:P``
    scan dropout: every scan after the first is left out with probability
    ``P`` (0 <= P < 1), independently; the kept frames are renumbered from 0
    (as a ``[::STEP]`` slice does) and keep their own odometry, reference
    pose and timestamp. The number of scans dropped says how much the
    motion between kept scans grows: a Bernoulli thinning, not a stride.

``offset`` and ``dropout`` are the suite's perturbations of the sensor set-up
rather than of the odometry's noise (issue 21: robustness on held-out logs).
A slice in the dataset's name (``NAME[::3]``, ``NAME[:N]``) is applied
first: a degradation acts on the steps between the scans the slice kept
(``bias:0.02:0.5`` on ``[::3]`` adds 0.02 m per three-scan step). Every
value is per step, not per metre or per second: ``gauss`` and ``thesis``
move a robot that stands still. A SPEC whose values are all 0 is refused
(it would repeat the undegraded run under a degraded label), and so is a
``bias`` or ``offset`` that only turns by whole turns (``bias:0:720``).
Each value is taken to the 12 significant digits of the SPEC's one spelling
(:attr:`Degradation.spec`, what ``albot1 run`` and suites run and key), and
checked there: ``dropout:0.9999999999999`` is ``dropout:1``, refused. A
``bias`` or ``offset`` rotation is its remainder of a whole turn, exactly
(``bias:0.1:370`` is ``bias:0.1:10``; ``bias:0:1e20`` turns 280 deg per step).

Otherwise only the odometry changes; scans, reference poses and relations are
kept. The random stream is a ``numpy.random.default_rng(seed)`` re-created for
every iteration, so a re-read of the sequence gives the same result.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterator
from dataclasses import dataclass, replace

import numpy as np

from albot1.config.numbers import is_number
from albot1.config.suggest import did_you_mean
from albot1.data.errors import DataError
from albot1.data.finite import pose_problem
from albot1.data.model import Frame, Sequence
from albot1.geometry import se2

#: kind -> the form of its SPEC (each error names the one it expected)
_FORM = {
    "gauss": "gauss:SIGMA_XY_M:SIGMA_THETA_DEG",
    "bias": "bias:DX_M:DTHETA_DEG",
    "offset": "offset:DX_M:DY_M:DTHETA_DEG",
    "dropout": "dropout:P",
}
EXPECTED_SPEC = f"expected none, thesis, {', '.join(list(_FORM.values())[:-1])} or {_FORM['dropout']}"
#: kind -> how many values its SPEC carries after the kind
_ARITY = {kind: form.count(":") for kind, form in _FORM.items()}
#: every kind a SPEC may name (the two without values first)
_KINDS = ("none", "thesis", *_FORM)
#: The metadata ``extra`` key a dropout sets ("dropout:P seed S"): the scans are a thinned subset of the source's.
SCAN_DROPOUT = "scan_dropout"
#: Seeds are what ``numpy.random.default_rng`` accepts and a suite's TOML integer can hold: 0 .. 2**63 - 1.
MAX_SEED = 2**63 - 1


class DegradationSpecError(DataError):
    """A degradation SPEC string does not parse."""


@dataclass(frozen=True)
class Degradation:
    """A parsed SPEC; ``kind`` is none | thesis | gauss | bias | offset | dropout."""

    kind: str
    a: float = 0.0  # translation (m): offset or sigma (offset: dx); dropout: the probability
    b: float = 0.0  # rotation (rad): offset or sigma
    c: float = 0.0  # offset: dy (m)

    @property
    def spec(self) -> str:
        """The canonical SPEC (in the odometry source's label and the dropout's metadata).

        12 significant digits (``:g`` kept 6: ``gauss:0.1234567:1`` read ``gauss:0.123457:1``, a level not run),
        which hides the degree -> radian -> degree round-off and nothing a SPEC would be written with.
        """
        if self.kind in ("none", "thesis"):
            return self.kind
        if self.kind == "dropout":
            return f"dropout:{_label(self.a)}"
        if self.kind == "offset":
            return f"offset:{_label(self.a)}:{_label(self.c)}:{_label(math.degrees(self.b))}"
        return f"{self.kind}:{_label(self.a)}:{_label(math.degrees(self.b))}"

    @property
    def seeded(self) -> bool:
        """Whether the result depends on the seed (otherwise every seed repeats one run)."""
        return (self.kind == "gauss" and not self.a == self.b == 0.0) or (self.kind == "dropout" and self.a > 0)

    def perturb(
        self, step: np.ndarray, rng: np.random.Generator, sensor_offset: np.ndarray | None = None
    ) -> np.ndarray:
        """One degraded increment ``(dx, dy, dtheta)`` of the robot's odometry.

        ``sensor_offset``: where the scanner sits on the robot (``metadata.sensor_offset``). ``offset``'s
        displacement is seen from the scanner, so on the robot it is ``S * D * inv(S)``: the method, which
        sees the odometry moved onto the scanner (``transforms.sensor_frame``), then gets ``inv(D) * M * D``
        for the scanner's own step ``M``, whatever the mounting.
        """
        dx, dy, dth = step
        if self.kind == "thesis":
            dist = math.hypot(dx, dy)
            if dist > 1e-9:
                dx, dy = dx * (dist + self.a) / dist, dy * (dist + self.a) / dist
            else:
                dx += self.a
            return np.array([dx, dy, dth + self.b])
        if self.kind == "gauss":
            noise = rng.normal(0.0, 1.0, size=3)
            return np.array([dx + self.a * noise[0], dy + self.a * noise[1], dth + self.b * noise[2]])
        if self.kind == "bias":
            return np.array([dx + self.a, dy, dth + self.b])
        if self.kind == "offset":
            mount = np.array([self.a, self.c, self.b])
            if sensor_offset is not None and np.any(sensor_offset):
                mount = se2.compose(se2.compose(sensor_offset, mount), se2.inverse(sensor_offset))
            return se2.compose(se2.compose(se2.inverse(mount), np.asarray(step, dtype=float)), mount)
        return np.asarray(step, dtype=float)


def _label(value: float) -> str:
    """A SPEC value as :attr:`Degradation.spec` spells it: 12 significant digits."""
    return f"{value:.12g}"


def _plain_finite(part: str) -> bool:
    """A value of a SPEC: the project's one test of a number as text (no ``1_000``, unicode minus or digits), finite."""
    return is_number(part) and math.isfinite(float(part))


def parse_spec(spec: str, *, stored: bool = False) -> Degradation:
    """Parse a SPEC string (see module doc); DegradationSpecError says what is expected.

    A SPEC that would change nothing (every value 0, or so small it rounds
    to 0) is refused: its runs would be scored and tabled as a degraded level
    while they repeat the undegraded run (write ``none`` for that). ``stored``:
    the SPEC of a run already made (``result.json``), read back to reopen or
    order it; a no-op is accepted there, so runs made before it was refused
    stay readable.
    """
    text = spec.strip().lower()
    if text in ("", "none"):
        return Degradation("none")
    if text == "thesis":
        return Degradation("thesis", 0.1, math.radians(1.0))
    named = [word for word in re.findall(r"[a-z]+", text) if word in _KINDS]
    if len(named) > 1:
        # `gauss:0.02:0.5,bias:-0.03:-1` used to read "gauss takes 2 value(s), got 4", as if a value were missing
        raise DegradationSpecError(
            f"degradation {spec!r} names {len(named)} kinds ({', '.join(named)}): a run takes one degradation, "
            f"combinations are not supported; {EXPECTED_SPEC}"
        )
    kind, _, rest = text.partition(":")
    if kind in ("none", "thesis"):
        # `thesis:1` used to read "unknown kind 'thesis'"
        raise DegradationSpecError(f"degradation {spec!r}: {kind} takes no values; {EXPECTED_SPEC}")
    if kind not in _ARITY:
        raise DegradationSpecError(
            f"degradation {spec!r} not understood (unknown kind {kind!r}){did_you_mean(kind, _KINDS)}; {EXPECTED_SPEC}"
        )
    parts = [part.strip() for part in rest.split(":")] if rest else []
    if len(parts) != _ARITY[kind]:
        raise DegradationSpecError(
            f"degradation {spec!r}: {kind} takes {_ARITY[kind]} value(s) ({_FORM[kind]}), got {len(parts)}; "
            f"{EXPECTED_SPEC}"
        )
    bad = next((part for part in parts if not _plain_finite(part)), None)
    if bad is not None:
        raise DegradationSpecError(
            f"degradation {spec!r}: value {bad!r} is not a plain finite number ({_FORM[kind]}); {EXPECTED_SPEC}"
        )
    # Each value as the label spells it (+ 0.0: -0 is 0; one spelling, one key): `albot1 run` and suites run, key
    # and table the label, so the checks below judge the level that runs. `dropout:0.9999999999999` (label
    # dropout:1) passed here and was refused as 'dropout:1', a SPEC nobody wrote, when the run started.
    values = [float(_label(float(part))) + 0.0 for part in parts]
    rounded = any(float(part) != value for part, value in zip(parts, values, strict=True))
    written, run = ":".join(parts), ":".join(map(_label, values))
    digits = f", {written} being {run} to the 12 significant digits a level is run with" if rounded else ""
    if kind == "gauss" and min(values) < 0:
        raise DegradationSpecError(f"degradation {spec!r}: sigmas must be >= 0 ({_FORM[kind]}); {EXPECTED_SPEC}")
    if kind == "dropout" and not 0.0 <= values[0] < 1.0:
        raise DegradationSpecError(
            f"degradation {spec!r}: the dropout probability must be in [0, 1) (the first scan is always kept)"
            f"{digits}; {EXPECTED_SPEC}"
        )
    turn = values[-1]  # bias's and offset's rotation (deg) is their last value
    if kind in ("bias", "offset"):
        # A turn per step acts as its remainder, taken exactly (fmod) in degrees: radians(1e20) rounded away the
        # whole turns' multiples of 2 pi, so `bias:0:1e20` turned each step by float noise, not 1e20 deg = 280 deg.
        # Spelt again to the label's 12 digits (then 360 is 0), so the label re-parses to this very turn.
        values[-1] = math.fmod(float(_label(math.fmod(turn, 360.0))), 360.0) + 0.0
    if kind == "offset":
        deg = Degradation(kind, values[0], math.radians(values[2]), values[1])
    else:
        deg = Degradation(kind, values[0], math.radians(values[1]) if len(values) > 1 else 0.0)
    whole = kind in ("bias", "offset") and turn != 0.0 and math.remainder(turn, 360.0) == 0.0
    if not stored and whole and not (deg.a or deg.c):
        # `bias:0:720` turns every step by two whole turns: the odometry is the undegraded one (to rounding)
        raise DegradationSpecError(
            f"degradation {spec!r} changes nothing (no translation, and {turn:g} deg is a whole number of "
            f"turns{digits}): its runs would repeat the undegraded run under a degraded label; write none"
        )
    if not (stored or deg.a or deg.b or deg.c):
        raise DegradationSpecError(
            f"degradation {spec!r} changes nothing (every value is 0): its runs would repeat the undegraded run "
            f"under a degraded label; write none"
        )
    return deg


def check_seed(seed: object) -> int:
    """``seed`` when it is an integer in 0 .. :data:`MAX_SEED`, else a DegradationSpecError saying so.

    Checked before any scan is read: numpy refuses a negative seed only when
    the first random number is drawn, deep inside a run.
    """
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or not 0 <= seed <= MAX_SEED:
        raise DegradationSpecError(f"seed {seed!r}: expected an integer from 0 to {MAX_SEED} (2**63 - 1)")
    return int(seed)


def degrade(sequence: Sequence, spec: str | Degradation, *, seed: int = 0) -> Sequence:
    """``sequence`` with degraded odometry (streamed; the same seed gives the same result)."""
    check_seed(seed)
    deg = parse_spec(spec) if isinstance(spec, str) else spec
    if deg.kind == "none":
        return sequence
    if deg.kind == "dropout":
        return _dropout(sequence, deg, seed)

    mounting = np.asarray(sequence.metadata.sensor_offset, dtype=float)

    def frames(source: Iterator[Frame]) -> Iterator[Frame]:
        rng = np.random.default_rng(seed)
        prev_raw: np.ndarray | None = None
        current: np.ndarray | None = None
        for frame in source:
            if prev_raw is None or current is None:
                current = np.asarray(frame.odometry, dtype=float)
            else:
                step = se2.between(prev_raw, frame.odometry)
                current = se2.compose(current, deg.perturb(step, rng, mounting))
                problem = pose_problem(current, "the degraded odometry")
                if problem is not None:  # e.g. gauss:1e300:1 overflows: refused, never mapped
                    raise DegradationSpecError(
                        f"{sequence.name}: degradation {deg.spec} seed {seed}, step to scan {frame.index} "
                        f"(t = {frame.scan.timestamp:.6f} s): {problem}"
                    )
            prev_raw = np.asarray(frame.odometry, dtype=float)
            yield replace(frame, odometry=current)

    source = sequence.metadata.odometry_source or "odometry"
    # A deterministic SPEC names no seed: every seed gives this odometry, and a label naming one would say otherwise.
    seeded = f" seed {seed}" if deg.seeded else ""
    meta = replace(sequence.metadata, odometry_source=f"{source} degraded {deg.spec}{seeded}")
    return sequence.with_frames(frames, metadata=meta, scan_count=sequence.known_scan_count)


def _dropout(sequence: Sequence, deg: Degradation, seed: int) -> Sequence:
    """Every frame after the first kept with probability 1 - P, renumbered from 0; nothing else changes."""

    def frames(source: Iterator[Frame]) -> Iterator[Frame]:
        rng = np.random.default_rng(seed)
        kept = 0
        for i, frame in enumerate(source):
            if i > 0 and rng.random() < deg.a:
                continue
            yield replace(frame, index=kept)
            kept += 1

    extra = {**sequence.metadata.extra, SCAN_DROPOUT: f"{deg.spec} seed {seed}"}
    meta = replace(sequence.metadata, extra=extra)
    return sequence.with_frames(frames, metadata=meta, scan_count=sequence.known_scan_count if deg.a == 0 else None)
