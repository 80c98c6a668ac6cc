"""The degeneracy screen's linear algebra (Albot1+), as one compiled call instead of a dozen numpy calls per view.

:func:`albot1.methods.albot1.mapping.screen.screen_measurement` decides what
to do with a view's pose fit; this kernel does its arithmetic: the
eigendecomposition of the fit's information in scaled units, the
disagreement with the odometry along the kept directions, the pose that
keeps the odometry's component along the others and the information left.
Issue 24 asked for Albot1+'s per-scan cost without changing its poses, so
every operation is the one the numpy code did, in the same order, and gives
the same bits:

* ``np.linalg.eigh`` compiles to the same LAPACK routine (``dsyevd``) numpy
  calls;
* the products are ``np.dot`` calls, i.e. BLAS ``dgemv`` / ``dgemm`` as in
  numpy's ``@``. Which BLAS kernel (``gemv`` transposed or not) a product
  runs follows the operands' memory layout, so each operand is given the
  layout that reproduces numpy's choice: a row-major copy of ``basis.T`` for
  the disagreement (``basis.T @ v`` in numpy), a column-major one for a single
  kept direction and for ``basis @ z``; the information kept, a matrix product
  (``dgemm`` in numpy), is computed column by column with that column-major
  ``dgemv``, which gave the same bits on the Intel Xeon this was written on
  and spares compiling a third variant. (On an AMD EPYC, OpenBLAS's ``dgemm``
  and ``dgemv`` round the last bit of this product differently, so there the
  information kept differs from the old numpy code's by at most one unit in
  the last place of its largest entry; the poses stay deterministic on each
  machine.)
  These layouts were found by comparing
  bits (numba calls SciPy's BLAS, numpy its own), and the parity tests
  (``tests/unit/methods/albot1/mapping/test_albot1_screen_kernels.py``)
  compare the kernel with numpy's expressions on random and degenerate
  matrices, so a BLAS that rounds differently fails there, not silently in
  the poses.
"""

from __future__ import annotations

import numpy as np

from albot1.geometry.se2 import wrap_angle
from albot1.geometry.types import FloatArray
from albot1.methods.albot1.compiled import kernel


@kernel
def screen_directions(
    mx: float,
    my: float,
    mphi: float,
    info: FloatArray,
    px: float,
    py: float,
    pphi: float,
    m_per_rad: float,
    floor: float,
) -> tuple[FloatArray, FloatArray, FloatArray, float, float, float, FloatArray]:
    """Screen measured pose ``(mx, my, mphi)``, information ``info`` (3x3), against prediction ``(px, py, pphi)``.

    Units: a turn of 1 rad counts ``m_per_rad`` metres; a direction is kept
    when its eigenvalue exceeds ``floor`` (``1 / degenerate_sd^2``, or 0).
    Returns ``(eigval (3,), basis (3, kept), z (kept,), x, y, phi,
    info_kept (3, 3))``: the eigenvalues, the kept eigenvectors (columns),
    the disagreement along them (m), the pose keeping the odometry's
    component along the dropped directions and the information along the
    kept ones; with no direction kept, the prediction and zeros.
    """
    scale = np.empty(3)
    scale[0] = 1.0
    scale[1] = 1.0
    scale[2] = m_per_rad
    scale2 = np.empty((3, 3))
    info_u = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            scale2[i, j] = scale[i] * scale[j]
            info_u[i, j] = info[i, j] / scale2[i, j]
    sym = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            sym[i, j] = 0.5 * (info_u[i, j] + info_u[j, i])
    eigval, eigvec = np.linalg.eigh(sym)
    keep = eigval > max(floor, 0.0)
    basis = eigvec[:, keep]
    kept_n = basis.shape[1]
    if kept_n == 0:  # (np.empty and a loop, not np.zeros: one numpy routine less to compile)
        nothing = np.empty((3, 3))
        for i in range(3):
            for j in range(3):
                nothing[i, j] = 0.0
        return eigval, basis, np.empty(0), px, py, pphi, nothing
    delta = np.empty(3)
    delta[0] = scale[0] * (mx - px)
    delta[1] = scale[1] * (my - py)
    delta[2] = scale[2] * wrap_angle(mphi - pphi)
    if kept_n == 1:
        z = np.dot(np.asfortranarray(basis.T), delta)
    else:
        z = np.dot(np.ascontiguousarray(basis.T), delta)
    kept = np.dot(np.asfortranarray(basis), z)
    x = px + kept[0] / scale[0]
    y = py + kept[1] / scale[1]
    phi = wrap_angle(pphi + kept[2] / scale[2])
    # (basis * eigval) @ basis.T one column at a time: the same bits as numpy's dgemm here, and one np.dot variant
    # fewer to compile (each costs 0.3-0.5 s of a cold warm-up).
    weighted = np.asfortranarray(basis * eigval[keep])
    info_kept = np.empty((3, 3))
    for j in range(3):
        column = np.dot(weighted, np.ascontiguousarray(basis[j, :]))
        for i in range(3):
            info_kept[i, j] = column[i] * scale2[i, j]
    return eigval, basis, z, x, y, phi, info_kept
