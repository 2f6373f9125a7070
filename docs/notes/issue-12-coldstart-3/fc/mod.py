import numpy as np
from numba import njit, types

@njit(cache=True)
def heavy(a, b):
    s = 0.0
    for i in range(a.shape[0]):
        for j in range(b.shape[0]):
            s += np.sqrt(abs(a[i, 0] - b[j, 1])) + np.sin(a[i, 1] * b[j, 2])
    x = np.sort(a[:, 0])
    return s + x[0] + np.linalg.norm(b[0])

arr2 = types.Array(types.float64, 2, "C")
heavy_t = types.FunctionType(types.float64(arr2, arr2))

@njit(cache=True)
def caller_static(a, b):
    return heavy(a, b) + heavy(b, a)

@njit(cache=True)
def caller_fc(fn, a, b):
    return fn(a, b) + fn(b, a)
