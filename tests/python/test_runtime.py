"""The call's behaviour around it: the GIL is released while the filter runs, Ctrl-C and a raising
progress callable stop it (inputs untouched), and the module starts and falls back where OpenCL
is missing: no platform (an empty ICD vendor directory) and no loader at all."""

from __future__ import annotations

import os
import signal
import threading
import time

import numpy as np
import pytest

import rsmooth
from conftest import box, noisy, run_python


@pytest.fixture(scope="module")
def big():
    v, f = box(60)  # 21602 vertices: seconds on the reference path with the best mode
    return noisy(v, f, 0.3), f


def test_gil_released(big):
    v, f = big
    ticks = []
    done = threading.Event()

    def count():
        while not done.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    t = threading.Thread(target=count)
    t.start()
    start = time.perf_counter()
    rsmooth.smooth(v, f, device="reference", best=True)
    end = time.perf_counter()
    done.set()
    t.join()
    during = [x for x in ticks if start < x < end]
    # With the GIL held for the call the other thread could not tick at all.
    assert len(during) > 0.2 * (end - start) / 0.001 * 0.1, (len(during), end - start)


def test_progress_raising_stops_the_call(big):
    v, f = big
    v0 = v.copy()

    class Stop(Exception):
        pass

    calls = []

    def progress(fraction):
        calls.append(fraction)
        if len(calls) == 2:
            raise Stop("enough")

    with pytest.raises(Stop):
        rsmooth.smooth(v, f, device="reference", best=True, progress=progress)
    assert len(calls) == 2 and np.array_equal(v, v0)


@pytest.mark.skipif(threading.current_thread() is not threading.main_thread(),
                    reason="signals reach the main thread only")
def test_ctrl_c_interrupts(big):
    v, f = big
    v0 = v.copy()

    # The SIGINT is sent from another thread once the call is under way (its first progress
    # report), so a loaded machine cannot make the call end before the signal is sent; a
    # progress callable that does nothing leaves the signal check to the library's reports.
    def attempt():
        timer = threading.Timer(0.2, lambda: os.kill(os.getpid(), signal.SIGINT))
        started = []

        def progress(fraction):
            if not started:
                started.append(time.perf_counter())
                timer.start()

        start = time.perf_counter()
        try:
            rsmooth.smooth(v, f, device="reference", best=True, passes=6, progress=progress)
        except KeyboardInterrupt:
            return time.perf_counter() - start
        finally:
            timer.cancel()
        return None

    stopped = None
    for _ in range(3):  # a call that ends within 0.2 s of its first report is tried again
        stopped = attempt()
        if stopped is not None:
            break
    assert stopped is not None, "Ctrl-C did not interrupt the call in 3 tries"
    assert np.array_equal(v, v0)
    t0 = time.perf_counter()
    full = rsmooth.smooth(v, f, device="reference", best=True, passes=6)
    whole = time.perf_counter() - t0
    assert full is not None
    assert stopped < 0.5 * whole, (stopped, whole)  # it stopped early, not at the end


SCRIPT = """
import warnings, numpy as np, rsmooth
v = np.array([[0,0,0],[1,0,0],[0,1,0],[1,1,0.1],[2,0,0],[2,1,0.05]], dtype=np.float64)
f = np.array([[0,1,2],[1,3,2],[1,4,3],[4,5,3]])
with warnings.catch_warnings(record=True) as w:
    warnings.simplefilter("always")
    out = rsmooth.smooth(v, f)
assert np.array_equal(out, rsmooth.smooth(v, f, device="reference")), "auto != reference"
print("warning:", w[0].message if w else None)
print("devices:", rsmooth.devices())
try:
    rsmooth.smooth(v, f, device="cpu")
    print("cpu: ran")
except rsmooth.DeviceError as e:
    print("cpu: DeviceError:", e)
"""


def test_no_platform(tmp_path):
    empty = tmp_path / "vendors"
    empty.mkdir()
    r = run_python(SCRIPT, {"OCL_ICD_VENDORS": str(empty), "RSMOOTH_DEVICE": ""})
    assert r.returncode == 0, r.stderr
    assert "warning: rsmooth: no OpenCL device" in r.stdout
    assert "devices: []" in r.stdout
    assert "cpu: DeviceError:" in r.stdout


def test_no_loader():
    r = run_python(SCRIPT, {"RSMOOTH_OPENCL_LIBRARY": "/nonexistent/libOpenCL.so.1",
                            "RSMOOTH_DEVICE": ""})
    assert r.returncode == 0, r.stderr
    assert "warning: rsmooth: no OpenCL device" in r.stdout and "loader" in r.stdout
    assert "devices: []" in r.stdout
    assert "cpu: DeviceError:" in r.stdout and "loader" in r.stdout.split("cpu:")[1]


def _installed_loader():
    import subprocess

    try:
        out = subprocess.run(["ldconfig", "-p"], capture_output=True, text=True).stdout
    except OSError:
        return None
    for line in out.splitlines():
        if line.strip().startswith("libOpenCL.so.1 ") and "=>" in line:
            return os.path.realpath(line.split("=>")[1].strip())
    return None


def test_loader_really_absent(tmp_path):
    """The installed loader hidden (/dev/null bound over it in a user namespace, where the system
    allows one): the same as no loader at all."""
    import shutil
    import subprocess
    import sys

    loader = _installed_loader()
    if not loader or not shutil.which("unshare") or \
            subprocess.run(["unshare", "-r", "-m", "true"], capture_output=True).returncode:
        pytest.skip("no installed loader, or no user namespaces to hide it in")
    script = tmp_path / "script.py"
    script.write_text(SCRIPT)
    env = dict(os.environ, RSMOOTH_DEVICE="")
    env.pop("RSMOOTH_OPENCL_LIBRARY", None)
    r = subprocess.run(
        ["unshare", "-r", "-m", "sh", "-c", 'mount --bind /dev/null "$1" && exec "$2" "$3"', "sh",
         loader, sys.executable, str(script)],
        env=env, cwd="/", capture_output=True, text=True, timeout=300,
    )
    assert r.returncode == 0, r.stderr
    assert "libOpenCL.so.1 could not be loaded" in r.stdout, r.stdout
    assert "devices: []" in r.stdout and "cpu: DeviceError:" in r.stdout


def test_module_links_no_opencl():
    import pathlib
    import subprocess

    so = pathlib.Path(rsmooth._rsmooth.__file__)
    r = subprocess.run(["readelf", "-d", str(so)], capture_output=True, text=True)
    if r.returncode != 0:
        pytest.skip("readelf not available")
    needed = [line for line in r.stdout.splitlines() if "NEEDED" in line]
    assert not any("OpenCL" in line for line in needed), needed
    assert not any("python" in line.lower() for line in needed), needed  # abi3: no libpython
