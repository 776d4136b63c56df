"""The BLAS-free products and solutions agree with numpy's to rounding, and refuse a singular
matrix as numpy does."""

import numpy as np
import pytest

from vplane_mj.planning.protocol.matrices import product, solve
from vplane_mj.planning.protocol.vectors import dot, rotated


@pytest.mark.parametrize("n", [1, 2, 3, 5])
def test_product_and_solve_agree_with_numpy(n):
    rng = np.random.default_rng(n)
    a = rng.normal(size=(n, n)) + n * np.eye(n)
    b, v = rng.normal(size=(n, 4)), rng.normal(size=n)
    np.testing.assert_allclose(product(a, b), a @ b, rtol=0, atol=1e-13)
    np.testing.assert_allclose(product(a, v), a @ v, rtol=0, atol=1e-13)
    np.testing.assert_allclose(solve(a, b), np.linalg.solve(a, b), rtol=0, atol=1e-12)
    np.testing.assert_allclose(solve(a, v), np.linalg.solve(a, v), rtol=0, atol=1e-12)


def test_solve_pivots_past_a_zero_and_refuses_a_singular_matrix():
    np.testing.assert_array_equal(solve(np.array([[0.0, 1.0], [2.0, 0.0]]), np.array([3.0, 4.0])), [2.0, 3.0])
    with pytest.raises(np.linalg.LinAlgError):
        solve(np.array([[1.0, 2.0], [2.0, 4.0]]), np.array([1.0, 1.0]))


def test_plane_dot_and_rotation():
    points = np.array([[1.0, 0.0], [0.0, 2.0]])
    np.testing.assert_array_equal(dot(points, np.array([3.0, 4.0])), [3.0, 8.0])
    np.testing.assert_allclose(rotated(points, np.pi / 2), [[0.0, 1.0], [-2.0, 0.0]], atol=1e-15)
