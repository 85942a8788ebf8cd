#!/usr/bin/env python3
"""Writes a closed tube around a polyline as a Wavefront OBJ (world mm, LPS), for a stand-in
vessel where a scan has no segmentation of one (the gallery's carotid behind the sphenoid
sinus of CThead, which has no contrast). Rings follow the polyline on rotation-minimising
frames (double reflection, Wang et al. 2008) so the tube does not twist; both ends are capped.

Usage: tube_obj.py X,Y,Z X,Y,Z [X,Y,Z ...] --radius MM [--sides N] [--per-segment N] -o OUT.obj
Pure Python (no numpy), so README's commands run wherever python3 does."""
import argparse
import math


def sub(a, b):
    return [a[i] - b[i] for i in range(3)]


def add(a, b, s=1.0):
    return [a[i] + s * b[i] for i in range(3)]


def dot(a, b):
    return sum(a[i] * b[i] for i in range(3))


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def unit(a):
    n = math.sqrt(dot(a, a))
    if n == 0:
        raise SystemExit("tube_obj.py: two consecutive points coincide")
    return [c / n for c in a]


def catmull_rom(points, per_segment):
    """The polyline resampled along a Catmull-Rom spline through its points."""
    p = [points[0]] + points + [points[-1]]
    out = []
    for i in range(1, len(p) - 2):
        for s in range(per_segment):
            t = s / per_segment
            t2, t3 = t * t, t * t * t
            out.append([0.5 * (2 * p[i][k] + (-p[i - 1][k] + p[i + 1][k]) * t
                               + (2 * p[i - 1][k] - 5 * p[i][k] + 4 * p[i + 1][k] - p[i + 2][k]) * t2
                               + (-p[i - 1][k] + 3 * p[i][k] - 3 * p[i + 1][k] + p[i + 2][k]) * t3)
                        for k in range(3)])
    out.append(points[-1])
    return out


def frames(centre):
    """Tangents and rotation-minimising normals along the centre line."""
    tangents = [unit(sub(centre[min(i + 1, len(centre) - 1)], centre[max(i - 1, 0)]))
                for i in range(len(centre))]
    t0 = tangents[0]
    seed = [1.0, 0.0, 0.0] if abs(t0[0]) < 0.9 else [0.0, 1.0, 0.0]
    normals = [unit(cross(cross(t0, seed), t0))]
    for i in range(len(centre) - 1):
        v1 = sub(centre[i + 1], centre[i])
        c1 = dot(v1, v1)
        r = add(normals[i], v1, -2.0 * dot(v1, normals[i]) / c1)
        t = add(tangents[i], v1, -2.0 * dot(v1, tangents[i]) / c1)
        v2 = sub(tangents[i + 1], t)
        c2 = dot(v2, v2)
        normals.append(unit(add(r, v2, -2.0 * dot(v2, r) / c2) if c2 > 0 else r))
    return tangents, normals


def tube(points, radius, sides, per_segment):
    centre = catmull_rom(points, per_segment)
    tangents, normals = frames(centre)
    vertices, faces = [], []
    for c, t, n in zip(centre, tangents, normals):
        b = cross(t, n)
        for s in range(sides):
            a = 2 * math.pi * s / sides
            vertices.append(add(add(c, n, radius * math.cos(a)), b, radius * math.sin(a)))
    for i in range(len(centre) - 1):
        for s in range(sides):
            a, b = i * sides + s, i * sides + (s + 1) % sides
            faces += [(a, b, b + sides), (a, b + sides, a + sides)]
    for ring, flip in ((0, True), (len(centre) - 1, False)):
        vertices.append(centre[ring])
        hub = len(vertices) - 1
        for s in range(sides):
            a, b = ring * sides + s, ring * sides + (s + 1) % sides
            faces.append((hub, b, a) if flip else (hub, a, b))
    return vertices, faces


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("points", nargs="+", help="X,Y,Z centre-line points, world mm")
    parser.add_argument("--radius", type=float, required=True)
    parser.add_argument("--sides", type=int, default=24)
    parser.add_argument("--per-segment", type=int, default=12)
    parser.add_argument("-o", "--output", required=True)
    args = parser.parse_args()
    points = [[float(c) for c in p.split(",")] for p in args.points]
    if len(points) < 2 or any(len(p) != 3 or not all(map(math.isfinite, p)) for p in points):
        raise SystemExit("tube_obj.py: give two or more finite X,Y,Z points")
    if not (math.isfinite(args.radius) and args.radius > 0 and args.sides >= 3):
        raise SystemExit("tube_obj.py: --radius must be positive and --sides at least 3")
    vertices, faces = tube(points, args.radius, args.sides, max(args.per_segment, 1))
    with open(args.output, "w") as out:
        out.writelines(f"v {x:.4f} {y:.4f} {z:.4f}\n" for x, y, z in vertices)
        out.writelines(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in faces)


if __name__ == "__main__":
    main()
