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
#: time slices and is often off it when the next call starts; the call then waits for it, and two
#: threads ran slower than one. Asleep, a worker is slower to wake on an idle machine, which costs the
#: smallest fits part of their parallel gain; results are the same to the bit. The measurements are in
#: docs/performance.md, "Numba's threads on a busy machine". The runtime reads the variable once, so
#: the setting has no effect where something else in the process loaded OpenMP first;
#: ``OMP_WAIT_POLICY=ACTIVE`` keeps the spinning threads.
OMP_WAIT_POLICY = "PASSIVE"

os.environ.setdefault("OMP_WAIT_POLICY", OMP_WAIT_POLICY)
