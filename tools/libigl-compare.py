"""texgeo inclusion --allow-open vs libigl's fast_winding_number; run through tools/libigl-compare.

MESH [--points N] [--seed S] [--runs R]: N uniform points in the mesh's bounding box (a .npy
file), then `texgeo inclusion MESH --points P.npy --allow-open -o L.npy` and one libigl run
(read the mesh and the points, fast_winding_number: build + query, write w) alternate --runs
times as separate processes. The table gives the median wall time of each whole process,
libigl's own build+query time (timed inside its process), and the labels compared wherever
libigl's |w − ½| > 0.05 (texgeo's boundary points, label 2, left out).

--voxels RES --solid SOLID: also `texgeo voxelize MESH --res RES --allow-open` against
`texgeo voxelize SOLID --res RES` (a valid solid of about the same size), --runs times each,
alternating: median wall times and their ratio.

--libigl MESH POINTS -o W: one libigl run; its phase times on stderr.

The tables are printed as Markdown; `--csv-dir DIR` also writes them as CSV (what
tools/results saves under docs/bench/).
"""

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time


def libigl_run(mesh_path, points_path, out):
    import igl
    import numpy as np

    t0 = time.perf_counter()
    v, f = igl.read_triangle_mesh(mesh_path)[:2]
    q = np.load(points_path)
    t1 = time.perf_counter()
    w = igl.fast_winding_number(v, f, q)
    t2 = time.perf_counter()
    np.save(out, w)
    t3 = time.perf_counter()
    print(
        f"libigl: read {1e3 * (t1 - t0):.1f} ms, build+query {1e3 * (t2 - t1):.1f} ms, "
        f"write {1e3 * (t3 - t2):.1f} ms, {len(w)} points, {int((w >= 0.5).sum())} with w >= 1/2",
        file=sys.stderr,
    )


def pts_of(path, i):
    import numpy as np

    return (float(c) for c in np.load(path, mmap_mode="r")[i])


def timed(cmd):
    """Wall seconds and stderr of one process (which must succeed)."""
    t = time.perf_counter()
    p = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    wall = time.perf_counter() - t
    if p.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed:\n{p.stderr.decode()}")
    return wall, p.stderr.decode()


def write_csv(folder, name, header, rows):
    """A table as CSV in `folder` (written whole: a temporary file renamed), when one is given."""
    if not folder:
        return
    import csv

    os.makedirs(folder, exist_ok=True)
    path = os.path.join(folder, name)
    with open(path + ".tmp", "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(header)
        w.writerows(rows)
    os.replace(path + ".tmp", path)
    print(f"wrote {path}", file=sys.stderr)


def compare(args):
    import numpy as np
    import igl

    root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
    texgeo = os.path.join(root, "target", "release", "texgeo")
    v = igl.read_triangle_mesh(args.mesh)[0]
    lo, hi = v.min(axis=0), v.max(axis=0)
    with tempfile.TemporaryDirectory() as tmp:
        pts, ours, theirs = (os.path.join(tmp, n) for n in ("p.npy", "labels.npy", "w.npy"))
        rng = np.random.default_rng(args.seed)
        np.save(pts, lo + (hi - lo) * rng.random((args.points, 3)))
        t_cmd = [texgeo, "inclusion", args.mesh, "--points", pts, "--allow-open", "-o", ours]
        l_cmd = [sys.executable, os.path.abspath(__file__), "--libigl", args.mesh, pts, "-o", theirs]
        t_runs, l_runs = [], []
        for _ in range(args.runs):
            t_runs.append(timed(t_cmd))
            l_runs.append(timed(l_cmd))
        labels, w = np.load(ours), np.load(theirs)
        clear = (np.abs(w - 0.5) > 0.05) & (labels != 2)
        agree = int(((labels == 1) == (w >= 0.5))[clear].sum())
        inner = statistics.median(float(r[1].split("build+query ")[1].split(" ms")[0]) / 1e3 for r in l_runs)
        tt, lt = statistics.median(r[0] for r in t_runs), statistics.median(r[0] for r in l_runs)
        print(f"texgeo: {t_runs[-1][1].strip()}", file=sys.stderr)
        print(l_runs[-1][1].strip(), file=sys.stderr)
        print(f"\n{args.mesh}: {args.points} uniform points in its box, {args.runs} runs each, alternating\n")
        header = ["points", "texgeo s (whole)", "libigl s (whole)", "libigl build+query s", "texgeo / libigl whole",
                  "texgeo / libigl build+query", "labels equal where abs(w - 1/2) > 0.05"]
        cells = [str(args.points), f"{tt:.3f}", f"{lt:.3f}", f"{inner:.3f}", f"{tt / lt:.3f}", f"{tt / inner:.3f}",
                 f"{agree} of {int(clear.sum())}"]
        print("| " + " | ".join(header) + " |\n|" + "---:|" * 6 + "---|\n| " + " | ".join(cells) + " |")
        write_csv(args.csv_dir, "inclusion.csv", header, [cells])
        if args.voxels:
            out = os.path.join(tmp, "v.binvox")
            o_cmd = [texgeo, "voxelize", args.mesh, "--res", str(args.voxels), "--allow-open", "-o", out]
            s_cmd = [texgeo, "voxelize", args.solid, "--res", str(args.voxels), "-o", out]
            o_runs, s_runs = [], []
            for _ in range(args.runs):
                o_runs.append(timed(o_cmd)[0])
                s_runs.append(timed(s_cmd)[0])
            ot, st = statistics.median(o_runs), statistics.median(s_runs)
            print(f"\nvoxelize at {args.voxels}^3, {args.runs} runs each, alternating, whole processes\n")
            header = ["N", f"{os.path.basename(args.mesh)} --allow-open s", f"{os.path.basename(args.solid)} (solid) s",
                      "ratio"]
            cells = [str(args.voxels), f"{ot:.3f}", f"{st:.3f}", f"{ot / st:.2f}"]
            print("| " + " | ".join(header) + " |\n|" + "---:|" * 4 + "\n| " + " | ".join(cells) + " |")
            write_csv(args.csv_dir, "voxelize.csv", header, [cells])
        differ = np.where(clear & ((labels == 1) != (w >= 0.5)))[0]
        for i in differ[:10]:
            # libigl's far field carries no error bound: such a point is worth a direct sum.
            x, y, z = pts_of(pts, i)
            print(f"differs: point {i} ({x!r} {y!r} {z!r}): libigl w = {w[i]:.6f}, texgeo label {labels[i]}")


def main():
    if len(sys.argv) > 1 and sys.argv[1] == "--libigl":
        p = argparse.ArgumentParser(prog="tools/libigl-compare --libigl")
        p.add_argument("--libigl", action="store_true")
        p.add_argument("mesh")
        p.add_argument("points")
        p.add_argument("-o", "--output", required=True)
        a = p.parse_args()
        libigl_run(a.mesh, a.points, a.output)
        return
    p = argparse.ArgumentParser(prog="tools/libigl-compare")
    p.add_argument("mesh")
    p.add_argument("--points", type=int, default=1_000_000)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--runs", type=int, default=3)
    p.add_argument("--voxels", type=int)
    p.add_argument("--solid")
    p.add_argument("--csv-dir", help="also write the tables as CSV into this folder (inclusion.csv, voxelize.csv)")
    a = p.parse_args()
    if a.voxels and not a.solid:
        p.error("--voxels needs --solid SOLID (a valid solid of about the same size)")
    compare(a)


if __name__ == "__main__":
    main()
