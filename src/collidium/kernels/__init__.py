"""Compiled kernels (numba). Arrays and scalars in, arrays out; no validation, no Python objects.

Every kernel has a plain NumPy twin in `reference.py` that the tests compare against.
"""

import os

from collidium.kernels.compilation import stamp_caches_with_every_kernel

#: Spins a thread of numba's OpenMP pool (GNU's) waits for the next parallel loop before it
#: sleeps. GNU's default, 300,000, keeps it spinning through the exact engine's serial events
#: between the parallel passes of a step, a core busy for nothing (1.7 s of CPU in the 2.3 s of
#: 300 steps of a 1e5-disk gas), taken from the viewer's browser or whatever else runs; 10,000
#: bridges back-to-back loops as well (ARCHITECTURE.md, "Threads"). A value set in the
#: environment is kept. Read when numba starts its threads, at the first parallel loop.
OPENMP_SPINS = 10_000

os.environ.setdefault("GOMP_SPINCOUNT", str(OPENMP_SPINS))

# Before any kernel is decorated: each kernel's cache is stamped with every kernel's source.
stamp_caches_with_every_kernel()
