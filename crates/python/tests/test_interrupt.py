"""Ctrl-C and progress: a SIGINT stops long calls within 0.5 s with KeyboardInterrupt (a
render keeps its image); progress callbacks see the work advance."""

import os
import pathlib
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

import facette

REPO = pathlib.Path(__file__).resolve().parents[3]

# The child starts a call that takes tens of seconds, says so, and on KeyboardInterrupt
# prints the time.monotonic() it caught it at (CLOCK_MONOTONIC is one clock for every
# process of the machine, so the parent can subtract its own send time) and what the
# exception carries. The call is the first facette call of the process: an interrupt
# there once became "PanicException: Failed to access NumPy array API capsule".
CHILD = r"""
import sys, time, numpy as np, facette
what = sys.argv[1]
try:
    # Inside the try: a signal that lands right after this line is still caught below.
    print("ready", flush=True)
    if what == "render":
        facette.render("scenes/bench-sphere.toml", spp=64, threads=1)
    elif what == "validate":
        # V-cavity multiple scattering: ~17 s on an idle 2-core machine (the plain IL body
        # validates in 1.4 s, which a fast machine finishes before the signal).
        facette.Material('{type = "il", kd = 0.5, ni = 1.5, alpha = 0.3, scattering = "multiple"}').validate(samples=20000)
    elif what == "eval":
        m = facette.Material('{type = "il", kd = 0.5, ni = 1.5, alpha = 0.5, scattering = "multiple"}')
        m.eval(np.tile([0.0, 0.0, 1.0], (2000, 1)), [0.5, 0.0, 0.8], samples=20000)
    print("finished", flush=True)
except KeyboardInterrupt as e:
    t = time.monotonic()
    img = getattr(e, "image", None)
    shape = "none" if img is None else "x".join(map(str, img.shape))
    filled = -1.0 if img is None else float(np.mean(img.sum(axis=2) > 0))
    print("interrupted", t, shape, filled, flush=True)
"""


def interrupt(what, after):
    p = subprocess.Popen([sys.executable, "-c", CHILD, what], cwd=REPO, stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True)
    assert p.stdout.readline().strip() == "ready"
    time.sleep(after)
    sent = time.monotonic()
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=60)
    assert "PanicException" not in err, err
    fields = out.split()
    assert fields and fields[0] == "interrupted", (out, err)
    return float(fields[1]) - sent, fields[2], float(fields[3])


@pytest.mark.parametrize("what", ["render", "validate", "eval"])
def test_ctrl_c_stops_within_half_a_second(what):
    # 2 s in: well inside each call (the render alone takes ~50 s on one thread), past
    # the imports and the scene load.
    latency, shape, filled = interrupt(what, 2.0)
    assert 0 <= latency < 0.5, latency
    if what == "render":
        # The image so far comes with the exception: every pixel has its first samples
        # (the first pass is one sample per pixel, well under 2 s).
        assert shape == "512x512x3"
        assert filled > 0.99, filled
    else:
        assert shape == "none"


def test_an_interrupt_at_once_is_a_keyboard_interrupt_not_a_panic():
    # Sent as soon as the child says it is ready: the signal lands during the imports'
    # tail or the first call's start, where the NumPy capsule used to be looked up.
    latency, _, _ = interrupt("render", 0.0)
    assert latency < 0.5


def test_render_progress_counts_samples_to_the_end(tiny_scene):
    seen = []
    img = facette.render(tiny_scene, spp=64, progress=lambda d, t: seen.append((d, t)))
    assert seen, "the callback was called"
    assert seen[-1] == (24 * 16 * 64, 24 * 16 * 64)
    done = [d for d, _ in seen]
    assert done == sorted(done)
    assert img.shape == (16, 24, 3)


def test_validate_and_albedo_progress_and_the_bar(capfd):
    steps = []
    r = facette.Material('{type = "lambert"}').validate(samples=2000, progress=lambda d, t: steps.append((d, t)))
    assert r.passed
    # Opaque: 4 incidences + 1 from below, then the two sweeps.
    assert steps[-1] == (7, 7)
    angles = []
    facette.Material('{type = "lambert"}').albedo([0, 30, 60], samples=1000, progress=lambda d, t: angles.append(d))
    assert angles[-1] == 3
    facette.Material('{type = "lambert"}').validate(samples=2000, progress=True)
    assert "validate: 100.0 %" in capfd.readouterr().err


def test_a_progress_callback_that_raises_stops_the_call(tiny_scene):
    def stop(done, total):
        raise RuntimeError("enough")

    t = time.monotonic()
    with pytest.raises(RuntimeError, match="enough"):
        facette.render(tiny_scene, spp=100000, progress=stop)
    assert time.monotonic() - t < 5


def test_time_limit_keeps_the_first_pass(tiny_scene):
    t = time.monotonic()
    img = facette.render(tiny_scene, spp=10**6, time_limit=0.3)
    assert time.monotonic() - t < 3
    assert np.all(img.sum(axis=2) > 0)
    with pytest.raises(ValueError, match="time_limit"):
        facette.render(tiny_scene, time_limit=-1)
