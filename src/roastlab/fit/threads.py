"""BLAS held to one thread while a fit's solver runs beside the compiled kernels' threads."""

from __future__ import annotations

_CONTROLLER = None


def one_blas_thread():
    """A context holding BLAS (OpenBLAS under NumPy and SciPy) to one thread.

    SciPy's least-squares solvers take an SVD of the Jacobian at every iteration; a small one, which
    one thread does as fast, but OpenBLAS wakes its threads for it and leaves them spinning after
    it. The model's next simulation then runs numba's threads on cores those spinning threads hold:
    on 2 cores a fit's every simulation took 4-8x as long (the Skywalker example's fit 5.6 s against
    1.4 s, its residuals 3.9 ms against 0.46 ms a call; the program optimiser likewise). The same
    arithmetic on one thread gives the same bits (the examples' model files compared).
    """
    global _CONTROLLER
    if _CONTROLLER is None:
        from threadpoolctl import ThreadpoolController

        _CONTROLLER = ThreadpoolController()
    return _CONTROLLER.limit(limits=1, user_api="blas")
