"""OBJ vertices and triangles for the experiment scripts (numpy arrays): the one reader and writer
scripts/do_no_harm.py uses. Vertex order is kept; polygons are fanned; `f` indices may be negative (relative)."""
import numpy as np


def read_obj(path):
    """(vertices float64 (n, 3), faces int64 (m, 3), 0-based)."""
    vs, fs = [], []
    with open(path) as fh:
        for line in fh:
            if line.startswith("v "):
                p = line.split()
                vs.append((float(p[1]), float(p[2]), float(p[3])))
            elif line.startswith("f "):
                idx = [int(t.split("/")[0]) for t in line.split()[1:]]
                for k in range(1, len(idx) - 1):
                    fs.append((idx[0], idx[k], idx[k + 1]))
    v = np.array(vs, dtype=np.float64).reshape(-1, 3)
    f = np.array(fs, dtype=np.int64).reshape(-1, 3)
    return v, np.where(f < 0, f + len(v), f - 1)


def write_obj(path, v, f, digits=17):
    """Vertices with `digits` significant digits, then 1-based triangles."""
    form = "v %%.%dg %%.%dg %%.%dg\n" % (digits, digits, digits)
    with open(path, "w") as fh:
        fh.write("".join(form % tuple(p) for p in v))
        fh.write("".join("f %d %d %d\n" % (a + 1, b + 1, c + 1) for a, b, c in f))
