"""Item 14: --mask given devices, folders, FIFOs, endless pipes, huge and sparse files, NUL bytes
at seeded places, and valid masks in seeded layouts.

Oracle for an accepted mask (the filter is one pass, so a vertex's result depends on the input
alone): the listed vertices get the unmasked run's positions, every other vertex keeps its input
position bit for bit (this script's PLY reader on both). A refusal must come within the time limit
with exit 2, write nothing, and for a NUL name the line and column this script computes."""

import os
import stat
import threading

from . import common as c

TITLE = "--mask (item 14)"


class MaskCases:
    def __init__(self, settings, build):
        self.s, self.b = settings, build
        self.surface = "%s/mask" % build.name
        self.dir = os.path.join(settings.out, build.name, "mask")
        os.makedirs(self.dir)

    def prepare(self):
        verts, tris = c.noisy_grid(20, seed=14)
        self.input = os.path.join(self.dir, "in.ply")
        c.write(self.input, c.ply_bytes(verts, tris))
        self.v = len(verts)
        out = os.path.join(self.dir, "full.ply")
        r = c.run([self.b.rsmooth, self.input, "-o", out, "-q", "--device", "reference"], self.s,
                  env=c.sanitizer_env(self.b), timeout=600)
        if r.rc != 0:
            raise RuntimeError("the unmasked run failed: %s" % r.err)
        self.before = c.read_ply_file(self.input)[0]
        self.full = c.read_ply_file(out)[0]

    def folder(self, case):
        d = os.path.join(self.dir, "case%03d" % int(case.name.split(":")[0]))
        os.makedirs(d)
        return d

    def run(self, case, d, mask, pass_fds=()):
        r = c.run([self.b.rsmooth, self.input, "-o", "out.ply", "-q", "--device", "reference",
                   "--mask", mask], self.s, env=c.sanitizer_env(self.b), cwd=d, timeout=30,
                  pass_fds=pass_fds)
        return r, case.judge(r)

    def refused(self, case, d, r, needle=None):
        if r.rc == 0:
            case.add("wrong", "exit 0 with a mask that must be refused")
        elif r.rc != 2:
            case.add("other", "exit %d, not 2: %s" % (r.rc, c.said(r.err)))
        elif needle and needle not in r.err:
            case.add("other", "the message lacks %r: %s" % (needle, c.said(r.err)))
        if os.path.exists(os.path.join(d, "out.ply")) and r.rc != 0:
            case.add("lost", "a refused run wrote out.ply")

    def accepted(self, case, d, r, selected):
        if r.rc != 0:
            case.add("other", "a valid mask refused (exit %d): %s" % (r.rc, c.said(r.err)))
            return
        got = c.read_ply_file(os.path.join(d, "out.ply"))[0]
        bad = [k for k in range(self.v)
               if got[k] != (self.full[k] if k in selected else self.before[k])]
        if bad:
            case.add("wrong", "exit 0, and %d vertices (first %d, %s) are not what the mask asks"
                     % (len(bad), bad[0], "selected" if bad[0] in selected else "not selected"))

    # the cases ---------------------------------------------------------------------------------
    def valid(self, case, rng):
        d = self.folder(case)
        selected = set(rng.sample(range(self.v), rng.randint(1, self.v // 3)))
        items = sorted(selected) + [rng.choice(sorted(selected)) for _ in range(3)]  # duplicates
        rng.shuffle(items)
        text = ""
        for k in items:
            text += str(k) + rng.choice([" ", ",", "\n", "\t", "\r\n", " , ", "\n# a comment\n"])
        c.write(os.path.join(d, "mask.txt"), text.encode())
        r, ok = self.run(case, d, "mask.txt")
        if ok:
            self.accepted(case, d, r, selected)

    def nul(self, case, rng):
        d = self.folder(case)
        text = " ".join(str(rng.randrange(self.v)) for _ in range(rng.randint(5, 60)))
        text = "\n".join(text[i:i + 17] for i in range(0, len(text), 17))  # lines of 17 characters
        at = rng.randrange(len(text) + 1)
        data = text[:at].encode() + b"\0" + text[at:].encode()
        c.write(os.path.join(d, "mask.txt"), data)
        line = text[:at].count("\n") + 1
        column = at - (text[:at].rfind("\n") + 1) + 1
        r, ok = self.run(case, d, "mask.txt")
        if ok:
            self.refused(case, d, r, "mask.txt:%d: a NUL byte at column %d" % (line, column))

    def bad_token(self, case, token):
        d = self.folder(case)
        c.write(os.path.join(d, "mask.txt"), ("1 2\n3 %s 4\n" % token).encode())
        r, ok = self.run(case, d, "mask.txt")
        if ok:
            self.refused(case, d, r, "mask.txt:2")

    def special(self, case, kind):
        d = self.folder(case)
        path = kind
        if kind == "fifo":
            path = os.path.join(d, "fifo")
            os.mkfifo(path)
        elif kind == "folder":
            path = d
        elif kind == "sparse":
            path = os.path.join(d, "sparse.txt")
            with open(path, "wb") as f:
                f.truncate(2 << 30)
        elif kind == "too long":
            path = os.path.join(d, "long.txt")
            c.write(path, b"1\n" * ((1 << 20) // 2 + 32 * self.v + 64))
        elif kind == "link-to-zero":
            path = os.path.join(d, "link")
            os.symlink("/dev/zero", path)
        elif kind == "zero-device":
            path = os.path.join(d, "zero")
            os.mknod(path, 0o600 | stat.S_IFCHR, os.makedev(1, 5))
        r, ok = self.run(case, d, path)
        if not ok:
            return
        if kind == "fifo" and r.rc == 0:  # no writer: an empty mask, nothing moves
            self.accepted(case, d, r, set())
        else:
            self.refused(case, d, r)

    def endless_pipe(self, case, line):
        """A pipe that never ends, as <(yes 1) gives: refused at the size bound, no hang."""
        d = self.folder(case)
        rfd, wfd = os.pipe()
        stop = threading.Event()

        def writer():
            chunk = line * 4096
            try:
                while not stop.is_set():
                    os.write(wfd, chunk)
            except OSError:
                pass

        t = threading.Thread(target=writer, daemon=True)
        t.start()
        try:
            r, ok = self.run(case, d, "/dev/fd/%d" % rfd, pass_fds=(rfd,))
        finally:
            stop.set()
            os.close(rfd)
            t.join(5)
            os.close(wfd)
        if ok:
            self.refused(case, d, r)

    def piped(self, case, rng):
        """A pipe holding a whole valid mask works as the file does."""
        d = self.folder(case)
        selected = set(rng.sample(range(self.v), 20))
        data = "\n".join(str(k) for k in sorted(selected)).encode() + b"\n"
        rfd, wfd = os.pipe()
        t = threading.Thread(target=lambda: (os.write(wfd, data), os.close(wfd)), daemon=True)
        t.start()
        try:
            r, ok = self.run(case, d, "/dev/fd/%d" % rfd, pass_fds=(rfd,))
        finally:
            os.close(rfd)
            t.join(5)
        if ok:
            self.accepted(case, d, r, selected)

    def jobs(self):
        rng = self.s.rng("mask", self.b.name)
        out = []

        def add(name, fn, *a):
            name = "%d: %s" % (len(out), name)
            out.append((self.surface, name, lambda case: fn(case, *a)))

        import random
        for k in range(12):
            add("valid mask %d" % k, self.valid, random.Random(rng.random()))
        for k in range(12):
            add("NUL byte %d" % k, self.nul, random.Random(rng.random()))
        for token in ("%d" % self.v, "4294967296", "18446744073709551617", "-1", "1.5", "abc",
                      "0x10", "1e2", "\xc3\xa9"):
            add("token %r" % token, self.bad_token, token)
        for kind in ("/dev/zero", "/dev/null", "/dev/urandom", "/dev/full", "fifo", "folder",
                     "sparse", "too long", "link-to-zero") + (("zero-device",) if self.s.root else ()):
            add(kind, self.special, kind)
        for line in (b"1\n", b" ", b"7,"):
            add("endless pipe of %r" % line, self.endless_pipe, line)
        add("a pipe holding a mask", self.piped, random.Random(rng.random()))
        return out
