"""Item 1: the program cache cannot be planted.

The payload is a working program binary built from other kernels than the ones asked for (the
same kernels compiled for another vertex-block width, RSMOOTH_LANES), wrapped under the genuine
program's key with a valid BLAKE2b digest, exactly as an attacker who copied a genuine file's
header would make it. The control plants it in the user's own folder, where it is trusted by
design, and shows what loading it does (the results change). Every hostile placement must then
give exit 0 and the bytes of a run with RSMOOTH_CACHE_DIR=off (otherwise the planted program ran:
a wrong answer and a security finding); folders and files others could have written must be
refused with the reason said on stderr, and nothing written into them; FIFOs, devices, links,
truncated, oversized and tampered files at the key's name must not hang and must not load."""

import hashlib
import os
import stat
import struct

from . import common as c

TITLE = "program cache (item 1)"
REFUSAL = "not using the program cache"


def wrap(genuine, other):
    """`other`'s binary under `genuine`'s key, with the size word and digest made to match."""
    header = bytearray(genuine[:64])
    binary = other[96:]
    struct.pack_into("<Q", header, 48, len(binary))
    return bytes(header) + hashlib.blake2b(bytes(header) + binary, digest_size=32).digest() + binary


class CacheCases:
    def __init__(self, settings, build):
        self.s, self.b = settings, build
        self.surface = "%s/cache" % build.name
        self.dir = os.path.join(settings.out, build.name, "cache")
        os.makedirs(self.dir)
        self.count = 0

    def cmd(self, out):
        return [self.b.rsmooth, self.input, "-o", out, "--force", "--device", "cpu"]

    def env(self, extra):
        e = c.sanitizer_env(self.b)
        e.update({"RSMOOTH_CACHE_DIR": None, "XDG_CACHE_HOME": None, "HOME": None})
        e.update(extra)
        return e

    def private(self, path):
        os.makedirs(path, exist_ok=True)
        os.chmod(path, 0o700)
        return path

    def prepare(self):
        """The expected bytes, the genuine file's name and content, and the payload; False when
        no OpenCL CPU device is here (then nothing of this surface runs)."""
        verts, tris = c.noisy_grid(30, seed=23)
        self.input = os.path.join(self.dir, "in.ply")
        c.write(self.input, c.ply_bytes(verts, tris))
        off = os.path.join(self.dir, "off.ply")
        r = c.run(self.cmd(off), self.s, env=self.env({"RSMOOTH_CACHE_DIR": "off"}), timeout=600)
        if r.rc != 0:
            self.why_not = "no OpenCL CPU device: %s" % c.said(r.err, 200)
            return False
        self.expected = c.read(off)
        own = self.private(os.path.join(self.dir, "genuine"))
        for _ in range(2):  # a miss that stores the file, then a hit of it
            r = c.run(self.cmd(os.path.join(self.dir, "genuine.ply")), self.s,
                      env=self.env({"RSMOOTH_CACHE_DIR": own}), timeout=600)
            if r.rc != 0 or c.read(os.path.join(self.dir, "genuine.ply")) != self.expected:
                raise RuntimeError("the genuine cache run failed: %s %s" % (r.text(), r.err))
        (self.key,) = os.listdir(own)
        self.genuine = c.read(os.path.join(own, self.key))
        for lanes in ("4", "8"):
            other = self.private(os.path.join(self.dir, "lanes" + lanes))
            c.run(self.cmd(os.path.join(self.dir, "lanes.ply")), self.s, timeout=600,
                  env=self.env({"RSMOOTH_CACHE_DIR": other, "RSMOOTH_LANES": lanes}))
            names = os.listdir(other)
            if names and names[0] != self.key:
                self.payload = wrap(self.genuine, c.read(os.path.join(other, names[0])))
                break
        else:
            raise RuntimeError("no second program binary to plant")
        # the control: the user's own folder trusts the payload, and it changes the results
        control = self.private(os.path.join(self.dir, "control"))
        c.write(os.path.join(control, self.key), self.payload, 0o600)
        out = os.path.join(self.dir, "control.ply")
        r = c.run(self.cmd(out), self.s, env=self.env({"RSMOOTH_CACHE_DIR": control}))
        got = c.read(out) if r.rc == 0 and os.path.exists(out) else b""
        if r.rc != 0:
            self.control = "the planted program ran and its results were refused: exit %d, %s" % (
                r.rc, c.said(r.err, 160))
        else:
            self.control = "the planted program ran: exit 0, %d of %d output bytes differ" % (
                sum(a != b for a, b in zip(got, self.expected)), len(self.expected))
        self.payload_works = r.rc != 0 or got != self.expected
        return True

    # one case ------------------------------------------------------------------------------------
    def attempt(self, case, env, watched, expect_refusal, outside=()):
        """Runs with this environment; `watched` are the folders a refusal must leave as they
        were, `outside` files that must never change (targets of planted links)."""
        out = os.path.join(self.dir, "out-%s.ply" % case.name.split(":")[0].replace(" ", "_"))
        before = {w: c.listing(w) for w in watched}
        kept = {p: c.listing(os.path.dirname(p)).get(os.path.basename(p)) for p in outside}
        r = c.run(self.cmd(out), self.s, env=self.env(env), timeout=60)
        if not case.judge(r):
            return
        if r.rc != 0:
            case.add("other", "exit %d instead of building from source: %s" % (r.rc, c.said(r.err)))
            return
        if c.read(out) != self.expected:
            case.add("wrong", "exit 0 with results that are not the uncached run's")
            case.add("security", "the planted program was loaded")
        if expect_refusal:
            if REFUSAL not in r.err:
                case.add("other", "no refusal said on stderr: %r" % c.said(r.err, 200))
            for w, b in before.items():
                ch = c.changes(b, c.listing(w))
                if ch:
                    case.add("security", "written into a refused folder: %s" % "; ".join(ch))
        for p, entry in kept.items():
            if c.listing(os.path.dirname(p)).get(os.path.basename(p)) != entry:
                case.add("security", "the file a planted link names was changed: %s" % p)

    def folder(self, case, *parts):
        d = os.path.join(self.dir, "case%03d" % int(case.name.split(":")[0]), *parts)
        os.makedirs(d)
        return d

    def plant(self, folder, content=None, mode=0o600, owner=None):
        p = os.path.join(folder, self.key)
        c.write(p, self.payload if content is None else content, mode)
        if owner:
            os.chown(p, *owner)
        return p

    # the placements ------------------------------------------------------------------------------
    def cache_dir_mode(self, case, mode, owner, genuine):
        d = self.folder(case, "cache")
        self.plant(d, self.genuine if genuine else None)
        if owner:
            os.chown(d, *owner)
        os.chmod(d, mode)
        self.attempt(case, {"RSMOOTH_CACHE_DIR": d}, [d], True)

    def file_mode(self, case, mode, owner):
        d = self.private(self.folder(case, "cache"))
        self.plant(d, mode=mode, owner=owner)
        self.attempt(case, {"RSMOOTH_CACHE_DIR": d}, [d], True)

    def linked_cache_dir(self, case, mode):
        d = self.folder(case, "hostile")
        self.plant(d)
        os.chmod(d, mode)
        link = os.path.join(os.path.dirname(d), "link")
        os.symlink(d, link)
        self.attempt(case, {"RSMOOTH_CACHE_DIR": link}, [d], True)

    def home_chain(self, case, bad, how):
        """HOME=H with H/.cache/rsmooth holding the payload, one folder of the chain hostile."""
        home = self.private(self.folder(case, "home"))
        dot = self.private(os.path.join(home, ".cache"))
        rs = self.private(os.path.join(dot, "rsmooth"))
        self.plant(rs)
        target = dot if bad == ".cache" else rs
        if how == "other-user":
            for p in (rs, os.path.join(rs, self.key)) if bad == "rsmooth" else (target,):
                os.chown(p, 1234, 1234)
        else:
            os.chmod(target, how)
        self.attempt(case, {"HOME": home}, [rs], True)

    def home_link(self, case, which):
        """A link in the chain below HOME (to a folder of the user's own): not followed, so no
        cache, and certainly not the payload behind it."""
        home = self.private(self.folder(case, "home"))
        elsewhere = self.private(os.path.join(home, "elsewhere"))
        if which == ".cache":
            self.private(os.path.join(elsewhere, "rsmooth"))
            self.plant(os.path.join(elsewhere, "rsmooth"))
            os.symlink(elsewhere, os.path.join(home, ".cache"))
        else:
            self.private(os.path.join(home, ".cache"))
            self.plant(elsewhere)
            os.symlink(elsewhere, os.path.join(home, ".cache", "rsmooth"))
        self.attempt(case, {"HOME": home}, [], False)

    def xdg(self, case, inside, mode):
        home = self.private(self.folder(case, "home"))
        xdg = self.private(os.path.join(home if inside else os.path.dirname(home), "xdg"))
        rs = self.private(os.path.join(xdg, "rsmooth"))
        self.plant(rs)
        os.chmod(xdg if inside else rs, mode)
        self.attempt(case, {"HOME": home, "XDG_CACHE_HOME": xdg}, [rs], True)

    def special_at_key(self, case, kind):
        d = self.private(self.folder(case, "cache"))
        p = os.path.join(d, self.key)
        outside = []
        if kind == "fifo":
            os.mkfifo(p, 0o600)
        elif kind == "zero-device":
            os.mknod(p, 0o600 | stat.S_IFCHR, os.makedev(1, 5))
        elif kind == "folder":
            os.makedirs(p)
        elif kind == "socket":
            import socket
            s = socket.socket(socket.AF_UNIX)
            s.bind(p)
            s.close()
        else:
            other = self.private(self.folder(case, "own"))
            target = os.path.join(other, "payload.clbin")
            if kind == "link-to-payload":
                c.write(target, self.payload, 0o600)
            elif kind == "link-to-fifo":
                os.mkfifo(target, 0o600)
            else:
                os.symlink("/dev/zero", target)
            os.symlink(target, p)
            outside.append(target)
        self.attempt(case, {"RSMOOTH_CACHE_DIR": d}, [], False, outside)

    def damaged(self, case, content):
        d = self.private(self.folder(case, "cache"))
        self.plant(d, content)
        self.attempt(case, {"RSMOOTH_CACHE_DIR": d}, [], False)

    def sparse(self, case, size):
        d = self.private(self.folder(case, "cache"))
        p = self.plant(d, self.payload[:96])
        with open(p, "r+b") as f:
            f.truncate(size)
        self.attempt(case, {"RSMOOTH_CACHE_DIR": d}, [], False)

    def jobs(self):
        rng = self.s.rng("cache", self.b.name)
        out = []

        def add(name, fn, *a):
            name = "%d: %s" % (len(out), name)
            out.append((self.surface, name, lambda case: fn(case, *a)))

        root = self.s.root
        for mode in (0o777, 0o775, 0o770, 0o757, 0o1777, 0o722, 0o702, 0o720, 0o730, 0o3777):
            add("RSMOOTH_CACHE_DIR mode %04o" % mode, self.cache_dir_mode, mode, None, False)
        add("RSMOOTH_CACHE_DIR mode 0777, the genuine file", self.cache_dir_mode, 0o777, None, True)
        if root:
            for owner, mode in (((65534, 65534), 0o700), ((1234, 0), 0o755), ((1234, 1234), 0o755)):
                add("RSMOOTH_CACHE_DIR owned by %d, %04o" % (owner[0], mode), self.cache_dir_mode,
                    mode, owner, False)
            add("RSMOOTH_CACHE_DIR owned by 65534, the genuine file", self.cache_dir_mode, 0o700,
                (65534, 65534), True)
            for owner, mode in (((65534, 65534), 0o600), ((1234, 0), 0o644), ((0, 1234), 0o660)):
                add("file owned by %d:%d, %04o" % (owner + (mode,)), self.file_mode, mode, owner)
        for mode in (0o666, 0o646, 0o664, 0o620, 0o602, 0o622):
            add("file mode %04o" % mode, self.file_mode, mode, None)
        add("RSMOOTH_CACHE_DIR a link to a folder of mode 0777", self.linked_cache_dir, 0o777)
        for bad, how in ((".cache", 0o777), (".cache", 0o770), ("rsmooth", 0o757),
                         ("rsmooth", 0o1777)) + (((".cache", "other-user"), ("rsmooth", "other-user"))
                                                 if root else ()):
            add("HOME chain: %s %s" % (bad, how if isinstance(how, str) else "%04o" % how),
                self.home_chain, bad, how)
        for which in (".cache", "rsmooth"):
            add("HOME chain: %s a link" % which, self.home_link, which)
        add("XDG_CACHE_HOME in HOME, mode 0777", self.xdg, True, 0o777)
        add("XDG_CACHE_HOME elsewhere, its rsmooth 0775", self.xdg, False, 0o775)
        for kind in ("fifo", "folder", "socket", "link-to-payload", "link-to-fifo", "link-to-zero") + (
                ("zero-device",) if root else ()):
            add("%s at the key's name" % kind, self.special_at_key, kind)
        cuts = sorted(set([0, 1, 8, 63, 64, 95, 96, 97] + [rng.randrange(97, len(self.payload))
                                                           for _ in range(4)]))
        for n in cuts:
            add("payload cut to %d bytes" % n, self.damaged, self.payload[:n])
        for n in (1, 4096, 1 << 20):
            junk = bytes(rng.randrange(256) for _ in range(min(n, 4096))) * max(1, n // 4096)
            add("payload and %d bytes of junk" % n, self.damaged, self.payload + junk)
        for _ in range(6):
            b = bytearray(self.payload)
            at = rng.randrange(96) if _ < 3 else rng.randrange(96, len(b))
            b[at] ^= 1 << rng.randrange(8)
            add("payload with byte %d flipped" % at, self.damaged, bytes(b))
        b = bytearray(self.payload)
        struct.pack_into("<Q", b, 48, (1 << 64) - 1)
        add("payload with size word 2^64-1", self.damaged, bytes(b))
        for size in ((65 << 20) + 96, 1 << 30, 1 << 40):
            add("sparse file of %d bytes" % size, self.sparse, size)
        return out
