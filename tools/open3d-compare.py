"""texgeo inclusion and voxelize vs open3d's occupancy query; run through tools/open3d-compare.

--voxels MESH RES... [--runs N]: `texgeo voxelize MESH --res N -o V.binvox` (defaults, whole
process) against open3d's occupancy query over the same N³ voxel centres (texgeo's grid: the
bounding cube, centres at min + (i + ½)·side/N), one x slice of centres per call so memory
stays bounded; open3d's time is its RaycastingScene build plus the queries (making the
centres is left out), and the voxels where the two differ are counted.

--open3d MESH POINTS [-o LABELS]: one open3d run (read, RaycastingScene build, compute_occupancy,
write), its phase times on stderr. Otherwise: for each points file, `texgeo inclusion MESH
--points P -o L` and the open3d run alternate --runs times as separate processes; the table
gives median wall time and peak RSS (wait4) of each whole process, open3d's own build+query
time (RaycastingScene + compute_occupancy, timed inside its process), and how many labels
agree (open3d has no boundary class: texgeo's boundary points are left out).

Both comparisons print a Markdown table; `--csv FILE` also writes it as CSV (what
tools/results saves under docs/bench/).
"""

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time


def read_points(path):
    import numpy as np

    if path.endswith(".npy"):
        return np.load(path).astype(np.float32).reshape(-1, 3)
    with open(path, "rb") as f:
        text = f.read()
    # Comments (`#` to the end of the line) are allowed in texgeo's format.
    if b"#" in text:
        text = b"\n".join(line.split(b"#", 1)[0] for line in text.splitlines())
    return np.array(text.split(), dtype=np.float32).reshape(-1, 3)


def run_open3d(mesh_path, points_path, out):
    import numpy as np
    import open3d as o3d

    t0 = time.perf_counter()
    mesh = o3d.io.read_triangle_mesh(mesh_path)
    if len(mesh.triangles) == 0:
        sys.exit(f"open3d read no triangles from {mesh_path}")
    pts = read_points(points_path)
    t1 = time.perf_counter()
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(o3d.t.geometry.TriangleMesh.from_legacy(mesh))
    occ = scene.compute_occupancy(o3d.core.Tensor(pts, dtype=o3d.core.Dtype.Float32))
    t2 = time.perf_counter()
    labels = occ.numpy().astype(np.uint8)
    t3 = time.perf_counter()
    if out:
        lines = np.empty((len(labels), 2), dtype=np.uint8)
        lines[:, 0] = labels + ord("0")
        lines[:, 1] = ord("\n")
        with open(out, "wb") as f:
            f.write(lines.tobytes())
    t4 = time.perf_counter()
    print(
        f"open3d: read {1e3 * (t1 - t0):.1f} ms, build+query {1e3 * (t2 - t1):.1f} ms, "
        f"write {1e3 * (t4 - t3):.1f} ms, {len(labels)} points, {int(labels.sum())} inside",
        file=sys.stderr,
    )


def grid_of(mesh):
    import numpy as np

    v = np.asarray(mesh.vertices)
    lo, hi = v.min(axis=0), v.max(axis=0)
    side = float((hi - lo).max())
    return (lo + hi) * 0.5 - side * 0.5, side


def run_open3d_voxels(mesh_path, n, binvox):
    """open3d's occupancy of the N³ centres, slice by slice; compared with texgeo's binvox
    (x-major, then z, then y) when one is given."""
    import numpy as np
    import open3d as o3d

    mesh = o3d.io.read_triangle_mesh(mesh_path)
    lo, side = grid_of(mesh)
    h = side / n
    c = lambda axis: (lo[axis] + (np.arange(n) + 0.5) * h)
    zz, yy = np.meshgrid(c(2), c(1), indexing="ij")
    yz = np.empty((n * n, 3), dtype=np.float32)
    yz[:, 1], yz[:, 2] = yy.ravel(), zz.ravel()
    ours = None
    if binvox:
        with open(binvox, "rb") as f:
            data = f.read()
        runs = np.frombuffer(data[data.index(b"data\n") + 5 :], dtype=np.uint8).reshape(-1, 2)
        ours = np.repeat(runs[:, 0], runs[:, 1].astype(np.int64))
    spent, occupied, differ = 0.0, 0, 0
    t = time.perf_counter()
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(o3d.t.geometry.TriangleMesh.from_legacy(mesh))
    spent += time.perf_counter() - t
    for i, x in enumerate(c(0)):
        yz[:, 0] = x
        t = time.perf_counter()
        occ = scene.compute_occupancy(o3d.core.Tensor(yz, dtype=o3d.core.Dtype.Float32)).numpy()
        spent += time.perf_counter() - t
        occupied += int(occ.sum())
        if ours is not None:
            differ += int((ours[i * n * n : (i + 1) * n * n] != occ.astype(np.uint8)).sum())
    print(
        f"open3d: build+query {1e3 * spent:.1f} ms, {n}^3 centres, {occupied} inside, {differ} differ",
        file=sys.stderr,
    )


def compare_voxels(args):
    root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
    texgeo = args.texgeo or os.path.join(root, "target", "release", "texgeo")
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "v.binvox")
        for n in args.res:
            t_cmd = [texgeo, *args.texgeo_args.split(), "voxelize", args.mesh, "--res", str(n), "-o", out]
            t_runs = [measured(t_cmd) for _ in range(args.runs)]
            o_cmd = [sys.executable, os.path.abspath(__file__), "--open3d-voxels", args.mesh, str(n), out]
            o_runs = [measured(o_cmd) for _ in range(args.open3d_runs)]
            med = lambda runs, i: statistics.median(r[i] for r in runs)
            inner = statistics.median(float(r[2].split("build+query ")[1].split(" ms")[0]) / 1e3 for r in o_runs)
            differ = o_runs[-1][2].split(" inside, ")[1].split(" differ")[0]
            rows.append((n, med(t_runs, 0), inner, med(t_runs, 1), os.path.getsize(out) / 2**20, differ))
            print(f"texgeo: {t_runs[-1][2].strip()}", file=sys.stderr)
            print(o_runs[-1][2].strip(), file=sys.stderr)
    print(f"\n{args.mesh}: texgeo {args.runs} runs (median), open3d {args.open3d_runs}; whole texgeo processes\n")
    header = ["N", "texgeo s", "open3d build+query s", "ratio", "texgeo peak MiB", "binvox MiB", "voxels that differ"]
    cells = [[str(n), f"{tt:.3f}", f"{inner:.2f}", f"{tt / inner:.4f}", f"{tm:.1f}", f"{out:.2f}", differ]
             for n, tt, inner, tm, out, differ in rows]
    print_table(header, cells, "|---:" * len(header) + "|")
    write_csv(args.csv, header, cells)


def print_table(header, cells, rule):
    print("| " + " | ".join(header) + " |")
    print(rule)
    for c in cells:
        print("| " + " | ".join(c) + " |")


def write_csv(path, header, cells):
    """The table as CSV at `path` (written whole: a temporary file renamed), when one is given."""
    if not path:
        return
    import csv

    tmp = path + ".tmp"
    with open(tmp, "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(header)
        w.writerows(cells)
    os.replace(tmp, path)
    print(f"wrote {path}", file=sys.stderr)


def measured(cmd):
    """(wall seconds, peak RSS MiB) of one process."""
    t = time.perf_counter()
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t
    err = proc.stderr.read().decode()
    proc.stderr.close()
    if os.waitstatus_to_exitcode(status) != 0:
        sys.exit(f"{' '.join(cmd)} failed:\n{err}")
    return wall, usage.ru_maxrss / 1024.0, err


def compare(args):
    root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
    texgeo = args.texgeo or os.path.join(root, "target", "release", "texgeo")
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for points in args.points:
            ours, theirs = os.path.join(tmp, "texgeo.txt"), os.path.join(tmp, "open3d.txt")
            t_cmd = [texgeo, *args.texgeo_args.split(), "inclusion", args.mesh, "--points", points, "-o", ours]
            o_cmd = [sys.executable, os.path.abspath(__file__), "--open3d", args.mesh, points, "-o", theirs]
            t_runs, o_runs = [], []
            for _ in range(args.runs):
                t_runs.append(measured(t_cmd))
                o_runs.append(measured(o_cmd))
            with open(ours, "rb") as f:
                a = f.read().split()
            with open(theirs, "rb") as f:
                b = f.read().split()
            decided = [(x, y) for x, y in zip(a, b) if x != b"2"]
            agree = sum(x == y for x, y in decided)
            med = lambda runs, i: statistics.median(r[i] for r in runs)
            inner = statistics.median(float(r[2].split("build+query ")[1].split(" ms")[0]) / 1e3 for r in o_runs)
            out_mib = os.path.getsize(ours) / 2**20
            rows.append((points, len(a), med(t_runs, 0), med(o_runs, 0), inner, med(t_runs, 1), med(o_runs, 1), out_mib, agree, len(decided)))
            print(f"texgeo: {t_runs[-1][2].strip()}", file=sys.stderr)
            print(o_runs[-1][2].strip(), file=sys.stderr)
    print(f"\n{args.mesh}, {args.runs} runs each, alternating; whole processes\n")
    header = ["points file", "points", "texgeo s", "open3d s", "open3d build+query s",
              "texgeo / open3d build+query", "texgeo peak MiB", "open3d peak MiB", "labels MiB",
              "agree (off the boundary)"]
    cells = [[os.path.basename(p), str(n), f"{tt:.3f}", f"{ot:.3f}", f"{inner:.3f}", f"{tt / inner:.2f}",
              f"{tm:.0f}", f"{om:.0f}", f"{out:.1f}", f"{agree} of {decided}"]
             for p, n, tt, ot, inner, tm, om, out, agree, decided in rows]
    print_table(header, cells, "|---|" + "---:|" * 8 + "---|")
    write_csv(args.csv, header, cells)


def main():
    if len(sys.argv) > 1 and sys.argv[1] == "--open3d-voxels":
        run_open3d_voxels(sys.argv[2], int(sys.argv[3]), sys.argv[4] if len(sys.argv) > 4 else None)
        return
    if len(sys.argv) > 1 and sys.argv[1] == "--voxels":
        p = argparse.ArgumentParser(prog="tools/open3d-compare --voxels")
        p.add_argument("--voxels", action="store_true")
        p.add_argument("mesh")
        p.add_argument("res", nargs="+", type=int)
        p.add_argument("--runs", type=int, default=5)
        p.add_argument("--open3d-runs", type=int, default=1, help="open3d runs per size (slow: one by default)")
        p.add_argument("--texgeo", help="texgeo binary (default target/release/texgeo)")
        p.add_argument("--texgeo-args", default="")
        p.add_argument("--csv", help="also write the table as CSV to this file")
        compare_voxels(p.parse_args())
        return
    if len(sys.argv) > 1 and sys.argv[1] == "--open3d":
        p = argparse.ArgumentParser(prog="tools/open3d-compare --open3d")
        p.add_argument("--open3d", action="store_true")
        p.add_argument("mesh")
        p.add_argument("points")
        p.add_argument("-o", "--output")
        a = p.parse_args()
        run_open3d(a.mesh, a.points, a.output)
        return
    p = argparse.ArgumentParser(prog="tools/open3d-compare")
    p.add_argument("mesh")
    p.add_argument("points", nargs="+")
    p.add_argument("--runs", type=int, default=5)
    p.add_argument("--texgeo", help="texgeo binary (default target/release/texgeo)")
    p.add_argument("--texgeo-args", default="", help="global texgeo options, e.g. '--threads 1'")
    p.add_argument("--csv", help="also write the table as CSV to this file")
    compare(p.parse_args())


if __name__ == "__main__":
    main()
