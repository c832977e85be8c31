#!/usr/bin/env python3
"""Hostile-input and fault campaign for the rsmooth command: issue 12's acceptance table.

    python3 scripts/hostile_campaign.py build-campaign/rsmooth --out out/campaign

Runs the built command against generated hostile inputs in six categories (scale, truncation,
corruption, byte-order marks and leading text, output files and data loss, bad arguments) and
prints, per category: cases tried, crashes, wrong answers with exit 0, data lost, unlocated
errors and other defects, then every failing case (files, command, why) so each can be rerun.
The same goes to OUT/campaign.json and OUT/table.txt; every generated input stays under OUT.

Every verdict comes from this script's own readers (OBJ, PLY ascii/binary LE/BE, OFF, STL
ascii/binary) and its own arithmetic, never from what rsmooth says about itself; `rsmooth compare
OUT OUT --json` is only a second check that rsmooth reads its own output back. Python 3 standard
library only. docs/hostile_campaign.md explains each column.
"""

import argparse
import datetime
import hashlib
import json
import math
import os
import random
import re
import shlex
import shutil
import signal
import stat
import struct
import subprocess
import sys
import threading
import time
from concurrent.futures import ThreadPoolExecutor

BOM = b"\xef\xbb\xbf"
MAX_COORD = 1e150  # what rsmooth reads (README: coordinates up to 1e150 in magnitude)
CL_TOLERANCE = 1e-3  # OpenCL vs reference, in mean edge lengths (issue 12 item 1)
SCALE_TOLERANCE = 1e-3  # result at scale s vs s x result at 1, in mean edge lengths
SANITIZER_RE = re.compile(
    r"(AddressSanitizer|UndefinedBehaviorSanitizer|LeakSanitizer|ThreadSanitizer|MemorySanitizer|"
    r"runtime error:|Segmentation fault|core dumped|stack smashing detected|double free|"
    r"free\(\): invalid|malloc\(\): |corrupted size vs|Assertion `.*' failed)")
LOCATION_RE = re.compile(r"(:\d+:|\bline \d+|\bbyte \d+|\boffset \d+|\bbytes? \d+)")
CATEGORIES = [
    ("scale", "1. scale (1e-300 ... 1e149, float32 1e-36 ... 1e36, beyond 1e150)"),
    ("truncation", "2. truncation (prefixes of every format)"),
    ("corruption", "3. corruption (seeded byte flips, insertions, deletions)"),
    ("bom", "4. byte-order marks, leading text, OFF keywords"),
    ("files", "5. output files and data loss"),
    ("arguments", "6. bad arguments and environment"),
]
COLUMNS = ["tried", "crashes", "wrong", "lost", "unlocated", "other"]


class ParseError(Exception):
    pass


# ------------------------------------------------------------------------------------------------
# Meshes: generation and writing (with the byte offsets the truncation oracle needs)
# ------------------------------------------------------------------------------------------------

def noisy_grid(n, seed, jitter=0.15, znoise=0.1):
    """An n x n grid of unit spacing, jittered in x and y, Gaussian noise in z (a noisy plane)."""
    rng = random.Random(seed)
    verts = []
    for j in range(n):
        for i in range(n):
            verts.append((i + rng.uniform(-jitter, jitter), j + rng.uniform(-jitter, jitter),
                          rng.gauss(0.0, znoise)))
    faces = []
    for j in range(n - 1):
        for i in range(n - 1):
            a = j * n + i
            faces.append((a, a + 1, a + n + 1))
            faces.append((a, a + n + 1, a + n))
    return verts, faces


TETRA_FACES = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]


def fmt_fixed(x):
    return "%.6f" % x


class Text:
    """Builds a text file, remembering where each line's last token starts and ends."""

    def __init__(self):
        self.chunks = []
        self.pos = 0

    def line(self, s, nl="\n"):
        b = s.encode("ascii")
        start = self.pos
        stripped = b.rstrip()
        last = stripped.split()[-1] if stripped.split() else b""
        last_end = start + len(stripped)
        last_start = last_end - len(last)
        self.chunks.append(b + nl.encode("ascii"))
        self.pos += len(b) + len(nl)
        return start, last_start, last_end

    def data(self):
        return b"".join(self.chunks)


def write_format(fmt, verts, faces, num=fmt_fixed, nl="\n"):
    """Returns (bytes, oracle) for a mesh in format `fmt`. `oracle` tells what every prefix holds:
    kind 'counted' (header counts: complete once the last token is whole), 'binary' (complete only
    whole), 'obj' (the z token of each vertex line, the span of each face line) or 'stl_ascii'."""
    V, F = len(verts), len(faces)
    if fmt == "obj":
        t = Text()
        t.line("# hostile campaign mesh", nl)
        vz, frec = [], []
        for v in verts:
            _, zs, ze = t.line("v %s %s %s" % tuple(num(c) for c in v), nl)
            vz.append((zs, ze))
        for f in faces:
            s, _, e = t.line("f %d %d %d" % (f[0] + 1, f[1] + 1, f[2] + 1), nl)
            frec.append((s, e))
        return t.data(), {"kind": "obj", "vz": vz, "faces": frec, "V": V}
    if fmt in ("ply_ascii", "off", "coff", "noff"):
        t = Text()
        if fmt == "ply_ascii":
            for h in ["ply", "format ascii 1.0", "comment hostile campaign",
                      "element vertex %d" % V, "property float x", "property float y",
                      "property float z", "property uchar red", "property uchar green",
                      "property uchar blue", "element face %d" % F,
                      "property list uchar int vertex_indices", "end_header"]:
                t.line(h, nl)
        else:
            t.line({"off": "OFF", "coff": "COFF", "noff": "NOFF"}[fmt], nl)
            t.line("%d %d 0" % (V, F), nl)
        for i, v in enumerate(verts):
            row = [num(c) for c in v]
            if fmt == "ply_ascii":
                row += ["%d" % (37 * i % 256), "%d" % (91 * i % 256), "%d" % (53 * i % 256)]
            elif fmt == "coff":
                row += ["%d" % (37 * i % 256), "%d" % (91 * i % 256), "%d" % (53 * i % 256), "255"]
            elif fmt == "noff":
                row += ["0", "0", "1"]
            t.line(" ".join(row), nl)
        last = None
        for f in faces:
            last = t.line("3 %d %d %d" % f, nl)
        return t.data(), {"kind": "counted", "last_start": last[1], "last_end": last[2], "V": V}
    if fmt in ("ply_le", "ply_be"):
        le = fmt == "ply_le"
        e = "<" if le else ">"
        if le:
            props = ["property float x", "property float y", "property float z",
                     "property uchar red", "property uchar green", "property uchar blue"]
            rowfmt = e + "fffBBB"
        else:
            props = ["property double x", "property double y", "property double z",
                     "property ushort flags"]
            rowfmt = e + "dddH"
        header = ["ply", "format binary_%s_endian 1.0" % ("little" if le else "big"),
                  "comment hostile campaign", "element vertex %d" % V] + props + [
            "element face %d" % F, "property list uchar %s vertex_indices" % ("int" if le else "uint"),
            "end_header"]
        out = ("\n".join(header) + "\n").encode("ascii")
        for i, v in enumerate(verts):
            extra = (37 * i % 256, 91 * i % 256, 53 * i % 256) if le else (i,)
            out += struct.pack(rowfmt, *(tuple(v) + extra))
        for f in faces:
            out += struct.pack(e + "B3" + ("i" if le else "I"), 3, *f)
        return out, {"kind": "binary", "V": V}
    if fmt == "stl_ascii":
        t = Text()
        t.line("solid campaign", nl)
        facets = []
        for f in faces:
            a, b, c = (verts[k] for k in f)
            t.line("  facet normal 0 0 1", nl)
            t.line("    outer loop", nl)
            t.line("      vertex %s %s %s" % tuple(num(x) for x in a), nl)
            t.line("      vertex %s %s %s" % tuple(num(x) for x in b), nl)
            _, zs, _ = t.line("      vertex %s %s %s" % tuple(num(x) for x in c), nl)
            t.line("    endloop", nl)
            _, _, fe = t.line("  endfacet", nl)
            facets.append((zs, fe))
        _, ls, le_ = t.line("endsolid campaign", nl)
        return t.data(), {"kind": "stl_ascii", "facets": facets, "last_start": ls, "last_end": le_,
                          "V": 3 * F}
    if fmt == "stl_bin":
        out = b"hostile campaign binary stl".ljust(80, b" ") + struct.pack("<I", F)
        for f in faces:
            out += struct.pack("<3f", 0.0, 0.0, 1.0)
            for k in f:
                out += struct.pack("<3f", *verts[k])
            out += struct.pack("<H", 0)
        return out, {"kind": "binary", "V": 3 * F}
    raise ValueError(fmt)


FORMATS = ["obj", "ply_ascii", "ply_le", "ply_be", "off", "coff", "noff", "stl_ascii", "stl_bin"]
EXT = {"obj": ".obj", "ply_ascii": ".ply", "ply_le": ".ply", "ply_be": ".ply", "off": ".off",
       "coff": ".off", "noff": ".off", "stl_ascii": ".stl", "stl_bin": ".stl"}


def obj_text(verts, faces, num=repr):
    lines = ["v %s %s %s" % tuple(num(c) for c in v) for v in verts]
    lines += ["f %d %d %d" % (f[0] + 1, f[1] + 1, f[2] + 1) for f in faces]
    return ("\n".join(lines) + "\n").encode("ascii")


# ------------------------------------------------------------------------------------------------
# Readers (independent of rsmooth): what a file holds, by the detection rules rsmooth_io.h documents
# ------------------------------------------------------------------------------------------------

class Mesh:
    def __init__(self, fmt, verts, faces, normals=0):
        self.fmt, self.verts, self.faces, self.normals = fmt, verts, faces, normals


OFF_KEYWORD_RE = re.compile(r"(ST)?C?N?(4)?(n)?OFF", re.I)
OBJ_STATEMENTS = {"v", "vt", "vn", "vp", "f", "l", "p", "o", "g", "s", "usemtl", "mtllib", "cstype", "deg",
                  "curv", "surf", "bmat", "step", "parm", "trim", "hole", "end", "con", "sp", "mg",
                  "lod", "usemap", "maplib", "shadow_obj", "trace_obj", "ctech", "stech", "bevel",
                  "c_interp", "d_interp", "curv2"}


def first_word(d):
    """The first word past blank lines, indentation and '#' comments."""
    i, n = 0, len(d)
    while i < n:
        c = d[i:i + 1]
        if c in (b" ", b"\t", b"\r", b"\n", b"\f", b"\v"):
            i += 1
        elif c == b"#":
            j = d.find(b"\n", i)
            i = n if j < 0 else j + 1
        else:
            break
    j = i
    while j < n and d[j:j + 1] not in (b" ", b"\t", b"\r", b"\n", b"\f", b"\v"):
        j += 1
    return d[i:j]


def detect(data):
    if len(data) >= 84:
        (count,) = struct.unpack_from("<I", data, 80)
        if len(data) == 84 + 50 * count:
            return "stl_bin"
    d = data[3:] if data.startswith(BOM) else data
    if d.startswith(b"ply"):
        return "ply"
    w = first_word(d)
    try:
        ws = w.decode("ascii")
    except UnicodeDecodeError:
        ws = ""
    if OFF_KEYWORD_RE.fullmatch(ws):
        return "off"
    if ws == "solid":
        return "stl_ascii"
    if ws not in OBJ_STATEMENTS and any(b < 32 and b not in (9, 10, 11, 12, 13) for b in d):
        return "stl_bin"
    return "obj"


def parse_float(tok):
    try:
        return float(tok)
    except ValueError:
        raise ParseError("not a number: %r" % tok[:40])


def parse_int(tok):
    try:
        return int(tok)
    except ValueError:
        raise ParseError("not an integer: %r" % tok[:40])


def read_obj(data):
    d = data[3:] if data.startswith(BOM) else data
    text = d.decode("latin-1")  # statements are ascii words; other bytes only in unknown ones
    verts, faces, vn = [], [], 0
    for raw in text.replace("\r\n", "\n").split("\n"):
        line = raw.split("#", 1)[0]
        tok = line.split()
        if not tok:
            continue
        if tok[0] == "v":
            nums = [parse_float(t) for t in tok[1:]]
            if len(nums) not in (3, 4, 6, 7):
                raise ParseError("v with %d values" % len(nums))
            verts.append(tuple(nums[:3]))
        elif tok[0] == "vn":
            vn += 1
        elif tok[0] == "f":
            if len(tok) < 4:
                raise ParseError("face with fewer than 3 vertices")
            idx = []
            for r in tok[1:]:
                k = parse_int(r.split("/")[0])
                if k == 0:
                    raise ParseError("face index 0")
                k = k - 1 if k > 0 else len(verts) + k  # positive: absolute, may come before its v
                if k < 0:
                    raise ParseError("face index out of range")
                idx.append(k)
            faces.append(tuple(idx))
    if not verts:
        raise ParseError("no vertices")
    if any(k >= len(verts) for f in faces for k in f):
        raise ParseError("face index out of range")
    return Mesh("obj", verts, faces, vn)


PLY_TYPES = {"char": "b", "int8": "b", "uchar": "B", "uint8": "B", "short": "h", "int16": "h",
             "ushort": "H", "uint16": "H", "int": "i", "int32": "i", "uint": "I", "uint32": "I",
             "float": "f", "float32": "f", "double": "d", "float64": "d"}


def read_ply(data):
    d = data[3:] if data.startswith(BOM) else data
    if not d.startswith(b"ply"):
        raise ParseError("no ply magic")
    pos, lines = 0, []
    while True:
        j = d.find(b"\n", pos)
        if j < 0:
            raise ParseError("header not terminated")
        line = d[pos:j].decode("latin-1").rstrip("\r")
        pos = j + 1
        lines.append(line)
        if line.strip() == "end_header":
            break
    body = d[pos:]
    if lines[0].strip() != "ply":
        raise ParseError("bad magic line")
    fmt, elements = None, []
    for line in lines[1:-1]:
        tok = line.split()
        if not tok or tok[0] in ("comment", "obj_info"):
            continue
        if tok[0] == "format":
            if len(tok) != 3 or tok[1] not in ("ascii", "binary_little_endian", "binary_big_endian"):
                raise ParseError("bad format line")
            fmt = tok[1]
        elif tok[0] == "element":
            if len(tok) != 3:
                raise ParseError("bad element line")
            elements.append((tok[1], parse_int(tok[2]), []))
        elif tok[0] == "property":
            if not elements:
                raise ParseError("property before element")
            if len(tok) == 5 and tok[1] == "list":
                if tok[2] not in PLY_TYPES or tok[3] not in PLY_TYPES:
                    raise ParseError("bad list type")
                prop = ("list", tok[2], tok[3], tok[4])
            elif len(tok) == 3 and tok[1] in PLY_TYPES:
                prop = ("scalar", tok[1], None, tok[2])
            else:
                raise ParseError("bad property line")
            if any(p[3] == prop[3] for p in elements[-1][2]):
                raise ParseError("duplicate property")
            elements[-1][2].append(prop)
        else:
            raise ParseError("unknown header line %r" % line[:40])
    if fmt is None:
        raise ParseError("no format line")
    if any(c < 0 for _, c, _ in elements):
        raise ParseError("negative count")
    values = {}
    if fmt == "ascii":
        try:
            rows = [r.split() for r in body.decode("ascii").replace("\r\n", "\n").split("\n")]
        except UnicodeDecodeError:
            raise ParseError("ascii body not ascii")
        rows = [r for r in rows if r]
        ri = 0
        for name, count, props in elements:
            vals = []
            for _ in range(count):
                if ri >= len(rows):
                    raise ParseError("ascii PLY ends early")
                row, ti, rec = rows[ri], 0, []
                ri += 1
                for kind, t1, t2, pname in props:
                    if kind == "scalar":
                        if ti >= len(row):
                            raise ParseError("row too short")
                        rec.append(parse_float(row[ti]) if PLY_TYPES[t1] in "fd" else parse_int(row[ti]))
                        ti += 1
                    else:
                        if ti >= len(row):
                            raise ParseError("row too short")
                        n = parse_int(row[ti])
                        ti += 1
                        if n < 0 or ti + n > len(row):
                            raise ParseError("list too short")
                        rec.append([parse_float(x) if PLY_TYPES[t2] in "fd" else parse_int(x)
                                    for x in row[ti:ti + n]])
                        ti += n
                if ti != len(row):
                    raise ParseError("row has extra values")
                vals.append(rec)
            values[name] = (props, vals)
        if ri != len(rows):
            raise ParseError("ascii PLY has extra rows")
    else:
        e = "<" if fmt == "binary_little_endian" else ">"
        off = 0
        for name, count, props in elements:
            vals = []
            if count > len(body) + 1:
                raise ParseError("count beyond the data")
            simple = all(p[0] == "scalar" for p in props)
            if simple:
                rowfmt = e + "".join(PLY_TYPES[p[1]] for p in props)
                size = struct.calcsize(rowfmt)
                if off + size * count > len(body):
                    raise ParseError("binary PLY ends early")
                for k in range(count):
                    vals.append(list(struct.unpack_from(rowfmt, body, off + k * size)))
                off += size * count
            else:
                for _ in range(count):
                    rec = []
                    for kind, t1, t2, pname in props:
                        f1 = e + PLY_TYPES[t1]
                        s1 = struct.calcsize(f1)
                        if off + s1 > len(body):
                            raise ParseError("binary PLY ends early")
                        (v,) = struct.unpack_from(f1, body, off)
                        off += s1
                        if kind == "scalar":
                            rec.append(v)
                        else:
                            f2 = e + PLY_TYPES[t2]
                            s2 = struct.calcsize(f2)
                            if v < 0 or off + s2 * v > len(body):
                                raise ParseError("binary PLY ends early")
                            rec.append(list(struct.unpack_from(e + "%d" % v + PLY_TYPES[t2], body, off)))
                            off += s2 * v
                    vals.append(rec)
            values[name] = (props, vals)
        if off != len(body):
            raise ParseError("binary PLY has %d bytes after its data" % (len(body) - off))
    if "vertex" not in values:
        raise ParseError("no vertex element")
    props, vals = values["vertex"]
    names = [p[3] for p in props]
    try:
        ix, iy, iz = names.index("x"), names.index("y"), names.index("z")
    except ValueError:
        raise ParseError("no x y z")
    verts = [(float(r[ix]), float(r[iy]), float(r[iz])) for r in vals]
    normals = len(vals) if "nx" in names else 0
    faces = []
    if "face" in values:
        fprops, fvals = values["face"]
        fn = [p[3] for p in fprops]
        k = fn.index("vertex_indices") if "vertex_indices" in fn else (
            fn.index("vertex_index") if "vertex_index" in fn else None)
        if k is None:
            raise ParseError("face without vertex_indices")
        for r in fvals:
            idx = r[k]
            if len(idx) < 3 or any(not 0 <= i < len(verts) for i in idx):
                raise ParseError("bad face")
            faces.append(tuple(idx))
    return Mesh("ply_" + fmt, verts, faces, normals)


def read_off(data):
    d = data[3:] if data.startswith(BOM) else data
    try:
        text = d.decode("ascii")
    except UnicodeDecodeError:
        raise ParseError("OFF not ascii")
    lines = [l.split("#", 1)[0].split() for l in text.replace("\r\n", "\n").split("\n")]
    lines = [l for l in lines if l]
    if not lines:
        raise ParseError("empty")
    kw = lines[0][0]
    m = OFF_KEYWORD_RE.fullmatch(kw)
    if not m or m.group(2) or m.group(3) or kw.upper().startswith("ST"):
        raise ParseError("OFF keyword %r not read" % kw)
    has_n = "N" in kw.upper()[:-3]
    has_c = "C" in kw.upper()[:-3]
    rest = lines[0][1:]
    li = 1
    if not rest:
        if li >= len(lines):
            raise ParseError("no counts")
        rest = lines[li]
        li += 1
    if len(rest) != 3:
        raise ParseError("bad counts line")
    V, F = parse_int(rest[0]), parse_int(rest[1])
    parse_int(rest[2])
    if V < 0 or F < 0 or li + V + F != len(lines):
        raise ParseError("counts disagree with the lines")
    verts, nrm = [], 0
    base = 3 + (3 if has_n else 0)
    for k in range(V):
        row = lines[li + k]
        allowed = (base + 1, base + 3, base + 4) if has_c else (base,)
        if len(row) not in allowed:
            raise ParseError("vertex row with %d values" % len(row))
        nums = [parse_float(t) for t in row]
        verts.append(tuple(nums[:3]))
        nrm += 1 if has_n else 0
    faces = []
    for k in range(F):
        row = lines[li + V + k]
        n = parse_int(row[0])
        if n < 3 or len(row) not in (1 + n, 2 + n, 4 + n, 5 + n):
            raise ParseError("bad face row")
        idx = [parse_int(t) for t in row[1:1 + n]]
        for t in row[1 + n:]:
            parse_float(t)
        if any(not 0 <= i < V for i in idx):
            raise ParseError("face index out of range")
        faces.append(tuple(idx))
    return Mesh("off", verts, faces, nrm)


def read_stl_ascii(data):
    d = data[3:] if data.startswith(BOM) else data
    try:
        text = d.decode("ascii")
    except UnicodeDecodeError:
        raise ParseError("STL not ascii")
    lines = [l.split() for l in text.replace("\r\n", "\n").split("\n")]
    lines = [l for l in lines if l]
    if not lines or lines[0][0] != "solid":
        raise ParseError("no solid")
    tok = [t for l in lines[1:] for t in l]
    verts, faces, i = [], [], 0

    def expect(word):
        nonlocal i
        if i >= len(tok) or tok[i] != word:
            raise ParseError("expected %s" % word)
        i += 1

    while i < len(tok) and tok[i] == "facet":
        i += 1
        expect("normal")
        if i + 3 > len(tok):
            raise ParseError("short normal")
        [parse_float(t) for t in tok[i:i + 3]]
        i += 3
        expect("outer")
        expect("loop")
        for _ in range(3):
            expect("vertex")
            if i + 3 > len(tok):
                raise ParseError("short vertex")
            verts.append(tuple(parse_float(t) for t in tok[i:i + 3]))
            i += 3
        expect("endloop")
        expect("endfacet")
        faces.append((len(verts) - 3, len(verts) - 2, len(verts) - 1))
    expect("endsolid")
    if not faces:
        raise ParseError("no facets")
    return Mesh("stl_ascii", verts, faces)


def read_stl_bin(data):
    if len(data) < 84:
        raise ParseError("short binary STL")
    (n,) = struct.unpack_from("<I", data, 80)
    if len(data) != 84 + 50 * n:
        raise ParseError("size disagrees with count")
    verts, faces = [], []
    for k in range(n):
        vals = struct.unpack_from("<12f", data, 84 + 50 * k)
        for j in range(3):
            verts.append(tuple(vals[3 + 3 * j:6 + 3 * j]))
        faces.append((3 * k, 3 * k + 1, 3 * k + 2))
    return Mesh("stl_bin", verts, faces)


def read_mesh(data):
    kind = detect(data)
    return {"obj": read_obj, "ply": read_ply, "off": read_off, "stl_ascii": read_stl_ascii,
            "stl_bin": read_stl_bin}[kind](data)


def read_mesh_file(path):
    with open(path, "rb") as f:
        return read_mesh(f.read())


def mean_edge(verts, faces, scale=1.0):
    edges = set()
    for f in faces:
        for k in range(len(f)):
            a, b = f[k], f[(k + 1) % len(f)]
            edges.add((min(a, b), max(a, b)))
    if not edges:
        return float("nan")
    tot = 0.0
    for a, b in edges:
        pa, pb = verts[a], verts[b]
        tot += math.sqrt(sum(((pa[i] - pb[i]) / scale) ** 2 for i in range(3)))
    return tot / len(edges)


def max_dist(va, vb, scale=1.0):
    m = 0.0
    for a, b in zip(va, vb):
        d = math.sqrt(sum(((a[i] - b[i]) / scale) ** 2 for i in range(3)))
        if d > m or d != d:
            m = d
    return m


def nonfinite_or_beyond(verts):
    for k, v in enumerate(verts):
        for c in v:
            if not math.isfinite(c):
                return "vertex %d has non-finite coordinate %r" % (k, c)
            if abs(c) > MAX_COORD:
                return "vertex %d has coordinate %r beyond 1e150" % (k, c)
    return None


# ------------------------------------------------------------------------------------------------
# Running the command and recording cases
# ------------------------------------------------------------------------------------------------

class Campaign:
    def __init__(self, binary, out, jobs, seed, cpu_every, full):
        self.binary = os.path.abspath(binary)
        self.out = os.path.abspath(out)
        self.jobs = jobs
        self.seed = seed
        self.cpu_every = cpu_every
        self.full = full
        self.cases = []
        self.lock = threading.Lock()
        self.process_runs = 0
        self.env = {k: v for k, v in os.environ.items() if not k.startswith("RSMOOTH_")}
        self.env["POCL_CACHE_DIR"] = os.path.join(self.out, "pocl-cache")
        self.have_cpu = False
        self.notes = []
        self.script_errors = []

    # paths --------------------------------------------------------------------------------------
    def path(self, *parts):
        p = os.path.join(self.out, *parts)
        os.makedirs(os.path.dirname(p), exist_ok=True)
        return p

    def rel(self, p):
        return os.path.relpath(p, self.out)

    def write(self, rel, data):
        p = self.path(rel)
        with open(p, "wb") as f:
            f.write(data)
        return rel

    # processes ----------------------------------------------------------------------------------
    def run(self, args, env=None, cwd=None, timeout=60, prefix=None):
        argv = (prefix or []) + [self.binary] + list(args)
        e = dict(self.env)
        if env:
            for k, v in env.items():
                if v is None:
                    e.pop(k, None)
                else:
                    e[k] = v
        with self.lock:
            self.process_runs += 1
        t0 = time.monotonic()
        try:
            p = subprocess.run(argv, env=e, cwd=cwd or self.out, capture_output=True, timeout=timeout)
            rc, so, se, to = p.returncode, p.stdout, p.stderr, False
        except subprocess.TimeoutExpired as ex:
            rc, so, se, to = None, ex.stdout or b"", ex.stderr or b"", True
        return {"argv": argv, "env": env or {}, "cwd": cwd or self.out, "rc": rc, "timeout": to,
                "stdout": so.decode("utf-8", "replace"), "stderr": se.decode("utf-8", "replace"),
                "seconds": time.monotonic() - t0, "limit": timeout}

    def command_text(self, r):
        envs = " ".join("%s=%s" % (k, shlex.quote(v)) for k, v in r["env"].items() if v is not None)
        cmd = shlex.join(r["argv"])
        if envs:
            cmd = envs + " " + cmd
        if os.path.abspath(r["cwd"]) != self.out:
            cmd = "(cd %s && %s)" % (shlex.quote(self.rel(r["cwd"])), cmd)
        return cmd

    @staticmethod
    def crash_of(r):
        if r["timeout"]:
            return None
        rc = r["rc"]
        if rc < 0:
            return "killed by signal %d (%s)" % (-rc, signal.Signals(-rc).name if -rc in
                                                  [s.value for s in signal.Signals] else "?")
        if rc >= 128:
            return "exit %d (>= 128)" % rc
        m = SANITIZER_RE.search(r["stderr"])
        if m:
            return "sanitizer/abort report on stderr: %r" % m.group(0)
        return None

    def new_case(self, category, name, files, runs=()):
        return {"category": category, "name": name, "files": list(files), "commands": [],
                "rc": None, "stderr": "", "crash": [], "wrong": [], "lost": [], "unlocated": [],
                "other": [], "seconds": 0.0, "_runs": list(runs)}

    def attach(self, case, r, primary=True):
        case["commands"].append(self.command_text(r))
        case["seconds"] += r["seconds"]
        if primary:
            case["rc"] = r["rc"]
            case["stderr"] = r["stderr"][-600:]
        c = self.crash_of(r)
        if c:
            case["crash"].append("%s: %s" % (self.command_text(r), c))
        if r["timeout"]:
            case["other"].append("hang: no exit within %d s (%s)" % (r["limit"], self.command_text(r)))
        return r

    def record(self, case):
        with self.lock:
            self.cases.append(case)
        return case

    # checks -------------------------------------------------------------------------------------
    def located(self, stderr, name):
        """The message names the file and a line or byte offset."""
        if name not in stderr:
            return "message does not name the file %r: %s" % (name, stderr.strip()[-300:])
        if not LOCATION_RE.search(stderr):
            return "message names no line or byte offset: %s" % stderr.strip()[-300:]
        return None

    def check_refusal(self, case, r, name, must_name_location=True):
        """Exit 2 expected (the caller decides); checks the message is located."""
        if r["rc"] == 2 and must_name_location:
            why = self.located(r["stderr"], name)
            if why:
                case["unlocated"].append(why)

    def reread(self, case, out_rel, expect_count=None, cwd=None):
        """Parses an output with this script's readers and re-reads it with `rsmooth compare`.
        Returns the mesh or None (reasons go to case['wrong'])."""
        p = os.path.join(cwd or self.out, out_rel)
        if not os.path.exists(p):
            case["wrong"].append("exit 0 but no output file %s" % out_rel)
            return None
        try:
            m = read_mesh_file(p)
        except ParseError as ex:
            r = self.attach(case, self.run(["compare", out_rel, out_rel, "--json"], cwd=cwd), primary=False)
            if r["rc"] == 0:
                case["other"].append("rsmooth wrote %s, which it reads back but which breaks the format (this"
                                     " script's strict %s reader: %s)" % (out_rel, detect(open(p, "rb").read()), ex))
            else:
                case["wrong"].append("exit 0 but the output %s is unreadable: %s; rsmooth: %s" % (
                    out_rel, ex, r["stderr"].strip()[-200:]))
            return None
        why = nonfinite_or_beyond(m.verts)
        if why:
            case["wrong"].append("exit 0 with output %s: %s" % (out_rel, why))
        if expect_count is not None and len(m.verts) not in (
                expect_count if isinstance(expect_count, (set, frozenset)) else {expect_count}):
            case["wrong"].append("exit 0 with %d vertices in %s, expected %s" % (
                len(m.verts), out_rel, sorted(expect_count) if isinstance(expect_count, (set, frozenset))
                else expect_count))
        if m.faces:
            r = self.attach(case, self.run(["compare", out_rel, out_rel, "--json"], cwd=cwd), primary=False)
            if r["rc"] != 0:
                case["wrong"].append("rsmooth cannot read back its output %s: exit %s: %s" % (
                    out_rel, r["rc"], r["stderr"].strip()[-300:]))
            else:
                try:
                    nv = json.loads(r["stdout"])["vertices"]
                    if nv != len(m.verts):
                        case["wrong"].append("rsmooth reads %d vertices back from %s, this script %d" % (
                            nv, out_rel, len(m.verts)))
                except (ValueError, KeyError):
                    case["other"].append("rsmooth compare --json printed no vertex count")
        return m

    def pool_map(self, fn, items):
        def guarded(item):
            try:
                return fn(item)
            except Exception:  # a bug of this script, not a defect of rsmooth: say so, go on
                import traceback
                with self.lock:
                    self.script_errors.append("%s(%r): %s" % (fn.__name__, str(item)[:120],
                                                              traceback.format_exc()[-800:]))
                return None
        with ThreadPoolExecutor(max_workers=self.jobs) as ex:
            return list(ex.map(guarded, items))

    def device_for(self, i):
        return "cpu" if self.have_cpu and self.cpu_every and i % self.cpu_every == 0 else "reference"


# ------------------------------------------------------------------------------------------------
# 1. Scale
# ------------------------------------------------------------------------------------------------

def rms_z(verts, scale):
    return math.sqrt(sum((v[2] / scale) ** 2 for v in verts) / len(verts))


def category_scale(c):
    n = 10
    base_v, base_f = noisy_grid(n, seed=c.seed)
    exps = list(range(-300, 150))

    def make(k):
        s = float("1e%d" % k)
        verts = [(x * s, y * s, z * s) for x, y, z in base_v]
        rel = c.write("inputs/scale/grid_1e%+04d.obj" % k, obj_text(verts, base_f))
        return k, s, verts, rel

    grids = {k: make(k) for k in exps}

    def smooth(rel, dev, outrel, extra=()):
        return c.run([rel, "-o", outrel, "--device", dev, "-q", "--force"] + list(extra))

    def load(case, outrel, count):
        try:
            m = read_mesh_file(c.path(outrel))
        except (ParseError, OSError) as ex:
            case["wrong"].append("exit 0 but output unreadable: %s" % ex)
            return None
        if len(m.verts) != count:
            case["wrong"].append("exit 0 with %d vertices, input has %d" % (len(m.verts), count))
            return None
        why = nonfinite_or_beyond(m.verts)
        if why:
            case["wrong"].append("exit 0 with " + why)
            return None
        return m.verts

    # the scale-1 reference result: every other scale must give s times it
    _, _, _, rel0 = grids[0]
    r0 = c.run([rel0, "-o", "outputs/scale/unit_reference.obj", "--device", "reference", "-q", "--force"])
    ref1 = read_mesh_file(c.path("outputs/scale/unit_reference.obj")).verts if r0["rc"] == 0 else None
    before = rms_z(base_v, 1.0)
    ratio1 = rms_z(ref1, 1.0) / before if ref1 else float("nan")
    c.notes.append("scale: at 1 the reference takes the grid's rms height from %.4f to %.4f spacings"
                   " (ratio %.3f); a result must stay below %.2f of the input's" % (
                       before, before * ratio1, ratio1, min(0.9, ratio1 + 0.2)))
    smooth_limit = min(0.9, ratio1 + 0.2)

    def verdict(case, verts_in, s, out, dev_ref=None, mel=None):
        """out: the result (list) or None. Checks it moved, smoothed and is s x the unit result."""
        if out is None:
            return
        moved = max_dist(verts_in, out, s)
        if moved == 0.0:
            case["wrong"].append("nothing moved (output equals input)")
        after = rms_z(out, s)
        if not after < smooth_limit * rms_z(verts_in, s):
            case["wrong"].append("not smoothed: rms height %.4g -> %.4g spacings" % (
                rms_z(verts_in, s), after))
        if ref1 is not None and mel:
            d = max_dist([(x * s, y * s, z * s) for x, y, z in ref1], out, s) / mel
            if not d <= SCALE_TOLERANCE:
                case["wrong"].append("result is not %g x the result at scale 1: max %.3g mean edges" % (s, d))

    sweep = []

    def both_devices(label, kind, rel, outrel_of, verts, s, mel, scale_check, sweep_into=None):
        """Smooths `rel` on each device: each result checked (verdict, against the unit result
        when scale_check), OpenCL against the reference; (k, difference) to sweep_into."""
        res = {}
        cases = []
        for dev in (["reference", "cpu"] if c.have_cpu else ["reference"]):
            case = c.new_case("scale", "%s --device %s" % (label, dev), [rel])
            outrel = outrel_of(dev)
            r = c.attach(case, smooth(rel, dev, outrel))
            out = None
            if r["rc"] == 0:
                out = load(case, outrel, len(verts))
                if out is not None:
                    c.reread(case, outrel, len(verts))
            elif not r["timeout"] and not c.crash_of(r):
                case["other"].append("exit %s at a supported %s: %s" % (
                    r["rc"], kind, r["stderr"].strip()[-300:]))
            verdict(case, verts, s, out, mel=mel if scale_check else None)
            res[dev] = out
            cases.append(case)
        if len(cases) == 2 and res.get("reference") is not None and res.get("cpu") is not None:
            d = max_dist(res["reference"], res["cpu"], s) / mel
            if sweep_into is not None:
                sweep_into.append(d)
            if not d <= CL_TOLERANCE:
                cases[1]["wrong"].append("OpenCL differs from the reference by %.3g mean edge lengths" % d)
            if max_dist(verts, res["cpu"], s) == 0.0 and max_dist(verts, res["reference"], s) > 0.0:
                cases[1]["wrong"].append("OpenCL moved nothing while the reference moved the grid")
        for case in cases:
            c.record(case)

    def one(k):
        _, s, verts, rel = grids[k]
        found = []
        both_devices("grid 10x10 spacing 1e%d" % k, "scale", rel,
                     lambda dev: "outputs/scale/grid_1e%+04d_%s.obj" % (k, dev), verts, s,
                     mean_edge(verts, base_f, s), True, found)
        sweep.extend((k, d) for d in found)

    c.pool_map(one, exps)
    if sweep:
        worst = max(sweep, key=lambda t: (t[1] != t[1], t[1]))
        c.notes.append("scale: worst OpenCL-vs-reference difference over 1e-300..1e149: %.3g mean edge"
                       " lengths (at 1e%d); median %.3g" % (worst[1], worst[0],
                                                            sorted(d for _, d in sweep)[len(sweep) // 2]))

    # float32 (binary PLY float) from 1e-36 to 1e36
    f32_exps = list(range(-36, 37))

    def f32_one(k):
        s = float("1e%d" % k)
        verts = [struct.unpack("<3f", struct.pack("<3f", x * s, y * s, z * s)) for x, y, z in base_v]
        data, _ = write_format("ply_le", verts, base_f)
        rel = c.write("inputs/scale/grid_f32_1e%+03d.ply" % k, data)
        both_devices("float32 PLY grid spacing 1e%d" % k, "float32 scale", rel,
                     lambda dev: "outputs/scale/grid_f32_1e%+03d_%s.ply" % (k, dev), verts, s,
                     mean_edge(verts, base_f, s), False)

    c.pool_map(f32_one, f32_exps)

    # a double mesh written as binary STL (float32): the same result to float rounding, or refused
    def stl_out(k):
        _, s, verts, rel = grids[k]
        mel = mean_edge(verts, base_f, s)
        outrel = "outputs/scale/grid_1e%+04d_as_float32.stl" % k
        case = c.new_case("scale", "grid spacing 1e%d written as binary STL (float32)" % k, [rel])
        r = c.attach(case, smooth(rel, "reference", outrel))
        ref = c.path("outputs/scale/grid_1e%+04d_reference.obj" % k)
        if r["rc"] == 0:
            m = c.reread(case, outrel, 3 * len(base_f))
            if m is not None and os.path.exists(ref):
                want = read_mesh_file(ref).verts
                soup = [want[i] for f in base_f for i in f]
                d = max_dist(soup, m.verts, s) / mel
                if not d <= CL_TOLERANCE:
                    case["wrong"].append("the binary STL differs from the double result by %.3g mean edge lengths"
                                         " (float32 cannot hold spacing 1e%d; first vertex %r)" % (d, k, m.verts[0]))
        elif r["rc"] in (1, 2) and r["stderr"].strip():
            if os.path.exists(c.path(outrel)):
                case["lost"].append("exit %s but %s was left behind" % (r["rc"], outrel))
        elif not r["timeout"] and not c.crash_of(r):
            case["other"].append("exit %s: %s" % (r["rc"], r["stderr"].strip()[-200:]))
        c.record(case)

    c.pool_map(stl_out, [-300, -200, -150, -100, -60, -50, -46, -45, -44, -43, -42, -41, -40, -39, -38, -37,
                         -36, -30, 0, 30, 36, 37, 38, 39, 40, 100, 148])

    # the tetrahedron reaching 1e39
    tv = [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1e39)]
    rel = c.write("inputs/scale/tetra_1e39.obj", obj_text(tv, TETRA_FACES))
    mel = mean_edge(tv, TETRA_FACES)
    res = {}
    tcases = []
    for dev in (["reference", "cpu"] if c.have_cpu else ["reference"]):
        case = c.new_case("scale", "tetrahedron to 1e39 --device %s" % dev, [rel])
        outrel = "outputs/scale/tetra_1e39_%s.obj" % dev
        r = c.attach(case, smooth(rel, dev, outrel))
        if r["rc"] == 0:
            res[dev] = load(case, outrel, 4)
            if res[dev] is not None:
                c.reread(case, outrel, 4)
        elif r["rc"] != 2 and not c.crash_of(r) and not r["timeout"]:
            case["other"].append("exit %s: %s" % (r["rc"], r["stderr"].strip()[-300:]))
        else:
            c.check_refusal(case, r, rel)
        tcases.append(case)
    if res.get("reference") is not None and res.get("cpu") is not None:
        d = max_dist(res["reference"], res["cpu"]) / mel
        if not d <= CL_TOLERANCE:
            tcases[1]["wrong"].append("OpenCL differs from the reference by %.3g mean edge lengths" % d)
        if max_dist(tv, res["cpu"]) == 0.0 and max_dist(tv, res["reference"]) > 0.0:
            tcases[1]["wrong"].append("OpenCL moved nothing while the reference moved")
    for case in tcases:
        c.record(case)

    # coordinates beyond 1e150 (and non-finite): exit 2 naming the line (text) or a byte offset
    bad_values = ["2e150", "-1.5e151", "1e200", "1e308", "1.7976931348623157e308", "1e309", "-1e400",
                  "inf", "-inf", "nan", "1.0000001e150"]
    jobs = []
    for fmt in ["obj", "ply_ascii", "off", "coff", "stl_ascii"]:
        for vi, val in enumerate(bad_values):
            jobs.append((fmt, val, vi))
    for fmt in ["ply_le_double", "ply_be"]:
        for vi, val in enumerate([2e150, -1e200, 1e308, float("inf"), float("nan"), -float("inf")]):
            jobs.append((fmt, val, vi))
    for vi, val in enumerate([float("inf"), float("nan"), -float("inf")]):
        jobs.append(("stl_bin", val, vi))  # binary STL holds float32: only non-finite values

    def beyond(job):
        fmt, val, vi = job
        verts = [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)]
        target = 2  # the third vertex gets the bad value in y
        if fmt in ("ply_le_double", "ply_be", "stl_bin"):
            verts2 = [list(v) for v in verts]
            verts2[target][1] = val
            if fmt == "stl_bin":
                out = b"campaign".ljust(80, b" ") + struct.pack("<I", 4)
                row_spans = []
                for fi, f in enumerate(TETRA_FACES):
                    off0 = len(out)
                    out += struct.pack("<3f", 0, 0, 1)
                    for k in f:
                        out += struct.pack("<3f", *verts2[k])
                    out += struct.pack("<H", 0)
                    if target in f:
                        row_spans.append((off0, off0 + 50))
                data = out
            else:
                le = fmt == "ply_le_double"
                e = "<" if le else ">"
                header = ("ply\nformat binary_%s_endian 1.0\nelement vertex 4\nproperty double x\n"
                          "property double y\nproperty double z\nelement face 4\n"
                          "property list uchar int vertex_indices\nend_header\n" % (
                              "little" if le else "big")).encode("ascii")
                data = header
                for v in verts2:
                    data += struct.pack(e + "3d", *v)
                for f in TETRA_FACES:
                    data += struct.pack(e + "B3i", 3, *f)
                row_spans = [(len(header) + 24 * target, len(header) + 24 * target + 24)]
            name = "beyond_%s_%d%s" % (fmt, vi, ".stl" if fmt == "stl_bin" else ".ply")
            line = None
        else:
            text_verts = [tuple(repr(x) for x in v) for v in verts]
            text_verts[target] = (text_verts[target][0], val, text_verts[target][2])
            ident = lambda s: s
            data, oracle = write_format(fmt, [tuple(v) for v in text_verts],
                                        TETRA_FACES if fmt != "stl_ascii" else TETRA_FACES, num=ident)
            lines = data.split(b"\n")
            needle = (" " + val + " ").encode()
            line = [i + 1 for i, l in enumerate(lines) if needle in l + b" "]
            if fmt == "stl_ascii":
                # the record is the facet: any of its lines (facet normal ... endfacet) locates it
                spans = set()
                for ln in line:
                    a = max(i for i in range(ln) if lines[i].strip().startswith(b"facet"))
                    b = min(i for i in range(ln - 1, len(lines)) if lines[i].strip() == b"endfacet")
                    spans |= set(range(a + 1, b + 2))
                line = sorted(spans)
            name = "beyond_%s_%d%s" % (fmt, vi, EXT[fmt])
            row_spans = None
        rel = c.write("inputs/scale/" + name, data)
        case = c.new_case("scale", "coordinate %s in %s must be refused" % (val, fmt), [rel])
        r = c.attach(case, c.run([rel, "-o", "outputs/scale/" + name, "--device", "reference", "-q"]))
        if r["rc"] == 0:
            case["wrong"].append("exit 0 for a coordinate %s (beyond 1e150 or non-finite)" % val)
        elif r["rc"] == 2:
            why = c.located(r["stderr"], rel)
            if why:
                case["unlocated"].append(why)
            elif line:
                if not any(re.search(r"(:%d:|\bline %d\b)" % (ln, ln), r["stderr"]) for ln in line):
                    case["unlocated"].append("names the wrong line (the value is on line %s): %s" % (
                        "/".join(map(str, line)), r["stderr"].strip()[-300:]))
            elif row_spans:
                offs = [int(x) for x in re.findall(r"\bbyte (\d+)", r["stderr"])]
                if not any(a <= o <= b for o in offs for a, b in row_spans):
                    case["unlocated"].append("names byte %s, the value lies in bytes %s: %s" % (
                        offs, row_spans, r["stderr"].strip()[-300:]))
        elif not c.crash_of(r) and not r["timeout"]:
            case["other"].append("exit %s (2 expected): %s" % (r["rc"], r["stderr"].strip()[-300:]))
        if r["rc"] != 0 and os.path.exists(c.path("outputs/scale/" + name)):
            case["other"].append("exit %s but an output file was written" % r["rc"])
        c.record(case)

    c.pool_map(beyond, jobs)


# ------------------------------------------------------------------------------------------------
# 2. Truncation
# ------------------------------------------------------------------------------------------------

def prefix_expectation(oracle, L, total):
    """(must_succeed, allowed_counts) for the prefix of length L: what a correct reader does.
    allowed_counts empty: exit 0 is wrong (the prefix does not hold the mesh)."""
    kind = oracle["kind"]
    V = oracle["V"]
    if kind == "binary":
        return (L == total, {V} if L == total else set())
    if kind == "counted":
        if L >= oracle["last_end"]:
            return True, {V}
        if L > oracle["last_start"]:
            return False, {V}  # the last index is cut but may still be a number
        return False, set()
    if kind == "obj":
        k = sum(1 for zs, ze in oracle["vz"] if ze <= L)
        allowed = {k}
        if any(zs < L < ze for zs, ze in oracle["vz"]):
            allowed.add(k + 1)
        inside = any(s < L < e for s, e in oracle["faces"]) or any(
            zs < L < ze for zs, ze in oracle["vz"])
        first_face_end = oracle["faces"][0][1]
        # a prefix that ends between records and holds every vertex and a whole face is a valid OBJ
        must = L >= first_face_end and not inside
        if k == 0:
            allowed.discard(0)
        return must, allowed
    if kind == "stl_ascii":
        k = sum(1 for _, fe in oracle["facets"] if fe <= L)
        allowed = {3 * k} if k else set()
        nxt = [zs for zs, fe in oracle["facets"] if fe > L]
        if nxt and nxt[0] < L:
            allowed.add(3 * (k + 1))
        return L >= oracle["last_end"], allowed
    raise ValueError(kind)


def sample_prefixes(total, cap, rng, oracle):
    if total + 1 <= cap:
        return list(range(total + 1))
    keep = set(range(0, 49)) | set(range(max(0, total - 48), total + 1))
    for key in ("last_start", "last_end"):
        if key in oracle:
            keep |= {oracle[key] - 1, oracle[key], oracle[key] + 1}
    keep = {x for x in keep if 0 <= x <= total}
    rest = [x for x in range(total + 1) if x not in keep]
    rng.shuffle(rest)
    keep |= set(rest[:max(0, cap - len(keep))])
    return sorted(keep)


def category_truncation(c):
    verts, faces = noisy_grid(3, seed=c.seed + 2)
    rng = random.Random("%d-truncation" % c.seed)
    jobs = []
    for fmt in FORMATS:
        data, oracle = write_format(fmt, verts, faces)
        c.write("inputs/truncation/%s_full%s" % (fmt, EXT[fmt]), data)
        cap = 10 ** 9 if c.full else 300
        for L in sample_prefixes(len(data), cap, rng, oracle):
            jobs.append((fmt, data, oracle, L))

    def one(job_i):
        i, (fmt, data, oracle, L) = job_i
        rel = c.write("inputs/truncation/%s_prefix%05d%s" % (fmt, L, EXT[fmt]), data[:L])
        must, allowed = prefix_expectation(oracle, L, len(data))
        dev = c.device_for(i)
        outrel = "outputs/truncation/%s_prefix%05d_%s%s" % (fmt, L, dev, EXT[fmt])
        case = c.new_case("truncation", "%s: first %d of %d bytes --device %s" % (fmt, L, len(data), dev), [rel])
        r = c.attach(case, c.run([rel, "-o", outrel, "--device", dev, "-q", "--force"]))
        if r["rc"] == 0:
            if not allowed:
                case["wrong"].append("exit 0 for a prefix that does not hold the whole mesh "
                                     "(%s declares more than the %d bytes hold)" % (fmt, L))
            c.reread(case, outrel, allowed if allowed else None)
        elif r["rc"] == 2:
            c.check_refusal(case, r, rel)
            if must:
                case["other"].append("a complete, valid prefix was refused: %s" % r["stderr"].strip()[-300:])
        elif not c.crash_of(r) and not r["timeout"]:
            case["other"].append("exit %s (0 or 2 expected): %s" % (r["rc"], r["stderr"].strip()[-300:]))
        if r["rc"] != 0 and os.path.exists(c.path(outrel)):
            case["other"].append("exit %s but an output file was written" % r["rc"])
        c.record(case)

    c.pool_map(one, list(enumerate(jobs)))


# ------------------------------------------------------------------------------------------------
# 3. Corruption
# ------------------------------------------------------------------------------------------------

INTERESTING = [b"nan", b"inf", b"-inf", b"1e400", b"-", b"99999999999", b"4294967295", b"-1", b"\x00",
               b"\r", b"#", b" ", b"\n", b"\t", b"0", b"1e-400", b"f", b"v", b"3", b"end_header\n",
               b"element vertex 5\n", b"endfacet", b"\xef\xbb\xbf", b"\xff", b"e", b".", b"/"]
WORDS = [b"\x00\x00\x00\x00", b"\xff\xff\xff\xff", b"\xff\xff\xff\x7f", b"\x00\x00\x00\x80",
         b"\x00\x00\x80\x7f", b"\x00\x00\xc0\x7f", b"\x01\x00\x00\x00", b"\x00\x00\x01\x00"]


def mutate(data, rng):
    d = bytearray(data)
    for _ in range(rng.choice([1, 1, 1, 2, 3, 5])):
        op = rng.randrange(9)
        p = rng.randrange(len(d) + 1) if d else 0
        if op == 0 and d:
            p = min(p, len(d) - 1)
            d[p] ^= 1 << rng.randrange(8)
        elif op == 1 and d:
            p = min(p, len(d) - 1)
            d[p] = rng.randrange(256)
        elif op == 2:
            d[p:p] = bytes([rng.randrange(256)])
        elif op == 3 and d:
            del d[p:p + rng.choice([1, 1, 2, 8, 50])]
        elif op == 4:
            d[p:p] = rng.choice(INTERESTING)
        elif op == 5 and d:
            w = rng.choice(WORDS)
            p = min(p, max(0, len(d) - 4))
            d[p:p + 4] = w
        elif op == 6 and d:
            a = rng.randrange(len(d))
            b = min(len(d), a + rng.randrange(1, 64))
            d[p:p] = d[a:b]
        elif op == 7 and d:
            # a digit replaced by another digit or sign inside the text
            digits = [i for i, ch in enumerate(d) if 48 <= ch <= 57]
            if digits:
                q = rng.choice(digits)
                d[q] = rng.choice(b"0123456789-.e")
        elif op == 8 and len(d) > 84:
            # the binary STL count / PLY binary counts region
            q = rng.choice([80, 81, 82, 83, rng.randrange(len(d) - 4)])
            d[q:q + 4] = rng.choice(WORDS)
    return bytes(d)


def category_corruption(c, per_format):
    verts, faces = noisy_grid(3, seed=c.seed + 3)
    jobs = []
    for fmt in FORMATS:
        data, _ = write_format(fmt, verts, faces)
        for i in range(per_format):
            jobs.append((fmt, data, i))

    def one(job_i):
        n, (fmt, data, i) = job_i
        rng = random.Random("%d-corrupt-%s-%d" % (c.seed, fmt, i))
        bad = mutate(data, rng)
        rel = c.write("inputs/corruption/%s_%04d%s" % (fmt, i, EXT[fmt]), bad)
        dev = c.device_for(n)
        outrel = "outputs/corruption/%s_%04d_%s%s" % (fmt, i, dev, EXT[fmt])
        case = c.new_case("corruption", "%s mutant %d (seed '%d-corrupt-%s-%d') --device %s" % (
            fmt, i, c.seed, fmt, i, dev), [rel])
        strict = None
        try:
            mine = read_mesh(bad)
            expect = len(mine.verts) if mine.faces else None
        except (ParseError, struct.error, ValueError, IndexError, OverflowError) as ex:
            mine, expect, strict = None, None, "%s reader: %s" % (detect(bad), ex)
        r = c.attach(case, c.run([rel, "-o", outrel, "--device", dev, "-q", "--force"]))
        if r["rc"] == 0:
            if strict:
                case["lenient"] = strict
            out = c.reread(case, outrel)
            if out is not None and expect is not None and len(out.verts) != expect:
                case["wrong"].append("exit 0 with %d vertices; the input holds %d (this script's %s reader)"
                                     % (len(out.verts), expect, mine.fmt))
        elif r["rc"] == 2:
            c.check_refusal(case, r, rel)
        elif not c.crash_of(r) and not r["timeout"]:
            case["other"].append("exit %s (0 or 2 expected for a bad file): %s" % (
                r["rc"], r["stderr"].strip()[-300:]))
        if r["rc"] != 0 and os.path.exists(c.path(outrel)):
            case["other"].append("exit %s but an output file was written" % r["rc"])
        c.record(case)

    c.pool_map(one, list(enumerate(jobs)))
    accepted = [x for x in c.cases if x["category"] == "corruption" and x["rc"] == 0]
    lenient = [x for x in accepted if x.get("lenient")]
    c.notes.append("corruption: rsmooth accepted %d of %d mutants (exit 0); this script's strict readers refuse"
                   " %d of those (not counted as defects; 'lenient' in cases.jsonl): %s" % (
                       len(accepted), len([x for x in c.cases if x["category"] == "corruption"]), len(lenient),
                       "; ".join(sorted(set(normalise(x["lenient"]) for x in lenient))[:12])))


# ------------------------------------------------------------------------------------------------
# 4. Byte-order marks, leading text, OFF keywords
# ------------------------------------------------------------------------------------------------

def category_bom(c):
    verts, faces = noisy_grid(4, seed=c.seed + 4)
    variants = []  # (name, fmt, bytes, expectation: same | refuse | either, refusal words)

    def crlf(b):
        return b.replace(b"\n", b"\r\n")

    base = {}
    for fmt in ["obj", "ply_ascii", "ply_le", "ply_be", "off", "coff", "noff", "stl_ascii", "stl_bin"]:
        data, _ = write_format(fmt, verts, faces)
        base[fmt] = data
    text_formats = ["obj", "ply_ascii", "off", "coff", "noff", "stl_ascii"]
    for fmt in text_formats:
        d = base[fmt]
        variants.append(("bom", fmt, BOM + d, "same", None))
        variants.append(("crlf", fmt, crlf(d), "same", None))
        variants.append(("bom+crlf", fmt, BOM + crlf(d), "same", None))
        if fmt.startswith("ply"):
            variants.append(("blank line first", fmt, b"\n" + d, "refuse", None))
            variants.append(("space first", fmt, b" " + d, "refuse", None))
            variants.append(("bom+space", fmt, BOM + b" " + d, "refuse", None))
        else:
            variants.append(("blank lines first", fmt, b"\n\n" + d, "same", None))
            variants.append(("indented", fmt, b"   " + d, "same", None))
            variants.append(("tab+crlf blank first", fmt, b"\t\r\n" + d, "same", None))
            variants.append(("bom+blank lines", fmt, BOM + b"\n\n" + d, "same", None))
            variants.append(("comment first", fmt, b"# made by hand\n" + d,
                             "either" if fmt == "stl_ascii" else "same", None))
            variants.append(("bom+comment first", fmt, BOM + b"# a comment\n\n" + d,
                             "either" if fmt == "stl_ascii" else "same", None))
    for fmt in ["ply_le", "ply_be"]:
        variants.append(("bom", fmt, BOM + base[fmt], "same", None))
        variants.append(("space first", fmt, b" " + base[fmt], "refuse", None))
    variants.append(("bom", "stl_bin", BOM + base["stl_bin"], "either", None))
    he = base["ply_le"].index(b"end_header\n") + len(b"end_header\n")
    variants.append(("ply CRLF header", "ply_le", base["ply_le"][:he].replace(b"\n", b"\r\n") +
                     base["ply_le"][he:], "either", None))
    off = base["off"]
    body = off.split(b"\n", 1)[1]
    for kw in [b"off", b"Off", b"oFF"]:
        variants.append(("keyword %s" % kw.decode(), "off", kw + b"\n" + body, "same", None))
    variants.append(("keyword COff", "coff", b"COff\n" + base["coff"].split(b"\n", 1)[1], "same", None))
    variants.append(("keyword NOff", "noff", b"NOff\n" + base["noff"].split(b"\n", 1)[1], "same", None))
    # a lowercase prefix letter: 'n' before OFF is the dimension form, so prefixes may be case-sensitive
    variants.append(("keyword coff", "coff", b"coff\n" + base["coff"].split(b"\n", 1)[1], "either", None))
    variants.append(("counts on the keyword line", "off", b"OFF " + body, "same", None))
    variants.append(("comment between keyword and counts", "off", b"OFF\n# counts next\n" + body, "same", None))
    variants.append(("comment and blank before OFF", "off", b"# scanner output\n\n  \nOFF\n" + body, "same", None))
    variants.append(("bom+comment+lowercase", "off", BOM + b"# x\noff\n" + body, "same", None))
    v4 = b"4OFF\n" + b"\n".join(
        (l + b" 1") if (i > 0 and i <= len(verts)) else l
        for i, l in enumerate(body.split(b"\n")))
    variants.append(("4OFF", "off", v4, "refuse", ("support",)))
    variants.append(("nOFF", "off", b"nOFF\n3\n" + body, "refuse", ("support",)))
    variants.append(("4nOFF", "off", b"4nOFF\n3\n" + body, "refuse", ("support",)))
    variants.append(("4OFF after a comment", "off", b"# c\n4OFF\n" + body, "refuse", ("support",)))

    # the plain results, one per format and device
    plain = {}
    devices = ["reference", "cpu"] if c.have_cpu else ["reference"]
    for fmt, d in base.items():
        rel = c.write("inputs/bom/plain_%s%s" % (fmt, EXT[fmt]), d)
        for dev in devices:
            outrel = "outputs/bom/plain_%s_%s%s" % (fmt, dev, EXT[fmt])
            case = c.new_case("bom", "%s without BOM (baseline) --device %s" % (fmt, dev), [rel])
            r = c.attach(case, c.run([rel, "-o", outrel, "--device", dev, "-q", "--force"] +
                                     (["--ascii"] if fmt == "stl_ascii" else [])))
            if r["rc"] == 0:
                m = c.reread(case, outrel, len(read_mesh(d).verts))
                plain[(fmt, dev)] = m
            else:
                case["other"].append("the plain file failed: exit %s: %s" % (r["rc"], r["stderr"].strip()[-300:]))
            c.record(case)

    jobs = []
    for i, v in enumerate(variants):
        jobs.append((i, v, "reference"))
        if c.have_cpu and i % 4 == 0:
            jobs.append((i, v, "cpu"))

    def one(job):
        i, (vname, fmt, data, expect, words), dev = job
        slug = re.sub(r"[^A-Za-z0-9]+", "-", vname).strip("-")
        rel = c.write("inputs/bom/%s_%02d_%s%s" % (fmt, i, slug, EXT[fmt]), data)
        outrel = "outputs/bom/%s_%02d_%s_%s%s" % (fmt, i, slug, dev, EXT[fmt])
        case = c.new_case("bom", "%s: %s (expect %s) --device %s" % (fmt, vname, expect, dev), [rel])
        r = c.attach(case, c.run([rel, "-o", outrel, "--device", dev, "-q", "--force"] +
                                 (["--ascii"] if fmt == "stl_ascii" else [])))
        ref = plain.get((fmt, dev))
        if r["rc"] == 0:
            if expect == "refuse":
                case["wrong"].append("exit 0 for a file that must be refused (%s)" % vname)
            m = c.reread(case, outrel)
            if m is not None and ref is not None and expect != "refuse":
                if len(m.verts) != len(ref.verts):
                    case["wrong"].append("%d vertices, %d without the variation" % (len(m.verts), len(ref.verts)))
                elif m.verts != ref.verts:
                    case["wrong"].append("coordinates differ from the result without the variation by up to %.3g"
                                         % max_dist(m.verts, ref.verts))
            if data.startswith(BOM) and fmt != "stl_bin":
                with open(c.path(outrel), "rb") as f:
                    if not f.read(3) == BOM:
                        case["other"].append("the byte-order mark is not kept on a round trip (%s)" % fmt)
        elif r["rc"] == 2:
            c.check_refusal(case, r, rel)
            if expect == "same":
                case["other"].append("refused, but must read as without the variation: %s" % r["stderr"].strip()[-300:])
            if fmt == "stl_ascii" and "binary STL" in r["stderr"]:
                case["other"].append("a text STL read as binary STL, though rsmooth_io.h says the first word past"
                                     " blank lines and '#' comments decides ('solid': ascii STL): %s" %
                                     r["stderr"].strip()[-200:])
            if words and not any(w in r["stderr"] for w in words):
                case["other"].append("refusal does not say %s: %s" % (" or ".join(words), r["stderr"].strip()[-200:]))
        elif not c.crash_of(r) and not r["timeout"]:
            case["other"].append("exit %s: %s" % (r["rc"], r["stderr"].strip()[-300:]))
        c.record(case)

    c.pool_map(one, jobs)


# ------------------------------------------------------------------------------------------------
# 5. Output files and data loss
# ------------------------------------------------------------------------------------------------

def snapshot(d):
    """Everything about a directory's entries (recursively): type, bytes' hash, mtime, mode, owner."""
    snap = {}
    for root, dirs, files in os.walk(d, followlinks=False):
        for name in dirs + files:
            p = os.path.join(root, name)
            rel = os.path.relpath(p, d)
            st = os.lstat(p)
            entry = {"mode": oct(st.st_mode), "uid": st.st_uid, "gid": st.st_gid}
            if not stat.S_ISDIR(st.st_mode):  # a folder's mtime moves with its entries: not data
                entry.update(mtime_ns=st.st_mtime_ns, ino=st.st_ino)
            if stat.S_ISLNK(st.st_mode):
                entry["link"] = os.readlink(p)
            elif stat.S_ISREG(st.st_mode):
                with open(p, "rb") as f:
                    entry["sha256"] = hashlib.sha256(f.read()).hexdigest()
                entry["size"] = st.st_size
            snap[rel] = entry
    return snap


def diff_snap(before, after, allowed_changes=(), allowed_new=()):
    """Entries changed, removed or added other than those allowed."""
    problems = []
    for k, v in before.items():
        if k not in after:
            if k not in allowed_changes:
                problems.append("%s was removed" % k)
        elif after[k] != v and k not in allowed_changes:
            what = [f for f in v if after[k].get(f) != v[f]]
            problems.append("%s changed (%s)" % (k, ", ".join(what)))
    for k in after:
        if k not in before and k not in allowed_new:
            problems.append("%s was left behind (%d bytes)" % (k, after[k].get("size", 0)))
    return problems


class FileScenarios:
    def __init__(self, c):
        self.c = c
        self.n = 0
        self.root = os.path.join(c.out, "files")
        os.makedirs(self.root, exist_ok=True)
        v, f = noisy_grid(8, seed=c.seed + 5)
        self.mesh = obj_text(v, f, num=fmt_fixed)
        self.mesh_v = len(v)
        self.as_root = os.geteuid() == 0
        self.setpriv = shutil.which("setpriv")

    def fresh(self, name):
        self.n += 1
        d = os.path.join(self.root, "%03d-%s" % (self.n, re.sub(r"[^A-Za-z0-9]+", "-", name).strip("-")[:60]))
        os.makedirs(d)
        return d

    def put(self, d, name, data, mode=None):
        p = os.path.join(d, name)
        with open(p, "wb") as f:
            f.write(data)
        if mode is not None:
            os.chmod(p, mode)
        return p

    def smoothed_ok(self, case, d, name, count=None, original=None):
        """The file `name` in d holds a complete smoothed mesh (parsed here, re-read by rsmooth)."""
        m = self.c.reread(case, name, self.mesh_v if count is None else count, cwd=d)
        if m is not None and original is not None:
            try:
                o = read_mesh(original)
                if m.verts == o.verts:
                    case["wrong"].append("%s holds the input unchanged (nothing written)" % name)
            except ParseError:
                pass
        return m

    def run(self, case, d, args, timeout=120, env=None, prefix=None):
        return self.c.attach(case, self.c.run(args, cwd=d, timeout=timeout, env=env, prefix=prefix))

    # ---------------------------------------------------------------------------------------------
    def existing_output(self):
        c = self.c
        for ext in [".obj", ".ply", ".off", ".stl"]:
            d = self.fresh("existing output " + ext)
            self.put(d, "in.obj", self.mesh)
            self.put(d, "out" + ext, b"precious data, not a mesh\n", 0o640)
            case = c.new_case("files", "existing output%s without --force" % ext, [c.rel(d)])
            before = snapshot(d)
            r = self.run(case, d, ["in.obj", "-o", "out" + ext, "--device", "reference", "-q"])
            if r["rc"] == 0:
                case["lost"].append("exit 0: an existing file was replaced without --force")
            elif r["rc"] != 2 and not r["timeout"] and not c.crash_of(r):
                case["other"].append("exit %s (2 expected)" % r["rc"])
            case["lost"] += diff_snap(before, snapshot(d))
            c.record(case)
        # the confidence file existing
        d = self.fresh("existing confidence")
        self.put(d, "in.obj", self.mesh)
        self.put(d, "conf.ply", b"precious confidence\n")
        case = c.new_case("files", "existing --confidence file without --force", [c.rel(d)])
        before = snapshot(d)
        r = self.run(case, d, ["in.obj", "-o", "new.obj", "--confidence", "conf.ply", "--device", "reference", "-q"])
        after = snapshot(d)
        if r["rc"] == 0:
            case["lost"].append("exit 0: the existing confidence file was replaced without --force")
        case["lost"] += [p for p in diff_snap(before, after, allowed_new=("new.obj",))]
        if r["rc"] != 0 and "new.obj" in after:
            case["other"].append("exit %s but new.obj was written" % r["rc"])
        c.record(case)
        # noise and render to an existing file
        for sub, args, outname in [("noise", ["noise", "in.obj", "out.obj", "--sigma", "0.1"], "out.obj"),
                                   ("render", ["render", "in.obj", "-o", "out.png", "--size", "64x64"], "out.png")]:
            d = self.fresh("existing " + sub)
            self.put(d, "in.obj", self.mesh)
            self.put(d, outname, b"precious\n")
            case = c.new_case("files", "rsmooth %s onto an existing file without --force" % sub, [c.rel(d)])
            before = snapshot(d)
            r = self.run(case, d, args + ["-q"] if sub == "noise" else args)
            if r["rc"] == 0:
                case["lost"].append("exit 0: an existing file was replaced without --force")
            case["lost"] += diff_snap(before, snapshot(d))
            c.record(case)

    def in_place_modes(self):
        c = self.c
        owners = [(None, None)]
        if self.as_root:
            owners += [(1234, 1234), (0, 1234)]
        for mode in [0o600, 0o640, 0o604, 0o755, 0o660, 0o444, 0o2640]:
            for uid, gid in owners:
                d = self.fresh("in-place mode %o owner %s" % (mode, uid))
                p = self.put(d, "scan.obj", self.mesh)
                if uid is not None:
                    os.chown(p, uid, gid)
                os.chmod(p, mode)
                st0 = os.stat(p)
                case = c.new_case("files", "--in-place on a %04o file owned by %s:%s" % (
                    mode, st0.st_uid, st0.st_gid), [c.rel(d)])
                before = snapshot(d)
                r = self.run(case, d, ["scan.obj", "--in-place", "--device", "reference", "-q"])
                st1 = os.stat(p)
                if r["rc"] == 0:
                    self.smoothed_ok(case, d, "scan.obj", original=self.mesh)
                    if stat.S_IMODE(st1.st_mode) != stat.S_IMODE(st0.st_mode):
                        case["lost"].append("mode %04o became %04o" % (stat.S_IMODE(st0.st_mode),
                                                                       stat.S_IMODE(st1.st_mode)))
                    if (st1.st_uid, st1.st_gid) != (st0.st_uid, st0.st_gid):
                        case["lost"].append("owner %d:%d became %d:%d" % (st0.st_uid, st0.st_gid,
                                                                           st1.st_uid, st1.st_gid))
                    case["lost"] += diff_snap(before, snapshot(d), allowed_changes=("scan.obj",))
                else:
                    if mode != 0o444:
                        case["other"].append("exit %s for --in-place on a writable file: %s" % (
                            r["rc"], r["stderr"].strip()[-200:]))
                    case["lost"] += diff_snap(before, snapshot(d))
                c.record(case)

    def symlinks(self):
        c = self.c
        # --in-place through a link (relative, absolute, chain, into a subfolder)
        for kind in ["relative", "absolute", "chain", "subfolder"]:
            d = self.fresh("in-place symlink " + kind)
            real_name = "sub/real.obj" if kind == "subfolder" else "real.obj"
            os.makedirs(os.path.join(d, "sub"), exist_ok=True)
            p = self.put(d, real_name, self.mesh, 0o600)
            target = p if kind == "absolute" else real_name
            os.symlink(target, os.path.join(d, "link.obj"))
            name = "link.obj"
            if kind == "chain":
                os.symlink("link.obj", os.path.join(d, "link2.obj"))
                name = "link2.obj"
            case = c.new_case("files", "--in-place on a %s symbolic link" % kind, [c.rel(d)])
            before = snapshot(d)
            r = self.run(case, d, [name, "--in-place", "--device", "reference", "-q"])
            after = snapshot(d)
            if r["rc"] == 0:
                for ln in ["link.obj", "link2.obj"]:
                    if ln in before and after.get(ln) != before[ln]:
                        case["lost"].append("%s is no longer the same symbolic link: %s" % (ln, after.get(ln)))
                self.smoothed_ok(case, d, real_name, original=self.mesh)
                if after.get(real_name, {}).get("mode") != before[real_name]["mode"]:
                    case["lost"].append("the target's mode changed: %s -> %s" % (
                        before[real_name]["mode"], after.get(real_name, {}).get("mode")))
                case["lost"] += diff_snap(before, after, allowed_changes=(real_name,))
            else:
                case["other"].append("exit %s: %s" % (r["rc"], r["stderr"].strip()[-200:]))
                case["lost"] += diff_snap(before, after)
            c.record(case)
        # -o through a link to an existing file, with --force
        d = self.fresh("force through symlink")
        self.put(d, "in.obj", self.mesh)
        self.put(d, "real.obj", b"old result\n", 0o640)
        os.symlink("real.obj", os.path.join(d, "out.obj"))
        case = c.new_case("files", "-o a symbolic link to an existing file, --force", [c.rel(d)])
        before = snapshot(d)
        r = self.run(case, d, ["in.obj", "-o", "out.obj", "--force", "--device", "reference", "-q"])
        after = snapshot(d)
        if r["rc"] == 0:
            if after.get("out.obj") != before["out.obj"]:
                case["lost"].append("out.obj is no longer the symbolic link: %s" % after.get("out.obj"))
            self.smoothed_ok(case, d, "real.obj")
            case["lost"] += diff_snap(before, after, allowed_changes=("real.obj",))
        else:
            case["other"].append("exit %s: %s" % (r["rc"], r["stderr"].strip()[-200:]))
        c.record(case)
        # dangling links and links to directories: never written
        for force in [False, True]:
            for kind in ["dangling", "dangling into missing folder", "to a directory", "to /dev/null"]:
                d = self.fresh("symlink %s force %s" % (kind, force))
                self.put(d, "in.obj", self.mesh)
                if kind == "dangling":
                    os.symlink("missing.obj", os.path.join(d, "out.obj"))
                elif kind == "dangling into missing folder":
                    os.symlink("nowhere/missing.obj", os.path.join(d, "out.obj"))
                elif kind == "to a directory":
                    os.makedirs(os.path.join(d, "adir"))
                    self.put(d, "adir/keep.txt", b"keep\n")
                    os.symlink("adir", os.path.join(d, "out.obj"))
                else:
                    os.symlink("/dev/null", os.path.join(d, "out.obj"))
                case = c.new_case("files", "-o a symbolic link %s%s" % (kind, " with --force" if force else ""),
                                  [c.rel(d)])
                before = snapshot(d)
                dn0 = os.stat("/dev/null")
                r = self.run(case, d, ["in.obj", "-o", "out.obj", "--device", "reference", "-q"] +
                             (["--force"] if force else []))
                if r["rc"] == 0:
                    case["lost"].append("exit 0: a link %s was written" % kind)
                elif r["rc"] != 2 and not r["timeout"] and not c.crash_of(r):
                    case["other"].append("exit %s (2 expected)" % r["rc"])
                case["lost"] += diff_snap(before, snapshot(d))
                dn1 = os.stat("/dev/null")
                if (dn0.st_ino, dn0.st_mode) != (dn1.st_ino, dn1.st_mode):
                    case["lost"].append("/dev/null was replaced")
                c.record(case)

    def directories(self):
        c = self.c
        # a read-only folder (as another user when running as root: root writes anywhere)
        for mode in [0o555, 0o755]:
            d = self.fresh("read-only folder %o" % mode)
            self.put(d, "in.obj", self.mesh, 0o644)
            ro = os.path.join(d, "ro")
            os.makedirs(ro)
            self.put(ro, "keep.obj", b"keep\n")
            os.chmod(ro, mode)
            prefix = None
            who = "this user"
            if self.as_root:
                if not self.setpriv:
                    os.chmod(ro, 0o755)
                    c.notes.append("files: read-only folder skipped (root without setpriv)")
                    continue
                os.chmod(d, 0o755)
                prefix = [self.setpriv, "--reuid", "1234", "--regid", "1234", "--clear-groups"]
                who = "uid 1234"
            elif mode == 0o755:
                continue
            case = c.new_case("files", "-o into a folder %s may not write (%04o, root-owned)" % (who, mode),
                              [c.rel(d)])
            before = snapshot(d)
            r = self.run(case, d, ["in.obj", "-o", "ro/out.obj", "--device", "reference", "-q"], prefix=prefix)
            if r["rc"] == 0:
                case["wrong"].append("exit 0 writing into a folder that may not be written")
            elif r["rc"] != 2 and not r["timeout"] and not c.crash_of(r):
                case["other"].append("exit %s (2 expected)" % r["rc"])
            case["lost"] += diff_snap(before, snapshot(d))
            os.chmod(ro, 0o755)
            c.record(case)
        for target in ["missing/out.obj", "missing/deeper/out.obj", "in.obj/out.obj"]:
            d = self.fresh("missing folder")
            self.put(d, "in.obj", self.mesh)
            case = c.new_case("files", "-o %s (the folder does not exist)" % target, [c.rel(d)])
            before = snapshot(d)
            r = self.run(case, d, ["in.obj", "-o", target, "--device", "reference", "-q"])
            if r["rc"] == 0:
                case["wrong"].append("exit 0 writing into a missing folder")
            elif r["rc"] != 2 and not r["timeout"] and not c.crash_of(r):
                case["other"].append("exit %s (2 expected)" % r["rc"])
            case["lost"] += diff_snap(before, snapshot(d))
            c.record(case)
        # an existing directory as the output
        for force in [False, True]:
            d = self.fresh("output is a directory")
            self.put(d, "in.obj", self.mesh)
            os.makedirs(os.path.join(d, "out.obj"))
            self.put(d, "out.obj/keep.txt", b"keep\n")
            case = c.new_case("files", "-o an existing directory%s" % (" --force" if force else ""), [c.rel(d)])
            before = snapshot(d)
            r = self.run(case, d, ["in.obj", "-o", "out.obj", "--device", "reference", "-q"] +
                         (["--force"] if force else []))
            if r["rc"] == 0:
                case["lost"].append("exit 0 writing onto a directory")
            case["lost"] += diff_snap(before, snapshot(d))
            c.record(case)

    def input_as_output(self):
        c = self.c
        d0 = self.fresh("input as output")
        for spelling in ["in.obj", "./in.obj", "ABS", "sub/../in.obj", "link.obj", "hard.obj"]:
            for force in [False, True]:
                d = self.fresh("input as output %s %s" % (spelling, force))
                p = self.put(d, "in.obj", self.mesh)
                os.makedirs(os.path.join(d, "sub"))
                os.symlink("in.obj", os.path.join(d, "link.obj"))
                os.link(p, os.path.join(d, "hard.obj"))
                target = p if spelling == "ABS" else spelling
                case = c.new_case("files", "-o %s (the input) without --in-place%s" % (
                    "an absolute path of the input" if spelling == "ABS" else spelling,
                    " --force" if force else ""), [c.rel(d)])
                before = snapshot(d)
                r = self.run(case, d, ["in.obj", "-o", target, "--device", "reference", "-q"] +
                             (["--force"] if force else []))
                after = snapshot(d)
                if after.get("in.obj", {}).get("sha256") != before["in.obj"]["sha256"]:
                    case["lost"].append("the input in.obj was changed")
                if r["rc"] == 0 and spelling == "hard.obj" and force:
                    # another name of the input's file: replacing that name is allowed, the input stays
                    self.smoothed_ok(case, d, "hard.obj")
                    case["lost"] += diff_snap(before, after, allowed_changes=("hard.obj",))
                elif r["rc"] == 0:
                    case["lost"].append("exit 0: the input was given as the output without --in-place")
                    case["lost"] += diff_snap(before, after)
                else:
                    if r["rc"] != 2 and not r["timeout"] and not c.crash_of(r):
                        case["other"].append("exit %s (2 expected)" % r["rc"])
                    case["lost"] += diff_snap(before, after)
                c.record(case)
        shutil.rmtree(d0)
        # --confidence naming the input, --in-place with -o, noise onto its input
        for label, args in [
                ("--confidence naming the input", ["in.obj", "-o", "new.obj", "--confidence", "in.obj"]),
                ("--confidence naming the input --force", ["in.obj", "-o", "new.obj", "--confidence", "in.obj", "--force"]),
                ("--confidence naming the output", ["in.obj", "-o", "new.obj", "--confidence", "new.obj"]),
                ("--in-place with -o", ["in.obj", "--in-place", "-o", "new.obj"]),
                ("--in-place with --confidence naming the input", ["in.obj", "--in-place", "--confidence", "in.obj"]),
                ("noise onto its input", ["noise", "in.obj", "in.obj", "--sigma", "0.1"]),
                ("noise onto its input --force", ["noise", "in.obj", "in.obj", "--sigma", "0.1", "--force"]),
                ("render onto its input --force", ["render", "in.obj", "-o", "in.obj", "--force", "--size", "32x32"])]:
            d = self.fresh(label)
            self.put(d, "in.obj", self.mesh)
            case = c.new_case("files", label, [c.rel(d)])
            before = snapshot(d)
            extra = ["--device", "reference"] if args[0] == "in.obj" else []
            r = self.run(case, d, args + extra)
            after = snapshot(d)
            if after.get("in.obj", {}).get("sha256") != before["in.obj"]["sha256"]:
                case["lost"].append("the input in.obj was changed")
            if r["rc"] == 0 and label != "--confidence naming the output":
                case["lost"].append("exit 0 (a refusal expected)")
            if r["rc"] == 0 and label == "--confidence naming the output":
                case["wrong"].append("exit 0 with the result and the confidence in one file")
            if r["rc"] not in (0, 2) and not r["timeout"] and not c.crash_of(r):
                case["other"].append("exit %s (2 expected)" % r["rc"])
            if r["rc"] != 0:
                case["lost"] += diff_snap(before, after)
            c.record(case)

    def writer_refusal(self):
        c = self.c
        # a result binary STL cannot hold (beyond float32): no file, no temporary
        tv = [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1e39)]
        for ext, args in [(".stl", []), (".stl", ["--ascii"]), (".ply", [])]:
            d = self.fresh("unwritable result " + ext)
            self.put(d, "in.obj", obj_text(tv, TETRA_FACES))
            case = c.new_case("files", "tetrahedron to 1e39 written as %s %s" % (ext, " ".join(args)), [c.rel(d)])
            before = snapshot(d)
            r = self.run(case, d, ["in.obj", "-o", "out" + ext, "--device", "reference", "-q"] + args)
            after = snapshot(d)
            if r["rc"] == 0:
                self.smoothed_ok(case, d, "out" + ext, count=4 if ext == ".ply" else 12)
                case["lost"] += diff_snap(before, after, allowed_new=("out" + ext,))
            else:
                if ext == ".ply" or "--ascii" in args:
                    case["other"].append("exit %s for a result the format can hold: %s" % (
                        r["rc"], r["stderr"].strip()[-200:]))
                case["lost"] += diff_snap(before, after)
            c.record(case)

    def long_names(self):
        c = self.c
        for length in list(range(245, 257)):
            for mode in ["-o", "--in-place", "noise"]:
                if mode != "-o" and length not in (250, 255, 256):
                    continue
                d = self.fresh("name %d %s" % (length, mode))
                name = "n" * (length - 4) + ".obj"
                if mode == "--in-place":
                    if length > 255:
                        continue
                    self.put(d, name, self.mesh)
                    args = [name, "--in-place", "--device", "reference", "-q"]
                else:
                    self.put(d, "in.obj", self.mesh)
                    args = (["in.obj", "-o", name, "--device", "reference", "-q"] if mode == "-o"
                            else ["noise", "in.obj", name, "--sigma", "0.1", "-q"])
                case = c.new_case("files", "%s with a %d-byte file name" % (mode, length), [c.rel(d)])
                before = snapshot(d)
                r = self.run(case, d, args)
                after = snapshot(d)
                if length <= 255:
                    if r["rc"] != 0:
                        case["other"].append("exit %s for a %d-byte name (the system allows 255): %s" % (
                            r["rc"], length, r["stderr"].strip()[-200:]))
                        case["lost"] += diff_snap(before, after)
                    else:
                        self.smoothed_ok(case, d, name, original=self.mesh if mode != "-o" else None)
                        case["lost"] += diff_snap(before, after, allowed_changes=(name,), allowed_new=(name,))
                else:
                    if r["rc"] == 0:
                        case["wrong"].append("exit 0 for a %d-byte name, longer than the system allows" % length)
                    elif r["rc"] != 2 and not r["timeout"] and not c.crash_of(r):
                        case["other"].append("exit %s (2 expected: an output that may not be written)" % r["rc"])
                    case["lost"] += diff_snap(before, after)
                c.record(case)

    def races(self, count):
        c = self.c
        v, f = noisy_grid(30, seed=c.seed + 6)
        racers = 4
        inputs = []
        d = self.fresh("race inputs")
        for i in range(racers):
            vv, _ = noisy_grid(30, seed=c.seed + 100 + i)
            self.put(d, "in%d.obj" % i, obj_text(vv, f, num=fmt_fixed))
            c.run(["in%d.obj" % i, "-o", "solo%d.obj" % i, "--device", "reference", "-q", "--force"], cwd=d)
            with open(os.path.join(d, "solo%d.obj" % i), "rb") as fh:
                inputs.append(fh.read())
        for k in range(count):
            rd = self.fresh("race %d" % k)
            for i in range(racers):
                shutil.copy(os.path.join(d, "in%d.obj" % i), os.path.join(rd, "in%d.obj" % i))
            case = c.new_case("files", "race %d: %d runs write the same new out.obj without --force" % (k, racers),
                              [c.rel(rd)])
            before = snapshot(rd)
            procs = []
            argvs = []
            for i in range(racers):
                argv = [c.binary, "in%d.obj" % i, "-o", "out.obj", "--device", "reference", "-q"]
                argvs.append(argv)
                procs.append(subprocess.Popen(argv, cwd=rd, env=c.env, stdout=subprocess.PIPE,
                                              stderr=subprocess.PIPE))
            results = []
            for i, p in enumerate(procs):
                try:
                    so, se = p.communicate(timeout=120)
                except subprocess.TimeoutExpired:
                    p.kill()
                    so, se = p.communicate()
                results.append((p.returncode, se.decode("utf-8", "replace")))
                fake = {"argv": argvs[i], "env": {}, "cwd": rd, "rc": p.returncode, "timeout": False,
                        "stdout": "", "stderr": se.decode("utf-8", "replace"), "seconds": 0, "limit": 120}
                c.attach(case, fake, primary=(i == 0))
            with c.lock:
                c.process_runs += racers
            winners = [i for i, (rc, _) in enumerate(results) if rc == 0]
            case["rc"] = [rc for rc, _ in results]
            after = snapshot(rd)
            if len(winners) != 1:
                (case["lost"] if len(winners) > 1 else case["other"]).append(
                    "%d runs exited 0 (exactly one expected): exits %s" % (len(winners), case["rc"]))
            for i, (rc, se) in enumerate(results):
                if rc not in (0, 2) and rc is not None and rc >= 0 and rc < 128:
                    case["other"].append("racer %d exit %s: %s" % (i, rc, se.strip()[-200:]))
                if rc == 2 and "exist" not in se:
                    case["other"].append("racer %d exit 2 without saying the file exists: %s" % (i, se.strip()[-200:]))
            if "out.obj" not in after:
                case["lost"].append("no out.obj after the race")
            else:
                with open(os.path.join(rd, "out.obj"), "rb") as fh:
                    got = fh.read()
                match = [i for i in range(racers) if inputs[i] == got]
                if winners and len(winners) == 1 and match != [winners[0]]:
                    case["lost"].append("out.obj is not the winner's result (racer %d won; the file matches %s)" % (
                        winners[0], match or "none of them"))
            case["lost"] += diff_snap(before, after, allowed_new=("out.obj",))
            c.record(case)

    def kills(self, trials):
        c = self.c
        n = 260
        v, f = noisy_grid(n, seed=c.seed + 7)
        big = obj_text(v, f, num=fmt_fixed)
        d0 = self.fresh("kill big input")
        self.put(d0, "big.obj", big)
        rng = random.Random("%d-kill" % c.seed)
        base_args = ["--device", "reference", "--sigma-f", "1", "-q"]

        def watch(p, outdir, exclude):
            """Seconds from start to the first open file in outdir (the temporary), None if none seen."""
            t0 = time.monotonic()
            while p.poll() is None:
                try:
                    for fd in os.listdir("/proc/%d/fd" % p.pid):
                        try:
                            t = os.readlink("/proc/%d/fd/%s" % (p.pid, fd))
                        except OSError:
                            continue
                        if t.startswith(outdir + "/") and not t.startswith(exclude):
                            return time.monotonic() - t0
                except OSError:
                    return None
                time.sleep(0.0005)
            return None

        # calibration: when does the write start and how long does it take
        cal = self.fresh("kill calibration")
        shutil.copy(os.path.join(d0, "big.obj"), os.path.join(cal, "big.obj"))
        argv = [c.binary, "big.obj", "-o", "out.ply", "--ascii"] + base_args
        t0 = time.monotonic()
        p = subprocess.Popen(argv, cwd=cal, env=c.env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        started = watch(p, cal, os.path.join(cal, "big.obj"))
        p.wait()
        total = time.monotonic() - t0
        with c.lock:
            c.process_runs += 1
        write_time = (total - started) if started is not None else None
        c.notes.append("files: kill tests on a %dx%d grid (%d vertices, %.1f MB OBJ): run %.2f s, the write"
                       " (temporary open to exit) %.2f s" % (n, n, n * n, len(big) / 1e6, total,
                                                              write_time if write_time else float("nan")))
        plan = []
        for t in range(trials):
            plan.append(("-o", signal.SIGKILL, t))
        for t in range(max(2, trials // 2)):
            plan.append(("--in-place", signal.SIGKILL, t))
        for t in range(2):
            plan.append(("-o", signal.SIGINT, t))
            plan.append(("-o", signal.SIGTERM, t))
            plan.append(("--in-place", signal.SIGINT, t))
        landed = 0
        for mode, sig, t in plan:
            d = self.fresh("kill %s %s %d" % (mode, sig.name, t))
            shutil.copy(os.path.join(d0, "big.obj"), os.path.join(d, "big.obj"))
            os.chmod(os.path.join(d, "big.obj"), 0o640)
            self.put(d, "other.txt", b"unrelated file\n")
            if mode == "-o":
                argv = [c.binary, "big.obj", "-o", "out.ply", "--ascii"] + base_args
            else:
                argv = [c.binary, "big.obj", "--in-place"] + base_args
            case = c.new_case("files", "%s during the write (%s, trial %d)" % (sig.name, mode, t), [c.rel(d)])
            case["commands"].append("(cd %s && %s) & sleep until it opens a file in the folder, +%s, kill -%s" % (
                shlex.quote(c.rel(d)), shlex.join(argv), "random fraction of the write time", sig.name))
            before = snapshot(d)
            p = subprocess.Popen(argv, cwd=d, env=c.env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
            with c.lock:
                c.process_runs += 1
            seen = watch(p, d, os.path.join(d, "big.obj"))
            if seen is not None and write_time:
                time.sleep(rng.uniform(0.0, 0.9 * write_time))
            alive = p.poll() is None
            if alive:
                p.send_signal(sig)
            _, se = p.communicate()
            se = se.decode("utf-8", "replace")
            case["rc"] = p.returncode
            case["stderr"] = se[-600:]
            if alive and seen is not None:
                landed += 1
                case["name"] += " [landed during the write]"
            else:
                case["name"] += " [%s]" % ("process ended before the signal" if not alive else
                                           "no temporary seen before the signal")
            if SANITIZER_RE.search(se):
                case["crash"].append("sanitizer report: %s" % se[-300:])
            after = snapshot(d)
            if mode == "-o":
                if "out.ply" in after:
                    # renamed in before the signal: it must be whole
                    self.smoothed_ok(case, d, "out.ply", count=n * n)
                case["lost"] += diff_snap(before, after, allowed_new=("out.ply",))
            else:
                with open(os.path.join(d, "big.obj"), "rb") as fh:
                    now = fh.read()
                if now != big:
                    self.smoothed_ok(case, d, "big.obj", count=n * n)
                    if after["big.obj"]["mode"] != before["big.obj"]["mode"]:
                        case["lost"].append("big.obj mode %s became %s" % (before["big.obj"]["mode"],
                                                                             after["big.obj"]["mode"]))
                case["lost"] += diff_snap(before, after, allowed_changes=("big.obj",))
            c.record(case)
        c.notes.append("files: %d of %d signals landed while the output was open" % (landed, len(plan)))


def category_files(c, races, kills):
    s = FileScenarios(c)
    s.existing_output()
    s.in_place_modes()
    s.symlinks()
    s.directories()
    s.input_as_output()
    s.writer_refusal()
    s.long_names()
    s.races(races)
    s.kills(kills)


# ------------------------------------------------------------------------------------------------
# 6. Bad arguments and environment
# ------------------------------------------------------------------------------------------------

JUNK = ["", "junk", "nan", "NaN", "-nan", "1e400", "-1e400", "1x", "1.2.3", "1e", " ", "1 2", "+", "-", ".",
        "--", "0x", "\u0661", "2,5"]
INT_JUNK = ["1.5", "-1", "4294967297", "18446744073709551617", "99999999999999999999", "1e400", "nan", "inf"]


def option_table():
    """option -> (context args, invalid values, values that may be accepted or refused)."""
    bil = ["--normals", "bilateral"]
    return {
        "--sigma-f": ([], JUNK + ["-1", "0", "-0", "1e-400", "-inf"], ["inf", "1e308", "1e-300", "1e6"]),
        "--sigma-g": ([], JUNK + ["-1", "0", "-0", "1e-400", "-inf"], ["inf", "1e308", "1e-300"]),
        "--cutoff": ([], JUNK + ["0", "-1", "5.000001", "6", "inf", "-inf", "1e-400"], ["5", "1e-300"]),
        "--normal-sigma-s": (bil, JUNK + ["0", "-1", "-inf", "1e-400"], ["inf", "1e308", "1e-300"]),
        "--normal-sigma-n": (bil, JUNK + ["0", "-1", "2.000001", "3", "inf", "-inf"], ["2", "1e-300"]),
        "--normal-iterations": (bil, JUNK + INT_JUNK, ["0", "0x10", "1e1", "+3", "007"]),
        "--passes": ([], JUNK + INT_JUNK + ["0"], ["0x2", "1e1", "+2"]),
        "--pass-confidence": (["--passes", "2"], JUNK + ["-0.5", "1.000001", "inf", "-inf"], ["0", "1", "1e-300"]),
        "--sigma-c": (["--best"], JUNK + ["0", "-1", "-inf", "1e-400"], ["inf", "1e308", "1e-300"]),
        "--iterations": (["--method", "taubin"], JUNK + INT_JUNK, ["0", "0x10", "1e1"]),
        "--lambda": (["--method", "laplacian"], JUNK + ["inf", "-inf"], ["0", "-1", "2", "1e308", "-1e308"]),
        "--mu": (["--method", "taubin"], JUNK + ["inf", "-inf"], ["0", "1", "-1e308", "1e308"]),
        "--memory-budget": (["--device", "cpu"], JUNK + ["0", "-1", "-0", "1Q", "18446744073709551616",
                                                         "99999999999999999999G", "1e400G", "inf", "0M"],
                            ["1", "1K", "256M", "1e9", "0x100000"]),
    }


def category_arguments(c):
    v, f = noisy_grid(5, seed=c.seed + 8)
    # vertex colours for --sigma-c
    lines = ["v %s %s %s %.3f %.3f %.3f" % (fmt_fixed(x), fmt_fixed(y), fmt_fixed(z), (i % 3) / 2, 0.5, 0.2)
             for i, (x, y, z) in enumerate(v)]
    lines += ["f %d %d %d" % (a + 1, b + 1, cc + 1) for a, b, cc in f]
    c.write("inputs/arguments/in.obj", ("\n".join(lines) + "\n").encode())
    inrel = "inputs/arguments/in.obj"
    nverts = len(v)
    jobs = []
    for opt, (ctx, bad, maybe) in option_table().items():
        if opt == "--memory-budget" and not c.have_cpu:
            ctx = ["--device", "reference"]
        for val in bad:
            jobs.append(("invalid", opt, ctx, [opt, val]))
        for val in maybe:
            jobs.append(("either", opt, ctx, [opt, val]))
        jobs.append(("invalid", opt, ctx, [opt]))  # missing value at the end
        if opt != "--memory-budget":
            jobs.append(("invalid", opt, ctx, [opt, "--quiet"]))  # an option taken as the value
    # 'junk' is bad usage (2); a well-formed name no device has may also be a device failure (3)
    for val in ["junk", "", "99:99", "0:99", "gpu-that-does-not-exist", "-1", "referenc"]:
        jobs.append(({"junk": "invalid", "": "either"}.get(val, "invalid23"), "--device", [], ["--device", val]))
    for opt in ["--method", "--normals", "--influence"]:
        for val in ["junk", "", "GAUSSIAN", "robust "]:
            jobs.append(("invalid", opt, [], [opt, val]))
        jobs.append(("invalid", opt, [], [opt]))
    for args in [["--bogus"], ["-x"], ["--sigma_f", "2"], ["--SIGMA-F", "2"], ["---sigma-f", "2"], ["-"],
                 ["--sigma-f=2"], ["--", "--sigma-f"], ["--json", "--quiet", "--stats", "--bogus"], ["-oo"]]:
        jobs.append(("invalid" if args != ["--sigma-f=2"] else "either", "syntax", [], args))
    # structure: no input, two inputs, no output, -o without value
    structure = [
        ("no input", ["-o", "OUT"]),
        ("no output", [inrel]),
        ("two inputs", [inrel, inrel, "-o", "OUT"]),
        ("-o without value", [inrel, "-o"]),
        ("missing input file", ["inputs/arguments/missing.obj", "-o", "OUT"]),
        ("input is a directory", ["inputs/arguments", "-o", "OUT"]),
        ("empty input name", ["", "-o", "OUT"]),
        ("empty output name", [inrel, "-o", ""]),
        ("output without extension (either)", [inrel, "-o", "OUTNOEXT"]),
        ("output with unknown extension (either)", [inrel, "-o", "OUT.xyz"]),
        ("compare with one file", ["compare", inrel]),
        ("compare with a bogus option", ["compare", inrel, inrel, "--bogus"]),
        ("compare with three files", ["compare", inrel, inrel, inrel]),
        ("noise without --sigma", ["noise", inrel, "NOISEOUT"]),
        ("noise without output", ["noise", inrel, "--sigma", "0.1"]),
        ("render without -o", ["render", inrel]),
        ("render without input", ["render", "-o", "PNGOUT"]),
        ("unknown subcommand-like word", ["smooth", inrel, "-o", "OUT"]),
    ]
    for label, args in structure:
        jobs.append(("either" if "(either)" in label else "invalid", "structure: " + label, [], args))
    # noise, render and compare options
    for val in JUNK + ["-1", "-inf", "inf", "1e400", "1000000.1", "1e7", "1e308"]:
        jobs.append(("invalid", "noise --sigma", [], ["noise", inrel, "NOISEOUT", "--sigma", val]))
    for val in JUNK + ["0", "-0.1", "1.000001", "inf", "1e-400"]:
        jobs.append(("invalid", "noise --impulsive", [], ["noise", inrel, "NOISEOUT", "--sigma", "0.1",
                                                          "--impulsive", val]))
    for val in ["-1", "18446744073709551616", "1e400", "junk", "", "1.5", "0x", "99999999999999999999"]:
        jobs.append(("invalid", "noise --seed", [], ["noise", inrel, "NOISEOUT", "--sigma", "0.1", "--seed", val]))
    for val in ["0", "18446744073709551615", "0x10"]:
        jobs.append(("either", "noise --seed", [], ["noise", inrel, "NOISEOUT", "--sigma", "0.1", "--seed", val]))
    for val in ["junk", "", "NORMAL"]:
        jobs.append(("invalid", "noise --direction", [], ["noise", inrel, "NOISEOUT", "--sigma", "0.1",
                                                          "--direction", val]))
    for val in ["0x0", "0x64", "64x0", "-5x5", "junk", "", "64", "64x", "x64", "1e400x1", "64x64x64",
                "99999999999999999999x1", "nanxnan"]:
        jobs.append(("invalid", "render --size", [], ["render", inrel, "-o", "PNGOUT", "--size", val]))
    for opt, vals in [("--azimuth", ["nan", "junk", "", "1e400", "inf"]),
                      ("--elevation", ["90", "-90", "91", "nan", "junk", "", "1e400", "inf"])]:
        for val in vals:
            jobs.append(("invalid", "render " + opt, [], ["render", inrel, "-o", "PNGOUT", "--size", "32x32", opt, val]))
    # environment
    env_jobs = []
    for val in ["junk", "0", "-1", "1Q", "1e400", "nan", "18446744073709551616", "0M", "256M junk"]:
        env_jobs.append(("invalid", {"RSMOOTH_MEMORY_BUDGET": val}, ["--device", "cpu" if c.have_cpu else "reference"]))
    for val in ["", " 256M"]:
        env_jobs.append(("either", {"RSMOOTH_MEMORY_BUDGET": val}, ["--device", "cpu" if c.have_cpu else "reference"]))
    for val in ["junk", "99:99", "gpu-that-does-not-exist", "-1"]:
        env_jobs.append(("invalid" if val == "junk" else "invalid23", {"RSMOOTH_DEVICE": val}, []))
    env_jobs.append(("either", {"RSMOOTH_DEVICE": ""}, []))
    for val in ["0", "9", "junk", "-1", "99999999999"]:
        env_jobs.append(("either", {"RSMOOTH_CELLS_PER_REACH": val}, ["--device", "cpu" if c.have_cpu else "reference"]))
    for val in ["0", "junk", "-1", "99999999999"]:
        env_jobs.append(("either", {"RSMOOTH_HOST_THREADS": val}, []))

    def finish(case, r, expect, outs, label):
        if r["rc"] == 0:
            if expect == "invalid":
                case["wrong"].append("exit 0 for an invalid argument (%s); exit 2 with a message expected" % label)
            for o in outs:
                if os.path.exists(c.path(o)) and o.endswith((".obj", ".ply", ".off", ".stl")):
                    c.reread(case, o, nverts)
        elif r["rc"] == 2 or (r["rc"] == 3 and expect == "invalid23"):
            if not r["stderr"].strip():
                case["other"].append("exit %s without a message" % r["rc"])
        elif r["timeout"] or c.crash_of(r):
            pass
        elif expect == "either" and r["rc"] in (1, 3):
            if not r["stderr"].strip():
                case["other"].append("exit %s without a message" % r["rc"])
        else:
            case["other"].append("exit %s (2 expected for bad usage): %s" % (r["rc"], r["stderr"].strip()[-200:]))
        if r["rc"] != 0:
            for o in outs:
                if os.path.exists(c.path(o)):
                    case["other"].append("exit %s but %s was written" % (r["rc"], o))

    def one(job_i):
        i, (expect, label, ctx, args) = job_i
        out = "outputs/arguments/out_%04d.obj" % i
        noise_out = "outputs/arguments/noise_%04d.obj" % i
        png = "outputs/arguments/render_%04d.png" % i
        subst = {"OUT": out, "NOISEOUT": noise_out, "PNGOUT": png,
                 "OUTNOEXT": "outputs/arguments/out_%04d" % i, "OUT.xyz": "outputs/arguments/out_%04d.xyz" % i}
        args = [subst.get(a, a) for a in args]
        if label.startswith(("structure", "noise", "render")):
            argv = args
            outs = [o for o in subst.values() if o in args]
        else:
            argv = [inrel, "-o", out, "-q"] + (["--device", "reference"] if "--device" not in ctx and
                                               "--device" not in args else []) + ctx + args
            outs = [out]
        case = c.new_case("arguments", "%s %s" % (label, " ".join(shlex.quote(a) for a in args[-2:])
                                                  if not label.startswith("structure") else ""),
                          [inrel])
        timeout = 20
        r = c.attach(case, c.run(argv, timeout=timeout))
        finish(case, r, expect, outs, label + " " + shlex.join(args))
        c.record(case)

    def env_one(job_i):
        i, (expect, env, ctx) = job_i
        out = "outputs/arguments/env_%04d.obj" % i
        k, val = list(env.items())[0]
        case = c.new_case("arguments", "%s=%r" % (k, val), [inrel])
        r = c.attach(case, c.run([inrel, "-o", out, "-q"] + ctx, env=env, timeout=20))
        if k in ("RSMOOTH_MEMORY_BUDGET", "RSMOOTH_DEVICE") and r["rc"] == 2 and k not in r["stderr"]:
            case["other"].append("the refusal does not name %s: %s" % (k, r["stderr"].strip()[-200:]))
        finish(case, r, expect, [out], "%s=%r" % (k, val))
        c.record(case)

    c.pool_map(one, list(enumerate(jobs)))
    c.pool_map(env_one, list(enumerate(env_jobs)))

    # rsmooth noise at extreme sigma and scale: never writes what rsmooth then refuses to read
    njobs = []
    for k in [-300, -150, -36, 0, 36, 100, 140, 148]:
        for sigma in ["0", "1e-300", "1e-10", "1", "1e3", "1e5", "1e6"]:
            for ext, extra in [(".obj", []), (".ply", []), (".stl", []), (".off", ["--direction", "random"])]:
                njobs.append((k, sigma, ext, extra))
    for k in [0, 148]:
        njobs.append((k, "1e6", ".ply", ["--impulsive", "0.5"]))
        njobs.append((k, "1", ".stl", ["--ascii"]))
    nv_base, nf_base = noisy_grid(5, seed=c.seed + 9)
    for k in sorted(set(j[0] for j in njobs)):
        s = float("1e%d" % k)
        c.write("inputs/arguments/noise_in_1e%+04d.obj" % k, obj_text([(x * s, y * s, z * s) for x, y, z in nv_base],
                                                                     nf_base))

    def noise_one(job_i):
        i, (k, sigma, ext, extra) = job_i
        s = float("1e%d" % k)
        rel = "inputs/arguments/noise_in_1e%+04d.obj" % k
        out = "outputs/arguments/noised_%04d%s" % (i, ext)
        case = c.new_case("arguments", "noise at scale 1e%d --sigma %s -> %s %s" % (k, sigma, ext, " ".join(extra)),
                          [rel])
        r = c.attach(case, c.run(["noise", rel, out, "--sigma", sigma, "--seed", str(i), "-q"] + extra))
        if r["rc"] == 0:
            m = c.reread(case, out, len(nv_base) if ext != ".stl" else 3 * len(nf_base))
            if m is not None:
                src = [(x * s, y * s, z * s) for x, y, z in nv_base]
                if ext == ".stl":
                    src = [src[j] for f in nf_base for j in f]
                mel = mean_edge(nv_base, nf_base)
                sig = float(sigma)
                worst = 0.0
                for a, b in zip(src, m.verts):
                    d = math.sqrt(sum(((a[q] - b[q]) / s) ** 2 for q in range(3)))
                    allow = 8.0 * sig * mel + 1e-6 * max(abs(x / s) for x in a) + 1e-9
                    worst = max(worst, d / allow)
                if worst > 1.0:
                    case["wrong"].append("a vertex moved %.3g times the most --sigma %s allows (8 sigma plus float"
                                         " rounding; e.g. vertex 0 %r -> %r)" % (worst, sigma, src[0], m.verts[0]))
                r2 = c.attach(case, c.run([out, "-o", out + ".smoothed.ply", "--device", "reference", "-q"]),
                              primary=False)
                if r2["rc"] not in (0,) and not c.crash_of(r2):
                    case["wrong"].append("rsmooth noise wrote %s (exit 0), which rsmooth then refuses: exit %s: %s" % (
                        out, r2["rc"], r2["stderr"].strip()[-200:]))
        elif r["rc"] == 2 or (r["rc"] == 1 and "cannot be written" in r["stderr"]):
            # 1: the output format cannot hold the values (binary STL's float32): refused, nothing written
            if not r["stderr"].strip():
                case["other"].append("exit %s without a message" % r["rc"])
            elif r["rc"] == 2 and "beyond" not in r["stderr"]:
                case["other"].append("refused noise on a mesh at a supported scale (--sigma %s in [0, 1e6]): %s" % (
                    sigma, r["stderr"].strip()[-200:]))
        elif not r["timeout"] and not c.crash_of(r):
            case["other"].append("exit %s: %s" % (r["rc"], r["stderr"].strip()[-200:]))
        if r["rc"] != 0 and os.path.exists(c.path(out)):
            case["lost"].append("exit %s but %s was left behind" % (r["rc"], out))
        c.record(case)

    c.pool_map(noise_one, list(enumerate(njobs)))


# ------------------------------------------------------------------------------------------------
# The table
# ------------------------------------------------------------------------------------------------

def normalise(reason):
    r = re.sub(r"outputs?/[^\s:]+|inputs/[^\s:]+|files/[^\s:)]+", "FILE", reason)
    r = re.sub(r"\d+(\.\d+)?(e[+-]?\d+)?", "N", r)
    return r[:160]


def summarise(c):
    stats = {}
    for key, _ in CATEGORIES:
        stats[key] = {col: 0 for col in COLUMNS}
        stats[key]["failing"] = []
    for case in c.cases:
        st = stats[case["category"]]
        st["tried"] += 1
        bad = False
        for col in COLUMNS[1:]:
            key = "crash" if col == "crashes" else col
            if case[key]:
                st[col] += 1
                bad = True
        if bad:
            st["failing"].append(case)
    return stats


def render_table(c, stats, seconds):
    lines = []
    head = "| category | cases tried | crashes | wrong answers with exit 0 | data lost | unlocated errors | other defects |"
    lines.append(head)
    lines.append("| --- | ---: | ---: | ---: | ---: | ---: | ---: |")
    tot = {col: 0 for col in COLUMNS}
    for key, title in CATEGORIES:
        st = stats[key]
        lines.append("| %s | %s |" % (title, " | ".join(str(st[col]) for col in COLUMNS)))
        for col in COLUMNS:
            tot[col] += st[col]
    lines.append("| **all** | %s |" % " | ".join("**%d**" % tot[col] for col in COLUMNS))
    lines.append("")
    lines.append("%d cases, %d runs of the command, %.0f s, %d jobs at once; binary %s" % (
        tot["tried"], c.process_runs, seconds, c.jobs, c.binary))
    for n in c.notes:
        lines.append("- " + n)
    for e in c.script_errors:
        lines.append("- SCRIPT ERROR (a bug of this script, not of rsmooth): " + e.replace("\n", " | "))
    return lines, tot


def render_failures(c, stats, limit):
    lines = []
    for key, title in CATEGORIES:
        failing = stats[key]["failing"]
        if not failing:
            continue
        lines.append("")
        lines.append("## %s: %d failing cases" % (title, len(failing)))
        groups = {}
        for case in failing:
            for col in ["crash", "wrong", "lost", "unlocated", "other"]:
                for why in case[col]:
                    groups.setdefault((col, normalise(why)), []).append(case)
        lines.append("By kind (count, column, reason pattern):")
        for (col, pat), cs in sorted(groups.items(), key=lambda kv: -len(kv[1])):
            lines.append("  %4d  %-9s %s" % (len(cs), col, pat))
        lines.append("Cases%s:" % ("" if len(failing) <= limit else " (first %d; all in campaign.json)" % limit))
        for case in failing[:limit]:
            lines.append("- %s" % case["name"])
            lines.append("    files: %s" % ", ".join(case["files"]))
            for cmd in case["commands"][:3]:
                lines.append("    command: %s" % cmd)
            lines.append("    exit: %s" % (case["rc"],))
            for col in ["crash", "wrong", "lost", "unlocated", "other"]:
                for why in case[col][:4]:
                    lines.append("    %s: %s" % (col, why.replace("\n", " | ")))
    return lines


def git_describe(path):
    try:
        return subprocess.run(["git", "-C", path, "describe", "--always", "--dirty"], capture_output=True,
                              text=True, timeout=10).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return ""


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("binary", help="the rsmooth command to test (e.g. build-campaign/rsmooth)")
    ap.add_argument("--out", default="out/campaign", help="output folder (emptied first; default out/campaign)")
    ap.add_argument("--jobs", type=int, default=2, help="runs at once (default 2)")
    ap.add_argument("--seed", type=int, default=12, help="seed of every generated input (default 12)")
    ap.add_argument("--only", default="", help="comma-separated categories: scale,truncation,corruption,bom,"
                                               "files,arguments (default all)")
    ap.add_argument("--cpu-every", type=int, default=15,
                    help="run every Nth truncation and corruption case on --device cpu (default 15; 0: never)")
    ap.add_argument("--mutants", type=int, default=130, help="corrupted files per format (default 130)")
    ap.add_argument("--races", type=int, default=20, help="concurrent-writer races (default 20)")
    ap.add_argument("--kills", type=int, default=6, help="kill -9 trials during a write (default 6)")
    ap.add_argument("--full", action="store_true", help="every prefix of every file (default: at most 300 each)")
    ap.add_argument("--list", type=int, default=30, help="failing cases printed per category (default 30)")
    args = ap.parse_args()

    if not os.access(args.binary, os.X_OK):
        sys.exit("hostile_campaign: %s is not an executable" % args.binary)
    out = os.path.abspath(args.out)
    marker = os.path.join(out, ".hostile_campaign")
    if os.path.exists(out) and os.listdir(out):
        if not os.path.exists(marker):
            sys.exit("hostile_campaign: %s exists and was not made by this script; give another --out" % out)
        for root, dirs, _ in os.walk(out):
            for dname in dirs:
                try:
                    os.chmod(os.path.join(root, dname), 0o755)
                except OSError:
                    pass
        shutil.rmtree(out)
    os.makedirs(out, exist_ok=True)
    open(marker, "w").close()
    for key, _ in CATEGORIES:
        os.makedirs(os.path.join(out, "outputs", key), exist_ok=True)
        os.makedirs(os.path.join(out, "inputs", key), exist_ok=True)
    c = Campaign(args.binary, out, max(1, args.jobs), args.seed, args.cpu_every, args.full)
    only = set(x.strip() for x in args.only.split(",") if x.strip())
    unknown = only - set(k for k, _ in CATEGORIES)
    if unknown:
        sys.exit("hostile_campaign: unknown categories %s" % ", ".join(sorted(unknown)))

    t0 = time.monotonic()
    ver = c.run(["--version"])
    devs = c.run(["--list-devices"])
    c.have_cpu = devs["rc"] == 0 and re.search(r"^\s*\d+:\d+\s+cpu\b", devs["stdout"] + devs["stderr"], re.M) is not None
    if c.have_cpu:
        # warm PoCL's cache once so parallel first runs do not all compile
        v, f = noisy_grid(3, seed=1)
        c.write("inputs/warm.obj", obj_text(v, f))
        w = c.run(["inputs/warm.obj", "-o", "outputs/warm.obj", "--device", "cpu", "-q", "--force"], timeout=300)
        if w["rc"] != 0:
            c.have_cpu = False
            c.notes.append("--device cpu failed on a trivial mesh (exit %s); OpenCL runs skipped: %s" % (
                w["rc"], w["stderr"].strip()[-200:]))
    else:
        c.notes.append("no OpenCL CPU device listed: every run uses --device reference")
    print("hostile campaign: %s (%s), out %s, OpenCL cpu %s" % (
        c.binary, ver["stdout"].strip() or ver["stderr"].strip(), out, "yes" if c.have_cpu else "no"), flush=True)
    timings = {}
    for key, title in CATEGORIES:
        if only and key not in only:
            continue
        t1 = time.monotonic()
        n0 = len(c.cases)
        if key == "scale":
            category_scale(c)
        elif key == "truncation":
            category_truncation(c)
        elif key == "corruption":
            category_corruption(c, args.mutants)
        elif key == "bom":
            category_bom(c)
        elif key == "files":
            category_files(c, args.races, args.kills)
        elif key == "arguments":
            category_arguments(c)
        timings[key] = time.monotonic() - t1
        print("  %-11s %5d cases in %6.1f s" % (key, len(c.cases) - n0, timings[key]), flush=True)
    seconds = time.monotonic() - t0
    stats = summarise(c)
    table, tot = render_table(c, stats, seconds)
    failures = render_failures(c, stats, args.list)
    text = "\n".join(["", "# rsmooth hostile campaign (issue 12 acceptance)", ""] + table + failures) + "\n"
    print(text)
    with open(os.path.join(out, "table.txt"), "w") as f:
        f.write(text)
    strip = lambda case: {k: v for k, v in case.items() if not k.startswith("_")}
    doc = {
        "binary": c.binary, "version": ver["stdout"].strip(), "git": git_describe(os.path.dirname(c.binary)),
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "seconds": round(seconds, 1), "category_seconds": {k: round(v, 1) for k, v in timings.items()},
        "process_runs": c.process_runs, "jobs": c.jobs, "seed": c.seed, "opencl_cpu": c.have_cpu,
        "working_directory": out, "notes": c.notes, "script_errors": c.script_errors,
        "totals": tot,
        "categories": {key: dict({col: stats[key][col] for col in COLUMNS}, title=title,
                                 failing=[strip(x) for x in stats[key]["failing"]])
                       for key, title in CATEGORIES},
    }
    with open(os.path.join(out, "campaign.json"), "w") as f:
        json.dump(doc, f, indent=1)
    with open(os.path.join(out, "cases.jsonl"), "w") as f:
        for case in c.cases:
            f.write(json.dumps(strip(case)) + "\n")
    failed = tot["crashes"] + tot["wrong"] + tot["lost"]
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
