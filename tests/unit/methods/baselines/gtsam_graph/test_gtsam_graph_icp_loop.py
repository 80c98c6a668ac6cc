"""ICP's compiled Gauss-Newton loop gives numpy's loop's bits: BLAS and LAPACK as numpy calls them, CPython's maths."""

from __future__ import annotations

import math

import numba
import numpy as np
import pytest

from albot1.data import open_sequence
from albot1.methods.baselines.gtsam_graph import icp_loop, registration
from albot1.methods.baselines.gtsam_graph.errors import RegistrationError
from albot1.methods.baselines.gtsam_graph.registration import IcpParams, Registration, Target, register
from albot1.methods.kernel_sources import OTHERS
from albot1.runs.execute import run_method

pytestmark = pytest.mark.skipif(not icp_loop.available(), reason="numpy's BLAS is not scipy-openblas64 here")


@numba.njit
def _solve_step(m: int, jac: np.ndarray, res: np.ndarray, wj: np.ndarray, prior: np.ndarray, s: np.ndarray) -> None:
    icp_loop._solve_step(m, jac, res, wj, prior, s)


@numba.njit
def _remainders(x: np.ndarray, y: float) -> np.ndarray:
    out = np.empty(x.shape[0])
    for i in range(x.shape[0]):
        out[i] = icp_loop.python_remainder(x[i], y)
    return out


def _same(a: object, b: object) -> bool:
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return a.shape == b.shape and a.tobytes() == b.tobytes()


def test_the_step_is_numpy_s_solve_of_numpy_s_products_bit_for_bit_where_plain_sums_differ() -> None:
    rng = np.random.default_rng(3)
    differs = 0
    for trial in range(300):
        n = int(rng.integers(10, 400))
        m = int(rng.integers(10, n + 1))
        jac, wj = rng.normal(size=(n, 3)), rng.normal(size=(n, 3)) * 10.0 ** rng.uniform(-2, 4)
        res = rng.normal(size=n) * 0.1
        prior = np.diag(rng.uniform(0.1, 2000.0, size=3))
        scratch = np.zeros(icp_loop.SCRATCH)
        offset = rng.normal(size=3) * 0.1
        scratch[icp_loop.OFFSET : icp_loop.OFFSET + 3] = offset
        _solve_step(m, jac, res, wj, prior, scratch)
        want = -np.linalg.solve(wj[:m].T @ jac[:m] + prior, wj[:m].T @ res[:m] + prior @ offset)
        assert _same(scratch[icp_loop.STEP : icp_loop.STEP + 3], want), trial
        # the normal matrix summed point after point: not BLAS's order, so not always its bits
        plain = np.zeros((3, 3))
        for k in range(m):
            plain += np.outer(wj[k], jac[k])
        differs += not _same(plain, wj[:m].T @ jac[:m])
    assert differs > 100  # the inputs do tell the orders of summation apart


def test_a_singular_normal_matrix_gives_a_step_that_is_not_finite() -> None:
    scratch = np.zeros(icp_loop.SCRATCH)
    jac = np.tile([1.0, 0.0, 0.0], (12, 1))
    _solve_step(12, jac, np.ones(12), jac.copy(), np.zeros((3, 3)), scratch)
    with pytest.raises(np.linalg.LinAlgError):
        np.linalg.solve(jac.T @ jac, jac.T @ np.ones(12))
    assert np.isnan(scratch[icp_loop.STEP : icp_loop.STEP + 3]).all()


def test_python_remainder_is_math_remainder_bit_for_bit() -> None:
    rng = np.random.default_rng(5)
    tau = 2.0 * math.pi
    x = np.concatenate([
        rng.uniform(-20.0, 20.0, 200_000),
        rng.normal(size=20_000) * 1e-9,
        np.arange(-8, 9) * math.pi,  # half-way cases and exact multiples
        np.array([0.0, -0.0, tau, -tau, 1e300, -1e-300, 5e-324, np.inf, -np.inf, np.nan]),
    ])  # fmt: skip
    for y in (tau, 1.0, 0.75, -3.0):
        want = np.array([math.remainder(v, y) if math.isfinite(v) else math.nan for v in x.tolist()])
        got = _remainders(x, y)
        assert got.view(np.int64).tolist() == want.view(np.int64).tolist() or _same(got, want), y


def _scene(rng: np.random.Generator, lattice: bool) -> tuple[Target, np.ndarray, np.ndarray]:
    """Walls (or a lattice of exact ties, which sends queries to the k-d tree) and a scan of them, moved."""
    if lattice:
        points = rng.integers(0, 40, size=(300, 2)) * 0.1
        target = Target(points, np.tile([0.0, 1.0], (len(points), 1)))
        scan = rng.integers(0, 40, size=(120, 2)) * 0.1 + 0.05
    else:
        t = rng.uniform(0.0, 8.0, 600)
        walls = np.concatenate([
            np.column_stack([t[:300], 0.01 * rng.normal(size=300)]),
            np.column_stack([0.01 * rng.normal(size=300), t[300:]]),
        ])  # fmt: skip
        target = Target.from_points(walls)
        scan = walls[rng.choice(len(walls), 200, replace=False)] + rng.normal(size=(200, 2)) * 0.01
    guess = np.array([rng.normal() * 0.2, rng.normal() * 0.2, rng.normal() * 0.05])
    return target, scan, guess


def _both(target: Target, scan: np.ndarray, guess: np.ndarray, params: IcpParams) -> tuple[Registration, Registration]:
    fast = register(target, scan, guess, params)
    slow_target = Target(target.points, target.normals)
    real = icp_loop.available
    try:
        icp_loop.available = lambda: False  # type: ignore[assignment]
        slow = register(slow_target, scan, guess, params)
    finally:
        icp_loop.available = real  # type: ignore[assignment]
    return fast, slow


@pytest.mark.parametrize("lattice", [False, True])
@pytest.mark.parametrize("seed", range(8))
def test_register_gives_numpy_s_loop_s_bits(lattice: bool, seed: int) -> None:
    rng = np.random.default_rng(seed)
    target, scan, guess = _scene(rng, lattice)
    for params in (IcpParams(), IcpParams(max_iterations=3, max_correspondence_m=2.0, prior_sigma_xy_m=0.05)):
        fast, slow = _both(target, scan, guess, params)
        for name in ("pose", "information"):
            assert _same(getattr(fast, name), getattr(slow, name)), name
        assert (fast.converged, fast.iterations, fast.inliers) == (slow.converged, slow.iterations, slow.inliers)
        assert _same([fast.fitness, fast.rmse_m], [slow.fitness, slow.rmse_m])


def test_on_a_lattice_the_loop_asks_the_k_d_tree(monkeypatch: pytest.MonkeyPatch) -> None:
    asked: list[int] = []
    real = registration.Matches.ask_tree

    def spy(self: registration.Matches, *args: object) -> None:
        asked.append(1)
        real(self, *args)  # type: ignore[arg-type]

    monkeypatch.setattr(registration.Matches, "ask_tree", spy)
    target, scan, guess = _scene(np.random.default_rng(0), lattice=True)
    register(target, scan, guess)
    assert asked


def test_a_gate_that_is_not_usable_is_refused_as_before() -> None:
    target, scan, guess = _scene(np.random.default_rng(1), lattice=False)
    for gate in (math.nan, -1.0):
        with pytest.raises(RegistrationError, match="finite positive correspondence gate"):
            register(target, scan, guess, IcpParams(max_correspondence_m=gate))


def test_zero_iterations_leave_the_guess() -> None:
    target, scan, guess = _scene(np.random.default_rng(2), lattice=False)
    fast, slow = _both(target, scan, guess, IcpParams(max_iterations=0))
    assert fast.iterations == slow.iterations == 0 and _same(fast.pose, guess) and _same(slow.pose, guess)


def test_the_wheel_carries_the_loop_and_after_the_warm_up_a_run_compiles_nothing() -> None:
    assert (icp_loop.warm_up, icp_loop.sample_calls) in OTHERS
    said: list[str] = []
    icp_loop.warm_up()
    icp_loop.warm_up(said.append)
    assert said == []
    before = len(icp_loop.icp_run.signatures)
    run_method("gtsam-graph", open_sequence("synthetic-office-loop[:200]"))
    assert len(icp_loop.icp_run.signatures) == before
