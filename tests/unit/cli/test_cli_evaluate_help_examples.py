"""The examples of `albot1 evaluate --help` do what they show: `--evo` and `--plot` need reference poses.

The `--evo` example named `aces`, a raw log with relations only (its manifest's loader says `reference = "none"`):
run as shown, it wrote no evo file and said "evo result files need reference poses".
"""

from __future__ import annotations

import re

from albot1.cli.evaluate import evaluate
from albot1.data import catalog


def examples() -> list[str]:
    """Each example command of the help, continuation lines joined."""
    text = (evaluate.__doc__ or "").split("Examples:", 1)[1]
    joined = re.sub(r"\\\s*\n\s*", " ", text)  # a line ending in a backslash goes on
    return [line.strip() for line in joined.splitlines() if line.strip().startswith("albot1 evaluate")]


def test_an_example_writing_evo_files_or_error_plots_names_a_dataset_with_reference_poses() -> None:
    needing = [e for e in examples() if "--evo" in e or "--plot" in e]
    assert needing  # the help shows at least one
    for example in needing:
        match = re.search(r"--dataset (\S+)", example)
        if match is None:
            continue  # --reference FILE: the file is the reference
        manifest = catalog.get(match[1])
        assert manifest.loader.get("reference") != "none", f"{example}: {match[1]} has no reference poses"
