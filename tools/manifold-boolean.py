#!/usr/bin/env python3
"""The manifold3d peer for `texgeo bench boolean` and hand timing: reads two OFF files,
applies texgeo's --transform-b steps to B, runs one Boolean with manifold3d, writes OFF.

usage: manifold-boolean.py A.off B.off --op union|intersection|difference
                           [--transform-b STEPS] [-o OUT.off] [--repeat N]

Prints `volume=V triangles=N` and, with --repeat, `min_seconds=S median_seconds=S` of
the operation alone (Manifold construction from arrays + Boolean + mesh extraction).
Run it through tools/bench-peers, which makes the venv."""
import argparse
import math
import sys
import time

import numpy as np
import manifold3d as m3d


def read_off(path):
    with open(path) as f:
        words = []
        for line in f:
            line = line.split("#", 1)[0].strip()
            if line:
                words.extend(line.split())
    if words[0] != "OFF":
        sys.exit(f"{path}: not an OFF file")
    nv, nf = int(words[1]), int(words[2])
    pos = np.array(words[4:4 + 3 * nv], dtype=np.float64).reshape(nv, 3)
    k = 4 + 3 * nv
    tris = []
    for _ in range(nf):
        n = int(words[k])
        face = [int(x) for x in words[k + 1:k + 1 + n]]
        k += 1 + n
        for j in range(1, n - 1):  # fan: the test solids' faces are triangles or convex
            tris.append((face[0], face[j], face[j + 1]))
    return pos, np.array(tris, dtype=np.uint32)


def transform(steps):
    m = np.eye(4)
    for step in filter(None, (s.strip() for s in steps.split(";"))):
        w = step.split()
        t = np.eye(4)
        if w[0] == "translate":
            t[:3, 3] = [float(x) for x in w[1:4]]
        elif w[0] == "scale":
            s = [float(x) for x in w[1:]]
            t[:3, :3] = np.diag(s * 3 if len(s) == 1 else s)
        elif w[0] == "rotate":
            if w[1] in "xyz":
                axis = np.eye(3)["xyz".index(w[1])]
                deg = float(w[2])
            else:
                axis = np.array([float(x) for x in w[1:4]])
                deg = float(w[4])
            axis = axis / np.linalg.norm(axis)
            a = math.radians(deg)
            x, y, z = axis
            c, s, C = math.cos(a), math.sin(a), 1 - math.cos(a)
            t[:3, :3] = [[c + x * x * C, x * y * C - z * s, x * z * C + y * s],
                         [y * x * C + z * s, c + y * y * C, y * z * C - x * s],
                         [z * x * C - y * s, z * y * C + x * s, c + z * z * C]]
        else:
            sys.exit(f"unknown transform step '{step}'")
        m = t @ m
    return m


def write_off(path, pos, tris):
    with open(path, "w") as f:
        f.write(f"OFF\n{len(pos)} {len(tris)} 0\n")
        for p in pos:
            f.write(f"{float(p[0])!r} {float(p[1])!r} {float(p[2])!r}\n")
        for t in tris:
            f.write(f"3 {t[0]} {t[1]} {t[2]}\n")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("a")
    ap.add_argument("b")
    ap.add_argument("--op", required=True)
    ap.add_argument("--transform-b", default="")
    ap.add_argument("-o", "--output")
    ap.add_argument("--repeat", type=int, default=0)
    args = ap.parse_args()
    pa, ta = read_off(args.a)
    pb, tb = read_off(args.b)
    if args.transform_b:
        m = transform(args.transform_b)
        pb = pb @ m[:3, :3].T + m[:3, 3]

    ops = {"union": lambda a, b: a + b, "intersection": lambda a, b: a ^ b,
           "difference": lambda a, b: a - b}
    if args.op not in ops:
        sys.exit(f"unknown op {args.op}")

    def run():
        # f64 positions (Mesh64), as tools/boolean-compare.py calls it: the same inputs texgeo reads.
        a = m3d.Manifold(m3d.Mesh64(pa, ta.astype(np.uint64)))
        b = m3d.Manifold(m3d.Mesh64(pb, tb.astype(np.uint64)))
        r = ops[args.op](a, b)
        return r, r.to_mesh64()

    r, mesh = run()
    print(f"volume={r.volume()} triangles={len(mesh.tri_verts)} status={r.status()}")
    if args.output:
        write_off(args.output, np.asarray(mesh.vert_properties)[:, :3], np.asarray(mesh.tri_verts))
    if args.repeat:
        times = []
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            run()
            times.append(time.perf_counter() - t0)
        times.sort()
        print(f"min_seconds={times[0]} median_seconds={times[len(times) // 2]}")


if __name__ == "__main__":
    main()
