"""Python code that runs during a call (the progress callable, a signal handler, other threads)
cannot hurt it: the call works on its own copies of the arrays, so
rewriting, resizing or freeing the caller's arrays leaves its result as it was, on every path; a
call that would wait for an OpenCL context the running call holds raises RuntimeError instead of
hanging; Ctrl-C from a progress callable cancels cleanly. Each runs in a child interpreter, so a
crash or a hang fails the test instead of taking pytest with it."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import pytest

from conftest import ROOT, require_opencl

HEAD = f"""
import os, signal, sys, threading, time
import numpy as np, rsmooth
sys.path.insert(0, {str(ROOT / "tests" / "python")!r})
from conftest import box, noisy
v0, f0 = box(8)
v0 = noisy(v0, f0, 0.3, seed=5)
f0 = f0.astype(np.uint32)  # what the module hands on without converting
"""


def child(code: str, timeout: float) -> subprocess.CompletedProcess:
    """Runs HEAD + code in a fresh interpreter; a hang past `timeout` s fails the test."""
    try:
        return subprocess.run([sys.executable, "-c", HEAD + textwrap.dedent(code)], cwd="/",
                              capture_output=True, text=True, timeout=timeout, env=dict(os.environ))
    except subprocess.TimeoutExpired as e:
        pytest.fail(f"the child hung for {timeout} s (a deadlock); it printed:\n{e.stdout}")


REWRITE = """
colors0 = np.random.default_rng(2).random(v0.shape).astype(np.float32)
devices = ["reference"] + (["cpu"] if rsmooth.devices() else [])

def vandal(v, f, c):
    def progress(fraction):
        f[:] = 4_000_000_000        # every index far outside the mesh
        v[::2] = np.nan             # and positions the library refused at the start
        v[1::2] = 1e300
        if c is not None:
            c[:] = np.nan
        calls.append(fraction)
    return progress

for device in devices:
    for name, kw in (("plain", {}), ("best", dict(best=True)), ("colors", dict(colors=colors0))):
        want = rsmooth.smooth(v0, f0, device=device, **kw)
        v, f = v0.copy(), f0.copy()
        c = colors0.copy() if "colors" in kw else None
        if c is not None:
            kw = dict(colors=c)
        calls = []
        got = rsmooth.smooth(v, f, device=device, progress=vandal(v, f, c), **kw)
        print(device, name, len(calls) > 0, "same" if np.array_equal(got, want) else "DIFFERENT")

    # resized (the old memory freed and reused) while the call runs
    want = rsmooth.smooth(v0, f0, device=device)
    v, f = v0.copy(), f0.copy()
    def shrink(fraction):
        if f.shape[0] > 1:
            f.resize((1, 3), refcheck=False)
            v.resize((3, 3), refcheck=False)
            np.zeros(10**6)
    got = rsmooth.smooth(v, f, device=device, progress=shrink)
    print(device, "resized", f.shape == (1, 3), "same" if np.array_equal(got, want) else "DIFFERENT")

n0 = v0 / np.linalg.norm(v0, axis=1, keepdims=True)  # the cube's outward directions
want = rsmooth.smooth_points(v0, n0, return_normals=True)
p, n, calls = v0.copy(), n0.copy(), []
def spoil(fraction):
    p[:] = np.nan
    n[:] = 0
    calls.append(fraction)
got = rsmooth.smooth_points(p, n, return_normals=True, progress=spoil)
print("points", len(calls) > 0, "same" if all(np.array_equal(a, b) for a, b in zip(got, want))
      else "DIFFERENT")
"""


def test_progress_rewriting_or_resizing_the_inputs_changes_nothing():
    """Item 10: before the fix the reference path read the rewritten faces (a segfault; ASan: an
    out-of-bounds read in mollified_normal) and so did the OpenCL path's normal update stage."""
    r = child(REWRITE, 300)
    assert r.returncode == 0, f"exit {r.returncode}\n{r.stdout}\n{r.stderr}"
    lines = r.stdout.splitlines()
    paths = 1 + ("cpu" in r.stdout)
    assert len(lines) == 4 * paths + 1, r.stdout
    assert all(line.endswith("True same") for line in lines), r.stdout


NESTED = """
ctx, other = rsmooth.Context("cpu"), rsmooth.Context("cpu")

def inside(outer, nested):
    said = []
    def progress(fraction):
        if not said:
            try:
                said.append(("ran", nested()))
            except RuntimeError as e:
                said.append(("RuntimeError", str(e)))
    result = outer(progress)
    return said[0], result

reference = rsmooth.smooth(v0, f0, device="reference")
plain = ctx.smooth(v0, f0)
module = rsmooth.smooth(v0, f0, device="cpu")
on_ctx = lambda p: ctx.smooth(v0, f0, progress=p)
cases = {  # name: (outer call, nested call, outer's result, nested's result)
    "same context": (on_ctx, lambda: ctx.smooth(v0, f0), plain, None),
    "module's context": (lambda p: rsmooth.smooth(v0, f0, device="cpu", progress=p),
                         lambda: rsmooth.smooth(v0, f0, device="cpu"), module, None),
    "other context": (on_ctx, lambda: other.smooth(v0, f0), plain, None),
    "new context": (on_ctx, lambda: rsmooth.Context("cpu"), plain, None),
    "reference inside": (on_ctx, lambda: rsmooth.smooth(v0, f0, device="reference"), plain,
                         reference),
    "context inside reference": (lambda p: rsmooth.smooth(v0, f0, device="reference", progress=p),
                                 lambda: ctx.smooth(v0, f0), reference, plain),
}
for name, (outer, nested, outer_want, nested_want) in cases.items():
    (what, value), result = inside(outer, nested)
    print(f"{name}: {what}:", value if what == "RuntimeError" else "ok",
          "| outer right:", np.array_equal(result, outer_want))
    if nested_want is not None:
        print(f"{name}: nested result right:", np.array_equal(value, nested_want))

# Ctrl-C in a progress callable (a signal, then a KeyboardInterrupt raised there) cancels the
# call on the context, leaves the input as it was and the context free for the next call.
for how in ("signal", "raise"):
    v = v0.copy()
    def interrupt(fraction):
        if how == "signal":
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.05)  # the handler runs at the next check
        else:
            raise KeyboardInterrupt
    try:
        ctx.smooth(v, f0, progress=interrupt)
        print(how, "not interrupted")
    except KeyboardInterrupt:
        print(how, "KeyboardInterrupt; input kept:", np.array_equal(v, v0),
              "| next call right:", np.array_equal(ctx.smooth(v0, f0), plain))

# A context's figures read on another thread while a call on it waits in its progress callable:
# the reader must not hold the GIL while it waits for the context.
started = threading.Event()
def slow(fraction):
    started.set()
    time.sleep(0.2)
worker = threading.Thread(target=lambda: ctx.smooth(v0, f0, progress=slow))
worker.start()
started.wait()
print("figures read during a call:", rsmooth._rsmooth._context_info(ctx._capsule)[0] == ctx.device)
worker.join()
"""


def test_calls_from_a_progress_callable_do_not_deadlock():
    """Item 11: before the fix a call on the context a running call holds, from its progress
    callable, waited for ever with the GIL held (Ctrl-C did nothing); now RuntimeError."""
    require_opencl()
    r = child(NESTED, 120)
    assert r.returncode == 0, f"exit {r.returncode}\n{r.stdout}\n{r.stderr}"
    out = r.stdout
    for name in ("same context", "module's context", "other context", "new context"):
        assert f"{name}: RuntimeError: rsmooth:" in out and "could wait for ever" in out, out
    assert "reference inside: ran: ok" in out and "reference inside: nested result right: True" in out
    assert "context inside reference: ran: ok" in out, out
    assert "context inside reference: nested result right: True" in out, out
    assert out.count("| outer right: True") == 6, out
    for how in ("signal", "raise"):
        assert f"{how} KeyboardInterrupt; input kept: True | next call right: True" in out, out
    assert "figures read during a call: True" in out, out
