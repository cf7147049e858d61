#!/usr/bin/env python3
"""Writes the explorer's embedded mesh (data/meshes/rounded-cube.obj): the superellipsoid
|x|^4 + |y|^4 + |z|^4 = 1, a cube with rounded edges. It is convex, so the mesh view's direct
lighting without visibility renders it exactly; its flat faces and round edges show a BRDF at
every angle. Normals are the implicit surface's gradients (vn), faces counter-clockwise from
outside.

Usage: scripts/make_mesh.py [OUT] [--u 64] [--v 32]
"""
import argparse
import math


def signed_pow(c, m):
    return math.copysign(abs(c) ** m, c)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out", nargs="?", default="data/meshes/rounded-cube.obj")
    ap.add_argument("--u", type=int, default=64)
    ap.add_argument("--v", type=int, default=32)
    a = ap.parse_args()
    r = 4.0
    m = 2.0 / r
    verts, normals, faces = [], [], []
    # Rings of latitude v in [-pi/2, pi/2] (poles single vertices), longitude u in [0, 2pi).
    top = None
    for j in range(a.v + 1):
        v = -math.pi / 2 + math.pi * j / a.v
        if j in (0, a.v):
            verts.append((0.0, 0.0, -1.0 if j == 0 else 1.0))
            normals.append((0.0, 0.0, -1.0 if j == 0 else 1.0))
            continue
        for i in range(a.u):
            u = 2 * math.pi * i / a.u
            x = signed_pow(math.cos(v), m) * signed_pow(math.cos(u), m)
            y = signed_pow(math.cos(v), m) * signed_pow(math.sin(u), m)
            z = signed_pow(math.sin(v), m)
            g = [math.copysign(abs(c) ** (r - 1), c) for c in (x, y, z)]
            n = math.sqrt(sum(c * c for c in g))
            verts.append((x, y, z))
            normals.append(tuple(c / n for c in g))

    def ring(j, i):  # 1-based OBJ index of ring j (1..v-1), column i
        return 2 + (j - 1) * a.u + (i % a.u)
    south, north = 1, 2 + (a.v - 1) * a.u
    for i in range(a.u):
        faces.append((south, ring(1, i + 1), ring(1, i)))
        faces.append((north, ring(a.v - 1, i), ring(a.v - 1, i + 1)))
    for j in range(1, a.v - 1):
        for i in range(a.u):
            faces.append((ring(j, i), ring(j, i + 1), ring(j + 1, i + 1)))
            faces.append((ring(j, i), ring(j + 1, i + 1), ring(j + 1, i)))
    # Counter-clockwise from outside: the face normal along the vertex normals.
    oriented = []
    for f in faces:
        p = [verts[k - 1] for k in f]
        e1 = [p[1][c] - p[0][c] for c in range(3)]
        e2 = [p[2][c] - p[0][c] for c in range(3)]
        fn = (e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0])
        vn = [sum(normals[k - 1][c] for k in f) for c in range(3)]
        oriented.append(f if sum(fn[c] * vn[c] for c in range(3)) >= 0 else (f[0], f[2], f[1]))
    with open(a.out, "w") as out:
        out.write("# rounded-cube: |x|^4 + |y|^4 + |z|^4 = 1, written by scripts/make_mesh.py\n")
        for p in verts:
            out.write("v {:.6f} {:.6f} {:.6f}\n".format(*p))
        for n in normals:
            out.write("vn {:.6f} {:.6f} {:.6f}\n".format(*n))
        for f in oriented:
            out.write("f {0}//{0} {1}//{1} {2}//{2}\n".format(*f))


if __name__ == "__main__":
    main()
