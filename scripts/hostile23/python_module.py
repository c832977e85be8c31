"""Items 10, 11 and 12: the Python module, as each build's extension (the sanitizer build's with
AddressSanitizer preloaded into the interpreter), run by an interpreter that has numpy.

A child interpreter runs the seeded cases in one process, printing "begin N" before each and a
JSON verdict after it, so a crash or a hang is pinned to its case and the next child starts after
it. The families:
  - progress callables that rewrite, resize or poison the arrays they were given (faces of every
    integer dtype and layout, vertices, colours, masks), on the reference path and the OpenCL
    device, for each method: the call works on copies, so the result must be bit for bit the
    unmolested call's (item 10);
  - progress callables that call rsmooth again: a call on an OpenCL context or a new Context
    raises RuntimeError (never a deadlock), a reference call works; callables that raise stop
    the call with their exception (item 11);
  - integer and real keywords across and far beyond their documented ranges, of every type:
    in range works, out of range is ValueError naming the keyword, a bool, float or string where a
    whole number goes TypeError naming it (item 12)."""

import json
import os
import subprocess

from . import common as c

TITLE = "Python module (items 10-12)"

CHILD = r'''
import json, sys, random, math
import numpy as np
import rsmooth

seed, first, count, have_cl = int(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3]), sys.argv[4] == "1"

def grid(n, s):
    r = np.random.default_rng(s)
    x, y = np.meshgrid(np.arange(n, dtype=float), np.arange(n, dtype=float))
    v = np.stack([x.ravel(), y.ravel(), np.zeros(n * n)], 1) + r.normal(0, 0.12, (n * n, 3))
    f = []
    for j in range(n - 1):
        for i in range(n - 1):
            a = j * n + i
            f += [(a, a + 1, a + n + 1), (a, a + n + 1, a + n)]
    return v, np.array(f, dtype=np.int64)

V0, F0 = grid(12, 5)
DEVICES = ["reference"] + (["cpu"] if have_cl else [])
COUNTS = {"normal_iterations": (1, 100, {"normal_filter": "bilateral"}),
          "passes": (0, 100, {"vertex_updates": 1}), "vertex_updates": (0, 1000, {}),
          "guided_rounds": (1, 100, {"vertex_updates": 1}), "stage_repeats": (1, 100, {"vertex_updates": 1}),
          "iterations": (0, 1000000, {"method": "taubin"})}
INF = float("inf")
# keyword: (inside its documented domain?, what else it needs)
REALS = {"sigma_f": (lambda x: 0 < x < INF, {}), "sigma_g": (lambda x: x > 0, {}),
         "cutoff": (lambda x: 0 < x <= 5, {}), "mollify_cutoff": (lambda x: 0 <= x <= 2, {}),
         "normal_sigma_s": (lambda x: 0 < x < INF, {"normal_filter": "bilateral"}),
         "normal_sigma_n": (lambda x: 0 < x <= 2, {"normal_filter": "bilateral"}),
         "pass_confidence": (lambda x: 0 <= x <= 1, {"passes": 2}),
         "sigma_c": (lambda x: x > 0, {"colors": np.full(V0.shape, 0.5)}),
         "guided_sigma_s": (lambda x: 0 < x < INF, {"vertex_updates": 1}),
         "guided_sigma_n": (lambda x: 0 < x <= 2, {"vertex_updates": 1}),
         "discrepancy_level": (lambda x: 0 <= x < INF, {}),
         "lam": (lambda x: 0 < x <= 1, {"method": "taubin"}),
         "mu": (lambda x: -1 <= x < 0, {"method": "taubin"})}

def out(i, what, verdict, detail=""):
    print(json.dumps({"case": i, "what": what, "verdict": verdict, "detail": detail}), flush=True)

def layout(r, a, dtype):
    a = np.asarray(a).astype(dtype)
    k = r.randrange(3)
    if k == 1:
        return np.asfortranarray(a)
    if k == 2:  # every other row of a twice-as-long array: not contiguous
        b = np.empty((2 * a.shape[0],) + a.shape[1:], dtype=a.dtype)
        b[::2] = a
        return b[::2]
    return np.ascontiguousarray(a)

def mutate_case(i, r):
    device = r.choice(DEVICES)
    # laplacian and taubin report no progress: a callable never runs there
    method = r.choice(["robust", "robust", "gaussian"])
    kw = {"method": method}
    if method == "robust" and r.random() < 0.3:
        kw["colors"] = np.random.default_rng(i).random(V0.shape).astype(np.float32)
    if method == "robust" and r.random() < 0.3:
        kw["mask"] = np.random.default_rng(i).random(len(V0)) < 0.5
    if method == "robust" and r.random() < 0.15:
        kw["best"] = True
    fdt = r.choice([np.uint32, np.int32, np.int64, np.uint64, np.int16])
    vdt = r.choice([np.float32, np.float64])
    what = "progress rewrites arrays: %s %s faces %s vertices %s %s" % (
        device, method, np.dtype(fdt).name, np.dtype(vdt).name, sorted(k for k in kw if k != "method"))
    v, f = layout(r, V0, vdt), layout(r, F0, fdt)
    want = rsmooth.smooth(v.copy(), f.copy(), device=device, **kw)
    attacks = r.sample(["faces far", "faces negative", "faces shuffled", "vertices nan",
                        "vertices huge", "resize", "colors nan", "mask flipped", "zero all"], 3)
    calls = []
    def progress(fraction):
        calls.append(fraction)
        for a in attacks:
            try:
                if a == "faces far":
                    f[:] = np.iinfo(f.dtype).max
                elif a == "faces negative" and np.issubdtype(f.dtype, np.signedinteger):
                    f[:] = -1
                elif a == "faces shuffled":
                    f[:] = f[::-1].copy()
                elif a == "vertices nan":
                    v[::2] = np.nan
                elif a == "vertices huge":
                    v[1::2] = 1e38 if v.dtype == np.float32 else 1e300
                elif a == "resize" and f.flags.owndata and v.flags.owndata:
                    f.resize((1, 3), refcheck=False)
                    v.resize((3, 3), refcheck=False)
                    np.zeros(10 ** 6)
                elif a == "colors nan" and "colors" in kw:
                    kw["colors"][:] = np.nan
                elif a == "mask flipped" and "mask" in kw:
                    kw["mask"][:] = ~kw["mask"]
                elif a == "zero all":
                    v[:] = 0
                    f[:] = 0
            except (ValueError, TypeError):
                pass
    what += " attacks %s" % attacks
    got = rsmooth.smooth(v, f, device=device, progress=progress, **kw)
    if np.array_equal(got, want):
        out(i, what, "ok", "" if calls else "progress never called")
    else:
        diff = np.nanmax(np.abs(np.asarray(got, float) - np.asarray(want, float)))
        out(i, what, "wrong", "the result changed: max difference %r, finite %s" % (
            float(diff), bool(np.isfinite(got).all())))

def reentry_case(i, r):
    device = r.choice(DEVICES)
    inner = r.choice(["cpu", "auto", None, "reference", "Context", "devices", "raise", "interrupt"])
    what = "progress on %s calls %s" % (device, inner)
    if not have_cl and inner in ("cpu", "auto", None, "Context"):
        inner = "reference"
    want = rsmooth.smooth(V0, F0, device=device)
    seen = []
    def progress(fraction):
        if seen:
            return
        try:
            if inner == "Context":
                rsmooth.Context("cpu")
            elif inner == "devices":
                rsmooth.devices()
            elif inner == "raise":
                seen.append("raised")
                raise LookupError("stop")
            elif inner == "interrupt":
                seen.append("raised")
                raise KeyboardInterrupt
            else:
                x = rsmooth.smooth(V0, F0, device=inner)
                direct = rsmooth.smooth(V0, F0, device=inner)
                seen.append("same" if np.array_equal(x, direct) else "differs")
                return
            seen.append("returned")
        except RuntimeError as e:
            seen.append("RuntimeError")
    try:
        got = rsmooth.smooth(V0, F0, device=device, progress=progress)
        raised = None
    except (LookupError, KeyboardInterrupt) as e:
        got, raised = None, type(e).__name__
    if inner in ("raise", "interrupt"):
        want_exc = "LookupError" if inner == "raise" else "KeyboardInterrupt"
        if raised != want_exc:
            return out(i, what, "wrong", "the callable raised %s; the call gave %s" % (want_exc, raised))
        return out(i, what, "ok")
    if got is None or not np.array_equal(got, want):
        return out(i, what, "wrong", "the outer result changed")
    # an OpenCL call inside a call that holds a context must raise (it would wait for itself);
    # inside a reference call, which holds none, it may work
    opencl_inner = inner in ("cpu", "auto", None, "Context")
    if opencl_inner and device != "reference" and seen and seen[0] != "RuntimeError":
        return out(i, what, "other", "an OpenCL call inside a callable did not raise RuntimeError: %s" % seen)
    if seen and seen[0] == "differs":
        return out(i, what, "wrong", "a reference call inside a callable: %s" % seen)
    out(i, what, "ok")

def int_values(r, low, high):
    return r.choice([low - 1, high + 1, -1, -2 ** 31, 2 ** 31, 2 ** 32, 2 ** 32 + low, 2 ** 63, 2 ** 64,
                     -2 ** 64, 10 ** 30, low, min(high, low + 1), np.int64(low), np.int64(-1),
                     np.uint64(2 ** 64 - 1), np.int32(2 ** 31 - 1), True, False, float(low), 2.5, "2", [1]])

def count_case(i, r):
    key = r.choice(sorted(COUNTS))
    low, high, beside = COUNTS[key]
    value = int_values(r, low, high)
    what = "%s=%r (%s)" % (key, value, type(value).__name__)
    whole = isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))
    try:
        res = rsmooth.smooth(V0, F0, device="reference", **{key: value}, **beside)
        got = "accepted"
    except ValueError as e:
        got, msg = "ValueError", str(e)
    except TypeError as e:
        got, msg = "TypeError", str(e)
    if whole and low <= int(value) <= high:
        if got != "accepted":
            return out(i, what, "other", "refused a value in [%d, %d]: %s" % (low, high, msg))
        if not np.isfinite(res).all():
            return out(i, what, "wrong", "non-finite result")
        return out(i, what, "ok")
    if got == "accepted":
        return out(i, what, "wrong", "accepted, outside [%d, %d] or not a whole number" % (low, high))
    if not msg.startswith(key):
        return out(i, what, "other", "%s does not name the keyword: %s" % (got, msg))
    if whole and got != "ValueError":
        return out(i, what, "other", "out of range gave %s: %s" % (got, msg))
    if not whole and got != "TypeError":
        return out(i, what, "other", "a %s gave %s: %s" % (type(value).__name__, got, msg))
    out(i, what, "ok")

def real_case(i, r):
    key = r.choice(sorted(REALS))
    inside, beside = REALS[key]
    value = r.choice([float("nan"), INF, -INF, -2.0, 0.0, -0.0, 10 ** 400, -(10 ** 400), 1e-320, 1e300,
                      0.5, -0.5, 1.0, 2.0, 5.0, 5.000001, np.float32(0.5), np.float64(-0.5), "0.5",
                      True, [0.5], 1j, None])
    what = "%s=%r (%s)" % (key, value, type(value).__name__)
    number = isinstance(value, (int, float, np.floating)) and not isinstance(value, bool)
    try:
        res = rsmooth.smooth(V0, F0, device="reference", **{key: value}, **beside)
        got = "accepted"
    except ValueError as e:
        got, msg = "ValueError", str(e)
    except TypeError as e:
        got, msg = "TypeError", str(e)
    except OverflowError as e:
        got, msg = "OverflowError", str(e)
    if value is None:  # the default where there is one, else a TypeError naming the keyword
        fine = got == "accepted" or (got == "TypeError" and msg.startswith(key))
        return out(i, what, "ok" if fine else "other", "" if fine else msg)
    try:
        as_float = float(value) if number else 0.0
    except OverflowError:
        as_float = INF if value > 0 else -INF
    if number and inside(as_float):
        if got == "accepted":
            return out(i, what, "ok" if np.isfinite(res).all() else "wrong", "")
        extreme = abs(as_float) < 1e-300 or abs(as_float) > 1e299
        if got == "ValueError" and msg.startswith(key) and extreme:
            return out(i, what, "ok", "refused an extreme value: %s" % msg)
        return out(i, what, "other", "refused a value in its domain: %s: %s" % (got, msg))
    if got == "accepted":
        return out(i, what, "wrong", "accepted a value outside its domain")
    if not msg.startswith(key):
        return out(i, what, "other", "%s does not name the keyword: %s" % (got, msg))
    out(i, what, "ok")

for i in range(first, count):
    r = random.Random("%d/%d" % (seed, i))
    print("begin %d" % i, flush=True)
    family = [mutate_case, mutate_case, reentry_case, count_case, real_case][i % 5]
    try:
        family(i, r)
    except Exception as e:
        out(i, family.__name__, "other", "unexpected %s: %s" % (type(e).__name__, e))
'''


class PythonCases:
    def __init__(self, settings, build, python):
        self.s, self.b, self.python = settings, build, python
        self.surface = "%s/python" % build.name
        self.dir = os.path.join(settings.out, build.name, "python")
        os.makedirs(self.dir)

    def prepare(self):
        """A package of this checkout's Python files and the build's extension; why not, or None."""
        if not self.python or not os.access(self.python, os.X_OK):
            return "no interpreter with numpy given (--python)"
        if not os.path.exists(self.b.python_module):
            return "no extension in %s (configure with -DRSMOOTH_BUILD_PYTHON=ON)" % self.b.dir
        pkg = os.path.join(self.dir, "pkg", "rsmooth")
        os.makedirs(pkg)
        package = os.path.join(self.b.source, "python", "rsmooth")  # the build's own sources
        for name in os.listdir(package):
            if name.endswith((".py", ".pyi")):
                os.symlink(os.path.join(package, name), os.path.join(pkg, name))
        os.symlink(self.b.python_module, os.path.join(pkg, os.path.basename(self.b.python_module)))
        c.write(os.path.join(self.dir, "child.py"), CHILD.encode())
        self.env = {"PYTHONPATH": os.path.join(self.dir, "pkg"), "PYTHONDONTWRITEBYTECODE": "1"}
        if self.b.sanitizer:
            lib = subprocess.run(["cc", "-print-file-name=libasan.so"], capture_output=True,
                                 text=True).stdout.strip()
            self.env.update({"LD_PRELOAD": lib, "ASAN_OPTIONS": "detect_leaks=0:abort_on_error=0",
                             "UBSAN_OPTIONS": "print_stacktrace=1"})
        probe = c.run([self.python, "-c", "import rsmooth; print(len(rsmooth.devices()))"], self.s,
                      env=self.env, cwd=self.dir, timeout=120)
        if probe.rc != 0:
            return "the module does not import: %s" % c.tail(probe.err, 300)
        self.have_cl = probe.out.strip() not in (b"0", b"")
        return None

    def batch(self, tally, count):
        first = 0
        while first < count:
            argv = [self.python, "child.py", str(self.s.seed), str(first), str(count),
                    "1" if self.have_cl else "0"]
            r = c.run(argv, self.s, env=self.env, cwd=self.dir,
                      timeout=self.s.timeout + count * (2 if self.b.sanitizer else 0.5))
            begun, done = c.record_batch(r, self.surface, "python",
                                         lambda d: "%s  # case %d" % (r.text(), d["case"]), tally)
            if r.rc == 0 and not r.hung and not c.SANITIZER_RE.search(r.err):
                return
            at = begun if begun is not None and begun not in done else first
            c.record_ended(r, argv, at, self.surface, "python %d (ended the interpreter)" % at,
                           tally)
            first = at + 1
