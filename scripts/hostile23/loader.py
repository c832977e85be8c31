"""Item 13: RSMOOTH_OPENCL_LIBRARY naming files that must never reach dlopen (or must not hurt it):
truncated copies of the real loader at seeded lengths, copies whose ELF header or program headers
point past the end, another class or byte order, FIFOs, devices, folders, text, links to those,
a sparse gigabyte, a library without OpenCL. `--device cpu` must end within the time limit with
exit 2 (or 3) and a message naming the file, or, where the file still loads as a working loader,
exit 0 with the normal run's bytes; `--device auto` must fall back with exit 0 and give either the
reference path's bytes or the device's."""

import os
import stat
import struct

from . import common as c

TITLE = "OpenCL loader (item 13)"
CANDIDATES = ["/lib/x86_64-linux-gnu/libOpenCL.so.1", "/usr/lib/x86_64-linux-gnu/libOpenCL.so.1",
              "/usr/lib64/libOpenCL.so.1", "/usr/lib/libOpenCL.so.1"]


def elf_program_headers(data):
    """(e_phoff, e_phentsize, e_phnum, [(p_type, p_offset, p_filesz, header offset)]) of a 64-bit
    little-endian ELF file."""
    phoff, = struct.unpack_from("<Q", data, 32)
    phentsize, phnum = struct.unpack_from("<HH", data, 54)
    heads = []
    for k in range(phnum):
        at = phoff + k * phentsize
        p_type, = struct.unpack_from("<I", data, at)
        p_offset, = struct.unpack_from("<Q", data, at + 8)
        p_filesz, = struct.unpack_from("<Q", data, at + 32)
        heads.append((p_type, p_offset, p_filesz, at))
    return phoff, phentsize, phnum, heads


class LoaderCases:
    def __init__(self, settings, build):
        self.s, self.b = settings, build
        self.surface = "%s/loader" % build.name
        self.dir = os.path.join(settings.out, build.name, "loader")
        os.makedirs(self.dir)

    def prepare(self):
        real = next((os.path.realpath(p) for p in CANDIDATES if os.path.exists(p)), None)
        if not real:
            return "no libOpenCL.so.1 here"
        self.real = c.read(real)
        if self.real[:4] != b"\x7fELF" or self.real[4] != 2 or self.real[5] != 1:
            return "the loader is not a 64-bit little-endian ELF file"
        verts, tris = c.noisy_grid(24, seed=13)
        self.input = os.path.join(self.dir, "in.ply")
        c.write(self.input, c.ply_bytes(verts, tris))
        self.expected = {}
        for device in ("reference", "cpu"):
            out = os.path.join(self.dir, "expected-%s.ply" % device)
            r = c.run([self.b.rsmooth, self.input, "-o", out, "-q", "--device", device], self.s,
                      env=c.sanitizer_env(self.b), timeout=600)
            self.expected[device] = c.read(out) if r.rc == 0 else None
        return None if self.expected["cpu"] else "no OpenCL CPU device"

    def attempt(self, case, path):
        d = os.path.join(self.dir, "case%03d" % int(case.name.split(":")[0]))
        os.makedirs(d, exist_ok=True)
        env = dict(c.sanitizer_env(self.b), RSMOOTH_OPENCL_LIBRARY=path)
        for device in ("cpu", "auto"):
            out = os.path.join(d, "out-%s.ply" % device)
            r = c.run([self.b.rsmooth, self.input, "-o", out, "--force", "--device", device],
                      self.s, env=env, cwd=d, timeout=30)
            if not case.judge(r):
                continue
            got = c.read(out) if r.rc == 0 and os.path.exists(out) else None
            if device == "cpu":
                if r.rc == 0:
                    if got != self.expected["cpu"]:
                        case.add("wrong", "--device cpu: exit 0 with other bytes than the normal run")
                    else:
                        case.notes.append("the file still loads and works")
                elif r.rc not in (2, 3):
                    case.add("other", "--device cpu: exit %d: %s" % (r.rc, c.said(r.err)))
                elif path not in r.err:
                    case.add("other", "--device cpu: the message does not name the file: %s" % c.said(r.err))
            else:
                if r.rc != 0:
                    case.add("other", "--device auto did not fall back (exit %d): %s" % (r.rc, c.said(r.err)))
                elif got not in (self.expected["reference"], self.expected["cpu"]):
                    case.add("wrong", "--device auto: exit 0 with neither path's bytes")

    def file(self, case, data, mode=0o755):
        d = os.path.join(self.dir, "case%03d" % int(case.name.split(":")[0]))
        os.makedirs(d)
        p = os.path.join(d, "libOpenCL.so.1")
        c.write(p, data, mode)
        self.attempt(case, p)

    def special(self, case, kind):
        d = os.path.join(self.dir, "case%03d" % int(case.name.split(":")[0]))
        os.makedirs(d)
        p = os.path.join(d, "libOpenCL.so.1")
        if kind == "fifo":
            os.mkfifo(p)
        elif kind == "folder":
            os.makedirs(p)
        elif kind == "link-to-fifo":
            os.mkfifo(os.path.join(d, "fifo"))
            os.symlink("fifo", p)
        elif kind == "link-loop":
            os.symlink("libOpenCL.so.1", p)
        elif kind == "link-to-truncated":
            c.write(os.path.join(d, "cut.so"), self.real[:len(self.real) // 3])
            os.symlink("cut.so", p)
        elif kind == "sparse-gigabyte":
            c.write(p, self.real[:4096])
            with open(p, "r+b") as f:
                f.truncate(1 << 30)
        elif kind == "zero-device":
            os.mknod(p, 0o666 | stat.S_IFCHR, os.makedev(1, 5))
        elif kind in ("/dev/zero", "/dev/null", "/dev/urandom", "/"):
            p = kind
        self.attempt(case, p)

    def jobs(self):
        rng = self.s.rng("loader", self.b.name)
        out = []

        def add(name, fn, *a):
            name = "%d: %s" % (len(out), name)
            out.append((self.surface, name, lambda case: fn(case, *a)))

        size = len(self.real)
        phoff, phentsize, phnum, heads = elf_program_headers(self.real)
        loads = [h for h in heads if h[0] == 1]
        cuts = {0, 1, 4, 16, 63, 64, phoff + phentsize * phnum - 1, phoff + phentsize * phnum,
                size - 1}
        cuts |= {loads[-1][1] + loads[-1][2] - 1} if loads else set()
        while len(cuts) < 16:
            cuts.add(rng.randrange(64, size))
        for n in sorted(cuts):
            add("a copy cut to %d of %d bytes" % (n, size), self.file, self.real[:n])
        add("a whole copy (the control)", self.file, self.real)
        for keep in (8192, size - 4096):  # a copy cut short and padded to its size with zeros
            add("a copy zeroed after %d of %d bytes" % (keep, size), self.file,
                self.real[:keep] + bytes(size - keep))

        def patched(at, fmt, value):
            b = bytearray(self.real)
            struct.pack_into(fmt, b, at, value)
            return bytes(b)

        add("e_phoff beyond the file", self.file, patched(32, "<Q", size + 4096))
        add("e_phoff 2^64-1", self.file, patched(32, "<Q", 2 ** 64 - 1))
        add("e_phnum 65535", self.file, patched(56, "<H", 0xFFFF))
        add("e_phentsize 1", self.file, patched(54, "<H", 1))
        for h in rng.sample(loads, min(2, len(loads))):
            add("a PT_LOAD's offset past the end", self.file, patched(h[3] + 8, "<Q", size + 8192))
            add("a PT_LOAD's file size 2^62", self.file, patched(h[3] + 32, "<Q", 2 ** 62))
        add("32-bit class", self.file, patched(4, "<B", 1))
        add("big-endian", self.file, patched(5, "<B", 2))
        add("no ELF magic", self.file, b"\x7fELG" + self.real[4:])
        add("another machine", self.file, patched(18, "<H", 183 if self.real[18] != 183 else 62))
        add("text", self.file, b"not a library\n" * 100)
        add("an empty file", self.file, b"")
        libm = next((p for p in ("/lib/x86_64-linux-gnu/libm.so.6", "/usr/lib64/libm.so.6")
                     if os.path.exists(p)), None)
        if libm:
            add("a library without OpenCL (libm)", self.file, c.read(libm))
        for kind in ("fifo", "folder", "link-to-fifo", "link-loop", "link-to-truncated",
                     "sparse-gigabyte", "/dev/zero", "/dev/null", "/dev/urandom", "/"):
            add(kind, self.special, kind)
        if self.s.root:
            add("a zero device", self.special, "zero-device")
        return out
