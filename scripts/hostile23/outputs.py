"""Items 2, 3, 5, 7 and 15 (output names, --tmpdir, signals): the output file, attacked the same way
for each of the three writers (the in-memory command, --max-memory, rsmooth-mpi on 2 ranks).

Each case runs in a folder of its own, listed before and after (kind, mode, owner, group, content
digest or link target of everything in it). The oracle is the in-memory command's result on the
reference path, made once per input: what a writer puts in place must be those bytes. Beside
that, what must not change is compared with the listing: a replaced file keeps mode, owner and
group (wider permissions or another owner: a security finding), other hard links and every other
file keep their content, links stay links, and nothing named .rsmooth-* is left (after SIGKILL
these are counted apart: a kill cannot be caught)."""

import os
import random
import signal
import socket
import stat
import time

from . import common as c

SURFACE_TITLES = {"memory": "output files: rsmooth (in memory)",
                  "stream": "output files: rsmooth --max-memory",
                  "mpi": "output files: rsmooth-mpi -n 2"}
OWNERS = [(0, 0), (65534, 65534), (0, 65534), (1234, 4321)]
MODES = [0o600, 0o640, 0o604, 0o644, 0o660, 0o400, 0o444, 0o2640, 0o4755, 0o1644, 0o664]


class Fixture:
    """The inputs of one build's output cases and the bytes each must give."""

    def __init__(self, settings, build):
        self.settings, self.build = settings, build
        self.dir = os.path.join(settings.out, build.name, "outputs")
        os.makedirs(self.dir, exist_ok=True)
        self.inputs, self.expected = {}, {}
        # the large input gives the signals and the races a window: smaller under the sanitizers,
        # which run the reference path about five times slower
        for k, n in (("a", 30), ("b", 31), ("c", 29), ("big", 100 if build.sanitizer else 170)):
            verts, tris = c.noisy_grid(n, seed=n)
            path = os.path.join(self.dir, "input-%s.ply" % k)
            c.write(path, c.ply_bytes(verts, tris))
            self.inputs[k] = path
            out = os.path.join(self.dir, "expected-%s.ply" % k)
            r = c.run([build.rsmooth, path, "-o", out, "--force", "-q", "--device", "reference"],
                      settings, env=c.sanitizer_env(build), timeout=600)
            if r.rc != 0:
                raise RuntimeError("the oracle run failed: %s: %s" % (r.text(), r.err))
            self.expected[k] = c.read(out)


def device_args():
    return ["--device", "reference"]


class OutputCases:
    """The cases of one writer on one build."""

    def __init__(self, settings, build, fixture, writer):
        self.s, self.b, self.f, self.w = settings, build, fixture, writer
        self.surface = "%s/%s" % (build.name, "output-" + writer)
        self.root = os.path.join(fixture.dir, writer)

    # helpers ------------------------------------------------------------------------------------
    def folder(self, name):
        d = os.path.join(self.root, "".join(ch if ch.isalnum() or ch in "-." else "_" for ch in name))
        os.makedirs(d)
        return d

    def argv(self, args, cap="10M"):
        return c.writer_argv(self.s, self.b, self.w, list(args) + device_args(), cap)

    def run(self, case, d, args, env=None, timeout=None, cap="10M"):
        r = c.run(self.argv(args, cap), self.s, env=c.writer_env(self.b, self.w, env), cwd=d,
                  timeout=timeout)
        return r, case.judge(r)

    def put_input(self, d, name="in.ply", key="a"):
        p = os.path.join(d, name)
        c.write(p, c.read(self.f.inputs[key]))
        return p

    def check_leftovers(self, case, d):
        left = c.leftovers(d)
        if left:
            case.add("lost", "left behind: %s" % left)

    def check_kept(self, case, before, after_entry, name):
        """A replaced file's mode, owner and group against its old listing entry."""
        if after_entry is None or before is None:
            return
        _, mode0, uid0, gid0, _ = before
        _, mode1, uid1, gid1, _ = after_entry
        if (uid0, gid0) != (uid1, gid1):
            case.add("security", "%s: owner %d:%d became %d:%d" % (name, uid0, gid0, uid1, gid1))
        if mode1 & ~mode0:
            case.add("security", "%s: mode %04o widened to %04o" % (name, mode0, mode1))
        elif mode1 != mode0:
            case.add("other", "%s: mode %04o became %04o" % (name, mode0, mode1))

    def expect_bytes(self, case, path, key="a"):
        try:
            got = c.read(path)
        except OSError as e:
            case.add("wrong", "exit 0 but %s cannot be read: %s" % (path, e))
            return
        if got != self.f.expected[key]:
            case.add("wrong", "exit 0 but %s is not the in-memory result (%d bytes, expected %d)"
                     % (os.path.basename(path), len(got), len(self.f.expected[key])))

    # the cases ---------------------------------------------------------------------------------
    def replace(self, case, mode, owner, in_place):
        """--force over (or --in-place on) a file of this mode and owner: both kept."""
        d = self.folder(case.name)
        self.put_input(d)
        target = "in.ply" if in_place else "out.ply"
        if not in_place:
            c.write(os.path.join(d, "out.ply"), b"old content\n")
        if self.s.root:
            os.chown(os.path.join(d, target), *owner)
        os.chmod(os.path.join(d, target), mode)
        before = c.listing(d)
        args = ["in.ply", "--in-place", "-q"] if in_place else ["in.ply", "-o", "out.ply", "--force", "-q"]
        r, ok = self.run(case, d, args)
        if not ok:
            return
        after = c.listing(d)
        if r.rc != 0:
            case.add("other", "refused a replacement it must do (exit %d): %s" % (r.rc, c.said(r.err)))
        else:
            self.expect_bytes(case, os.path.join(d, target))
            self.check_kept(case, before[target], after.get(target), target)
        lost = c.changes(before, after, allowed={target} if r.rc == 0 else ())
        if lost:
            case.add("lost", "; ".join(lost))
        self.check_leftovers(case, d)

    def hard_links(self, case, links, in_place):
        d = self.folder(case.name)
        os.makedirs(os.path.join(d, "sub"))
        self.put_input(d)
        name = "in.ply" if in_place else "out.ply"
        if not in_place:
            c.write(os.path.join(d, name), b"old content\n")
        others = []
        for k in range(links):
            other = ("sub/link%d.ply" if k % 2 else "link%d.ply") % k
            os.link(os.path.join(d, name), os.path.join(d, other))
            others.append(other)
        before = c.listing(d)
        args = ["in.ply", "--in-place"] if in_place else ["in.ply", "-o", name, "--force"]
        r, ok = self.run(case, d, args)
        if not ok:
            return
        after = c.listing(d)
        if r.rc != 0:
            case.add("other", "refused (exit %d): %s" % (r.rc, c.said(r.err)))
            return
        self.expect_bytes(case, os.path.join(d, name))
        if "hard link" not in r.err:
            case.add("other", "no hard-link warning: %r" % c.said(r.err))
        lost = c.changes(before, after, allowed={name})
        if lost:
            case.add("lost", "; ".join(lost))
        self.check_leftovers(case, d)

    def symlinks(self, case, rng, in_place):
        """-o LINK --force, or --in-place LINK: a chain of 1-3 links, relative or absolute,
        across folders, is written through to its final target; every link stays."""
        d = self.folder(case.name)
        os.makedirs(os.path.join(d, "sub", "deeper"))
        self.put_input(d)
        final = rng.choice(["target.ply", "sub/target.ply", "sub/deeper/target.ply"])
        if in_place:
            self.put_input(d, final)
        else:
            c.write(os.path.join(d, final), b"old content\n")
        mode, owner = rng.choice(MODES[:7]), rng.choice(OWNERS)
        if self.s.root:
            os.chown(os.path.join(d, final), *owner)
        os.chmod(os.path.join(d, final), mode)
        chain = []
        points_to = os.path.join(d, final)
        for k in range(rng.randint(1, 3)):
            link = rng.choice(["", "sub/"]) + "link%d.ply" % k
            absolute = rng.random() < 0.5
            text = points_to if absolute else os.path.relpath(points_to, os.path.dirname(os.path.join(d, link)))
            os.symlink(text, os.path.join(d, link))
            chain.append(link)
            points_to = os.path.join(d, link)
        first = chain[-1]
        before = c.listing(d)
        args = [first, "--in-place", "-q"] if in_place else ["in.ply", "-o", first, "--force", "-q"]
        r, ok = self.run(case, d, args)
        if not ok:
            return
        after = c.listing(d)
        if r.rc != 0:
            case.add("other", "refused to write through a link (exit %d): %s" % (r.rc, c.said(r.err)))
            return
        for link in chain:
            if after.get(link) != before[link]:
                case.add("lost", "the link %s became %s" % (link, c.describe(after.get(link))))
        self.expect_bytes(case, os.path.join(d, final))
        self.check_kept(case, before[final], after.get(final), final)
        lost = c.changes(before, after, allowed={final} | set(chain))
        if lost:
            case.add("lost", "; ".join(lost))
        self.check_leftovers(case, d)

    def special(self, case, kind, force):
        """Outputs that are never written: FIFOs, devices, folders, sockets, links to nothing,
        into a missing folder, to a folder, a FIFO or a device."""
        d = self.folder(case.name)
        os.makedirs(os.path.join(d, "folder"))
        self.put_input(d)
        out = os.path.join(d, "out.ply")
        c.make_special(out, kind)
        before = c.listing(d)
        r, ok = self.run(case, d, ["in.ply", "-o", "out.ply", "-q"] + (["--force"] if force else []),
                         timeout=60)
        if not ok:
            return
        after = c.listing(d)
        if r.rc == 0:
            case.add("wrong", "exit 0 writing to a %s" % kind)
        elif not r.err.strip():
            case.add("other", "refused without a message")
        elif "out.ply" not in r.err:
            case.add("other", "the message does not name the output: %s" % c.said(r.err))
        lost = c.changes(before, after)
        if lost:
            case.add("lost", "; ".join(lost))
        self.check_leftovers(case, d)

    def appears(self, case, kind):
        """A file (or link, FIFO, folder) made at the output's name while the run works, without
        --force: it is never replaced and the run fails saying so."""
        d = self.folder(case.name)
        c.write(os.path.join(d, "precious.txt"), b"precious\n")
        p, r = c.start(self.argv([self.f.inputs["big"], "-o", "out.ply", "-q"], cap="16M"), self.s,
                       env=c.writer_env(self.b, self.w, {"RSMOOTH_NAMED_TEMPORARY": "1"}), cwd=d)
        made = False
        out = os.path.join(d, "out.ply")
        deadline = time.monotonic() + self.s.timeout
        while time.monotonic() < deadline and p.poll() is None:
            if c.leftovers(d):
                try:
                    if kind == "file":
                        fd = os.open(out, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644)
                        os.write(fd, b"precious\n")
                        os.close(fd)
                    elif kind == "link":
                        os.symlink("precious.txt", out)
                    elif kind == "fifo":
                        os.mkfifo(out)
                    else:
                        os.mkdir(out)
                    made = True
                except FileExistsError:
                    pass
                break
            time.sleep(0.001)
        before = c.listing(d)
        c.finish(p, r, self.s.timeout)
        if not case.judge(r):
            return
        if not made:
            case.notes.append("race not hit: the run published before the %s was made" % kind)
            if r.rc == 0:
                self.expect_bytes(case, out, "big")
            return
        after = c.listing(d)
        lost = c.changes(before, after, allowed=set(n for n in after if n.startswith(".rsmooth-"))
                         | set(n for n in before if n.startswith(".rsmooth-")))
        if lost:
            case.add("lost", "; ".join(lost))
        if r.rc == 0:
            case.add("wrong", "exit 0 although a %s took the name during the run" % kind)
        elif r.rc != 2 or "already exists" not in r.err:
            case.add("other", "exit %d, not 2 'already exists': %s" % (r.rc, c.said(r.err)))
        self.check_leftovers(case, d)

    def race(self, case, racers):
        """`racers` runs to one new name from different inputs: one wins, the file is its result
        byte for byte, the others exit 2, nothing is left."""
        d = self.folder(case.name)
        keys = ["a", "b", "c"][:racers]
        started = [c.start(self.argv([self.f.inputs[k], "-o", "out.ply", "-q"]), self.s,
                           env=c.writer_env(self.b, self.w), cwd=d) for k in keys]
        runs = [c.finish(p, r, self.s.timeout) for p, r in started]
        if not all([case.judge(r) for r in runs]):
            return
        winners = [k for k, r in zip(keys, runs) if r.rc == 0]
        if len(winners) > 1:
            case.add("lost", "%d runs exited 0 writing one new name: all but one result lost"
                     % len(winners))
        elif not winners:
            case.add("other", "no run wrote the file: %s" % "; ".join(c.said(r.err, 200) for r in runs))
        else:
            got = c.read(os.path.join(d, "out.ply"))
            if got != self.f.expected[winners[0]]:
                case.add("wrong", "the file is not the winner's result")
        for k, r in zip(keys, runs):
            if r.rc not in (0, 2):
                case.add("other", "a loser exited %d: %s" % (r.rc, c.said(r.err)))
        self.check_leftovers(case, d)

    def long_name(self, case, length):
        """Output names of `length` bytes: up to 255 written (new, --force, --in-place), 256
        refused with nothing left."""
        d = self.folder(case.name)
        self.put_input(d)
        name = "n" * (length - 4) + ".ply"
        steps = [["in.ply", "-o", name, "-q"], ["in.ply", "-o", name, "--force", "-q"],
                 [name, "--in-place", "-q"]]
        for args in steps:
            if "--in-place" in args and length <= 255:
                self.put_input(d, name)
            r, ok = self.run(case, d, args)
            if not ok:
                return
            if length <= 255:
                if r.rc != 0:
                    case.add("other", "a %d-byte name refused (exit %d): %s" % (length, r.rc, c.said(r.err)))
                    return
                self.expect_bytes(case, os.path.join(d, name))
            else:
                if r.rc == 0:
                    case.add("wrong", "exit 0 writing a %d-byte name" % length)
                elif not r.err.strip():
                    case.add("other", "refused without a message")
                break
        self.check_leftovers(case, d)

    def tmpdir(self, case, kind):
        """--tmpdir: '' and names past PATH_MAX, missing folders and files refused with a
        message naming it; folders (also deep, linked or relative) work and stay empty."""
        d = self.folder(case.name)
        self.put_input(d)
        os.makedirs(os.path.join(d, "tmp"))
        valid = True
        if kind == "empty":
            t, valid = "", False
        elif kind == "overlong":
            t, valid = "/" + "d" * 5000, False
        elif kind == "missing":
            t, valid = os.path.join(d, "missing"), False
        elif kind == "file":
            t, valid = os.path.join(d, "in.ply"), False
        elif kind == "folder":
            t = os.path.join(d, "tmp")
        elif kind == "relative":
            t = "tmp"
        elif kind == "link":
            os.symlink("tmp", os.path.join(d, "tmplink"))
            t = "tmplink"
        else:  # deep: about 4,000 bytes, within PATH_MAX
            t = d
            while len(t) < 3900:
                t = os.path.join(t, "t" * min(200, 3950 - len(t)))
            os.makedirs(t)
        before = c.listing(d)
        r, ok = self.run(case, d, ["in.ply", "-o", "out.ply", "-q", "--tmpdir", t])
        if not ok:
            return
        after = c.listing(d)
        if valid:
            if r.rc == 0:
                self.expect_bytes(case, os.path.join(d, "out.ply"))
            elif kind == "deep" and r.rc == 2 and "tmpdir" in r.err:
                case.notes.append("a %d-byte --tmpdir refused: %s" % (len(t), c.said(r.err, 200)))
            else:
                case.add("other", "--tmpdir %s refused (exit %d): %s" % (kind, r.rc, c.said(r.err)))
        else:
            if r.rc == 0:
                case.add("wrong", "exit 0 with --tmpdir %s" % kind)
            elif "tmpdir" not in r.err:
                case.add("other", "--tmpdir %s: the message does not name it: %s" % (kind, c.said(r.err)))
            lost = c.changes(before, after)
            if lost:
                case.add("lost", "; ".join(lost))
        self.check_leftovers(case, d)

    def killed(self, case, sig, mode, fraction):
        """A signal at a random point of the run: the output is absent or old, or whole and
        right; with --in-place the input is the original or the result. After SIGKILL only
        rsmooth's documented .rsmooth-* files may stay (counted apart); after SIGTERM and SIGINT
        nothing."""
        d = self.folder(case.name)
        self.put_input(d, key="big")
        if mode == "force":
            c.write(os.path.join(d, "out.ply"), b"old content\n")
        target = "in.ply" if mode == "in-place" else "out.ply"
        old = c.read(os.path.join(d, target)) if mode != "new" else None
        args = ["in.ply", "--in-place", "-q"] if mode == "in-place" else \
            ["in.ply", "-o", "out.ply", "-q"] + (["--force"] if mode == "force" else [])
        p, r = c.start(self.argv(args, cap="16M"), self.s, env=c.writer_env(self.b, self.w), cwd=d)
        time.sleep(fraction * self.duration)
        if p.poll() is None:
            r.signalled = sig
            if sig == signal.SIGKILL:  # every process, the ranks too: a machine that stops
                c.kill_session(p.pid, sig)
            else:  # mpirun passes it on to the ranks
                os.kill(p.pid, sig)
        c.finish(p, r, self.s.timeout)
        case.commands.append(r.text() + "  # %s after %.2f s" % (c.signal_name(sig), fraction * self.duration))
        if r.hung:
            case.add("hangs", "still running %.0f s after %s" % (r.seconds, c.signal_name(sig)))
            return
        if c.SANITIZER_RE.search(r.err):
            case.add("sanitizer", c.tail(r.err))
        if r.signalled is None:
            case.judge(r)
        got = c.read(os.path.join(d, target)) if os.path.exists(os.path.join(d, target)) else None
        expected = self.f.expected["big"]
        if got is not None and got != expected and got != old:
            case.add("lost", "%s is neither the old content nor the result (%d bytes) after %s"
                     % (target, len(got), c.signal_name(sig)))
        if got is None and mode != "new":
            case.add("lost", "%s is gone after %s" % (target, c.signal_name(sig)))
        if r.signalled is None and r.rc == 0 and got != expected:
            case.add("wrong", "exit 0 but %s is not the result" % target)
        left = c.leftovers(d)
        if left and sig == signal.SIGKILL:
            case.notes.append("after SIGKILL: %s" % left)
            self.kill_leftovers.append(left)
            if self.w == "mpi" and any("partial" in n for n in left):
                # a later run to the same output must say what to remove, and touch nothing
                before = c.listing(d)
                r2, ok = self.run(case, d, args, cap="16M")
                if ok and (r2.rc == 0 or "remove it" not in r2.err):
                    case.add("other", "after a killed run's partial file: exit %d: %s"
                             % (r2.rc, c.said(r2.err)))
                if ok and c.changes(before, c.listing(d)):
                    case.add("lost", "; ".join(c.changes(before, c.listing(d))))
        elif left:
            case.add("lost", "left behind after %s: %s" % (c.signal_name(sig), left))

    def measure(self):
        """How long one run on the large input takes, for the signals' random times."""
        d = self.folder("timing")
        self.put_input(d, key="big")
        t0 = time.monotonic()
        c.run(self.argv(["in.ply", "-o", "out.ply", "-q"], cap="16M"), self.s,
              env=c.writer_env(self.b, self.w), cwd=d)
        self.duration = max(0.05, time.monotonic() - t0)

    def jobs(self, kills):
        rng = self.s.rng("outputs", self.b.name, self.w)
        out = []

        def add(name, fn, *a):
            name = "%s %02d: %s" % (self.w, len(out), name)
            out.append((self.surface, name, lambda case: fn(case, *a)))

        for k in range(4):
            mode, owner = rng.choice(MODES), rng.choice(OWNERS)
            in_place = k % 2 == 1
            add("replace %s %04o %d:%d" % ("in-place" if in_place else "-o --force", mode, *owner),
                self.replace, mode, owner, in_place)
        for k in range(2):
            add("hard links %d %s" % (k + 1, "in-place" if k else "-o"), self.hard_links, k + 1, k == 1)
        for k in range(4):
            add("symlink chain %d%s" % (k, " in-place" if k % 2 else ""), self.symlinks,
                random.Random(rng.random()), k % 2 == 1)
        kinds = ["fifo", "folder", "socket", "dangling-link", "link-into-missing-folder",
                 "link-to-folder", "link-to-fifo", "link-loop"] + (["device", "link-to-device"]
                                                                   if self.s.root else [])
        for kind in kinds:
            for force in (False, True):
                if self.w == "mpi" and (not force and kind not in ("fifo", "device", "dangling-link")
                                        or force and kind in ("socket", "link-loop")):
                    continue  # the refusal is the command's; the ranks' share is tried with --force
                add("special %s%s" % (kind, " --force" if force else ""), self.special, kind, force)
        for kind in ("file", "link", "fifo", "folder"):
            add("appears during the run: %s" % kind, self.appears, kind)
        for racers in (2, 3, 2):
            add("race of %d" % racers, self.race, racers)
        for length in sorted(set([245, rng.randint(246, 254), 255, 256])):
            add("name of %d bytes" % length, self.long_name, length)
        if self.w != "memory":
            for kind in ("empty", "overlong", "missing", "file", "folder", "relative", "link", "deep"):
                if self.w == "mpi" and kind in ("file", "relative", "link"):
                    continue  # the command's checks, tried with --max-memory
                add("--tmpdir %s" % kind, self.tmpdir, kind)
        self.kill_leftovers = []
        sigs = [signal.SIGTERM, signal.SIGINT, signal.SIGKILL]
        if kills:
            self.measure()
        for k in range(kills):
            sig = sigs[k % 3]
            mode = ["new", "force", "in-place"][(k // 3) % 3]
            fraction = rng.uniform(0.05, 1.1)
            add("%s at %.2f of the run, %s" % (c.signal_name(sig), fraction, mode), self.killed,
                sig, mode, fraction)
        return out
