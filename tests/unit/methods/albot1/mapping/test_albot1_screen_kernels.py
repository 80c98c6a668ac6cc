"""The degeneracy screen's kernel gives the bits of the numpy expressions it replaced (issue 24: same poses, cheaper).

``screen_directions`` runs numba's ``eigh`` and BLAS products where the
screen ran numpy's; the reference below is the numpy code as it was, and
both the compiled kernel and its Python source must match it bit for bit on
matrices that keep 0, 1, 2 and 3 directions, on headings across the wrap
and on rank-deficient (corridor) information.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np
import pytest

from albot1.geometry.se2 import wrap_angle
from albot1.methods.albot1.compiled import as_written
from albot1.methods.albot1.mapping.screen_kernels import screen_directions

M_PER_RAD = 0.4
FLOOR = 1.0 / 0.05**2


def numpy_screen(
    measured: tuple[float, float, float], info: np.ndarray, predicted: tuple[float, float, float], floor: float
) -> tuple[np.ndarray, np.ndarray, tuple[float, float, float], np.ndarray]:
    """The screen's arithmetic as numpy expressions (the code before the kernel): basis, z, pose, info kept."""
    scale = np.asarray([1.0, 1.0, M_PER_RAD])
    scale2 = np.outer(scale, scale)
    info_u = np.asarray(info, dtype=float) / scale2
    eigval, eigvec = np.linalg.eigh(0.5 * (info_u + info_u.T))
    keep = eigval > max(floor, 0.0)
    basis = eigvec[:, keep]
    if not keep.any():
        return basis, np.zeros(0), predicted, np.zeros((3, 3))
    delta = np.asarray([measured[0] - predicted[0], measured[1] - predicted[1], wrap_angle(measured[2] - predicted[2])])
    z = basis.T @ (scale * delta)
    kept = (basis @ z) / scale
    pose = (predicted[0] + float(kept[0]), predicted[1] + float(kept[1]), wrap_angle(predicted[2] + float(kept[2])))
    return basis, z, pose, (basis * eigval[keep]) @ basis.T * scale2


def columns_kept(info: np.ndarray, basis: np.ndarray) -> np.ndarray:
    """The information kept as the kernel computes it: numpy's ``dgemv`` one column at a time, then the units."""
    scale2 = np.outer([1.0, 1.0, M_PER_RAD], [1.0, 1.0, M_PER_RAD])
    info_u = np.asarray(info, dtype=float) / scale2
    eigval = np.linalg.eigh(0.5 * (info_u + info_u.T))[0]
    weighted = np.asfortranarray(basis * eigval[eigval > FLOOR])
    out = np.empty((3, 3))
    for j in range(3):
        out[:, j] = np.dot(weighted, np.ascontiguousarray(basis[j, :]))
    return out * scale2


def _cases() -> Iterator[tuple[tuple[float, float, float], np.ndarray, tuple[float, float, float]]]:
    rng = np.random.default_rng(24)
    for _ in range(400):
        rotation, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        eigenvalues = 10.0 ** rng.uniform(1.0, 6.0, 3)  # straddles FLOOR = 400: 0 to 3 directions kept
        info = (rotation * eigenvalues) @ rotation.T * np.outer([1.0, 1.0, M_PER_RAD], [1.0, 1.0, M_PER_RAD])
        measured = (float(rng.normal()), float(rng.normal()), float(rng.uniform(-math.pi, math.pi)))
        predicted = (
            measured[0] + float(rng.normal(0.0, 0.1)),
            measured[1] + float(rng.normal(0.0, 0.1)),
            wrap_angle(measured[2] + float(rng.normal(0.0, 0.2))),  # some across the wrap
        )
        yield measured, np.ascontiguousarray(info), predicted
    corridor = np.zeros((3, 3))
    corridor[1, 1] = 5e4  # a corridor along x: only y is fixed
    yield (0.2, 1.0, 3.1), corridor, (0.0, 0.9, -3.1)
    yield (0.2, 1.0, 0.1), np.zeros((3, 3)), (0.0, 0.9, 0.0)


@pytest.mark.parametrize("compiled", [True, False], ids=["compiled", "as-written"])
def test_the_kernel_gives_the_bits_of_the_numpy_screen(compiled: bool) -> None:
    kernel = screen_directions if compiled else as_written(screen_directions)
    kept_counts = set()
    for measured, info, predicted in _cases():
        basis, z, pose, info_kept = numpy_screen(measured, info, predicted, FLOOR)
        _, k_basis, k_z, x, y, phi, k_info = kernel(*measured, info, *predicted, M_PER_RAD, FLOOR)
        kept_counts.add(basis.shape[1])
        assert np.array_equal(k_basis, basis)
        assert np.array_equal(k_z, z)
        assert (x, y, phi) == pose
        # The information kept: the kernel's column-by-column dgemv, bit for bit; numpy's dgemm of the code before
        # the kernel (``@``) gives the same bits on the Intel Xeon the kernel was written on, but on an AMD EPYC
        # its OpenBLAS rounds the last bit differently in about 70 % of these cases, so there it is compared to
        # one unit in the last place of the matrix's largest entry (docs/albot1-mapper.md, the screen kernel).
        assert np.array_equal(k_info, columns_kept(info, basis) if basis.shape[1] else np.zeros((3, 3)))
        assert np.max(np.abs(k_info - info_kept)) <= np.spacing(np.max(np.abs(info_kept)))
    assert kept_counts == {0, 1, 2, 3}
