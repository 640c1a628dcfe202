"""roastlab.sim: the compiled kernels and the simulations built on them.

Importing the package sets the OpenMP wait policy of numba's threads (:data:`OMP_WAIT_POLICY`) unless
the environment already names one. It imports before any kernel module, so the setting is in place
when the first parallel kernel loads the OpenMP runtime, which reads it once.
"""

import os

#: The OpenMP wait policy given to numba's threads (its ``omp`` threading layer), unless the user's
#: environment sets ``OMP_WAIT_POLICY`` itself. PASSIVE: a thread with no work sleeps at once. The
#: default, an active wait, has it spin for a while first. The kernels run many short parallel calls
#: (a fit's every residual and Jacobian: a few runs, well under a millisecond), so between calls
#: numba's workers spin. On a core that another process also wants, a spinning worker holds the core's
#: time slices and is often off it when the next call starts; the call then waits for it. Measured on
#: 2 cores with a busy loop on one (docs/performance.md, "Numba's threads on a busy machine"):
#: - the identification of dataset-I on both cores took 205-241 ms against 78-90 ms on one thread
#:   (PASSIVE: 81-90 ms);
#: - the Bullet example's fit took 6.7-6.9 s (PASSIVE: 4.4-4.9 s).
#: On an idle machine a sleeping worker is slower to wake: dataset-I's identification takes 66-69 ms
#: against 57 ms, the Bullet fit 3.2-3.5 s against 3.1 s. Results are the same to the bit. The
#: runtime reads the variable once, so the setting has no effect where something else in the process
#: loaded OpenMP first; ``OMP_WAIT_POLICY=ACTIVE`` keeps the spinning threads.
OMP_WAIT_POLICY = "PASSIVE"

os.environ.setdefault("OMP_WAIT_POLICY", OMP_WAIT_POLICY)
