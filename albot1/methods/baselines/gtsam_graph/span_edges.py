"""Edges spanning runs of node steps (``span_nodes``; measured, off: docs/baselines.md, gtsam-graph, "edges
spanning runs of steps").

A node's sequential edge ties it to the node before only, although its match
was made against the local map of the last ``local_map_nodes`` node scans.
The match's heading error then enters the graph as one step's error, and
the next match, made against a local map that holds the node as placed,
largely takes it back (lag-1 autocorrelation of the matches' heading errors
-0.27 on edmonton-corrected, docs/baselines.md, "where edmonton's 0.30 m
is"). What is left of such pairs random-walks into the heading of the route.
A between edge from node ``key - span_nodes`` to the new node, from a match
of the new node's scan against the scans of ``span_map_nodes`` nodes ending
at ``key - span_nodes`` (placed with their current estimates, in that
node's frame), constrains the heading over ``span_nodes`` steps at once:
per-step errors that cancel within the run do not reach it, and the graph
sees the run's heading measured directly instead of as a sum of steps.

The match is an ordinary sequential match (the sequential ICP and its
tests, :meth:`.FrontEnd.attempt`), from the guess the new node's edge
gives; a match that fails them adds no edge. Its covariance is the match's
own plus the floor, like a sequential edge's.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from albot1.geometry import se2
from albot1.geometry.types import FloatArray


@dataclass(frozen=True)
class SpanEdge:
    """A between edge ``x_first^-1 * x_key = relative`` from a match spanning ``key - first`` node steps."""

    first: int
    key: int
    relative: FloatArray
    covariance: FloatArray
    #: the robust kernel on the edge: a span match's is ``span_kernel``; an odometry run factor has none
    kernel: Literal["cauchy", "huber", "none"] = "none"


def span_target_nodes(key: int, span: int, map_nodes: int) -> range:
    """The nodes whose scans the new node ``key`` is matched against: ``map_nodes`` ending at ``key - span``.

    Empty when ``key - span`` does not exist yet (the first ``span`` nodes get no span edge).
    """
    first = key - span
    if span < 2 or first < 0:
        return range(0)
    return range(max(0, first - map_nodes + 1), first + 1)


def span_guess(estimates: FloatArray, first: int, newest: int, relative: FloatArray) -> FloatArray:
    """The new node's pose in node ``first``'s frame: the newest node's estimate composed with its new edge."""
    return se2.between(estimates[first], se2.compose(estimates[newest], np.asarray(relative, dtype=float)))
