"""One BLAS thread for the commands that do no dense linear algebra.

numpy's and scipy's wheels carry OpenBLAS, which starts a worker thread per core when numpy
is first imported; the workers spin a while before they sleep. Measured on a 2-core machine:
``python -c "import numpy"`` took 83 ms of CPU with ``OPENBLAS_NUM_THREADS=1`` against 122 ms
without, and ``geobrep info`` of a 3-vertex file 212 against 261 ms. Commands that read,
convert, cut, check or build (their numpy work is elementwise, or small batched solves, which
OpenBLAS runs on one thread anyway) therefore start numpy with one BLAS thread; ``fit``, ``map``,
``run`` and ``demo``, which may solve large systems, keep OpenBLAS's default.

A thread count the user chose (``OPENBLAS_NUM_THREADS``, ``GOTO_NUM_THREADS`` or
``OMP_NUM_THREADS``, which OpenBLAS reads in that order) is left alone, and so is a process
that imported numpy already (the setting is read once, when OpenBLAS loads). Child processes
(``convert --jobs``) inherit the setting, as parallel workers should.
"""

from __future__ import annotations

import os
import sys
from collections.abc import MutableMapping

__all__ = ["BLAS_THREADS_ENV", "one_blas_thread"]

#: The variables OpenBLAS takes its thread count from, in the order it reads them.
BLAS_THREADS_ENV = ("OPENBLAS_NUM_THREADS", "GOTO_NUM_THREADS", "OMP_NUM_THREADS")


def one_blas_thread(environ: MutableMapping[str, str] = os.environ) -> bool:
    """Have OpenBLAS start one thread when numpy loads; False if it is too late or the user
    chose a count (see the module)."""
    if "numpy" in sys.modules or any(name in environ for name in BLAS_THREADS_ENV):
        return False
    environ["OPENBLAS_NUM_THREADS"] = "1"
    return True
