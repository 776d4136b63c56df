"""Products and solutions of the small matrices of a control tick, without BLAS or LAPACK.

numpy hands `a @ b` and `np.linalg.solve` to BLAS and LAPACK, whose kernels for the CPU at
hand sum with fused multiply-adds or without and so decide the last bit of the result, and a
trajectory's with it. These use numpy's own element-wise arithmetic, which rounds the same on
every CPU.
"""

from __future__ import annotations

import numpy as np


def product(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a @ b of an (n, k) array and a (k, m) or (k,) one."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    if b.ndim == 1:
        return (a * b).sum(axis=-1)
    return (a[:, :, None] * b[None, :, :]).sum(axis=1)


def solve(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """x with a @ x = b for a square, non-singular `a` (n, n) and `b` (n, m) or (n,): Gaussian
    elimination with partial pivoting."""
    a, x = np.array(a, float), np.array(b, float)
    n = len(a)
    for k in range(n):
        pivot = k + int(np.argmax(np.abs(a[k:, k])))
        if a[pivot, k] == 0.0:
            raise np.linalg.LinAlgError("singular matrix")
        a[[k, pivot]], x[[k, pivot]] = a[[pivot, k]], x[[pivot, k]]
        factors = a[k + 1 :, k] / a[k, k]
        a[k + 1 :] -= factors[:, None] * a[k]
        x[k + 1 :] -= factors[:, None] * x[k] if x.ndim == 2 else factors * x[k]
    for k in range(n - 1, -1, -1):
        x[k] = (x[k] - product(a[k : k + 1, k + 1 :], x[k + 1 :])[0]) / a[k, k]
    return x
