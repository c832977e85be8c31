"""Random CAD-like parts: a base body plus machined features.

A part is drawn from a numpy Generator only, so a part seed fixes it.
Every step is logged in a recipe (primitive, operation, sizes) that goes
to the manifest, so a strange training sample can be traced back.
"""

import numpy as np
from manifold3d import Manifold

import cad_primitives as prim

SEGMENT_CHOICES = (16, 24, 32, 48, 64, 96)
# Kept as manifold3d meshes it, a part needs fine circles to reach 2k+ faces.
DENSE_SEGMENT_CHOICES = (64, 96, 128, 192, 256)
BASES = ("block", "disc", "bracket")
FEATURES = ("boss", "hole", "pocket", "dome", "dimple", "ring", "groove",
            "rib", "side_hole")


class Recipe(list):
    """List of recipe steps with floats rounded for a readable manifest."""

    def log(self, op, primitive, **params):
        self.append({"op": op, "primitive": primitive,
                     **{k: _plain(v) for k, v in params.items()}})


def _plain(value):
    if isinstance(value, (float, np.floating)):
        return round(float(value), 4)
    if isinstance(value, (np.integer,)):
        return int(value)
    if isinstance(value, (list, tuple, np.ndarray)):
        return [_plain(v) for v in value]
    return value


class Footprint:
    """Where features may go: the top face at height z, rectangle or disc."""

    def __init__(self, z, centre, half=None, radius=None):
        self.z, self.centre, self.half, self.radius = z, centre, half, radius

    @property
    def scale(self):
        return self.radius if self.radius else float(min(self.half))

    def sample(self, rng, margin):
        if self.radius:
            r = max(self.radius - margin, 0.0) * np.sqrt(rng.random())
            t = rng.uniform(0, 2 * np.pi)
            offset = np.array([r * np.cos(t), r * np.sin(t)])
        else:
            room = np.maximum(np.asarray(self.half) - margin, 0.0)
            offset = rng.uniform(-room, room)
        return np.asarray(self.centre) + offset


def build_part(rng, segment_choices=SEGMENT_CHOICES):
    """Draw one part; returns (Manifold, recipe, segments).

    segments (circle resolution) sets the density of the CAD triangulation.
    """
    segments = int(rng.choice(segment_choices))
    recipe = Recipe()
    base = str(rng.choice(BASES))
    part, footprint = BASE_BUILDERS[base](rng, segments, recipe)
    for _ in range(int(rng.integers(1, 7))):
        feature = str(rng.choice(FEATURES))
        part = FEATURE_BUILDERS[feature](rng, part, footprint, segments,
                                         recipe)
    return part, recipe, segments


# ---- bases ---------------------------------------------------------------

def _block(rng, segments, recipe):
    size = np.array([rng.uniform(1.0, 2.0), rng.uniform(0.6, 1.5),
                     rng.uniform(0.2, 0.8)])
    edges = str(rng.choice(["sharp", "fillet_all", "fillet_vertical",
                            "chamfer"]))
    radius = rng.uniform(0.1, 0.45) * size.min()
    if edges == "fillet_all":
        part = prim.rounded_box(size, radius, segments)
    elif edges == "fillet_vertical":
        part = prim.slab(size, radius, segments)
    elif edges == "chamfer":
        part = prim.chamfered_box(size, radius, _random_edges(rng))
    else:
        part = prim.box(size)
    recipe.log("base", "box", size=size, edges=edges, edge_size=radius)
    return part, Footprint(_top(part), (0.0, 0.0), half=size[:2] / 2 - radius)


def _top(part):
    """The exact top height as built: profiles pass through Clipper's fixed
    precision, and features placed 1e-9 off a face leave sliver triangles."""
    return part.bounding_box()[5]


def _random_edges(rng):
    """A random subset (at least 4) of the 12 box edges."""
    all_edges = [(axis, s1, s2) for axis in range(3)
                 for s1 in (-1, 1) for s2 in (-1, 1)]
    keep = rng.permutation(12)[:int(rng.integers(4, 13))]
    return [all_edges[k] for k in sorted(keep)]


def _disc(rng, segments, recipe):
    radius, height = rng.uniform(0.5, 1.0), rng.uniform(0.2, 0.8)
    edge = str(rng.choice(["sharp", "chamfer", "fillet"]))
    edge_size = rng.uniform(0.1, 0.45) * min(radius, height)
    profile = prim.boss_profile(radius, height, edge, edge_size, 0.0,
                                segments, 0.0)
    part = prim.revolve(profile, segments).translate((0, 0, -height / 2))
    recipe.log("base", "cylinder", radius=radius, height=height,
               top_edge=edge, edge_size=edge_size)
    return part, Footprint(_top(part), (0.0, 0.0),
                           radius=radius - edge_size)


def _bracket(rng, segments, recipe):
    """L-bracket: floor plate, wall plate, concave fillet in the corner."""
    length, width = rng.uniform(1.2, 2.0), rng.uniform(0.6, 1.4)
    thick, height = rng.uniform(0.1, 0.3), rng.uniform(0.5, 1.2)
    floor = prim.box((length, width, thick), (0, 0, thick / 2))
    wall = prim.box((thick, width, height),
                    (-length / 2 + thick / 2, 0, height / 2))
    fillet = rng.uniform(0.2, 0.8) * thick
    # The strip is built along z; turning it about x lays it along y.
    strip = prim.fillet_strip(fillet, width, segments).rotate((90, 0, 0)) \
        .translate((-length / 2 + thick, 0, thick))
    part = Manifold.batch_boolean([floor, wall, strip], prim.OpType.Add)
    recipe.log("base", "box", size=(length, width, thick), role="floor")
    recipe.log("union", "box", size=(thick, width, height), role="wall")
    recipe.log("union", "fillet_strip", radius=fillet, role="inner fillet")
    free = length - thick - fillet
    centre = (length / 2 - free / 2, 0.0)
    return part, Footprint(thick, centre, half=(free / 2, width / 2))


BASE_BUILDERS = {"block": _block, "disc": _disc, "bracket": _bracket}


# ---- features ------------------------------------------------------------

def _segments_for(radius, reference, segments):
    """Fewer segments on small circles, as CAD tessellators do, but >= 8."""
    n = segments * np.sqrt(min(radius / reference, 1.0))
    return int(max(8, 4 * round(n / 4)))


def _boss(rng, part, fp, segments, recipe):
    s = fp.scale
    radius = rng.uniform(0.08, 0.3) * s
    height = rng.uniform(0.1, 0.5) * s
    edge = str(rng.choice(["sharp", "chamfer", "fillet"]))
    edge_size = rng.uniform(0.1, 0.4) * min(radius, height)
    foot = float(rng.choice([0.0, rng.uniform(0.1, 0.4) * radius]))
    xy = fp.sample(rng, radius + foot)
    n = _segments_for(radius, s, segments)
    profile = prim.boss_profile(radius, height, edge, edge_size, foot, n,
                                0.05 * height)
    boss = prim.revolve(profile, n).translate((xy[0], xy[1], fp.z))
    recipe.log("union", "cylinder", at=xy, radius=radius, height=height,
               top_edge=edge, edge_size=edge_size, foot_fillet=foot)
    return part + boss


def _depth_below(part, z):
    return z - part.bounding_box()[2] + 0.05


def _hole(rng, part, fp, segments, recipe):
    s = fp.scale
    radius = rng.uniform(0.04, 0.18) * s
    rim = str(rng.choice(["sharp", "chamfer", "counterbore"]))
    rim_size = rng.uniform(0.2, 0.5) * radius
    through = bool(rng.random() < 0.6)
    full = _depth_below(part, fp.z)
    depth = full if through else rng.uniform(0.3, 0.8) * (full - 0.05)
    xy = fp.sample(rng, radius * 1.6)
    n = _segments_for(radius, s, segments)
    cutter = prim.through_hole(radius, depth, rim, rim_size, n) \
        .translate((xy[0], xy[1], fp.z))
    recipe.log("difference", "cylinder", at=xy, radius=radius, depth=depth,
               rim=rim, rim_size=rim_size, through=through)
    return part - cutter


def _pocket(rng, part, fp, segments, recipe):
    s = fp.scale
    w, d = rng.uniform(0.2, 0.8, size=2) * s
    corner = rng.uniform(0.05, 0.45) * min(w, d)
    depth = rng.uniform(0.2, 0.6) * (_depth_below(part, fp.z) - 0.05)
    angle = rng.uniform(0, 180)
    xy = fp.sample(rng, 0.5 * max(w, d))
    section = prim.rounded_rect(w, d, corner, _segments_for(corner, s,
                                                            segments) * 2)
    cutter = Manifold.extrude(section, depth + 0.05).rotate((0, 0, angle)) \
        .translate((xy[0], xy[1], fp.z - depth))
    recipe.log("difference", "box", at=xy, size=(w, d, depth),
               corner_fillet=corner, angle=angle)
    return part - cutter


def _dome(rng, part, fp, segments, recipe):
    radius = rng.uniform(0.1, 0.3) * fp.scale
    sink = rng.uniform(0.2, 0.7) * radius
    xy = fp.sample(rng, radius)
    ball = Manifold.sphere(radius, segments) \
        .translate((xy[0], xy[1], fp.z - sink))
    recipe.log("union", "sphere", at=xy, radius=radius, sink=sink)
    return part + ball


def _dimple(rng, part, fp, segments, recipe):
    radius = rng.uniform(0.1, 0.3) * fp.scale
    lift = rng.uniform(0.2, 0.7) * radius
    xy = fp.sample(rng, radius)
    ball = Manifold.sphere(radius, segments) \
        .translate((xy[0], xy[1], fp.z + lift))
    recipe.log("difference", "sphere", at=xy, radius=radius, lift=lift)
    return part - ball


def _torus_on_top(rng, fp, segments):
    major = rng.uniform(0.12, 0.35) * fp.scale
    minor = rng.uniform(0.15, 0.35) * major
    xy = fp.sample(rng, major + minor)
    ring = prim.torus(major, minor, segments).translate((xy[0], xy[1], fp.z))
    return ring, dict(at=xy, major=major, minor=minor)


def _ring(rng, part, fp, segments, recipe):
    ring, params = _torus_on_top(rng, fp, segments)
    recipe.log("union", "torus", **params)
    return part + ring


def _groove(rng, part, fp, segments, recipe):
    ring, params = _torus_on_top(rng, fp, segments)
    recipe.log("difference", "torus", **params)
    return part - ring


def _rib(rng, part, fp, segments, recipe):
    s = fp.scale
    length = rng.uniform(0.4, 1.2) * s
    width = rng.uniform(0.04, 0.12) * s
    height = rng.uniform(0.1, 0.4) * s
    angle = float(rng.choice([0.0, 45.0, 90.0, rng.uniform(0, 180)]))
    xy = fp.sample(rng, 0.5 * length)
    rib = prim.box((length, width, height + 0.02)).rotate((0, 0, angle)) \
        .translate((xy[0], xy[1], fp.z + height / 2 - 0.01))
    recipe.log("union", "box", at=xy, size=(length, width, height),
               angle=angle)
    return part + rib


def _side_hole(rng, part, fp, segments, recipe):
    lo, hi = np.reshape(part.bounding_box(), (2, 3))
    radius = rng.uniform(0.03, 0.12) * fp.scale
    axis = int(rng.integers(0, 2))
    z = rng.uniform(lo[2] + 1.5 * radius, max(hi[2] - 1.5 * radius,
                                              lo[2] + 1.5 * radius))
    across = fp.sample(rng, 2 * radius)[1 - axis]
    length = float(hi[axis] - lo[axis]) + 0.2
    n = _segments_for(radius, fp.scale, segments)
    rod = Manifold.cylinder(length, radius, circular_segments=n, center=True)
    rod = rod.rotate((0, 90, 0) if axis == 0 else (90, 0, 0))
    centre = [0.0, 0.0, z]
    centre[axis] = float(lo[axis] + hi[axis]) / 2
    centre[1 - axis] = across
    recipe.log("difference", "cylinder", axis="xy"[axis], at=centre,
               radius=radius)
    return part - rod.translate(tuple(centre))


FEATURE_BUILDERS = {
    "boss": _boss, "hole": _hole, "pocket": _pocket, "dome": _dome,
    "dimple": _dimple, "ring": _ring, "groove": _groove, "rib": _rib,
    "side_hole": _side_hole,
}
