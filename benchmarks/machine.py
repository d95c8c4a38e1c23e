"""Machine description printed at the top of every benchmark."""

import os
import platform

import numba
import numpy as np

SIMD = ("avx2", "fma", "avx512f")      # the instruction sets the kernels' speed depends on (/proc/cpuinfo flags)


def machine_info() -> dict:
    """Platform, CPU (model and the SIMD instruction sets it exposes) and library versions of this run."""
    cpu, flags = platform.processor() or "unknown", set()
    try:
        with open("/proc/cpuinfo") as f:
            lines = f.read().splitlines()
        cpu = next(line.split(":", 1)[1].strip() for line in lines if line.startswith("model name"))
        flags = set(next(line.split(":", 1)[1].split() for line in lines if line.startswith("flags")))
    except (OSError, StopIteration):
        pass
    usable = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    return {"platform": platform.platform(), "cpu": cpu,
            "simd": " ".join(x for x in SIMD if x in flags) or "none of " + ", ".join(SIMD),
            "cpu_count": os.cpu_count(),
            "usable_cpus": usable, "python": platform.python_version(),
            "numpy": np.__version__, "numba": numba.__version__,
            "numba_default_threads": numba.get_num_threads(),
            "load_average_1min": round(os.getloadavg()[0], 2) if hasattr(os, "getloadavg") else None}
