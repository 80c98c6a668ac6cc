"""Third-party methods: the installed entry points of group ``albot1.methods``.

A distribution that ships a mapper declares it the way pytest plugins are
declared, in its packaging metadata::

    [project.entry-points."albot1.methods"]
    my-slam = "my_slam.mapper:MySlamMapper"

The entry point's name is the method name, its value the mapper class
(``module:Class``). Reading the entry points imports nothing (they come
from each distribution's ``entry_points.txt``); the class's module is
imported only when the method is run or its config resolved, exactly as for
a built-in method. A benchmark suite names methods only, so a suite file
cannot make the tool import a module that no installed distribution
declares (docs/benchmarking.md).
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass
from importlib.metadata import EntryPoint, entry_points

from albot1.config.env import method_prefix
from albot1.config.targets import TargetError, check_target
from albot1.methods.errors import PluginError

#: The entry point group that registers a method.
ENTRY_POINT_GROUP = "albot1.methods"

#: The error class a plugin's failures are reported as (the runner wraps any other exception in it).
PLUGIN_ERROR_CLASS = "albot1.methods.errors:PluginMethodError"


#: What a method's name may be: it is typed on command lines, makes the ``ALBOT1_<NAME>_`` variables' prefix and a
#: suite's ``name:preset`` column. A plugin ``my slam`` could set no variable, and ``odometry:fast`` read in every
#: report as the built-in ``odometry`` under a preset ``fast``.
METHOD_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_-]*")


def _distribution(point: EntryPoint) -> str:
    dist = point.dist
    return f"{dist.name} {dist.version}" if dist is not None else "an unknown distribution"


@dataclass(frozen=True)
class Plugin:
    """One declared method: its name, its mapper class (``module:Class``) and the distribution declaring it."""

    name: str
    target: str
    source: str


def plugin(point: EntryPoint) -> Plugin:
    """The method an entry point declares; PluginError (one line) when its name is no method name
    (:data:`METHOD_NAME`) or its value is not ``module:Class``."""
    if not METHOD_NAME.fullmatch(point.name):
        raise PluginError(
            f"entry point {point.name!r} of {_distribution(point)} (group {ENTRY_POINT_GROUP}): a method name is "
            "letters, digits, '-' and '_', starting with a letter or digit (it is typed on command lines, names "
            "ALBOT1_<METHOD>_ variables and a suite's name:preset columns); the plugin must choose another name"
        )
    try:
        check_target(point.value)
    except TargetError:
        raise PluginError(
            f"entry point {point.name!r} of {_distribution(point)} (group {ENTRY_POINT_GROUP}): expected "
            f"'module:Class' naming a mapper class, got {point.value!r}"
        ) from None
    return Plugin(point.name, point.value, _distribution(point))


def installed_plugins(builtin: Iterable[str]) -> list[Plugin]:
    """The installed plugins' methods, by name; PluginError when one takes a built-in method's name.

    A name is taken by its environment prefix too (``ALBOT1_<METHOD>_``, upper case, dashes as underscores,
    :func:`albot1.config.env.method_prefix`): a plugin ``kiss_icp`` would otherwise read the variables meant
    for the built-in ``kiss-icp`` (and a suite's typo ``kiss_icp`` would run the plugin instead of a "did you
    mean").
    """
    taken = {method_prefix(name): name for name in builtin}
    seen: dict[str, EntryPoint] = {}
    prefixes: dict[str, EntryPoint] = {}
    out = []
    for point in sorted(entry_points(group=ENTRY_POINT_GROUP), key=lambda p: p.name):
        prefix = method_prefix(point.name)
        if prefix in taken:
            same = taken[prefix] == point.name
            raise PluginError(
                f"entry point {point.name!r} of {_distribution(point)} (group {ENTRY_POINT_GROUP}) takes the name "
                + ("of a built-in method" if same else f"{taken[prefix]!r} of a built-in method as {prefix}* variables")
                + "; the plugin must choose another name"
            )
        other = prefixes.setdefault(prefix, point)
        if other.name != point.name:
            raise PluginError(
                f"methods {other.name!r} ({_distribution(other)}) and {point.name!r} ({_distribution(point)}) of "
                f"group {ENTRY_POINT_GROUP} would read the same {prefix}* variables; one must choose another name"
            )
        if point.name in seen:
            if seen[point.name].value == point.value:
                continue  # one distribution found twice on sys.path
            raise PluginError(
                f"method {point.name!r} is declared by two entry points of group {ENTRY_POINT_GROUP}: "
                f"{seen[point.name].value} ({_distribution(seen[point.name])}) and {point.value} "
                f"({_distribution(point)}); uninstall one"
            )
        seen[point.name] = point
        out.append(plugin(point))
    return out
