"""Machine description printed at the top of every benchmark."""

import os
import platform

import numba
import numpy as np


def machine_info() -> dict:
    """Platform, CPU and library versions of this run."""
    cpu = platform.processor() or "unknown"
    try:
        with open("/proc/cpuinfo") as f:
            cpu = next(line.split(":", 1)[1].strip() for line in f if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    usable = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    return {"platform": platform.platform(), "cpu": cpu, "cpu_count": os.cpu_count(),
            "usable_cpus": usable, "python": platform.python_version(),
            "numpy": np.__version__, "numba": numba.__version__,
            "numba_default_threads": numba.get_num_threads(),
            "load_average_1min": round(os.getloadavg()[0], 2) if hasattr(os, "getloadavg") else None}
