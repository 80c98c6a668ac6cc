"""Every preset's start-up work of some methods, done now: the bench's forkserver and ``albot1 warm-up`` share it.

A method's optional ``warm_up`` (``Mapper.warm_up``; Albot1's compiles its
numba kernels, or loads them from numba's on-disk cache) runs before a run's
first scan. Doing it for every preset ahead of the runs serves two callers:
the bench's forkserver, so that each forked cell starts with the kernels in
memory, and ``albot1 warm-up`` (run by ``make venv``), so that the first run
after an install loads the kernels from the cache instead of compiling them
(``docs/albot1-mapper.md``, "Kernels").
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from albot1.methods.registry import MethodRegistry


@dataclass(frozen=True)
class WarmUpOutcome:
    """What :func:`warm_up_methods` found: one line per method whose warm-up failed, and a joint-only failure.

    ``joint_failure``: the joint pass failed but each method's warm-up alone then
    succeeded (every kernel is ready; the error is still reported, not swallowed).
    """

    failures: list[str] = field(default_factory=list)
    joint_failure: str | None = None

    def lines(self) -> list[str]:
        """Every failure line, the joint one last (what the forkserver's preload reports)."""
        return self.failures + ([self.joint_failure] if self.joint_failure else [])


def has_warm_up(cls: type) -> bool:
    """Whether mapper class ``cls`` has the optional start-up step (``Mapper.warm_up``)."""
    return callable(getattr(cls, "warm_up", None))


def warm_up_methods(
    methods: list[str], registry: MethodRegistry | None = None, announce: Callable[[str], None] | None = None
) -> WarmUpOutcome:
    """Every preset's warm-up of ``methods``, compiled together where the classes offer it.

    A class may offer ``warm_up_together()``, a context manager inside which
    its warm-ups only note their kernels and which compiles them all when
    it ends (:func:`albot1.methods.albot1.warm_up.together`): one cold compile
    of every preset of ``albot1`` and ``albot1-places`` keeps the cores busy
    to the end, where a warm-up per preset waits for its own dearest kernel
    each time. Should anything in it fail, the warm-ups run again one by one,
    so that each failure is reported under its own method (what was compiled
    before the failure is loaded from numba's cache, not compiled again).
    ``announce`` receives the warm-ups' own lines (a real compilation says so
    and how long it took; a cache load is silent).
    """
    from albot1.methods.registry import get_method

    try:
        with contextlib.ExitStack() as stack:
            for method in methods:
                together = getattr(get_method(method, registry).load_class(), "warm_up_together", None)
                if together is not None:
                    stack.enter_context(together())
            for method in methods:
                warm_up_method(method, registry, announce)
    except Exception as exc:  # noqa: BLE001 -- reported: under its method below, or as itself if it does not recur
        failures: list[str] = []
        for method in methods:
            try:
                warm_up_method(method, registry, announce)
            except Exception as again:  # noqa: BLE001 -- each method's own failure, reported under its name
                failures.append(f"method {method}: warm-up: {type(again).__name__}: {again}")
        if failures:
            return WarmUpOutcome(failures=failures)
        return WarmUpOutcome(
            joint_failure=f"methods {', '.join(methods)}: warm-up together: {type(exc).__name__}: {exc} "
            "(each method's warm-up alone then succeeded)"
        )
    return WarmUpOutcome()


def warm_up_method(
    method: str, registry: MethodRegistry | None = None, announce: Callable[[str], None] | None = None
) -> None:
    """Run ``method``'s optional ``warm_up`` once for each of its presets (nothing for a method without one).

    Every preset: a preset's warm-up may leave out kernels that only the
    others call. Methods without ``warm_up`` are not built.
    """
    from albot1.methods.registry import get_method, resolve_config

    cls = get_method(method, registry).load_class()
    if not has_warm_up(cls):
        return
    for preset in cls.presets:
        cls(resolve_config(method, preset, registry=registry), seed=0).warm_up(announce)  # type: ignore[attr-defined]
