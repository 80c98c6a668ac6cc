"""``"module:Class"`` strings -> the objects they name (plugins, lazily imported classes).

The registries name their classes by such strings so that a heavy library
(gtsam, rosbags, ...) is imported only when its class is used, and so that a
benchmark suite can name a mapper outside the package. The one resolver is
:func:`pkgutil.resolve_name`; this module adds the syntax check (exactly
``dotted.module:Attribute``, since ``resolve_name`` would also accept the
ambiguous colon-less form) and turns its failures into a :class:`TargetError`
naming the target.
"""

from __future__ import annotations

import importlib
import pkgutil
import re

from albot1.errors import ConfigError

_IDENTIFIER = r"[A-Za-z_][A-Za-z0-9_]*"
_TARGET = re.compile(rf"{_IDENTIFIER}(?:\.{_IDENTIFIER})*:{_IDENTIFIER}(?:\.{_IDENTIFIER})*")


class TargetError(ConfigError):
    """A ``module:Class`` string is malformed, or its module or attribute cannot be loaded."""


def check_target(target: str) -> str:
    """``target`` unchanged if it reads ``dotted.module:Attribute``; else TargetError."""
    if not _TARGET.fullmatch(target):
        raise TargetError(f"expected 'module:Class' (a dotted module path, a colon, a class name), got {target!r}")
    return target


def resolve_target(target: str) -> object:
    """Import the module of ``target`` and return its attribute.

    An ImportError of the module (a missing optional dependency, a broken
    plugin) stays chained to the TargetError, so its traceback is kept for
    whoever logs it; so does any other exception the module's code raises as
    it is imported, ``SystemExit`` included (a third-party module must not end
    the command, or exit 0 from it with nothing done).
    """
    check_target(target)
    module = target.partition(":")[0]
    try:
        importlib.import_module(module)
    except ImportError as exc:
        raise TargetError(f"{target}: the module {module} cannot be imported: {exc}") from exc
    except KeyboardInterrupt:
        raise
    except BaseException as exc:  # a plugin's module that fails or calls sys.exit() as it is imported
        what = f"SystemExit({exc.code!r}) (sys.exit)" if isinstance(exc, SystemExit) else f"{type(exc).__name__}: {exc}"
        raise TargetError(f"{target}: the module {module} cannot be imported: importing it raised {what}") from exc
    try:
        return pkgutil.resolve_name(target)
    except AttributeError:
        raise TargetError(f"{target}: the module {module} has no attribute {target.partition(':')[2]!r}") from None


def resolve_class(target: str) -> type:
    """:func:`resolve_target`, checked to be a class."""
    obj = resolve_target(target)
    if not isinstance(obj, type):
        raise TargetError(f"{target}: expected a class, found {type(obj).__name__}")
    return obj
