#!/usr/bin/env python3
"""texgeo's Booleans beside manifold3d and CGAL's exact corefinement on a corpus of solids,
each solid against a transformed copy of itself. Run it through tools/boolean-compare,
which makes the venv and finds the binaries.

For every solid A of the corpus that texgeo accepts as a solid and every transform T, B = T(A)
is written once (exact where the transform allows: quarter turns swap coordinates) and the
three tools get the same two files. Per tool, pair and operation the outcome is one of

  ok         an answer; its volume is compared with CGAL's exact one where CGAL answers,
             and the result is re-read by `texgeo mesh stats` (closed, oriented, no crossing
             faces: a solid texgeo accepts as an operand) — `valid` says whether it is
  refused    the tool declined the input (texgeo: an operand is not a solid; manifold: the
             input is not a manifold; CGAL: its input checks)
  failed     the tool ran and gave no answer (an error, a crash, CGAL declining the operation)
  timeout    over --timeout seconds (texgeo and CGAL run as processes; manifold in process)

The volume compared is texgeo's exact one (its result before rounding to f64, which `texgeo
boolean --json` reports with a certified error bound) and manifold's written file's; the
written file's volume (`texgeo mesh stats`, which sums a thin sliver's tetrahedra in
double-double) is compared too, in the last columns. CGAL's is its exact volume converted to
f64 (tools/cgal-boolean.cpp).

Writes results.csv (one row per tool, pair and operation) and table.md and table.csv (per tool and
transform: counts of each outcome, invalid results, volumes more than 1e-9 (relative) from
CGAL's, the written files' volumes more than 1e-9 from CGAL's, the largest relative volume
difference from CGAL, the median time) into --out. Times: texgeo and CGAL are whole processes (CGAL's one
process computes all four operations, its time is divided by four); manifold's is the operation
alone (construction from arrays, the Boolean, extraction), as its own benchmarks quote it.
"""
import argparse
import csv
import json
import importlib.util
import math
import os
import statistics
import subprocess
import sys
import time

import numpy as np
import manifold3d as m3d

HERE = os.path.dirname(os.path.abspath(__file__))
_spec = importlib.util.spec_from_file_location("manifold_boolean", os.path.join(HERE, "manifold-boolean.py"))
_mb = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_mb)
read_off, write_off = _mb.read_off, _mb.write_off

OPS = ["union", "intersection", "difference", "symmetric-difference"]


def rotation(axis, degrees):
    """Rotation matrix; quarter turns about a coordinate axis are exact (no cos(90°) = 6e-17)."""
    axis = np.asarray(axis, dtype=np.float64)
    axis = axis / np.linalg.norm(axis)
    if degrees % 90 == 0 and np.count_nonzero(axis) == 1:
        q = int(degrees // 90) % 4
        c, s = [1.0, 0.0, -1.0, 0.0][q], [0.0, 1.0, 0.0, -1.0][q]
    else:
        a = math.radians(degrees)
        c, s = math.cos(a), math.sin(a)
    x, y, z = axis
    C = 1.0 - c
    return np.array([[c + x * x * C, x * y * C - z * s, x * z * C + y * s],
                     [y * x * C + z * s, c + y * y * C, y * z * C - x * s],
                     [z * x * C - y * s, z * y * C + x * s, c + z * z * C]])


def about(pos, centre, m):
    return (pos - centre) @ m.T + centre


# The seven transforms: name -> (positions, triangles) -> (positions, triangles).
def t_turn10(pos, tris):
    lo, hi = pos.min(0), pos.max(0)
    c = (lo + hi) / 2
    return about(pos, c, rotation([0, 1, 0], 10)) + 0.01 * np.linalg.norm(hi - lo), tris


def t_quarter(pos, tris):
    return about(pos, (pos.min(0) + pos.max(0)) / 2, rotation([0, 0, 1], 90)), tris


def t_quarter_origin(pos, tris):
    # Exactly 90° about z through the origin: coordinates swap, nothing is rounded.
    return np.stack([-pos[:, 1], pos[:, 0], pos[:, 2]], axis=1), tris


def t_micro(pos, tris):
    return about(pos, (pos.min(0) + pos.max(0)) / 2, rotation([1, 2, 3], 1e-6)), tris


def t_copy(pos, tris):
    return pos.copy(), tris


def t_half(pos, tris):
    lo, hi = pos.min(0), pos.max(0)
    return pos + np.array([(hi - lo)[0] / 2, 0.0, 0.0]), tris


def t_mirror30(pos, tris):
    c = (pos.min(0) + pos.max(0)) / 2
    p = pos.copy()
    p[:, 0] = 2 * c[0] - p[:, 0]
    return about(p, c, rotation([0, 0, 1], 30)), tris[:, ::-1].copy()  # mirrored: faces reversed


def t_shrink(pos, tris):
    c = pos.mean(0)
    return c + 0.999 * (pos - c), tris


TRANSFORMS = {
    "turn10+shift": t_turn10,
    "quarter": t_quarter_origin,
    "quarter-centre": t_quarter,
    "micro-turn": t_micro,
    "copy": t_copy,
    "half-shift": t_half,
    "mirror+30": t_mirror30,
    "scale0.999": t_shrink,
}
DEFAULT_TRANSFORMS = ["turn10+shift", "quarter", "micro-turn", "copy", "half-shift", "mirror+30", "scale0.999"]


def run(cmd, timeout):
    t0 = time.perf_counter()
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return "timeout", None, time.perf_counter() - t0
    return p, p.returncode, time.perf_counter() - t0


def stats_of(texgeo, path, timeout):
    """(is a solid texgeo accepts, volume) of a mesh file, by `texgeo mesh stats --json`."""
    p, rc, _ = run([texgeo, "mesh", "stats", "--json", path], timeout)
    if p == "timeout" or rc != 0:
        return False, None
    stats = json.loads(p.stdout)
    return bool(stats.get("solid")), stats.get("volume")


def texgeo_op(texgeo, a, b, op, out, timeout):
    """(outcome, seconds, message, exact volume of the result before rounding or None)."""
    p, rc, dt = run([texgeo, "boolean", a, b, "--op", op, "-o", out, "--json"], timeout)
    if p == "timeout":
        return "timeout", dt, "", None
    if rc == 0:
        ops = json.loads(p.stdout).get("operations") or [{}]
        return "ok", dt, "", ops[0].get("exact_volume")
    msg = (p.stderr.strip().splitlines() or [""])[-1]
    refused = "is not a valid solid" in msg or "not a solid" in msg
    return ("refused" if refused else "failed"), dt, msg, None


def manifold_op(pa, ta, pb, tb, op, out):
    t0 = time.perf_counter()
    try:
        a = m3d.Manifold(m3d.Mesh64(pa, ta.astype(np.uint64)))
        b = m3d.Manifold(m3d.Mesh64(pb, tb.astype(np.uint64)))
        if a.status() != m3d.Error.NoError or b.status() != m3d.Error.NoError:
            return "refused", time.perf_counter() - t0, f"{a.status()} {b.status()}"
        r = {"union": lambda: a + b, "intersection": lambda: a ^ b, "difference": lambda: a - b,
             "symmetric-difference": lambda: (a - b) + (b - a)}[op]()
        mesh = r.to_mesh64()
        dt = time.perf_counter() - t0
    except Exception as e:  # the peer's own failure is an outcome, not a crash of the table
        return "failed", time.perf_counter() - t0, str(e)
    if r.status() != m3d.Error.NoError:
        return "failed", dt, str(r.status())
    write_off(out, np.asarray(mesh.vert_properties)[:, :3], np.asarray(mesh.tri_verts))
    return "ok", dt, ""


def cgal_all(cgal, a, b, timeout):
    """{op: (outcome, volume)} for the four operations and the per-operation time."""
    p, rc, dt = run([cgal, a, b, "--op", "all"], timeout)
    if p == "timeout":
        return {op: ("timeout", None) for op in OPS}, dt / 4
    if rc != 0:
        kind = "refused" if rc == 2 else "failed"
        return {op: (kind, None) for op in OPS}, dt / 4
    got = {}
    for line in p.stdout.splitlines():
        kv = dict(w.split("=", 1) for w in line.split() if "=" in w)
        if kv.get("op") in ("union", "intersection", "difference", "reverse-difference") and "ok" in kv:
            got[kv["op"]] = float(kv["volume"]) if kv["ok"] == "1" else None
    res = {}
    for op in ("union", "intersection", "difference"):
        v = got.get(op)
        res[op] = ("ok", v) if v is not None else ("failed", None)
    d, r = got.get("difference"), got.get("reverse-difference")
    res["symmetric-difference"] = ("ok", d + r) if d is not None and r is not None else ("failed", None)
    return res, dt / 4


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--corpus", default=os.path.join(HERE, "..", "models", "corpus"))
    ap.add_argument("--transforms", default=",".join(DEFAULT_TRANSFORMS),
                    help="comma-separated, from: " + ", ".join(TRANSFORMS))
    ap.add_argument("--ops", default=",".join(OPS))
    ap.add_argument("--models", default="", help="comma-separated file names (default: every .off)")
    ap.add_argument("--max-faces", type=int, default=0, help="skip solids with more triangles")
    ap.add_argument("--timeout", type=float, default=60.0, help="seconds per texgeo run and CGAL pair")
    ap.add_argument("--no-cgal", action="store_true")
    ap.add_argument("--texgeo", required=True)
    ap.add_argument("--cgal", default="")
    ap.add_argument("--out", required=True)
    ap.add_argument("--cgal-from", default="",
                    help="take CGAL's answers from an earlier run's results.csv instead of running it "
                         "again (they do not depend on texgeo; pairs it lacks are skipped for CGAL)")
    ap.add_argument("--resume", action="store_true",
                    help="keep the models OUT/results.csv already holds and run only the others")
    args = ap.parse_args()
    transforms = [t for t in args.transforms.split(",") if t]
    for t in transforms:
        if t not in TRANSFORMS:
            sys.exit(f"boolean-compare: unknown transform '{t}' (known: {', '.join(TRANSFORMS)})")
    ops = [o for o in args.ops.split(",") if o]
    for o in ops:
        if o not in OPS:
            sys.exit(f"boolean-compare: unknown operation '{o}' (known: {', '.join(OPS)})")
    names = [m for m in args.models.split(",") if m] or sorted(
        f for f in os.listdir(args.corpus) if f.endswith(".off"))
    work = os.path.join(args.out, "work")
    os.makedirs(work, exist_ok=True)
    rows = read_rows(args.out) if args.resume else []
    if args.cgal_from and not os.path.exists(args.cgal_from):
        sys.exit(f"boolean-compare: {args.cgal_from}: no such file")
    earlier = cgal_answers(args.cgal_from) if args.cgal_from else None
    done = {r["model"] for r in rows}
    for name in names:
        src = os.path.join(args.corpus, name)
        if name[:-4] in done:
            continue
        solid, _ = stats_of(args.texgeo, src, args.timeout)
        if not solid:
            print(f"{name}: not a solid texgeo accepts, skipped", file=sys.stderr)
            continue
        # texgeo's own reader normalises the corpus' OFF dialects (COFF colours, comments), and
        # its STL writer triangulates polygons as every command does (a fan of a non-convex
        # polygon would cross itself)
        plain = os.path.join(work, f"{name[:-4]}.in.off")
        tri = os.path.join(work, f"{name[:-4]}.in.stl")
        if any(run([args.texgeo, "mesh", "convert", i, o], args.timeout)[1] != 0
               for i, o in ((src, tri), (tri, plain))):
            print(f"{name}: texgeo could not convert it, skipped", file=sys.stderr)
            continue
        pos, tris = read_off(plain)
        if args.max_faces and len(tris) > args.max_faces:
            continue
        stem = name[:-4]
        a_path = os.path.join(work, f"{stem}.A.off")
        write_off(a_path, pos, tris)
        for tname in transforms:
            pb, tb = TRANSFORMS[tname](pos, tris)
            b_path = os.path.join(work, f"{stem}.{tname}.B.off")
            write_off(b_path, pb, tb)
            ref, cgal_dt = ({}, None)
            if earlier is not None:
                ref, cgal_dt = earlier.get((stem, len(tris), tname), ({}, None))
            elif not args.no_cgal:
                ref, cgal_dt = cgal_all(args.cgal, a_path, b_path, args.timeout)
            for op in ops:
                cgal_outcome, cgal_volume = ref.get(op, ("skipped", None))
                base = dict(model=stem, triangles=len(tris), transform=tname, op=op)
                if not args.no_cgal:
                    rows.append(dict(base, tool="cgal", outcome=cgal_outcome, seconds=cgal_dt,
                                     volume=cgal_volume, rel_volume_diff="", valid="", message=""))
                for tool in ("texgeo", "manifold"):
                    out = os.path.join(work, f"{stem}.{tname}.{op}.{tool}.off")
                    exact = None
                    if tool == "texgeo":
                        outcome, dt, msg, exact = texgeo_op(args.texgeo, a_path, b_path, op, out, args.timeout)
                    else:
                        outcome, dt, msg = manifold_op(pos, tris, pb, tb, op, out)
                    volume, written, valid, diff, written_diff = None, None, "", "", ""
                    if outcome == "ok":
                        ok_solid, written = stats_of(args.texgeo, out, args.timeout)
                        valid = "yes" if ok_solid else "no"
                        volume = exact if exact is not None else written
                        diff = rel_diff(volume, cgal_volume)
                        written_diff = rel_diff(written, cgal_volume)
                    rows.append(dict(base, tool=tool, outcome=outcome, seconds=dt, volume=volume,
                                     rel_volume_diff=diff, valid=valid, message=msg,
                                     written_volume=written, written_rel_volume_diff=written_diff))
                    if os.path.exists(out):
                        os.remove(out)
                line = " ".join(f"{r['tool']}={r['outcome']}" for r in rows[-(2 if args.no_cgal else 3):])
                print(f"{stem} {tname} {op}: {line}", file=sys.stderr)
        write_tables(args.out, rows, quiet=True)  # a long run keeps what it measured so far
    write_tables(args.out, rows)


def rel_diff(volume, reference):
    """|volume − reference| relative to the reference (absolute when it is 0); "" without both."""
    if volume is None or reference is None:
        return ""
    return abs(volume - reference) / abs(reference) if reference else abs(volume)


# volume: texgeo's exact volume (before rounding), manifold's written file's; written_volume:
# the written file's, as `texgeo mesh stats` measures it.
FIELDS = ["model", "triangles", "transform", "op", "tool", "outcome", "seconds", "volume",
          "rel_volume_diff", "valid", "message", "written_volume", "written_rel_volume_diff"]


def cgal_answers(path):
    """CGAL's answers in an earlier results.csv: {(model, triangles, transform): ({op: (outcome,
    volume)}, seconds)}; the triangle count keys them to the same input."""
    found = {}
    for r in read_rows(os.path.dirname(path) or ".", os.path.basename(path)):
        if r["tool"] == "cgal":
            ref, _ = found.setdefault((r["model"], r["triangles"], r["transform"]), ({}, r["seconds"]))
            ref[r["op"]] = (r["outcome"], r["volume"])
    return found


def read_rows(out, name="results.csv"):
    """The rows of an earlier run's results.csv, numbers as numbers (empty when there is none)."""
    path = os.path.join(out, name)
    if not os.path.exists(path):
        return []
    rows = []
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            r["triangles"] = int(r["triangles"])
            for k in ("seconds", "volume", "written_volume"):
                r[k] = float(r[k]) if r.get(k) not in ("", None) else None
            for k in ("rel_volume_diff", "written_rel_volume_diff"):
                r[k] = float(r[k]) if r.get(k) not in ("", None) else ""
            rows.append(r)
    return rows


def write_tables(out, rows, quiet=False):
    fields = FIELDS
    tmp = os.path.join(out, "results.csv.tmp")
    with open(tmp, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields)
        w.writeheader()
        for r in rows:
            w.writerow({k: ("" if r.get(k) is None else r.get(k)) for k in fields})
    os.replace(tmp, os.path.join(out, "results.csv"))
    outcomes = ["ok", "refused", "failed", "timeout"]
    lines = ["| tool | transform | runs | " + " | ".join(outcomes) +
             " | invalid results | volume off by > 1e-9 | written file's volume off by > 1e-9"
             " | max rel. volume diff vs CGAL | median s |",
             "|---|---|---:|" + "---:|" * len(outcomes) + "---:|---:|---:|---:|---:|"]
    keys = sorted({(r["tool"], r["transform"]) for r in rows}, key=lambda k: (k[0] != "texgeo", k))
    table = []
    for tool, tname in keys + [(t, "all") for t in sorted({r["tool"] for r in rows})]:
        sel = [r for r in rows if r["tool"] == tool and (tname == "all" or r["transform"] == tname)]
        counts = [sum(r["outcome"] == o for r in sel) for o in outcomes]
        invalid = sum(r["valid"] == "no" for r in sel)
        diffs = [r["rel_volume_diff"] for r in sel if r["rel_volume_diff"] != ""]
        written_diffs = [r["written_rel_volume_diff"] for r in sel if r.get("written_rel_volume_diff", "") != ""]
        times = [r["seconds"] for r in sel if r["outcome"] == "ok" and r["seconds"] is not None]
        cells = [tool, tname, str(len(sel))] + [str(c) for c in counts]
        cells += [str(invalid) if tool != "cgal" else "",
                  str(sum(d > 1e-9 for d in diffs)) if tool != "cgal" else "",
                  str(sum(d > 1e-9 for d in written_diffs)) if tool != "cgal" else "",
                  f"{max(diffs):.1e}" if diffs else "",
                  f"{statistics.median(times):.3f}" if times else ""]
        table.append(cells)
        md = [c or "–" for c in cells]
        md[1] = f"**{tname}**" if tname == "all" else tname
        lines.append("| " + " | ".join(md) + " |")
    with open(os.path.join(out, "table.md.tmp"), "w") as f:
        f.write("\n".join(lines) + "\n")
    os.replace(os.path.join(out, "table.md.tmp"), os.path.join(out, "table.md"))
    with open(os.path.join(out, "table.csv.tmp"), "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(["tool", "transform", "runs"] + outcomes +
                   ["invalid results", "volume off by > 1e-9", "written file's volume off by > 1e-9",
                    "max rel. volume diff vs CGAL", "median s"])
        w.writerows(table)
    os.replace(os.path.join(out, "table.csv.tmp"), os.path.join(out, "table.csv"))
    if not quiet:
        print(os.path.join(out, "table.md"), file=sys.stderr)


if __name__ == "__main__":
    main()
