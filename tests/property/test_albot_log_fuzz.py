"""Random and mutated albot-log lines: the reader raises only its documented errors."""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from albot1.data.errors import DataError
from albot1.data.loaders.albot_log.loader import AlbotLogLoader, AlbotLogWriter
from albot1.data.model import Frame, Scan, Sequence

ANGLES = np.deg2rad(np.arange(-90.0, 91.0, 30.0))


def valid_text() -> list[str]:
    rng = np.random.default_rng(7)
    frames = [
        Frame(
            i,
            Scan(np.where(rng.random(7) < 0.2, np.nan, np.round(rng.uniform(0, 20, 7), 2)), ANGLES, 1.0 + i, 20.0),
            np.array([0.1 * i, 0.0, 0.05 * i]),
            np.array([1.0, 2.0, 0.3 * i]),  # every view or none: a log of both is refused
        )
        for i in range(4)
    ]
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "v.albotlog"
        AlbotLogWriter().write(Sequence.from_frames("v", frames), path)
        return path.read_text(encoding="utf-8").splitlines(keepends=True)


VALID = valid_text()
TOKENS = st.sampled_from(
    [
        "VIEW",
        "SENSOR",
        "SENSOR-ANGLES",
        "UNITS",
        "FRAME",
        "NAME",
        "-",
        "nan",
        "inf",
        "-inf",
        "0",
        "1",
        "-1",
        "1e400",
        "3.5",
        "abc",
        "",
        "#",
        "7",
        "180",
        "ALBOT1-LOG",
        "1_0",
        "0x1",
    ]
)
LINE = st.lists(st.one_of(TOKENS, st.text(max_size=8)), max_size=20).map(lambda t: " ".join(t) + "\n")


def check(tmp_dir: Path, lines: list[str]) -> None:
    path = tmp_dir / "fuzz.albotlog"
    path.write_text("".join(lines), encoding="utf-8", errors="surrogatepass")
    try:
        for frame in AlbotLogLoader().load(path).frames():
            assert np.all(np.isnan(frame.scan.ranges) | (frame.scan.ranges >= 0))
            assert np.all(np.isfinite(frame.odometry))
    except DataError:
        pass  # ParseError is a DataError: the only documented failure


FUZZ = settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])


@FUZZ
@given(lines=st.lists(LINE, max_size=6), where=st.integers(0, len(VALID)))
def test_random_lines_inserted_into_a_valid_log(tmp_path: Path, lines: list[str], where: int) -> None:
    check(tmp_path, VALID[:where] + lines + VALID[where:])


@FUZZ
@given(data=st.data())
def test_mutated_tokens_of_a_valid_log(tmp_path: Path, data: st.DataObject) -> None:
    lines = list(VALID)
    for _ in range(data.draw(st.integers(1, 4))):
        i = data.draw(st.integers(0, len(lines) - 1))
        tokens = lines[i].split()
        if not tokens:
            continue
        action = data.draw(st.sampled_from(["replace", "drop", "duplicate", "truncate"]))
        k = data.draw(st.integers(0, len(tokens) - 1))
        if action == "replace":
            tokens[k] = data.draw(st.one_of(TOKENS, st.text(max_size=6)))
        elif action == "drop":
            del tokens[k]
        elif action == "duplicate":
            tokens.insert(k, tokens[k])
        else:
            tokens = tokens[:k]
        lines[i] = " ".join(tokens) + "\n"
    check(tmp_path, lines)


@FUZZ
@given(raw=st.binary(max_size=300))
def test_arbitrary_bytes_after_the_magic_line(tmp_path: Path, raw: bytes) -> None:
    path = tmp_path / "bytes.albotlog"
    path.write_bytes(b"ALBOT1-LOG 1\n" + raw)
    try:
        list(AlbotLogLoader().load(path).frames())
    except DataError:
        pass
