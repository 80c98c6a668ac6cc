"""ICP's Gauss-Newton loop in one compiled call, calling numpy's own BLAS and LAPACK functions as numpy calls them.

Why: after the grid search was compiled (:mod:`.nearest`), two thirds of an
ICP iteration's CPU were the numpy calls around it: the rotation ``src @ R``,
``wj.T @ jac``, ``wj.T @ res``, ``prior @ offset`` and ``np.linalg.solve``,
each a few microseconds of Python and numpy dispatch around a BLAS or
LAPACK call of well under one (docs/baselines.md, "Cost (issue 24), fourth
round"). Those products cannot be written out in numba with the same bits:
OpenBLAS picks its kernel (and its order of fused multiply-adds) for the CPU
at run time. So this module does not reproduce them; it calls the very
functions numpy's ``matmul`` and ``linalg.solve`` call, in numpy's own
library (the ``scipy-openblas64`` of numpy's wheels), with the arguments
numpy passes (numpy 2's ``matmul.c.src`` and ``umath_linalg.cpp``):

* ``src @ R``, ``(n, 2)`` C-ordered times ``(2, 2)`` C-ordered:
  ``cblas_dgemm(RowMajor, NoTrans, NoTrans, n, 2, 2, 1, src, 2, R, 2, 0, out, 2)``;
* ``wj.T @ jac``, the transpose of the first ``m`` rows of a C-ordered ``(n, 3)``
  buffer times those of another: ``cblas_dgemm(RowMajor, Trans, NoTrans, 3, 3, m, 1, wj, 3, jac, 3, 0, out, 3)``;
* ``wj.T @ res`` (matrix times vector): ``cblas_dgemv(RowMajor, Trans, m, 3, 1, wj, 3, res, 1, 0, out, 1)``;
* ``prior @ offset``, C-ordered ``(3, 3)`` times ``(3,)``:
  ``cblas_dgemv(ColMajor, Trans, 3, 3, 1, prior, 3, offset, 1, 0, out, 1)``;
* ``np.linalg.solve(A, b)`` (``solve1``): ``dgesv(3, 1, A in column order, 3, ipiv, b, 3, info)``,
  NaN where ``info`` is not 0 (numpy raises ``LinAlgError`` there, and ICP stops either way).

(numpy takes these branches for at least two rows and two matches, which
:func:`.registration.register` checks.) The same functions with the same
arguments on the same data: the same bits (the unit tests compare them with
numpy's). Everything else in the loop is the grid search and the terms of
:mod:`.nearest`, the additions and the negation numpy did elementwise, and
what Python did with the step: CPython's ``math.cos`` and ``math.sin`` are
C's ``cos`` and ``sin``, called here too (not numba's, which are LLVM's);
``math.remainder`` and ``math.hypot`` are written out step for step
(:func:`python_remainder`, Albot1's ``python_hypot``). The C functions are
found by their symbols in numpy's library and the C library (:func:`bind`);
where they are not there (another BLAS) or numba is switched off,
:func:`available` is False and ICP keeps numpy's calls
(:func:`.registration._iterate`). A query the grid search cannot answer for
sure still goes to the k-d tree: the compiled loop returns for it and resumes.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import functools
import glob
import math
import os
from collections.abc import Callable
from typing import Any

import numpy as np
from numba import types

from albot1.geometry.types import FloatArray
from albot1.methods.albot1 import compiled
from albot1.methods.albot1.compiled import jitable, kernel
from albot1.methods.albot1.mapping.localise_kernels import python_hypot
from albot1.methods.baselines.gtsam_graph.block_sums import DEPTH, pairwise_sum
from albot1.methods.baselines.gtsam_graph.nearest import AMBIGUOUS, IntArray, _nearest_one, _terms
from albot1.methods.baselines.gtsam_graph.warming import warm_kernels

#: numpy's BLAS and LAPACK functions this module calls, by their symbols in numpy's scipy-openblas64 library
SYMBOLS = ("scipy_cblas_dgemm64_", "scipy_cblas_dgemv64_", "scipy_dgesv_64_")
#: the library's file name in numpy's wheels (``numpy.libs`` on Linux, ``numpy/.dylibs`` on macOS)
LIBRARY_GLOB = "libscipy_openblas64_*"

# CBLAS's enums (C ints) and the ILP64 integers of the 64_ symbols; the functions typed Any for mypy (numba types them)
_ROW, _COL, _NOTRANS, _TRANS = 101, 102, 111, 112
_i32, _i64, _f64, _ptr = types.int32, types.int64, types.float64, types.voidptr
_dgemm: Any = types.ExternalFunction(
    SYMBOLS[0], types.void(_i32, _i32, _i32, _i64, _i64, _i64, _f64, _ptr, _i64, _ptr, _i64, _f64, _ptr, _i64)
)
_dgemv: Any = types.ExternalFunction(
    SYMBOLS[1], types.void(_i32, _i32, _i64, _i64, _f64, _ptr, _i64, _ptr, _i64, _f64, _ptr, _i64)
)
_dgesv: Any = types.ExternalFunction(SYMBOLS[2], types.void(_ptr, _ptr, _ptr, _ptr, _ptr, _ptr, _ptr, _ptr))
#: the C library's ``cos``, ``sin`` and ``fmod`` that CPython's ``math.cos``, ``math.sin`` and ``math.remainder``
#: call, under names of our own (numba's ``math.cos`` is LLVM's, which need not be the same function; numba has
#: no ``math.fmod``)
LIBM = {"albot1_gtsam_graph_cos": "cos", "albot1_gtsam_graph_sin": "sin", "albot1_gtsam_graph_fmod": "fmod"}
_cos: Any = types.ExternalFunction("albot1_gtsam_graph_cos", types.float64(types.float64))
_sin: Any = types.ExternalFunction("albot1_gtsam_graph_sin", types.float64(types.float64))
_fmod: Any = types.ExternalFunction("albot1_gtsam_graph_fmod", types.float64(types.float64, types.float64))

#: the scratch buffer's layout: the rotation (2x2), J^T W J + prior (3x3), its column-ordered copy for LAPACK,
#: J^T W r, prior @ offset, the offset, the solution (negated: the step), and the final terms' J^T W J (3x3)
_R, _A, _AF, _G, _P, OFFSET, STEP, INFORMATION, SCRATCH = 0, 4, 13, 22, 25, 28, 31, 34, 43


@functools.cache
def bind() -> bool:
    """Whether numpy's BLAS and LAPACK functions and C's ``cos``, ``sin``, ``fmod`` were made known to numba (once).

    The library is the one in numpy's own wheel folder, which numpy's
    extension modules load; a numpy built against another BLAS has no such
    file (or not these symbols), and ICP then keeps numpy's calls.
    """
    from llvmlite import binding as llvm

    root = os.path.dirname(os.path.abspath(np.__file__))
    found = sorted(
        glob.glob(os.path.join(root, os.pardir, "numpy.libs", LIBRARY_GLOB + ".so"))
        + glob.glob(os.path.join(root, ".dylibs", LIBRARY_GLOB + ".dylib"))
    )
    if len(found) != 1:
        return False
    libm = ctypes.util.find_library("m")
    if libm is None:
        return False
    try:
        library, c_library = ctypes.CDLL(found[0]), ctypes.CDLL(libm)
        addresses = {name: ctypes.cast(getattr(library, name), ctypes.c_void_p).value for name in SYMBOLS}
        addresses.update(
            {ours: ctypes.cast(getattr(c_library, theirs), ctypes.c_void_p).value for ours, theirs in LIBM.items()}
        )
    except (OSError, AttributeError):
        return False
    for name, address in addresses.items():
        llvm.add_symbol(name, address)
    return True


def available() -> bool:
    """Whether ICP iterates in :func:`icp_run` (the C functions bound, numba compiling) or through numpy's calls."""
    return hasattr(icp_run, "py_func") and bind()  # a plain function where NUMBA_DISABLE_JIT is set


@jitable
def _solve_step(
    m: int, jac: FloatArray, res: FloatArray, wj: FloatArray, prior: FloatArray, scratch: FloatArray
) -> None:
    """``scratch[STEP:STEP + 3]``: ``-solve(wj.T @ jac + prior, wj.T @ res + prior @ offset)``, first ``m`` rows."""
    a, g, p = scratch[_A : _A + 9], scratch[_G : _G + 3], scratch[_P : _P + 3]
    _dgemm(_ROW, _TRANS, _NOTRANS, 3, 3, m, 1.0, wj.ctypes, 3, jac.ctypes, 3, 0.0, a.ctypes, 3)
    _dgemv(_ROW, _TRANS, m, 3, 1.0, wj.ctypes, 3, res.ctypes, 1, 0.0, g.ctypes, 1)
    _dgemv(_COL, _TRANS, 3, 3, 1.0, prior.ctypes, 3, scratch[OFFSET : OFFSET + 3].ctypes, 1, 0.0, p.ctypes, 1)
    af, x = scratch[_AF : _AF + 9], scratch[STEP : STEP + 3]
    for i in range(3):
        for j in range(3):
            a[i * 3 + j] = a[i * 3 + j] + prior[i, j]
            af[j * 3 + i] = a[i * 3 + j]  # numpy hands LAPACK a column-ordered copy
        x[i] = g[i] + p[i]
    ints = np.empty(7, dtype=np.int64)  # n, nrhs, lda (= ldb), info, ipiv[3]
    ints[0], ints[1], ints[2], ints[3] = 3, 1, 3, 0
    _dgesv(
        ints[0:].ctypes, ints[1:].ctypes, af.ctypes, ints[2:].ctypes, ints[4:].ctypes, x.ctypes, ints[2:].ctypes,
        ints[3:].ctypes,
    )  # fmt: skip
    for i in range(3):
        x[i] = -x[i] if ints[3] == 0 else np.nan


#: ``knobs``, set once per registration: the iteration limit, the gates, the terms' scales, the tolerances,
#: the least match count and the initial pose
(
    K_ITERATIONS,
    K_MIN_GATE,
    K_CAUCHY,
    K_INV_VAR,
    K_DECAY,
    K_TOL_M,
    K_TOL_RAD,
    K_SETTLE,
    K_LEAST,
    K_X0,
    K_Y0,
    K_THETA0,
) = range(12)
KNOBS = 12
#: ``state``, carried across calls: the pose, the gate, the iteration, whether it settled or converged, whether
#: the next call resumes an iteration whose ambiguous queries the k-d tree answered, whether the loop is over and
#: the final terms are being found, and what they gave: the inliers and their RMS residual
S_X, S_Y, S_THETA, S_GATE, S_ITERATION, S_SETTLED, S_CONVERGED, S_RESUME, S_FINAL, S_INLIERS, S_RMSE = range(11)
STATE = 11
#: :func:`icp_run`'s outcomes: done, ambiguous queries to answer (then call again), a gate that is not usable
DONE, ASK_TREE, BAD_GATE = 0, 1, 2


@jitable
def _correspond(
    origin: FloatArray,
    dims: IntArray,
    cell: float,
    starts: IntArray,
    xy: FloatArray,
    order: IntArray,
    src: FloatArray,
    x: float,
    y: float,
    theta: float,
    gate: float,
    idx: IntArray,
    rot: FloatArray,
    scratch: FloatArray,
) -> int:
    """``src`` turned by ``theta`` into ``rot``, each point's nearest line within ``gate`` of ``(x, y)`` in ``idx``.

    One iteration's correspondences as :func:`.nearest.linearise_terms` finds
    them (the rotation by CPython's ``cos`` and ``sin`` and numpy's dgemm, the
    grid search): :data:`DONE`, :data:`BAD_GATE` for a gate that is not
    usable, or :data:`ASK_TREE` with the ambiguous queries marked
    :data:`.nearest.AMBIGUOUS` for the k-d tree. The loop and the final terms
    call it alike.
    """
    if not (math.isfinite(gate) and gate > 0):
        return BAD_GATE
    n = src.shape[0]
    c, s = _cos(theta), _sin(theta)
    scratch[_R], scratch[_R + 1], scratch[_R + 2], scratch[_R + 3] = c, s, -s, c
    _dgemm(
        _ROW, _NOTRANS, _NOTRANS, n, 2, 2, 1.0, src.ctypes, 2, scratch[_R : _R + 4].ctypes, 2, 0.0, rot.ctypes, 2
    )  # fmt: skip
    gate2 = gate * gate
    ambiguous = False
    for i in range(n):
        at, unsure = _nearest_one(origin, dims, cell, starts, xy, rot[i, 0] + x, rot[i, 1] + y, gate2)
        if unsure:
            idx[i] = AMBIGUOUS
            ambiguous = True
        else:
            idx[i] = order[at] if at >= 0 else -1
    return ASK_TREE if ambiguous else DONE


@jitable
def python_remainder(x: float, y: float) -> float:
    """``math.remainder(x, y)`` as CPython 3.11 computes it (``m_remainder``), step for step: every step is exact.

    numba has no ``math.remainder``; CPython's is C's ``fmod`` of the magnitudes (bound by :func:`bind`), the
    nearer of the two candidates, the half-way case to the even multiple, and the sign of ``x``.
    """
    if math.isfinite(x) and math.isfinite(y):
        if y == 0.0:
            return math.nan
        absx, absy = abs(x), abs(y)
        m = _fmod(absx, absy)
        c = absy - m
        if m < c:
            r = m
        elif m > c:
            r = -c
        else:
            r = m - 2.0 * _fmod(0.5 * (absx - m), absy)
        signed: float = math.copysign(1.0, x) * r
        return signed
    if math.isnan(x):
        return x
    if math.isnan(y):
        return y
    if math.isinf(x):
        return math.nan
    return x


@kernel
def icp_run(
    origin: FloatArray,
    dims: IntArray,
    cell: float,
    starts: IntArray,
    xy: FloatArray,
    order: IntArray,
    lines: FloatArray,
    src: FloatArray,
    prior: FloatArray,
    knobs: FloatArray,
    state: FloatArray,
    idx: IntArray,
    jac: FloatArray,
    res: FloatArray,
    w: FloatArray,
    wj: FloatArray,
    rot: FloatArray,
    scratch: FloatArray,
) -> int:
    """:func:`.registration.register`'s Gauss-Newton loop from ``state`` on, compiled: :data:`DONE` or why it stopped.

    Each iteration as the numpy loop did it: the rotation by CPython's own
    ``cos`` and ``sin`` and numpy's dgemm, the correspondences and terms of
    :mod:`.nearest`, the step by numpy's BLAS and LAPACK (:func:`_solve_step`),
    the pose update with ``math.remainder``'s bits (:func:`python_remainder`),
    the convergence tests with ``math.hypot``'s (``python_hypot``), and the
    gate annealed as Python's ``max`` picks. An iteration with an ambiguous
    query stops at :data:`ASK_TREE` (``rot`` and ``idx`` as
    :func:`.nearest.linearise_terms` leaves them); the caller fills ``idx``
    from the k-d tree, sets ``state[S_RESUME]`` and calls again. After the
    loop the same call finds the terms ``register`` reports
    (:func:`_final_terms`; ``state[S_FINAL]`` set, the gate at its minimum).
    """
    if state[S_FINAL] != 0.0:
        return _final_terms(
            origin, dims, cell, starts, xy, order, lines, src, knobs, state, idx, jac, res, w, wj, rot, scratch
        )  # fmt: skip
    tau = 2.0 * math.pi
    x, y, theta, gate = state[S_X], state[S_Y], state[S_THETA], state[S_GATE]
    it, settled, converged = int(state[S_ITERATION]), state[S_SETTLED] != 0.0, False
    resume = state[S_RESUME] != 0.0
    last, least, min_gate = int(knobs[K_ITERATIONS]), int(knobs[K_LEAST]), knobs[K_MIN_GATE]
    tol_m, tol_rad, settle = knobs[K_TOL_M], knobs[K_TOL_RAD], knobs[K_SETTLE]
    status = DONE
    while it <= last:
        if not resume:
            status = _correspond(origin, dims, cell, starts, xy, order, src, x, y, theta, gate, idx, rot, scratch)
            if status != DONE:
                break
        resume = False
        m = _terms(lines, rot, x, y, knobs[K_CAUCHY], knobs[K_INV_VAR], idx, jac, res, w, wj)
        if m < least:
            break
        scratch[OFFSET] = x - knobs[K_X0]
        scratch[OFFSET + 1] = y - knobs[K_Y0]
        scratch[OFFSET + 2] = python_remainder(theta - knobs[K_THETA0], tau)
        _solve_step(m, jac, res, wj, prior, scratch)
        dx, dy, dtheta = scratch[STEP], scratch[STEP + 1], scratch[STEP + 2]
        if not (math.isfinite(dx) and math.isfinite(dy) and math.isfinite(dtheta)):
            break
        x, y, theta = x + dx, y + dy, python_remainder(theta + dtheta, tau)
        moved, turned = python_hypot(dx, dy), abs(dtheta)
        if moved < tol_m and turned < tol_rad and gate <= min_gate:
            converged = True
            break
        settled = gate <= min_gate and moved < settle * tol_m and turned < settle * tol_rad
        shrunk = gate * knobs[K_DECAY]
        gate = shrunk if shrunk > min_gate else min_gate  # Python's max(min_gate, shrunk): the first unless exceeded
        it += 1
    state[S_X], state[S_Y], state[S_THETA], state[S_GATE] = x, y, theta, gate
    state[S_ITERATION] = it
    state[S_SETTLED] = 1.0 if settled else 0.0
    state[S_CONVERGED] = 1.0 if converged else 0.0
    state[S_RESUME] = 0.0
    if status != DONE:
        return status
    state[S_FINAL], state[S_GATE] = 1.0, min_gate
    return _final_terms(
        origin, dims, cell, starts, xy, order, lines, src, knobs, state, idx, jac, res, w, wj, rot, scratch
    )  # fmt: skip


@jitable
def _final_terms(
    origin: FloatArray,
    dims: IntArray,
    cell: float,
    starts: IntArray,
    xy: FloatArray,
    order: IntArray,
    lines: FloatArray,
    src: FloatArray,
    knobs: FloatArray,
    state: FloatArray,
    idx: IntArray,
    jac: FloatArray,
    res: FloatArray,
    w: FloatArray,
    wj: FloatArray,
    rot: FloatArray,
    scratch: FloatArray,
) -> int:
    """The terms at the final pose within the smallest gate, their ``J^T W J`` and RMS: what ``register`` reports.

    What :func:`.registration.register` computed after the loop with numpy's
    calls (``_linearise`` at the final pose and ``min_correspondence_m``,
    ``wj.T @ jac``, ``sqrt(mean(res ** 2))``), here with the same operations:
    the rotation and the search as an iteration does them, ``wj.T @ jac`` by
    the dgemm numpy calls (into ``scratch[INFORMATION:]``, for at least two
    inliers; the caller has numpy multiply one), the squares summed as
    ``np.add.reduce`` sums them (:func:`.block_sums.pairwise_sum`, from 0.0),
    divided by the count, and the square root (exact either way).
    ``state[S_INLIERS]`` and ``state[S_RMSE]`` receive the count and the RMS.
    An ambiguous query stops at :data:`ASK_TREE` as in the loop; a gate that
    is not usable at :data:`BAD_GATE`.
    """
    x, y, theta, gate = state[S_X], state[S_Y], state[S_THETA], state[S_GATE]
    if state[S_RESUME] == 0.0:
        status = _correspond(origin, dims, cell, starts, xy, order, src, x, y, theta, gate, idx, rot, scratch)
        if status != DONE:
            return status
    state[S_RESUME] = 0.0
    m = _terms(lines, rot, x, y, knobs[K_CAUCHY], knobs[K_INV_VAR], idx, jac, res, w, wj)
    state[S_INLIERS] = m
    if m >= 2:
        info = scratch[INFORMATION : INFORMATION + 9]
        _dgemm(_ROW, _TRANS, _NOTRANS, 3, 3, m, 1.0, wj.ctypes, 3, jac.ctypes, 3, 0.0, info.ctypes, 3)
    if m > 0:
        for i in range(m):  # the weights are not reported: their buffer takes the squares
            w[i] = res[i] * res[i]
        total = 0.0 + pairwise_sum(w, m, np.empty((DEPTH, 3), dtype=np.int64), np.empty(DEPTH))
        state[S_RMSE] = math.sqrt(total / m)
    return DONE


@kernel
def rotate_runs(vectors: FloatArray, angles: FloatArray, counts: IntArray, out: FloatArray) -> None:
    """Each run of ``vectors`` (``counts[r]`` rows, in order) turned by ``angles[r]`` into ``out``, as
    :func:`.registration.rotate` turns it: CPython's ``cos`` and ``sin``, numpy's dgemm with numpy's arguments.

    Runs of fewer than two rows are left as they are (numpy's matmul takes
    another branch for a single row; the caller has numpy turn it).
    """
    turn = np.empty(4)
    start = 0
    for r in range(counts.shape[0]):
        n = counts[r]
        if n >= 2:
            c, s = _cos(angles[r]), _sin(angles[r])
            turn[0], turn[1], turn[2], turn[3] = c, s, -s, c
            _dgemm(
                _ROW, _NOTRANS, _NOTRANS, n, 2, 2, 1.0, vectors[start:].ctypes, 2, turn.ctypes, 2, 0.0,
                out[start:].ctypes, 2,
            )  # fmt: skip
        start += n


def sample_calls() -> list[tuple[str, Callable[..., Any], tuple[Any, ...]]]:
    """``(kernel name, kernel, arguments)`` typed as :func:`.registration.register` calls :func:`icp_run`, and as
    :func:`.registration.rotate_runs` calls :func:`rotate_runs` (bundle).

    None where :func:`available` is False: the kernel cannot be linked there, and ICP never calls it.
    """
    if not available():
        return []
    from albot1.methods.baselines.gtsam_graph.nearest import CELL_M, MAX_CELLS_PER_POINT, _sample, build_grid

    points, normals, source = _sample()
    pts = np.ascontiguousarray(points, dtype=np.float64)
    origin, dims, cell, starts, order = compiled.as_written(build_grid)(pts, CELL_M, MAX_CELLS_PER_POINT)
    xy = np.ascontiguousarray(pts[order])
    n = len(source)
    knobs = np.array([3.0, 0.2, 0.1, 400.0, 0.7, 5e-4, 1e-4, 10.0, 1.0, 0.0, 0.0, 0.0])
    state = np.array([0.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    buffers = (np.empty((n, 3)), np.empty(n), np.empty(n), np.empty((n, 3)), np.empty((n, 2)), np.zeros(SCRATCH))
    args = (
        origin,
        dims,
        float(cell),
        starts,
        xy,
        order,
        np.hstack([points, normals]),
        source,
        np.diag([1.0, 1.0, 25.0]),
    )
    runs = (source, np.array([0.3]), np.array([n], dtype=np.int64), np.empty_like(source))
    return [
        ("gtsam_graph.icp_run", icp_run, (*args, knobs, state, np.zeros(n, dtype=np.int64), *buffers)),
        ("gtsam_graph.rotate_runs", rotate_runs, runs),
    ]


def warm_up(announce: Callable[[str], None] | None = None) -> None:
    """Compile :func:`icp_run` (or load numba's cache or the wheel's bundle) before a run's first scan.

    Nothing to do where :func:`available` is False (ICP then never calls it). The first sample query is an exact
    tie: it stops at ``ASK_TREE``, typed as a run calls it.
    """
    if available():
        warm_kernels((icp_run, rotate_runs), sample_calls, "ICP step", announce)
