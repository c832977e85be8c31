"""CAD building blocks on top of manifold3d: rounded and chamfered solids.

manifold3d has boxes, cylinders and spheres but no fillet or chamfer
operation, so edges are shaped here: convex fillets by hulls of spheres or
by revolving/extruding rounded 2-D profiles, concave fillets by a ring or
strip minus a torus or cylinder, chamfers by cutting with rotated boxes.
"""

import math

import numpy as np
from manifold3d import CrossSection, JoinType, Manifold, OpType


def box(size, center=(0.0, 0.0, 0.0)):
    return Manifold.cube(tuple(size), center=True).translate(tuple(center))


def rounded_box(size, radius, segments):
    """Box with every edge filleted: the hull of 8 corner spheres."""
    half = np.asarray(size) / 2.0 - radius
    ball = Manifold.sphere(radius, segments)
    corners = [ball.translate((sx * half[0], sy * half[1], sz * half[2]))
               for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]
    return Manifold.batch_hull(corners)


def rounded_rect(width, depth, radius, segments):
    """2-D rectangle centred at the origin with filleted corners."""
    inner = CrossSection.square((width - 2 * radius, depth - 2 * radius),
                                center=True)
    return inner.offset(radius, JoinType.Round, circular_segments=segments)


def slab(size, radius, segments):
    """Box with filleted vertical edges: an extruded rounded rectangle."""
    section = rounded_rect(size[0], size[1], radius, segments)
    return Manifold.extrude(section, size[2]).translate((0, 0, -size[2] / 2))


def chamfered_box(size, chamfer, edges):
    """Box with the chosen edges cut at 45 degrees.

    Each edge is (axis, s1, s2): the edge parallel to `axis` at the corner
    with signs s1, s2 on the two other axes. A box of side chamfer*sqrt(2),
    turned 45 degrees about the edge and centred on it, removes a
    right-angled prism with legs `chamfer`.
    """
    size = np.asarray(size, dtype=float)
    part = box(size)
    cutters = [_edge_cutter(size, chamfer, *edge) for edge in edges]
    if not cutters:
        return part
    return part - Manifold.batch_boolean(cutters, OpType.Add)


def _edge_cutter(size, chamfer, axis, s1, s2):
    side = chamfer * math.sqrt(2.0)
    dims = [side, side, side]
    dims[axis] = size[axis] + 4 * chamfer
    rot = [0.0, 0.0, 0.0]
    rot[axis] = 45.0
    centre = [0.0, 0.0, 0.0]
    others = [k for k in range(3) if k != axis]
    centre[others[0]] = s1 * size[others[0]] / 2
    centre[others[1]] = s2 * size[others[1]] / 2
    return Manifold.cube(tuple(dims), center=True).rotate(tuple(rot)) \
        .translate(tuple(centre))


def _arc(cx, cy, r, a0, a1, steps):
    """Points on a circular arc from a0 to a1 degrees, ends included."""
    t = np.radians(np.linspace(a0, a1, max(steps, 1) + 1))
    return list(zip(cx + r * np.cos(t), cy + r * np.sin(t)))


def boss_profile(radius, height, top_edge, top_size, foot_fillet,
                 segments, overlap):
    """Half-section (r, z) of a round boss standing on z = 0.

    top_edge is 'sharp', 'chamfer' or 'fillet'; foot_fillet > 0 adds a
    concave fillet where the boss meets the floor. `overlap` sinks the
    profile below z = 0 so the union with the floor is robust.
    """
    arc_steps = max(segments // 4, 2)
    pts = [(0.0, -overlap)]
    if foot_fillet > 0:
        pts += [(radius + foot_fillet, -overlap)]
        pts += _arc(radius + foot_fillet, foot_fillet, foot_fillet,
                    270.0, 180.0, arc_steps)
    else:
        pts += [(radius, -overlap)]
    pts += _top_edge(radius, height, top_edge, top_size, arc_steps)
    pts += [(0.0, height)]
    return pts


def _top_edge(radius, height, kind, size, steps):
    if kind == "chamfer":
        return [(radius, height - size), (radius - size, height)]
    if kind == "fillet":
        return _arc(radius - size, height - size, size, 0.0, 90.0, steps)
    return [(radius, height)]


def revolve(profile, segments):
    """Solid of revolution about z from a half-section in the (r, z) plane."""
    return Manifold.revolve(CrossSection([np.asarray(profile)]), segments)


def torus(major, minor, segments):
    circle = CrossSection.circle(minor, max(segments // 2, 8))
    return Manifold.revolve(circle.translate((major, 0.0)), segments)


def fillet_strip(radius, length, segments):
    """Concave fillet along the z axis for the inner corner x>0, y>0.

    A square strip minus the cylinder tangent to both walls; its 2 flat
    faces sit on the walls, slightly sunk into them for a robust union.
    """
    sink = 0.02 * radius
    square = CrossSection.square((radius + sink, radius + sink)) \
        .translate((-sink, -sink))
    hole = CrossSection.circle(radius, segments).translate((radius, radius))
    section = square - hole
    return Manifold.extrude(section, length).translate((0, 0, -length / 2))


def through_hole(radius, depth, top_edge, top_size, segments):
    """Cutter for a round hole from z = 0 down to -depth, with its rim
    chamfered (countersink) or counterbored."""
    pts = [(0.0, -depth), (radius, -depth)]
    if top_edge == "chamfer":
        pts += [(radius, -top_size), (radius + top_size, 0.0)]
    elif top_edge == "counterbore":
        pts += [(radius, -top_size), (radius * 1.6, -top_size),
                (radius * 1.6, 0.0)]
    else:
        pts += [(radius, 0.0)]
    # Reach above the surface so the difference leaves no skin.
    top = pts[-1][0]
    pts += [(top, 0.05 * depth + top_size), (0.0, 0.05 * depth + top_size)]
    return revolve(pts, segments)
