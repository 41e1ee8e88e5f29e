#!/usr/bin/env python3
"""Writes l_bracket.obj: the project's own non-convex test object with a through-hole.

An L-shaped plate (100 x 80 mm, arms 40 mm wide, 12 mm thick, metres in the file) with an
octagonal hole (circumradius 10 mm) through its corner block, as a closed triangle-and-quad
mesh (every vertex shared, no T-junctions): top and bottom faces, outer and hole walls. The corner block around the hole is a ring of
eight convex quads joining the octagon to the block's square outline along the same rays, so
every face is convex and the footprint's exact union sees no gaps or overlaps.

    python3 data/meshes/make_l_bracket.py   # rewrites data/meshes/l_bracket.obj
"""
import math
import os

MM = 0.001
THICKNESS = 12 * MM
HOLE_CENTRE = (20 * MM, 20 * MM)
HOLE_RADIUS = 10 * MM

# The corner block [0, 40]^2 mm: eight boundary points on the rays at k * 45 degrees from the
# hole centre (edge midpoints and corners), counter-clockwise from angle 0.
block = [(40, 20), (40, 40), (20, 40), (0, 40), (0, 20), (0, 0), (20, 0), (40, 0)]
block = [(x * MM, y * MM) for x, y in block]
octagon = [(HOLE_CENTRE[0] + HOLE_RADIUS * math.cos(k * math.pi / 4),
            HOLE_CENTRE[1] + HOLE_RADIUS * math.sin(k * math.pi / 4)) for k in range(8)]
# The arms as counter-clockwise triangles fanned from the block's side vertices (40, 20) and
# (20, 40), which they share with the block: no T-junctions and no zero-area triangles.
arm_x = [[(40, 20), (40, 0), (100, 0)], [(40, 20), (100, 0), (100, 40)], [(40, 20), (100, 40), (40, 40)]]
arm_y = [[(20, 40), (40, 40), (40, 80)], [(20, 40), (40, 80), (0, 80)], [(20, 40), (0, 80), (0, 40)]]
arms = [[(x * MM, y * MM) for x, y in triangle] for triangle in arm_x + arm_y]
# The outline (CCW) and the hole (any order) for the walls.
outline = [(0, 0), (20, 0), (40, 0), (100, 0), (100, 40), (40, 40), (40, 80), (0, 80), (0, 40), (0, 20)]
outline = [(x * MM, y * MM) for x, y in outline]

vertices = []   # (x, y, z)
index = {}


def vertex(p, z):
    key = (round(p[0], 12), round(p[1], 12), z)
    if key not in index:
        vertices.append((p[0], p[1], z))
        index[key] = len(vertices)  # OBJ indices are 1-based
    return index[key]


top, bottom = THICKNESS / 2, -THICKNESS / 2
faces = []


def cap(polygon_ccw):
    """The polygon on the top (CCW seen from +z) and on the bottom (reversed)."""
    faces.append([vertex(p, top) for p in polygon_ccw])
    faces.append([vertex(p, bottom) for p in reversed(polygon_ccw)])


for k in range(8):
    cap([octagon[k], block[k], block[(k + 1) % 8], octagon[(k + 1) % 8]])
for triangle in arms:
    cap(triangle)


def walls(ring, outward_ccw):
    for a, b in zip(ring, ring[1:] + ring[:1]):
        if not outward_ccw:
            a, b = b, a
        faces.append([vertex(a, bottom), vertex(b, bottom), vertex(b, top), vertex(a, top)])


walls(outline, True)
walls(octagon, False)  # the hole's walls face into the hole

path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "l_bracket.obj")
with open(path, "w") as out:
    out.write("# L-shaped bracket with an octagonal through-hole, metres; written by make_l_bracket.py\n")
    out.write("o l_bracket\n")
    for x, y, z in vertices:
        out.write(f"v {x:.6f} {y:.6f} {z:.6f}\n")
    for f in faces:
        out.write("f " + " ".join(str(i) for i in f) + "\n")
print(f"wrote {path}: {len(vertices)} vertices, {len(faces)} faces")
