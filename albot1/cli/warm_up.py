"""``albot1 warm-up``: every preset's start-up work (Albot1's kernel compilation) done now, not in the first run.

Why a command: Albot1's kernels are compiled by numba on a code version's
first run on a machine (``docs/albot1-mapper.md``, "Kernels") and cached on
disk; ``make venv`` runs this command after installing, so that the first
``albot1 run`` after an install loads them instead of compiling them. A user
who installed the wheel with pip can run it once, too; without it, the first
run compiles and says so.
"""

from __future__ import annotations

import time
from typing import Annotated

import typer


def register(app: typer.Typer) -> None:
    app.command("warm-up")(warm_up)


def warm_up(
    methods: Annotated[
        list[str] | None,
        typer.Argument(help="the methods to warm up (default: every available method that has a start-up step)"),
    ] = None,
) -> None:
    """Compile (or load from numba's cache) the kernels of every preset of METHODS, so no run compiles them.

    Albot1's kernels (and gtsam-graph's grid search) are compiled once per
    code version and machine and cached on disk; this does it now, for every
    preset of albot1, albot1-places and gtsam-graph (or of the METHODS
    named), and says how long it took.
    `make venv` runs it after installing. A method without a start-up step
    has nothing to do here. Exit 1 with one line per method that failed
    (the others are still warmed up).

    Examples:\n
      albot1 warm-up\n
      albot1 warm-up albot1
    """
    # Imported by the command, not by this module: see albot1.cli.app.
    from albot1.errors import Albot1Error
    from albot1.methods.registry import get_method, method_registry
    from albot1.methods.warm_ups import has_warm_up, warm_up_methods

    start = time.perf_counter()
    registry = method_registry()
    named = list(dict.fromkeys(methods or ()))  # each once, in the order given
    # A method named here that is unknown or not installed is one line, exit 1 (get_method / load_class say why).
    specs = [get_method(name, registry) for name in named] if named else [s for s in registry if s.available()]
    names: list[str] = []
    failures: list[str] = []
    for spec in specs:
        if named:
            cls = spec.load_class()
        else:  # every available method: one that cannot be loaded is reported, the others still warm up
            try:
                cls = spec.load_class()
            except (Albot1Error, ImportError) as exc:
                failures.append(f"method {spec.name} ({spec.target}): {type(exc).__name__}: {exc}")
                continue
        if has_warm_up(cls):
            names.append(spec.name)
    if names:
        outcome = warm_up_methods(names, registry, announce=lambda line: typer.echo(line, err=True))
        failures.extend(outcome.failures)
        if outcome.joint_failure:  # every kernel is ready: said, not an error
            typer.echo(f"albot1 warm-up: warning: {outcome.joint_failure}", err=True)
    for failure in failures:
        typer.echo(f"albot1: error: warm-up: {failure}", err=True)
    if failures:
        raise typer.Exit(1)
    if not names:
        typer.echo("albot1 warm-up: none of these methods has a start-up step; nothing to do")
        return
    typer.echo(f"albot1 warm-up: {', '.join(names)}: every preset ready in {time.perf_counter() - start:.1f} s")
