"""One BLAS thread per impstab process, unless the user asked for threads.

impstab's linear algebra is many small problems (6 to a few hundred rows: batched eigenvalue
problems, solves, decompositions), where OpenBLAS's worker threads cost more than they give:
they spin and hand tiny blocks to each other (OpenBLAS issues 731 and 4387; numpy issue 12220).
On a shared 2-core machine under load the linear part of impstab's test suite took 116 s of CPU with OpenBLAS's
default threads and 39 s with one, and a batched ``numpy.linalg.eig`` of 50 matrices of order
100 2.2 s against 0.29 s. Parallel work in impstab is across processes (study workers; Dask's
nanny gives each worker one BLAS thread too), never inside a small matrix.

The thread count of a BLAS library is read from the environment when the library loads, so
:func:`prefer_single_thread` acts only before numpy is first imported (the command line calls it
first thing; in a notebook, set ``OPENBLAS_NUM_THREADS=1`` before importing numpy). It never
overrides a choice: if any of :data:`THREAD_VARIABLES` is set, nothing changes.
"""

from __future__ import annotations

import os
from collections.abc import MutableMapping

__all__ = ["THREAD_VARIABLES", "prefer_single_thread"]

#: environment variables by which a user chooses the BLAS (or OpenMP) thread count
THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "BLIS_NUM_THREADS", "OMP_NUM_THREADS")


def prefer_single_thread(environ: MutableMapping[str, str] | None = None) -> bool:
    """Set one BLAS thread in ``environ`` (default ``os.environ``) unless the user chose a count.

    Returns True when it set the variables (OpenBLAS's and MKL's), False when one of
    :data:`THREAD_VARIABLES` was already set.
    """
    env = os.environ if environ is None else environ
    if any(name in env for name in THREAD_VARIABLES):
        return False
    env["OPENBLAS_NUM_THREADS"] = "1"
    env["MKL_NUM_THREADS"] = "1"
    return True
