"""Items 4 and 15: the streamed path (--max-memory, and rsmooth-mpi on 2 ranks) accepts what the
in-memory command accepts and writes the same bytes, and never writes what a float32 file cannot
hold.

Generated inputs: PLYs without comments, with a byte-order mark, with headers over 1 MB (a comment
holding 'end_header' before the real one), doubles at 1e-200 ... 1e-307 (OpenCL and reference),
negative list counts in an element before the vertices, float32 domes reaching FLT_MAX and grids at
1e-44 ... 1e-36, and seeded prefixes and corruptions of scripts/stream_hostile.py's files. Oracle:
the in-memory run of the same command (its status and its bytes), and this script's own PLY reader
for infinities, NaNs and float32 subnormals in anything written with exit 0."""

import os
import struct
import sys

from . import common as c

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import stream_hostile  # noqa: E402  (its generator of binary PLYs)

TITLE_STREAM = "streamed = in memory (items 4, 15)"
TITLE_WIDE = "filter widths up to double range"


def negative_count(verts, tris, count_type, value, row):
    """A PLY whose element before the vertices has a list whose count at `row` is `value`."""
    rows = 4
    head = ("ply\nformat binary_little_endian 1.0\ncomment hostile\nelement extra %d\n"
            "property list %s int data\nelement vertex %d\nproperty float x\nproperty float y\n"
            "property float z\nelement face %d\nproperty list uchar int vertex_indices\n"
            "end_header\n" % (rows, count_type, len(verts), len(tris))).encode()
    code = c.TYPES[count_type]
    extra = b"".join(struct.pack("<" + code, value if k == row else 2) +
                     (struct.pack("<2i", 1, 2) if k != row else b"") for k in range(rows))
    body = b"".join(struct.pack("<3f", *v) for v in verts)
    body += b"".join(struct.pack("<B3i", 3, *t) for t in tris)
    return head + extra + body


def mean_edge(verts, tris):
    """Mean length of the unique edges, as rsmooth's unit of relative widths."""
    edges = {tuple(sorted((t[i], t[(i + 1) % 3]))) for t in tris for i in range(3)}
    return sum(sum((verts[a][k] - verts[b][k]) ** 2 for k in range(3)) ** 0.5
               for a, b in edges) / len(edges)


class StreamCases:
    def __init__(self, settings, build, corruptions):
        self.s, self.b = settings, build
        self.surface = "%s/stream" % build.name
        self.wide_surface = "%s/wide" % build.name
        self.dir = os.path.join(settings.out, build.name, "stream")
        os.makedirs(self.dir)
        self.corruptions = corruptions

    def compare(self, case, data, device="reference", mpi=True, cap="10M", precision=False):
        d = os.path.join(self.dir, "case%03d" % int(case.name.split(":")[0]))
        os.makedirs(d)
        c.write(os.path.join(d, "in.ply"), data)
        case.files.append(os.path.join(d, "in.ply"))
        dev = ["--device", device]
        rm = c.run([self.b.rsmooth, "in.ply", "-o", "memory.ply", "-q"] + dev, self.s, cwd=d,
                   env=c.sanitizer_env(self.b))
        if not case.judge(rm):
            return
        memory = c.read(os.path.join(d, "memory.ply")) if rm.rc == 0 else None
        exact = self.double_result(case, d, data) if precision and device == "reference" else None
        if memory is not None:
            self.representable(case, memory, "the in-memory output", exact)
        writers = ["stream"] + (["mpi"] if mpi and self.b.has_mpi() else [])
        for w in writers:
            name = "%s.ply" % w
            r = c.run(c.writer_argv(self.s, self.b, w, ["in.ply", "-o", name, "-q"] + dev, cap),
                      self.s, cwd=d, env=c.writer_env(self.b, w))
            if not case.judge(r):
                continue
            out = os.path.join(d, name)
            if r.rc == 0:
                got = c.read(out)
                self.representable(case, got, "the %s output" % w, exact)
                if memory is None:
                    case.add("wrong", "%s exit 0 where the in-memory run refuses: %s"
                             % (w, c.said(rm.err, 200)))
                elif got != memory:
                    case.add("wrong", "%s output differs from the in-memory bytes (%s)"
                             % (w, self.how_different(got, memory)))
            else:
                if os.path.exists(out):
                    case.add("lost", "%s exit %d left its output" % (w, r.rc))
                if not r.err.strip():
                    case.add("other", "%s refused without a message" % w)
                if memory is not None:
                    if self.switched_to_double(data, memory) and r.rc == 1:
                        case.notes.append("%s refused a float file the in-memory writer wrote as "
                                          "double (documented): %s" % (w, c.said(r.err, 160)))
                    else:
                        case.add("other", "%s refused (exit %d) what the in-memory run accepts: %s"
                                 % (w, r.rc, c.said(r.err, 200)))
                elif (rm.rc == 1) != (r.rc == 1):
                    case.notes.append("statuses differ: in memory %d, %s %d" % (rm.rc, w, r.rc))
        left = c.leftovers(d)
        if left:
            case.add("lost", "left behind: %s" % left)

    def double_result(self, case, d, data):
        """The reference path's result on the same values written as doubles: what a float32
        output must hold within float precision at the mesh's scale."""
        verts, tris = self.faces_of(data)
        c.write(os.path.join(d, "double.ply"), c.ply_bytes(verts, tris, vtype="double"))
        r = c.run([self.b.rsmooth, "double.ply", "-o", "double-out.ply", "-q", "--device",
                   "reference"], self.s, cwd=d, env=c.sanitizer_env(self.b))
        if not case.judge(r) or r.rc != 0:
            case.notes.append("no double result: %s" % c.said(r.err, 160))
            return None
        return c.read_ply_file(os.path.join(d, "double-out.ply"))[0]

    @staticmethod
    def faces_of(data):
        """This campaign's own float PLYs: positions and triangles back."""
        verts, _ = c.read_ply(data)
        head = data[:data.index(b"end_header\n") + 11]
        body = data[len(head) + 12 * len(verts):]
        tris = [struct.unpack_from("<3i", body, 13 * k + 1) for k in range(len(body) // 13)]
        return verts, tris

    @staticmethod
    def representable(case, data, what, exact=None):
        try:
            verts, vtype = c.read_ply(data)
        except (c.PlyError, struct.error, ValueError, IndexError) as e:
            case.add("wrong", "%s is not a PLY this script reads: %s" % (what, e))
            return
        bad = c.unrepresentable(verts, vtype)
        if bad:
            case.add("wrong", "%s holds %s (x type %s), exit 0" % (what, bad, vtype))
        elif exact is not None and vtype in ("float", "float32"):
            largest = max(abs(x) for v in exact for x in v)
            worst = max(abs(a - b) for p, q in zip(verts, exact) for a, b in zip(p, q))
            if worst > largest * 2.0 ** -24:
                case.add("wrong", "%s is off the double result by %.3g, beyond float precision at "
                         "the mesh's scale (%.3g), exit 0" % (what, worst, largest * 2.0 ** -24))

    def wide(self, case, data, args, device, edge):
        """Filter widths up to and past double range on a noisy grid: with exit 0 the vertices
        move (the widest filter is a global average), a device agrees with the reference path
        within 1e-3 mean edges, and the streamed runs write the in-memory bytes or refuse."""
        d = os.path.join(self.dir, "case%03d" % int(case.name.split(":")[0]))
        os.makedirs(d)
        c.write(os.path.join(d, "in.ply"), data)
        before = c.read_ply(data)[0]
        results = {}
        for w, dev in (("memory", device), ("reference", "reference"), ("stream", device),
                       ("mpi", device)):
            if (w == "reference" and device == "reference") or (w == "mpi" and not self.b.has_mpi()):
                continue
            argv = c.writer_argv(self.s, self.b, "memory" if w == "reference" else w,
                                 ["in.ply", "-o", w + ".ply", "-q", "--device", dev] + args)
            r = c.run(argv, self.s, cwd=d, env=c.writer_env(self.b, w))
            if not case.judge(r):
                continue
            if r.rc == 0:
                results[w] = c.read(os.path.join(d, w + ".ply"))
                after = c.read_ply(results[w])[0]
                if all(p == q for p, q in zip(before, after)):
                    case.add("wrong", "%s on %s: exit 0 and not one vertex moved" % (w, dev))
            elif not r.err.strip():
                case.add("other", "%s refused without a message" % w)
            else:
                case.notes.append("%s refused: %s" % (w, c.said(r.err, 160)))
        if "memory" in results and "reference" in results:
            a, b = c.read_ply(results["memory"])[0], c.read_ply(results["reference"])[0]
            worst = max(abs(x - y) for p, q in zip(a, b) for x, y in zip(p, q)) / edge
            if worst > 1e-3:
                case.add("wrong", "exit 0 on %s, %.3g mean edges from the reference path" % (device, worst))
        for w in ("stream", "mpi"):
            if w in results and "memory" in results and results[w] != results["memory"]:
                case.add("wrong", "%s output differs from the in-memory bytes" % w)

    @staticmethod
    def switched_to_double(data, memory):
        try:
            return c.read_ply(data)[1] in ("float", "float32") and \
                c.read_ply(memory)[1] in ("double", "float64")
        except Exception:
            return False

    @staticmethod
    def how_different(a, b):
        try:
            va, vb = c.read_ply(a)[0], c.read_ply(b)[0]
            moved = sum(p != q for p, q in zip(va, vb))
            return "%d and %d bytes; %d of %d positions differ" % (len(a), len(b), moved, len(vb))
        except Exception:
            return "%d and %d bytes" % (len(a), len(b))

    def jobs(self):
        rng = self.s.rng("stream", self.b.name)
        out = []

        def add(name, data, **kw):
            name = "%d: %s" % (len(out), name)
            out.append((self.surface, name, lambda case: self.compare(case, data, **kw)))

        verts, tris = c.noisy_grid(40 if self.b.sanitizer else 60, seed=15)
        # rsmooth-mpi runs every case of these families that is not marked mpi=False
        for fmt in ("binary_little_endian", "binary_big_endian"):
            for vtype in ("float", "double"):
                add("no comment, %s %s" % (fmt, vtype), c.ply_bytes(verts, tris, fmt, vtype, comments=()),
                    mpi=vtype == "float")
        add("byte-order mark, no comment", c.ply_bytes(verts, tris, comments=(), bom=True))
        add("byte-order mark, big-endian double",
            c.ply_bytes(verts, tris, "binary_big_endian", "double", bom=True), mpi=False)
        add("byte-order mark on the OpenCL device", c.ply_bytes(verts, tris, bom=True), device="cpu",
            mpi=False)
        for k in range(2):
            size = rng.randint(1_050_000, 2_000_000)
            lines, total = ["the end_header line comes later"], 0
            while total < size:
                n = rng.randint(10, 60000)
                lines.append("x" * n)
                total += n + 9
            add("header of %d bytes" % total, c.ply_bytes(verts, tris, comments=lines,
                                                          vtype=rng.choice(["float", "double"])),
                mpi=k == 0)
        for exponent in (-300, -305, -307, -250, rng.randint(-290, -200)):
            v, t = c.noisy_grid(40, seed=exponent, scale=10.0 ** exponent)
            for device in ("reference", "cpu"):
                add("doubles at 1e%d on %s" % (exponent, device), c.ply_bytes(v, t, vtype="double"),
                    device=device, mpi=exponent in (-300, -307))
        for count_type, value in (("char", -3), ("char", -128), ("int", -1), ("int", -2 ** 31),
                                  ("short", -7)):
            add("list count %d (%s) before the vertices" % (value, count_type),
                negative_count(verts, tris, count_type, value, rng.randrange(4)),
                mpi=count_type == "char")
        for apex in (c.FLT_MAX, c.FLT_MAX * 0.9999, 3.0e38, 1.0e38):
            v, t = c.dome(41, apex, seed=int(apex % 1000))
            for device in ("reference", "cpu"):
                add("float32 dome to %.6g on %s" % (apex, device), c.ply_bytes(v, t), device=device,
                    precision=True, mpi=False)
        for top, low in ((c.FLT_MAX, 0.9), (c.FLT_MAX * (1 - 2 ** -22), rng.uniform(0.5, 0.95)),
                         (c.FLT_MAX * 0.999, 0.5), (3.0e38, 0.9)):
            v, t = c.plateau(24, top, low)
            for device in ("reference", "cpu"):
                add("float32 plateau at %.6g on %s" % (top, device), c.ply_bytes(v, t),
                    device=device, precision=True, mpi=device == "cpu")
        for scale in (1e-44, 1e-42, 1e-40, 1e-39, 1e-38, 3e-38, 1e-37, 1e-36):
            v, t = c.noisy_grid(30, seed=7, scale=scale)
            for device in ("reference", "cpu"):
                add("float32 grid at %g on %s" % (scale, device), c.ply_bytes(v, t), device=device,
                    precision=True, mpi=device == "reference" and scale in (1e-44, 1e-39, 1e-37))
        # filter widths far past the mesh, up to double range (beyond the issue: a row of its own)
        v, t = c.noisy_grid(20, seed=9)
        edge = mean_edge(v, t)
        for wide in (["--sigma-f", "1e3"], ["--sigma-f", "1e6"], ["--sigma-f", "1e10"],
                     ["--sigma-f", "1e20"], ["--sigma-f", "1e300"], ["--sigma-f", "1.7e308"],
                     ["--sigma-f", "1e308", "--cutoff", "5"],
                     ["--absolute", "--sigma-f", "1e308", "--cutoff", "5"],
                     ["--normals", "bilateral", "--normal-sigma-s", "1e308", "--cutoff", "5"]):
            for device in ("reference", "cpu"):
                name = "%d: %s on %s" % (len(out), " ".join(wide), device)
                out.append((self.wide_surface, name, lambda case, w=wide, dv=device, dt=c.ply_bytes(v, t):
                            self.wide(case, dt, w, dv, edge)))
        v, t = c.noisy_grid(30, seed=8, scale=1e-30, origin=(1e-20, 0, 0))
        add("float32 grid at 1e-30 beside 1e-20", c.ply_bytes(v, t), precision=True)
        # prefixes and corruptions of scripts/stream_hostile.py's files, streamed and in memory
        import random
        hrng = random.Random(rng.random())
        hv, hq = stream_hostile.grid(6, hrng)
        htris = [x for f in hq for x in ((f[0], f[1], f[2]), (f[0], f[2], f[3]))]
        bases = {
            "le-float": stream_hostile.ply(hv, htris),
            "be-double-colours": stream_hostile.ply(hv, htris, ">", True, True),
            "quads-flag-lists": stream_hostile.ply(hv, hq, "<", False, False, True, True),
            "faces-first": stream_hostile.ply(hv, htris, "<", False, True, False, True, True),
        }
        for k in range(self.corruptions):
            name, data = hrng.choice(sorted(bases.items()))
            if k % 2 == 0:
                n = hrng.randrange(len(data) + 1)
                add("%s prefix %d" % (name, n), data[:n], mpi=k % 10 == 0)
            else:
                b = bytearray(data)
                for _ in range(hrng.randint(1, 4)):
                    i = hrng.randrange(len(b))
                    b[i] = hrng.randrange(256) if hrng.random() < 0.7 else b[i] ^ (1 << hrng.randrange(8))
                add("%s corrupted" % name, bytes(b), mpi=k % 10 == 1)
        for name, data in sorted(bases.items()):
            add("%s whole" % name, data)
        return out
