"""Items 7, 8 and 9: the piece and stream C API, through scripts/hostile_api.c compiled against each
build's static libraries (with the sanitizers for the sanitizer build).

rsmooth_smooth_piece and rsmooth_piece_halo run hundreds of seeded cases in one process, judged
in C against the whole mesh filtered in memory (see hostile_api.c); a crash, sanitizer report or
hang ends the process at a known case, which is counted, and the next process starts after it.
A progress callback calls rsmooth again from inside a call on a context (the same context, another,
the reference path, destroy, getters): a hang there is a deadlock. rsmooth_stream_smooth runs once
per case, with outputs that are special files (item 7), ranks without a sync, a two-process
all-reduce, bad tmpdirs and caps; the files are judged here."""

import json
import os
import socket
import stat
import subprocess

from . import common as c

TITLE_PIECE = "C API: rsmooth_smooth_piece (items 8, 9)"
TITLE_HALO = "C API: rsmooth_piece_halo (item 8)"
TITLE_REENTRY = "C API: calls from a progress callback"
TITLE_STREAM = "C API: rsmooth_stream_smooth (items 7, 8)"
SCRIPTS = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


class ApiCases:
    def __init__(self, settings, build):
        self.s, self.b = settings, build
        self.dir = os.path.join(settings.out, build.name, "api")
        os.makedirs(self.dir)
        self.driver = os.path.join(self.dir, "hostile_api")
        self.surfaces = {k: "%s/api-%s" % (build.name, k)
                         for k in ("piece", "reentry", "halo", "stream")}

    def compile(self):
        flags = ["-std=c11", "-O1", "-g", "-Wall", "-Wextra"]
        if self.b.sanitizer:
            flags += ["-fsanitize=address,undefined", "-fno-sanitize-recover=all",
                      "-fno-omit-frame-pointer"]
        argv = (["cc"] + flags + ["-o", self.driver, os.path.join(SCRIPTS, "hostile_api.c"),
                                  "-I" + os.path.join(self.b.source, "lib", "include")] + self.b.libs + ["-lpthread", "-lm", "-ldl"])
        p = subprocess.run(argv, capture_output=True, text=True)
        if p.returncode != 0:
            raise RuntimeError("cannot build hostile_api.c: %s\n%s" % (" ".join(argv), p.stderr))

    # in-process cases ----------------------------------------------------------------------------
    def batch(self, tally, mode, count, device=None):
        """Runs cases 0..count-1 of `mode`, starting again after any case that ends the process.
        Returns why nothing ran (no such device), or None."""
        surface = self.surfaces[mode]
        first = 0
        while first < count:
            argv = [self.driver, mode, str(self.s.seed), str(first), str(count)] + (
                [device] if device else [])
            r = c.run(argv, self.s, env=c.sanitizer_env(self.b), cwd=self.dir,
                      timeout=max(60, count // 2 if not self.b.sanitizer else count * 2))
            begun, done = c.record_batch(
                r, surface, mode, lambda d: " ".join(argv[:2] + [str(self.s.seed), str(d["case"]),
                                                                 str(d["case"] + 1)] + argv[5:]),
                tally)
            if r.rc == 0 and not r.hung:
                return None
            if r.rc == 5 and begun is None:
                return "no device %s: %s" % (device, c.said(r.err, 200))
            # the process ended inside case `begun`
            at = begun if begun is not None and begun not in done else first
            c.record_ended(r, argv, at, surface, "%s %d" % (mode, at), tally)
            first = at + 1

    # rsmooth_stream_smooth ----------------------------------------------------------------------
    def prepare_stream(self):
        verts, tris = c.noisy_grid(90, seed=9)
        self.input = os.path.join(self.dir, "in.ply")
        c.write(self.input, c.ply_bytes(verts, tris))
        out = os.path.join(self.dir, "expected.ply")
        r = c.run([self.b.rsmooth, self.input, "-o", out, "-q", "--device", "reference"], self.s,
                  env=c.sanitizer_env(self.b), timeout=600)
        if r.rc != 0:
            raise RuntimeError("the oracle run failed: %s" % r.err)
        self.expected = c.read(out)

    def stream(self, case, output_kind="new", replace=0, rank=0, ranks=0, sync="none",
               tmpdir="-", max_memory=64 << 20, must_fail=False, input_kind="file"):
        d = os.path.join(self.dir, "case%03d" % int(case.name.split(":")[0]))
        os.makedirs(os.path.join(d, "folder"))
        inp = os.path.join(d, "in.ply")
        c.write(inp, c.read(self.input))
        out = os.path.join(d, "out.ply")
        final = out
        if output_kind in ("regular", "link"):
            final = os.path.join(d, "target.ply")
            c.write(final, b"old content\n", 0o640)
            if self.s.root:
                os.chown(final, 65534, 1234)
            if output_kind == "link":
                os.symlink("target.ply", out)
            else:
                final = out
                os.rename(os.path.join(d, "target.ply"), out)
        elif output_kind != "new":
            c.make_special(out, output_kind)
        if input_kind == "zero":
            inp = "/dev/zero"
        elif input_kind == "folder":
            inp = os.path.join(d, "folder")
        elif input_kind == "missing":
            inp = os.path.join(d, "missing.ply")
        if tmpdir == "file":
            tmpdir = inp
        elif tmpdir == "folder":
            tmpdir = os.path.join(d, "folder")
        elif tmpdir == "missing":
            tmpdir = os.path.join(d, "missing")
        before = c.listing(d)
        argv = [self.driver, "stream", inp, out, str(replace), str(rank), str(ranks), sync, tmpdir,
                str(max_memory)]
        r = c.run(argv, self.s, env=c.sanitizer_env(self.b), cwd=d, timeout=120)
        if not case.judge(r):
            return
        if r.rc != 0:
            case.add("crashes" if r.rc >= 3 else "other", "the driver exited %d: %s" % (r.rc, c.said(r.err)))
            return
        results = [json.loads(line) for line in r.out.decode().splitlines()]
        ok = all(x["status"] == "success" for x in results)
        after = c.listing(d)
        name = os.path.relpath(final, d)
        if must_fail:
            if ok:
                case.add("wrong", "success with %s" % case.name.split(": ", 1)[1])
            elif any(not x["message"] for x in results if x["status"] != "success"):
                case.add("other", "refused without a message")
            lost = c.changes(before, {k: v for k, v in after.items() if k in before})
            if lost:
                case.add("lost", "; ".join(lost))
        else:
            if not ok:
                case.add("other", "refused: %s" % "; ".join("%s: %s" % (x["status"], x["message"])
                                                             for x in results))
            elif c.read(final) != self.expected:
                case.add("wrong", "success, and %s is not the in-memory result" % name)
            else:
                if name in before and before[name][0] == stat.S_IFREG:
                    b, a = before[name], after[name]
                    if b[1:4] != a[1:4]:
                        case.add("security", "%s: mode/owner %04o %d:%d became %04o %d:%d"
                                 % ((name,) + b[1:4] + a[1:4]))
                if output_kind == "link" and after.get("out.ply") != before.get("out.ply"):
                    case.add("lost", "the link was replaced: %s" % c.describe(after.get("out.ply")))
            lost = c.changes(before, after, allowed={name, "out.ply"})
            if lost:
                case.add("lost", "; ".join(lost))
        left = c.leftovers(d)
        if left:
            case.add("lost", "left behind: %s" % left)

    def stream_jobs(self):
        out = []
        surface = self.surfaces["stream"]

        def add(name, **kw):
            name = "%d: %s" % (len(out), name)
            out.append((surface, name, lambda case: self.stream(case, **kw)))

        add("new output", output_kind="new")
        add("replace=0 over a file", output_kind="regular", must_fail=True)
        add("replace=1 over a file (mode, owner kept)", output_kind="regular", replace=1)
        add("replace=1 through a link", output_kind="link", replace=1)
        kinds = ["fifo", "folder", "socket", "dangling-link", "link-to-folder", "link-to-fifo"]
        if self.s.root:
            kinds += ["device", "link-to-device"]
        for kind in kinds:
            for replace in (0, 1):
                add("replace=%d over a %s" % (replace, kind), output_kind=kind, replace=replace,
                    must_fail=True)
        for rank, ranks in ((0, 2), (1, 2), (1, 1), (2, 1), (-1, 0), (0, -1), (2 ** 31 - 1, 2 ** 31 - 1),
                            (0, -2 ** 31), (1, 0), (3, 2)):
            add("rank %d of %d without sync" % (rank, ranks), rank=rank, ranks=ranks, must_fail=True)
        for rank, ranks in ((0, 0), (0, 1)):
            add("rank %d of %d alone" % (rank, ranks), rank=rank, ranks=ranks)
        add("two processes, an all-reduce over pipes", sync="fork")
        add("two processes over a file, replace=1", sync="fork", output_kind="regular", replace=1)
        for t in ("", "missing", "file", "/" + "d" * 5000):
            add("tmpdir %r" % t[:20], tmpdir=t, must_fail=True)
        add("tmpdir a folder", tmpdir="folder")
        for cap in (1, 4096, 1 << 20):
            add("max_memory %d" % cap, max_memory=cap, must_fail=True)
        add("max_memory 0 (the default)", max_memory=0)
        add("max_memory 2^63", max_memory=1 << 63)
        for kind in ("zero", "folder", "missing"):
            add("input %s" % kind, input_kind=kind, must_fail=True)
        return out
