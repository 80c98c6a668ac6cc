"""Property tests of the dataset manifest parser: any document gives a manifest or one DataError."""

from __future__ import annotations

import json
import math
import tempfile
from pathlib import Path
from typing import Any

from hypothesis import given
from hypothesis import strategies as st

from albot1.data.errors import DataError
from albot1.data.loaders.registry import FORMATS
from albot1.data.manifest import parse_manifest


def toml_string(text: str) -> str:
    """A TOML basic string: JSON's escapes are TOML's, except that TOML also escapes DEL and has no surrogates."""
    return json.dumps(text, ensure_ascii=False).replace("\x7f", "\\u007f")


def toml_value(value: Any) -> str:
    """A TOML inline value."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf") if math.isinf(value) else repr(value)
    if isinstance(value, str):
        return toml_string(value)
    if isinstance(value, list):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    return "{" + ", ".join(f"{toml_string(k)} = {toml_value(v)}" for k, v in value.items()) + "}"


def toml_document(data: dict[str, Any]) -> str:
    return "".join(f"{toml_string(key)} = {toml_value(value)}\n" for key, value in data.items())


def parse(name: str, text: str | bytes) -> Any:
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / f"{name}.toml"
        if isinstance(text, bytes):
            path.write_bytes(text)
        else:
            path.write_text(text, encoding="utf-8")
        return parse_manifest(path)


TEXT = st.text(st.characters(codec="utf-8", exclude_categories=("Cs",)), max_size=12)
SCALAR = st.one_of(st.booleans(), st.integers(-(2**63), 2**63 - 1), st.floats(), TEXT)
ANY_VALUE = st.recursive(SCALAR, lambda inner: st.lists(inner, max_size=3) | st.dictionaries(TEXT, inner, max_size=3))
SHA = st.text("0123456789abcdefABCDEF", min_size=64, max_size=64)
#: A path a manifest may give: relative, inside the data folder (test_data_trust_props.py covers the refused ones).
RELATIVE_PATH = (
    st.lists(st.text("abcXYZ019-_.é", min_size=1, max_size=6), min_size=1, max_size=3)
    .filter(lambda parts: all(p not in (".", "..") for p in parts))
    .map("/".join)
)
GOOD_FILE = st.fixed_dictionaries(
    {"role": st.sampled_from(["log", "relations"]), "path": RELATIVE_PATH, "sha256": SHA},
    optional={"size": st.integers(0, 2**40), "urls": st.lists(TEXT, max_size=2)},
)
ENTRY = st.one_of(GOOD_FILE, st.dictionaries(st.sampled_from(["role", "path", "sha256", "size", "urls"]), ANY_VALUE))
KEYS = ["description", "format", "license", "citation", "source", "local_only", "reference", "notes", "loader"]


@given(
    st.dictionaries(st.sampled_from([*KEYS, "name", "files"]), ANY_VALUE),
    st.lists(ENTRY | ANY_VALUE, max_size=3),
    st.booleans(),
)
def test_any_document_parses_or_raises_data_error(data: dict[str, Any], files: list[Any], named: bool) -> None:
    if named:
        data = {**data, "name": "m", "files": files}
    try:
        manifest = parse("m", toml_document(data))
    except DataError as exc:
        assert str(exc).startswith(str(Path(tempfile.gettempdir())))  # names the file
        return
    assert manifest.name == "m" and sum(f.role == "log" for f in manifest.files) == 1
    assert all(len(f.sha256) == 64 and isinstance(f.urls, tuple) for f in manifest.files)


@given(st.binary(max_size=200))
def test_any_bytes_parse_or_raise_data_error(raw: bytes) -> None:
    try:
        parse("m", raw)
    except DataError:
        pass


@given(
    GOOD_FILE.map(lambda f: {**f, "role": "log"}),
    st.lists(GOOD_FILE.map(lambda f: {**f, "role": "relations"}), max_size=1),
    st.fixed_dictionaries(
        {},
        optional={
            **{k: TEXT for k in KEYS if k not in ("local_only", "loader", "format")},
            "format": st.sampled_from(list(FORMATS)),  # any other format is refused (test_manifest.py)
        },
    ),
    st.booleans(),
    st.dictionaries(TEXT, SCALAR, max_size=3),
)
def test_valid_manifests_read_back(
    log: dict[str, Any], more: list[dict[str, Any]], texts: dict[str, str], local: bool, loader: dict[str, Any]
) -> None:
    data = {"name": "m", **texts, "local_only": local, "loader": loader, "files": [log, *more]}
    manifest = parse("m", toml_document(data))
    for key, value in texts.items():
        assert getattr(manifest, key) == value
    assert manifest.local_only is local and manifest.log.path == log["path"]
    assert manifest.log.sha256 == log["sha256"].lower() and manifest.log.size == log.get("size")
    assert manifest.log.urls == tuple(log.get("urls", ()))
    assert [f.role for f in manifest.files] == ["log", *(["relations"] if more else [])]
    assert manifest.loader.keys() == loader.keys()
