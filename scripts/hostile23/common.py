"""What every surface of the campaign shares: the builds under test, running a program with a time
limit (its whole session killed on a hang), judging a run (signal, sanitizer report, hang), the
tally of cases and defects per surface, meshes and PLY files written and read by this script's own
code (never by rsmooth's), and listings of folders taken before and after a run."""

import hashlib
import os
import random
import re
import shlex
import signal
import stat
import struct
import subprocess
import threading
import time
import traceback
from concurrent.futures import ThreadPoolExecutor

SANITIZER_RE = re.compile(
    r"(AddressSanitizer|UndefinedBehaviorSanitizer|LeakSanitizer|ThreadSanitizer|"
    r"runtime error:|stack smashing detected|double free|free\(\): invalid|malloc\(\): |"
    r"corrupted size vs|Assertion `.*' failed)")
# the columns of the acceptance table, and what each counts (docs/hostile_campaign.md)
COLUMNS = [("cases", "cases tried"), ("crashes", "crashes"), ("sanitizer", "sanitizer reports"),
           ("hangs", "hangs"), ("wrong", "wrong answers with exit 0"), ("lost", "data lost"),
           ("security", "security findings"), ("other", "other defects")]
FLT_MAX = 3.4028234663852886e38
FLT_MIN = 1.1754943508222875e-38  # the smallest normal float32


# ------------------------------------------------------------------------------------------------
# The builds under test
# ------------------------------------------------------------------------------------------------

class Build:
    """One build folder: its programs, and whether it is the sanitizer build (stderr is then
    searched for reports, and leak checks are off where Open MPI or Python own the process)."""

    def __init__(self, name, folder, sanitizer):
        self.name = name
        self.dir = os.path.abspath(folder)
        self.sanitizer = sanitizer
        self.rsmooth = os.path.join(self.dir, "rsmooth")
        self.mpi = os.path.join(self.dir, "rsmooth-mpi")
        self.libs = [os.path.join(self.dir, "librsmooth_io.a"), os.path.join(self.dir, "librsmooth.a")]
        self.python_module = os.path.join(self.dir, "python", "_rsmooth.abi3.so")
        self.source = self.source_dir()

    def source_dir(self):
        """The source tree the build was configured from (its headers and Python package go with
        its libraries), else this checkout."""
        try:
            with open(os.path.join(self.dir, "CMakeCache.txt")) as f:
                for line in f:
                    if line.startswith("CMAKE_HOME_DIRECTORY:INTERNAL="):
                        return line.split("=", 1)[1].strip()
        except OSError:
            pass
        return os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

    def has_mpi(self):
        return os.access(self.mpi, os.X_OK)


class Settings:
    """What the whole run shares: the output folder, the environment every program gets (its own
    caches), the seed, the time limits and how many cases run at once."""

    def __init__(self, out, seed, jobs, timeout, mpirun):
        self.out = os.path.abspath(out)
        self.seed = seed
        self.jobs = jobs
        self.timeout = timeout
        self.mpirun = mpirun
        self.root = os.geteuid() == 0
        self.env = dict(os.environ)
        for k in list(self.env):
            if k.startswith("RSMOOTH_"):
                del self.env[k]
        self.env.update({
            # PoCL's kernels, kept between runs (a cold build of every variant takes a minute)
            "POCL_CACHE_DIR": os.environ.get("POCL_CACHE_DIR") or os.path.join(self.out, "pocl-cache"),
            "RSMOOTH_CACHE_DIR": os.path.join(self.out, "program-cache"),
            "OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
            "OMPI_MCA_btl_base_warn_component_unused": "0",
            "LC_ALL": "C",
            # PoCL on this machine's cores; the sanitizer build ignores the compiler state PoCL
            # and its LLVM keep for the life of the process (tests/lsan.supp, as ctest does)
            "POCL_MAX_PTHREAD_COUNT": "2", "POCL_CPU_MAX_CU_COUNT": "2",
            "LSAN_OPTIONS": "suppressions=%s:print_suppressions=0" % os.path.join(
                os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))),
                "tests", "lsan.supp"),
        })

    def rng(self, *what):
        return random.Random("%s/%s" % (self.seed, "/".join(str(w) for w in what)))


# ------------------------------------------------------------------------------------------------
# Running programs
# ------------------------------------------------------------------------------------------------

def session_pids(sid):
    """Every process of session `sid` (mpirun and its ranks: each rank has a process group of its
    own, so killing mpirun's group would miss them)."""
    pids = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open("/proc/%s/stat" % entry) as f:
                fields = f.read().rsplit(")", 1)[1].split()
            if int(fields[3]) == sid:
                pids.append(int(entry))
        except (OSError, IndexError, ValueError):
            pass
    return pids


def kill_session(sid, sig):
    for pid in session_pids(sid):
        try:
            os.kill(pid, sig)
        except OSError:
            pass


class Run:
    """A finished (or killed) run: argv, what was added to the environment, status, output."""

    def __init__(self, argv, env_delta, cwd):
        self.argv, self.env_delta, self.cwd = list(argv), dict(env_delta or {}), cwd
        self.rc, self.out, self.err, self.hung, self.seconds = None, b"", "", False, 0.0
        self.signalled = None  # the signal this script sent on purpose

    def text(self):
        envs = " ".join("%s=%s" % (k, shlex.quote(str(v))) for k, v in self.env_delta.items())
        return "(cd %s && %s%s)" % (shlex.quote(self.cwd), envs + " " if envs else "",
                                    shlex.join(self.argv))


def start(argv, settings, env=None, cwd=None, stdin=subprocess.DEVNULL, pass_fds=()):
    """Starts a run in a session of its own; returns (Popen, Run)."""
    e = dict(settings.env)
    for k, v in (env or {}).items():
        if v is None:
            e.pop(k, None)
        else:
            e[k] = v
    r = Run(argv, env, cwd or settings.out)
    p = subprocess.Popen(argv, env=e, cwd=r.cwd, stdin=stdin, stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, start_new_session=True, pass_fds=pass_fds)
    r.started = time.monotonic()
    return p, r


def finish(p, r, timeout):
    """Waits for a started run; past `timeout` its whole session is killed and it is a hang."""
    try:
        out, err = p.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        r.hung = True
        kill_session(p.pid, signal.SIGKILL)
        out, err = p.communicate()
    r.rc, r.out, r.err = p.returncode, out, err.decode("utf-8", "replace")
    r.seconds = time.monotonic() - r.started
    # ranks of a killed mpirun may still run: none may outlive the case
    for _ in range(200):
        if not session_pids(p.pid):
            break
        time.sleep(0.02)
    kill_session(p.pid, signal.SIGKILL)
    return r


def run(argv, settings, env=None, cwd=None, timeout=None, stdin_data=None, pass_fds=()):
    p, r = start(argv, settings, env, cwd,
                 stdin=subprocess.PIPE if stdin_data is not None else subprocess.DEVNULL,
                 pass_fds=pass_fds)
    if stdin_data is not None:
        try:
            p.stdin.write(stdin_data)
        except OSError:
            pass
        p.stdin.close()
    return finish(p, r, timeout or settings.timeout)


def sanitizer_env(build, leaks=True):
    if not build.sanitizer:
        return {}
    return {"ASAN_OPTIONS": "detect_leaks=%d:abort_on_error=0" % (1 if leaks else 0),
            "UBSAN_OPTIONS": "print_stacktrace=1"}


# ------------------------------------------------------------------------------------------------
# The tally: cases and defects per surface
# ------------------------------------------------------------------------------------------------

class Case:
    """One hostile case: its runs, and every defect found in it, by column."""

    def __init__(self, surface, name):
        self.surface, self.name = surface, name
        self.commands, self.files = [], []
        self.defects = {c: [] for c, _ in COLUMNS[1:]}
        self.notes = []

    def add(self, column, why):
        self.defects[column].append(why)

    def judge(self, r, expected_signal=None):
        """Records the run's command and any crash, sanitizer report or hang. True when the run
        ended on its own (its status and files may be judged further)."""
        self.commands.append(r.text())
        if r.hung:
            self.add("hangs", "still running after %.0f s: %s" % (r.seconds, r.text()))
            return False
        m = SANITIZER_RE.search(r.err)
        if m:
            self.add("sanitizer", "%r on stderr: %s" % (m.group(0), tail(r.err)))
        if r.signalled is not None:
            return False
        if r.rc < 0 and -r.rc != expected_signal:
            self.add("crashes", "killed by %s: %s" % (signal_name(-r.rc), tail(r.err)))
            return False
        if r.rc >= 128:
            self.add("crashes", "exit %d: %s" % (r.rc, tail(r.err)))
            return False
        return not m

    def failed(self):
        return any(self.defects.values())


class Tally:
    def __init__(self):
        self.lock = threading.Lock()
        self.order = []
        self.rows = {}
        self.cases = []
        self.errors = []  # the campaign's own exceptions (not rsmooth's defects)
        self.notes = {}

    def surface(self, key, title):
        with self.lock:
            if key not in self.rows:
                self.order.append(key)
                self.rows[key] = {"title": title, **{c: 0 for c, _ in COLUMNS}}

    def record(self, case):
        with self.lock:
            row = self.rows[case.surface]
            row["cases"] += 1
            for column, found in case.defects.items():
                if found:
                    row[column] += 1
            self.cases.append(case)

    def note(self, surface, key, count=1):
        with self.lock:
            n = self.notes.setdefault(surface, {})
            n[key] = n.get(key, 0) + count


def run_cases(settings, tally, jobs):
    """Runs (surface, name, function) jobs, `settings.jobs` at a time; each function takes its
    Case and fills it. An exception in the campaign's own code is reported, not counted."""
    def one(job):
        surface, name, fn = job
        case = Case(surface, name)
        try:
            fn(case)
        except Exception:  # the campaign's bug, shown so it gets fixed
            with tally.lock:
                tally.errors.append("%s / %s:\n%s" % (surface, name, traceback.format_exc()))
            return
        tally.record(case)

    with ThreadPoolExecutor(max_workers=max(1, settings.jobs)) as pool:
        list(pool.map(one, jobs))


def tail(text, n=400):
    text = text.strip()
    return text if len(text) <= n else "..." + text[-n:]


def said(err, n=400):
    """rsmooth's own lines of a stderr (Open MPI adds its banners), else its tail."""
    mine = [line for line in err.splitlines() if line.startswith(("rsmooth", "hostile_api"))]
    return tail("\n".join(mine) if mine else err, n)


def signal_name(n):
    try:
        return signal.Signals(n).name
    except ValueError:
        return "signal %d" % n


# ------------------------------------------------------------------------------------------------
# Meshes and PLY files
# ------------------------------------------------------------------------------------------------

def noisy_grid(n, seed, scale=1.0, noise=0.12, origin=(0.0, 0.0, 0.0)):
    """An n x n grid of spacing `scale`, jittered, with noisy heights, and its triangles."""
    rng = random.Random(seed)
    verts = [(origin[0] + scale * (i + rng.uniform(-.2, .2)),
              origin[1] + scale * (j + rng.uniform(-.2, .2)),
              origin[2] + scale * rng.gauss(0, noise))
             for j in range(n) for i in range(n)]
    tris = []
    for j in range(n - 1):
        for i in range(n - 1):
            a = j * n + i
            tris += [(a, a + 1, a + n + 1), (a, a + n + 1, a + n)]
    return verts, tris


def dome(n, apex, seed):
    """A dome over an n x n grid of unit spacing whose apex reaches `apex` (float32 extremes)."""
    rng = random.Random(seed)
    c = (n - 1) / 2
    verts = []
    for j in range(n):
        for i in range(n):
            r2 = ((i - c) ** 2 + (j - c) ** 2) / (c * c)
            verts.append((i + rng.uniform(-.1, .1), j + rng.uniform(-.1, .1),
                          max(0.0, 1 - r2) * apex * (1 - rng.uniform(0, 1e-3))))
    _, tris = noisy_grid(n, 0)
    return verts, tris


def plateau(n, top, low=0.9):
    """A plateau at height `top` (spacing top / 50) whose every third vertex lies lower (`low`
    times `top`): the tilted planes of their triangles reach past `top`, so smoothing moves
    vertices above it (beyond FLT_MAX when `top` is near it)."""
    verts = [(i * 0.02 * top, j * 0.02 * top, top if (7 * i + 3 * j) % 3 else low * top)
             for j in range(n) for i in range(n)]
    _, tris = noisy_grid(n, 0)
    return verts, tris


TYPES = {"char": "b", "int8": "b", "uchar": "B", "uint8": "B", "short": "h", "int16": "h",
         "ushort": "H", "uint16": "H", "int": "i", "int32": "i", "uint": "I", "uint32": "I",
         "float": "f", "float32": "f", "double": "d", "float64": "d"}


def ply_bytes(verts, tris, fmt="binary_little_endian", vtype="float", comments=("hostile 23",),
              bom=False, header_extra=()):
    """A PLY file of these vertices and triangles, in this script's own writer."""
    lines = ["ply", "format %s 1.0" % fmt] + ["comment " + c for c in comments] + list(header_extra)
    lines += ["element vertex %d" % len(verts)] + ["property %s %s" % (vtype, a) for a in "xyz"]
    lines += ["element face %d" % len(tris), "property list uchar int vertex_indices", "end_header"]
    head = ("\n".join(lines) + "\n").encode()
    if fmt == "ascii":
        body = "".join("%r %r %r\n" % tuple(float(c) for c in v) for v in verts)
        body += "".join("3 %d %d %d\n" % t for t in tris)
        data = head + body.encode()
    else:
        e = "<" if fmt == "binary_little_endian" else ">"
        c = TYPES[vtype]
        data = head + b"".join(struct.pack(e + "3" + c, *v) for v in verts)
        data += b"".join(struct.pack(e + "B3i", 3, *t) for t in tris)
    return (b"\xef\xbb\xbf" if bom else b"") + data


class PlyError(Exception):
    pass


def read_ply(data):
    """The vertex positions of a PLY file and the x type, by this script's own reader: ascii and
    binary of either byte order, any elements and list properties before the vertices."""
    if data.startswith(b"\xef\xbb\xbf"):
        data = data[3:]
    pos, elements, fmt = 0, [], None
    while True:
        end = data.find(b"\n", pos)
        if end < 0:
            raise PlyError("no end_header")
        words = data[pos:end].decode("latin-1").split()
        pos = end + 1
        if not words:
            continue
        if words[0] == "end_header":
            break
        if words[0] == "format":
            fmt = words[1]
        elif words[0] == "element":
            elements.append((words[1], int(words[2]), []))
        elif words[0] == "property":
            elements[-1][2].append(words[1:])
    vertex = [e for e in elements if e[0] == "vertex"]
    if not vertex or fmt not in ("ascii", "binary_little_endian", "binary_big_endian"):
        raise PlyError("no vertex element or format")
    if fmt == "ascii":
        tokens = data[pos:].split()
        t = 0
        for name, count, props in elements:
            rows = []
            for _ in range(count):
                row = {}
                for p in props:
                    if p[0] == "list":
                        n = int(tokens[t])
                        t += 1 + n
                    else:
                        row[p[1]] = float(tokens[t])
                        t += 1
                rows.append(row)
            if name == "vertex":
                xt = [p[0] for p in props if p[-1] == "x"][0]
                return [(r["x"], r["y"], r["z"]) for r in rows], xt
    e = "<" if fmt == "binary_little_endian" else ">"
    for name, count, props in elements:
        if name == "vertex":
            if any(p[0] == "list" for p in props):
                raise PlyError("a list in the vertex element")
            row = e + "".join(TYPES[p[0]] for p in props)
            size = struct.calcsize(row)
            names = [p[1] for p in props]
            ix, iy, iz = names.index("x"), names.index("y"), names.index("z")
            if pos + size * count > len(data):
                raise PlyError("vertex data truncated")
            out = []
            for k in range(count):
                r = struct.unpack_from(row, data, pos + k * size)
                out.append((r[ix], r[iy], r[iz]))
            return out, props[ix][0]
        for _ in range(count):
            for p in props:
                if p[0] == "list":
                    (n,) = struct.unpack_from(e + TYPES[p[1]], data, pos)
                    pos += struct.calcsize(TYPES[p[1]]) + n * struct.calcsize(TYPES[p[2]])
                else:
                    pos += struct.calcsize(TYPES[p[0]])
    raise PlyError("unreachable")


def read_ply_file(path):
    with open(path, "rb") as f:
        return read_ply(f.read())


def unrepresentable(verts, vtype):
    """The first coordinate a file of `vtype` must not hold with exit 0: not finite, or a float32
    subnormal in a mesh that lies wholly below FLT_MIN (where float32 keeps no precision at the
    mesh's own scale: a subnormal beside larger coordinates loses nothing that matters)."""
    largest = max([abs(x) for v in verts for x in v if x == x] or [0])
    for i, v in enumerate(verts):
        for x in v:
            if x != x or abs(x) == float("inf"):
                return "vertex %d: %r" % (i, x)
            if vtype in ("float", "float32") and 0 < abs(x) < FLT_MIN and largest < FLT_MIN:
                return "vertex %d: %r, a float32 subnormal in a mesh below FLT_MIN" % (i, x)
    return None


# ------------------------------------------------------------------------------------------------
# Folders before and after
# ------------------------------------------------------------------------------------------------

def digest(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()[:16]


def listing(folder):
    """name -> (kind, mode, uid, gid, content) for everything under `folder`, links not
    followed; content is a regular file's digest or a link's target."""
    out = {}
    for dirpath, dirs, files in os.walk(folder):
        for name in dirs + files:
            p = os.path.join(dirpath, name)
            try:
                st = os.lstat(p)
            except OSError:
                continue
            kind = stat.S_IFMT(st.st_mode)
            if stat.S_ISREG(st.st_mode):
                content = digest(p)
            elif stat.S_ISLNK(st.st_mode):
                content = os.readlink(p)
            else:
                content = ""
            out[os.path.relpath(p, folder)] = (kind, stat.S_IMODE(st.st_mode), st.st_uid,
                                               st.st_gid, content)
    return out


KIND_NAMES = {stat.S_IFREG: "file", stat.S_IFDIR: "folder", stat.S_IFLNK: "link",
              stat.S_IFIFO: "FIFO", stat.S_IFCHR: "device", stat.S_IFBLK: "block device",
              stat.S_IFSOCK: "socket"}


def describe(entry):
    if entry is None:
        return "absent"
    kind, mode, uid, gid, content = entry
    return "%s %04o %d:%d %s" % (KIND_NAMES.get(kind, "?"), mode, uid, gid, content)


def changes(before, after, allowed=()):
    """What changed between two listings, except the names in `allowed`."""
    out = []
    for name in sorted(set(before) | set(after)):
        if name in allowed:
            continue
        b, a = before.get(name), after.get(name)
        if b != a:
            out.append("%s: %s -> %s" % (name, describe(b), describe(a)))
    return out


def leftovers(folder):
    """rsmooth's temporaries and partial files left in `folder` (not recursive)."""
    try:
        return sorted(n for n in os.listdir(folder) if n.startswith(".rsmooth-"))
    except OSError:
        return []


def write(path, data, mode=None):
    with open(path, "wb") as f:
        f.write(data)
    if mode is not None:
        os.chmod(path, mode)


def read(path):
    with open(path, "rb") as f:
        return f.read()


# ------------------------------------------------------------------------------------------------
# The three writers of an output file
# ------------------------------------------------------------------------------------------------

WRITERS = ("memory", "stream", "mpi")


def writer_argv(settings, build, writer, args, cap="10M"):
    """The command of one writer: the in-memory command, the streamed command (--max-memory) or
    rsmooth-mpi on 2 ranks, with `args` after it."""
    if writer == "memory":
        return [build.rsmooth] + list(args)
    if writer == "stream":
        return [build.rsmooth, "--max-memory", cap] + list(args)
    return [settings.mpirun, "-n", "2", "--oversubscribe", build.mpi, "--max-memory", cap] + list(args)


def writer_env(build, writer, extra=None):
    """Open MPI's own allocations read as leaks under AddressSanitizer: leak checks off there."""
    e = sanitizer_env(build, leaks=writer != "mpi")
    e.update(extra or {})
    return e


def make_special(path, kind):
    """Makes a file that is not a regular one at `path`, links beside it named as the README of
    the campaign says: fifo, device (/dev/null's numbers), folder, socket, dangling-link,
    link-into-missing-folder, link-to-folder (./folder), link-to-fifo, link-to-device, link-loop."""
    import socket
    d = os.path.dirname(path)
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "device":
        os.mknod(path, 0o666 | stat.S_IFCHR, os.makedev(1, 3))
    elif kind == "folder":
        os.makedirs(path)
    elif kind == "socket":
        s = socket.socket(socket.AF_UNIX)
        s.bind(path)
        s.close()
    elif kind == "dangling-link":
        os.symlink("missing.ply", path)
    elif kind == "link-into-missing-folder":
        os.symlink("nowhere/out.ply", path)
    elif kind == "link-to-folder":
        os.symlink("folder", path)
    elif kind == "link-to-fifo":
        os.mkfifo(os.path.join(d, "fifo"))
        os.symlink("fifo", path)
    elif kind == "link-to-device":
        os.mknod(os.path.join(d, "null"), 0o666 | stat.S_IFCHR, os.makedev(1, 3))
        os.symlink("null", path)
    elif kind == "link-loop":
        os.symlink("loop2.ply", path)
        os.symlink(os.path.basename(path), os.path.join(d, "loop2.ply"))
    else:
        raise ValueError("no special file kind " + kind)


def record_batch(r, surface, label, command, tally):
    """Records each case a batch child printed (a line "begin N" before case N, then one JSON
    line with its verdict); returns the case begun last and the set of cases finished."""
    import json
    begun, done = None, set()
    for line in r.out.decode("utf-8", "replace").splitlines():
        if line.startswith("begin "):
            begun = int(line.split()[1])
            continue
        try:
            d = json.loads(line)
        except ValueError:
            continue
        done.add(d["case"])
        case = Case(surface, "%s %d: %s" % (label, d["case"], d["what"]))
        case.commands.append(command(d))
        if d["verdict"] != "ok":
            detail = d["detail"]
            if "status" in d:
                detail = "%s: %s (status %s: %s)" % (d["verdict"], detail, d["status"], d["message"])
            case.add(d["verdict"], detail)
        elif d["detail"]:
            case.notes.append(d["detail"])
        tally.record(case)
    return begun, done


def record_ended(r, argv, at, surface, label, tally):
    """Records the batch child that ended (crash, hang, sanitizer report) inside case `at`, with
    the command that runs that case alone (argv[3:5] are the first and end case)."""
    case = Case(surface, label)
    r.argv = argv[:3] + [str(at), str(at + 1)] + argv[5:]
    case.judge(r)
    if not case.failed():
        case.add("crashes", "exit %d: %s" % (r.rc, tail(r.err)))
    tally.record(case)
