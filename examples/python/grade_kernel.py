#!/usr/bin/env python3
"""Grades another signed-distance kernel against pushgraph's exact queries: here a plain NumPy
point-to-segment kernel with even-odd containment, the kind many robotics codes carry. Reports
its worst error, its sign errors (inside/outside decided wrongly) and where they happen.

    python3 examples/python/grade_kernel.py
"""
import pathlib

import numpy as np

import pushgraph as pg

ROOT = pathlib.Path(__file__).resolve().parents[2]


def naive_signed_distance(rings, points):
    """Distance to the nearest edge of any ring, negative inside by the even-odd rule."""
    best = np.full(len(points), np.inf)
    inside = np.zeros(len(points), dtype=bool)
    for ring in rings:
        a, b = ring, np.roll(ring, -1, axis=0)
        for (ax, ay), (bx, by) in zip(a, b):
            d = np.array([bx - ax, by - ay])
            t = np.clip(((points - (ax, ay)) @ d) / (d @ d), 0.0, 1.0)
            closest = np.array([ax, ay]) + t[:, None] * d
            best = np.minimum(best, np.linalg.norm(points - closest, axis=1))
            with np.errstate(divide="ignore", invalid="ignore"):  # horizontal edges never cross
                crosses = ((ay > points[:, 1]) != (by > points[:, 1])) & (
                    points[:, 0] < ax + (points[:, 1] - ay) * (bx - ax) / (by - ay))
            inside ^= crosses
    return np.where(inside, -best, best)


shape = pg.Shape.load_json(str(ROOT / "data" / "shapes" / "notched_block.json"))
polygons = shape.polygons()["polygons"]
rings = [p["outer"] for p in polygons] + [h for p in polygons for h in p["holes"]]
rng = np.random.default_rng(1)
lo, hi = shape.bounds
points = rng.uniform(lo - 0.01, hi + 0.01, (200000, 2))
# Points exactly on the boundary and on the vertices: where kernels decide the sign wrongly.
vertices = np.concatenate(rings)
edges = np.concatenate([(r + np.roll(r, -1, axis=0)) / 2 for r in rings])
points = np.concatenate([points, vertices, edges])

exact = shape.query(points)
naive = naive_signed_distance(rings, points)
error = np.abs(naive - exact["signed_distance"])
sign_errors = (naive < 0) != (exact["containment"] == pg.INSIDE)
print("points: %d (%d on vertices and edge midpoints)" % (len(points), len(vertices) + len(edges)))
print("worst |naive - exact|: %.3g m at %s" % (error.max(), points[np.argmax(error)]))
print("sign errors: %d (exactly on the boundary: %d)" % (
    sign_errors.sum(), (sign_errors & (exact["containment"] == pg.ON_BOUNDARY)).sum()))
ulps = error / np.maximum(np.spacing(np.abs(exact["signed_distance"])), np.spacing(1e-300))
print("median error: %.1f ulp of the exact value" % np.median(ulps))
