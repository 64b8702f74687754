"""What the side-by-side scripts (`bench_render.py`, `efficiency.py`) print about the machine.

Mitsuba's LLVM back end compiles its kernels for the host's widest vectors (16 f32 lanes
with AVX-512) while facette's render kernel is 8 lanes wide (AVX2, or SSE2): the same
builds give different ratios on hosts with and without AVX-512, so the scripts say which
this one is.
"""


def load_average():
    """The 1, 5 and 15 minute load averages, or "?" where /proc is not there."""
    try:
        return " ".join(open("/proc/loadavg").read().split()[:3])
    except OSError:
        return "?"


def cpu_description():
    """The CPU's model name and its widest vector extension of the ones that matter here
    ("AVX-512", "AVX2", "SSE2 only"), from /proc/cpuinfo; "unknown CPU" elsewhere."""
    model, flags = None, set()
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                key, _, value = line.partition(":")
                key = key.strip()
                if key == "model name" and model is None:
                    model = value.strip()
                elif key == "flags" and not flags:
                    flags = set(value.split())
    except OSError:
        return "unknown CPU"
    if "avx512f" in flags:
        widest = "AVX-512"
    elif "avx2" in flags:
        widest = "AVX2"
    elif flags:
        widest = "SSE2 only"
    else:
        widest = "vector extensions unknown"
    return f"{model or 'unknown model'}, {widest}"
