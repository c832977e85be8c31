"""Item 6: rsmooth-mpi ranks started with different jobs (MPMD: `mpirun -n 1 rsmooth-mpi A : -n 1
rsmooth-mpi B`). A rank given another cap, input, parameter or output must make the whole run
fail, naming that rank, with nothing written and nothing left; what may differ (--device, --quiet)
must give the single process's bytes. Oracle: `rsmooth --max-memory` on one process.

One case goes past what the issue asked for: rank 1's input has the same size, time and header as
rank 0's and differs only between the bytes the ranks' digest samples. It has a row of its own."""

import os

from . import common as c

TITLE = "rsmooth-mpi ranks that differ (item 6)"
TITLE_SAMPLED = "rsmooth-mpi: input differing between sampled bytes"
CAP = "10M"


class MpiAgreeCases:
    def __init__(self, settings, build):
        self.s, self.b = settings, build
        self.surface = "%s/mpi-agree" % build.name
        self.sampled_surface = "%s/mpi-sampled" % build.name
        self.dir = os.path.join(settings.out, build.name, "mpi-agree")
        os.makedirs(self.dir)

    def prepare(self):
        verts, tris = c.noisy_grid(120, seed=6)  # several pieces under the 10 MB cap
        self.input = os.path.join(self.dir, "in.ply")
        self.data = c.ply_bytes(verts, tris)
        c.write(self.input, self.data)
        v2, t2 = c.noisy_grid(120, seed=7)
        c.write(os.path.join(self.dir, "other.ply"), c.ply_bytes(v2, t2))
        c.write(os.path.join(self.dir, "truncated.ply"), self.data[:len(self.data) // 2])
        c.write(os.path.join(self.dir, "copy.ply"), self.data)
        os.utime(os.path.join(self.dir, "copy.ply"), (1e9, 1e9))
        os.symlink("in.ply", os.path.join(self.dir, "link.ply"))
        out = os.path.join(self.dir, "single.ply")
        r = c.run([self.b.rsmooth, self.input, "-o", out, "-q", "--max-memory", CAP, "--device",
                   "reference"], self.s, env=c.sanitizer_env(self.b), timeout=600)
        if r.rc != 0:
            raise RuntimeError("the single-process run failed: %s" % r.err)
        self.expected = c.read(out)
        out = os.path.join(self.dir, "single-cpu.ply")
        r = c.run([self.b.rsmooth, self.input, "-o", out, "-q", "--max-memory", CAP, "--device",
                   "cpu"], self.s, env=c.sanitizer_env(self.b), timeout=600)
        self.expected_cpu = c.read(out) if r.rc == 0 else None
        self.sampled = self.unsampled_change(verts, tris)

    def unsampled_change(self, verts, tris):
        """A copy that the ranks' digest cannot tell from in.ply: one vertex changed outside the
        first 64 KiB and the 16 windows of 4 KiB it samples (host/mpi_agree.c), same size and
        times. Returns its name."""
        size, head, window, samples = len(self.data), 64 * 1024, 4096, 16
        sampled = [(0, head)] + [(int((size - window) * i / samples),
                                  int((size - window) * i / samples) + window)
                                 for i in range(1, samples + 1)]
        header = self.data.index(b"end_header\n") + 11
        for v in range(len(verts) // 2, len(verts)):
            at = header + 12 * v
            if all(at + 12 <= a or at >= b for a, b in sampled):
                break
        b = bytearray(self.data)
        b[at + 8:at + 12] = bytes(b[at + 8:at + 12][::-1])  # z's bytes reversed: far off
        path = os.path.join(self.dir, "sampled.ply")
        c.write(path, bytes(b))
        st = os.stat(self.input)
        os.utime(path, ns=(st.st_atime_ns, st.st_mtime_ns))
        return "sampled.ply"

    def mpmd(self, case, ranks_args, must_fail, blamed=None, part=None):
        d = os.path.join(self.dir, "case%03d" % int(case.name.split(":")[0]))
        os.makedirs(d)
        for name in ("in.ply", "other.ply", "truncated.ply", "copy.ply", "link.ply", "sampled.ply"):
            src = os.path.join(self.dir, name)
            if os.path.islink(src):
                os.symlink(os.readlink(src), os.path.join(d, name))
            else:
                os.link(src, os.path.join(d, name))
        argv = [self.s.mpirun, "--oversubscribe"]
        for k, args in enumerate(ranks_args):
            argv += ([":"] if k else []) + ["-n", "1", self.b.mpi] + args
        before = c.listing(d)
        r = c.run(argv, self.s, cwd=d, env=c.writer_env(self.b, "mpi"))
        if not case.judge(r):
            return
        made = c.changes(before, c.listing(d))
        if must_fail:
            if r.rc == 0:
                case.add("wrong", "exit 0 with ranks given different %s" % part)
                try:
                    if c.read(os.path.join(d, "out.ply")) != self.expected:
                        case.notes.append("and out.ply is not the single process's result")
                except OSError:
                    pass
            else:
                if made:
                    case.add("lost", "a refused run changed the folder: %s" % "; ".join(made))
                if "rank %d" % blamed not in r.err:
                    case.add("other", "the message does not name rank %d: %s" % (blamed, c.said(r.err)))
        else:
            if r.rc != 0:
                if part == "either":
                    case.notes.append("refused: %s" % c.said(r.err))
                else:
                    case.add("other", "refused ranks that may differ in %s: %s" % (part, c.said(r.err)))
            elif c.read(os.path.join(d, "out.ply")) != (self.expected_cpu if part == "--device"
                                                        else self.expected):
                case.add("wrong", "exit 0, and out.ply is not the single process's bytes")
        left = c.leftovers(d)
        if left:
            case.add("lost", "left behind: %s" % left)

    def jobs(self):
        rng = self.s.rng("mpi-agree", self.b.name)
        out = []
        base = ["in.ply", "-o", "out.ply", "-q", "--device", "reference"]

        def add(name, ranks_args, must_fail, blamed=1, part=None, surface=None):
            name = "%d: %s" % (len(out), name)
            out.append((surface or self.surface, name,
                        lambda case: self.mpmd(case, ranks_args, must_fail, blamed, part)))

        caps = ["10M", "11M", "12M", "24M", "1G", "10485761"]
        for k in range(3):
            a, b = rng.sample(caps, 2)
            add("--max-memory %s and %s" % (a, b), [base + ["--max-memory", a], base + ["--max-memory", b]],
                True, part="--max-memory")
        with_cap = base + ["--max-memory", CAP]
        for other in ("other.ply", "truncated.ply", "copy.ply", "missing.ply"):
            add("rank 1 reads %s" % other, [with_cap, [other] + with_cap[1:]], True, part="the input")
        add("rank 1 reads a link to the same file", [with_cap, ["link.ply"] + with_cap[1:]], False,
            part="a link to the same file")
        params = [["--sigma-f", "%.3g" % rng.uniform(0.5, 4)], ["--sigma-g", "%.3g" % rng.uniform(0.1, 2)],
                  ["--cutoff", "%.3g" % rng.uniform(1, 5)], ["--normals", "bilateral"],
                  ["--influence", rng.choice(["tukey", "huber", "lorentzian"])], ["--no-mollify"],
                  ["--absolute"], ["--method", "gaussian"], ["--sigma-g", "inf"],
                  ["--normals", "bilateral", "--normal-sigma-n", "0.5"],
                  ["--normals", "bilateral", "--normal-iterations", "3"]]
        for p in rng.sample(params, 6):
            add("rank 1 adds %s" % " ".join(p), [with_cap, with_cap + p], True, part="the parameters")
        add("rank 1 writes elsewhere.ply", [with_cap, ["in.ply", "-o", "elsewhere.ply"] + with_cap[3:]],
            True, part="the output")
        add("rank 1 adds --force", [with_cap, with_cap + ["--force"]], True, part="the output")
        add("rank 1 writes ./out.ply", [with_cap, ["in.ply", "-o", "./out.ply"] + with_cap[3:]], False,
            part="either")
        add("rank 1 adds --tmpdir .", [with_cap, with_cap + ["--tmpdir", "."]], False, part="either")
        if self.expected_cpu is not None:
            on_cpu = with_cap[:4] + ["--device", "cpu"] + with_cap[6:]
            add("rank 0 on --device cpu, rank 1 on auto (one device, two names)",
                [on_cpu, on_cpu[:5] + ["auto"] + on_cpu[6:]], False, part="--device")
        add("rank 1 without -q", [with_cap, [a for a in with_cap if a != "-q"]], False, part="--quiet")
        add("3 ranks, rank 2 with --sigma-f 3", [with_cap, with_cap, with_cap + ["--sigma-f", "3"]],
            True, blamed=2, part="the parameters")
        add("3 ranks, rank 1 with --max-memory 20M", [with_cap, base + ["--max-memory", "20M"], with_cap],
            True, blamed=1, part="--max-memory")
        add("rank 1 reads a file of the same size, time and header, differing between the sampled "
            "bytes", [with_cap, [self.sampled] + with_cap[1:]], True, part="the input",
            surface=self.sampled_surface)
        return out
