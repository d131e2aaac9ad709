"""Wall-clock timing shared by the benchmarks."""

import time

import numpy as np


def median_time(function, *args, repeats: int, warm_up: bool = False):
    """The median wall time [s] of ``repeats`` calls ``function(*args)`` (after one call left
    out of the timing, with ``warm_up``), and the last call's result."""
    if warm_up:
        function(*args)
    runs, result = [], None
    for _ in range(repeats):
        began = time.perf_counter()
        result = function(*args)
        runs.append(time.perf_counter() - began)
    return float(np.median(runs)), result
