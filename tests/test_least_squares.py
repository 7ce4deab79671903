"""Least squares from chunks (symdyn.apps.identification.least_squares) against numpy.linalg on all
rows at once."""

from __future__ import annotations

import numpy as np

from symdyn.apps.identification.least_squares import Triangular, combine, triangular_factor


def test_chunks_give_the_least_squares_of_all_rows():
    rng = np.random.default_rng(7)
    A = rng.normal(size=(500, 6)) * np.logspace(0, 4, 6)  # condition ~1e4: scaled columns
    b = A @ rng.normal(size=6) + rng.normal(size=500)
    blocks = [Triangular(6), Triangular(6)]
    for start in range(0, 300, 7):  # rows 0..299 to block 0, 13 rows at a time to block 1
        blocks[0].add(A[start : min(start + 7, 300)], b[start : min(start + 7, 300)])
    for start in range(300, 500, 13):
        blocks[1].add(A[start : start + 13], b[start : start + 13])
    scales = np.array([1.0, 0.25])
    g = np.repeat(scales, [300, 200])
    Ag, bg = A * g[:, None], b * g
    whole = combine(blocks, scales)
    want = np.linalg.lstsq(Ag, bg, rcond=None)[0]
    x = whole.solve()
    np.testing.assert_allclose(x, want, rtol=1e-11)
    assert whole.rows == 500
    assert abs(whole.residual_norm(x) - np.linalg.norm(Ag @ want - bg)) <= 1e-12 * np.linalg.norm(bg)
    assert abs(blocks[1].residual_norm(x) - np.linalg.norm(A[300:] @ x - b[300:])) <= 1e-12 * np.linalg.norm(
        b
    )
    assert abs(whole.condition_number() / np.linalg.cond(Ag) - 1) < 1e-10
    inv = np.linalg.inv(Ag.T @ Ag)
    np.testing.assert_allclose(whole.covariance_factor(), inv, rtol=1e-8, atol=1e-8 * np.abs(inv).max())


def test_lapack_factor_is_numpys_up_to_row_signs():
    a = np.random.default_rng(3).normal(size=(40, 7))
    r, want = triangular_factor(a), np.linalg.qr(a, mode="r")
    np.testing.assert_allclose(
        r * np.sign(np.diag(r))[:, None], want * np.sign(np.diag(want))[:, None], atol=1e-12
    )
    np.testing.assert_allclose(r.T @ r, a.T @ a, rtol=1e-12, atol=1e-12 * np.abs(a.T @ a).max())
