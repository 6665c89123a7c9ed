"""The Python module gives the CLI's answers on the same inputs: labels, voxels,
subdivided meshes, Boolean volumes, stats and error messages."""

import json
import os
import pathlib
import subprocess

import numpy as np
import pytest

import texgeo

ROOT = pathlib.Path(__file__).resolve().parents[2]
CLI = os.environ.get("TEXGEO_BIN", str(ROOT / "target" / "release" / "texgeo"))


def cli(*args, check=True):
    """Runs the texgeo CLI; its completed process."""
    p = subprocess.run([CLI, *map(str, args)], capture_output=True, text=True)
    if check and p.returncode != 0:
        raise AssertionError(f"texgeo {' '.join(map(str, args))}: {p.stderr}")
    return p


def cli_error(*args):
    """The CLI's one-line error message (without the `texgeo: error: ` prefix)."""
    p = cli(*args, check=False)
    assert p.returncode == 2, p
    line = p.stderr.strip()
    assert line.startswith("texgeo: error: ") and "\n" not in line, line
    return line[len("texgeo: error: "):]


def cube(offset=(0.0, 0.0, 0.0)):
    v = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float) + offset
    faces = np.array([[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]])
    return texgeo.Mesh(v, faces)


def test_the_cli_is_there():
    assert pathlib.Path(CLI).is_file(), f"build the CLI first (cargo build --release): {CLI}"


@pytest.mark.parametrize("name", ["torus", "knot", "cavity"])
def test_contains_gives_the_cli_labels(tmp_path, name):
    mesh = texgeo.load(f"builtin:{name}")
    lo, hi = np.array(mesh.stats()["bbox"])
    rng = np.random.default_rng(7)
    # Random points, the vertices (on the boundary) and face centres (on it too).
    points = np.vstack([lo + (hi - lo) * rng.random((2000, 3)), mesh.vertices])
    np.save(tmp_path / "p.npy", points)
    cli("inclusion", f"builtin:{name}", "--points", tmp_path / "p.npy", "--method", "cpu", "-o", tmp_path / "l.npy")
    want = np.load(tmp_path / "l.npy")
    for method in ["auto", "cpu", "octants", "bvh"]:
        got = mesh.contains(points, method)
        assert got.dtype == np.uint8 and got.shape == (len(points),)
        assert np.array_equal(got, want), method
    assert (want[2000:] == 2).all()
    # float32 and lists are any (N, 3) float array.
    assert np.array_equal(mesh.contains(points.astype(np.float32)),
                          mesh.contains(points.astype(np.float32).astype(np.float64)))
    assert mesh.contains(points[:10].tolist()).tolist() == want[:10].tolist()


def test_voxelize_gives_the_cli_voxels(tmp_path):
    for name, res in [("knot", 24), ("cavity", 17)]:
        cli("voxelize", f"builtin:{name}", "--res", res, "-o", tmp_path / "cli.npy")
        cli("voxelize", f"builtin:{name}", "--res", res, "-o", tmp_path / "cli.binvox")
        v = texgeo.load(f"builtin:{name}").voxelize(res)
        want = np.load(tmp_path / "cli.npy")
        assert v.occupied.shape == (res, res, res) and v.occupied.dtype == np.bool_
        assert np.array_equal(v.occupied, want), name
        grid = json.loads((tmp_path / "cli.json").read_text())
        assert v.origin.tolist() == grid["origin"] and v.pitch == grid["pitch"]
        v.save(tmp_path / "py.binvox")
        assert (tmp_path / "py.binvox").read_bytes() == (tmp_path / "cli.binvox").read_bytes()
        v.save(tmp_path / "py.npy")
        assert np.array_equal(np.load(tmp_path / "py.npy"), want)
    # Voxel (i, j, k)'s centre is origin + (i + ½, j + ½, k + ½) · pitch: occupied iff inside.
    torus = texgeo.load("builtin:torus")
    v = torus.voxelize(12, "cpu")
    idx = np.indices((12, 12, 12)).reshape(3, -1).T
    labels = torus.contains(v.origin + (idx + 0.5) * v.pitch)
    assert np.array_equal(v.occupied.reshape(-1), labels == 1)


@pytest.mark.parametrize("method", ["cpu", "gpu"])
def test_subdivide_gives_the_cli_mesh(tmp_path, method):
    src = tmp_path / "tagged.obj"
    # A cube with one infinitely sharp crease edge (OpenSubdiv's tag): honoured as in the CLI.
    src.write_text(
        "v -1 -1 -1\nv 1 -1 -1\nv -1 1 -1\nv 1 1 -1\nv -1 -1 1\nv 1 -1 1\nv -1 1 1\nv 1 1 1\n"
        "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\nt crease 2/1/0 0 1 10\n"
    )
    cli("subdivide", src, "-l", 3, "--method", method, "-o", tmp_path / "cli.obj")
    refined = texgeo.load(src).subdivide(3, method)
    refined.save(tmp_path / "py.obj")
    assert (tmp_path / "py.obj").read_bytes() == (tmp_path / "cli.obj").read_bytes()
    assert refined.stats()["faces"] == 6 * 4 ** 3
    plain = texgeo.Mesh(texgeo.load(src).vertices, texgeo.load(src).polygons()).subdivide(3, method)
    assert not np.array_equal(plain.vertices, refined.vertices), "the crease tag changes the surface"


def test_boolean_volumes():
    a, b = cube(), cube((1.0, 0.0, 0.0))
    want = {"union": 12.0, "intersection": 4.0, "difference": 4.0, "symmetric-difference": 8.0}
    for op, volume in want.items():
        assert texgeo.boolean(a, b, op).volume == pytest.approx(volume, rel=1e-12)
    assert (a | b).volume == pytest.approx(12.0)
    assert (a & b).volume == pytest.approx(4.0)
    assert (a - b).volume == pytest.approx(4.0)
    assert (a ^ b).volume == pytest.approx(8.0)
    c = cube((0.0, 1.0, 0.0))
    expr = texgeo.csg("(a | b) - c", a=a, b=b, c=c)
    assert expr.volume == pytest.approx(8.0)  # 12 minus the 2 × 1 × 2 the union shares with c
    assert expr.stats()["solid"] is True


def test_boolean_gives_the_cli_volume(tmp_path):
    out = tmp_path / "u.off"
    line = cli("boolean", "builtin:cube", "builtin:sphere", "--op", "union", "-o", out, "--json").stdout
    want = json.loads(line)["operations"][0]
    got = texgeo.load("builtin:cube") | texgeo.load("builtin:sphere")
    assert got.volume == want["volume"] and len(got.triangles()) == want["triangles"]


def test_stats_are_the_cli_json(tmp_path):
    for name in ["torus", "cavity", "two-cubes"]:
        want = json.loads(cli("mesh", "stats", f"builtin:{name}", "--json").stdout)
        got = texgeo.load(f"builtin:{name}").stats()
        assert got == want
        for key in ["vertices", "faces", "closed", "oriented", "manifold", "solid", "volume", "area", "bbox"]:
            assert key in got
        assert isinstance(got["solid"], bool)
        assert ("reason" in got) == (not got["solid"])


def test_load_places_the_mesh_by_the_steps_after_at():
    cube = texgeo.load("builtin:cube")
    placed = texgeo.load("builtin:cube@scale 2; translate 1 0 0")
    assert np.allclose(placed.vertices, cube.vertices * 2 + [1, 0, 0])
    with pytest.raises(texgeo.MeshError, match="unknown transform step 'twist 3'"):
        texgeo.load("builtin:cube@twist 3")


def test_arrays_round_trip(tmp_path):
    m = texgeo.load("builtin:cube")
    assert m.vertices.shape == (8, 3) and m.vertices.dtype == np.float64
    assert m.triangles().shape == (12, 3) and m.triangles().dtype == np.int64
    polys = m.polygons()
    assert len(polys) == 6 and all(p.dtype == np.int64 and len(p) == 4 for p in polys)
    again = texgeo.Mesh(m.vertices, polys)
    assert np.array_equal(again.vertices, m.vertices)
    assert [p.tolist() for p in again.polygons()] == [p.tolist() for p in polys]
    tri = texgeo.Mesh(m.vertices, m.triangles())
    assert tri.volume == pytest.approx(m.volume) and tri.area == pytest.approx(m.area)
    m.save(tmp_path / "c.off")
    assert texgeo.load(tmp_path / "c.off").stats()["volume"] == 8.0


def test_errors_carry_the_cli_message(tmp_path):
    missing = tmp_path / "missing.obj"
    with pytest.raises(texgeo.MeshError) as e:
        texgeo.load(missing)
    assert str(e.value) == cli_error("mesh", "stats", missing)
    with pytest.raises(texgeo.MeshError, match="no built-in model"):
        texgeo.load("builtin:nope")
    open_mesh = texgeo.Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], [[0, 2, 1], [0, 1, 3], [0, 3, 2]])
    with pytest.raises(texgeo.NotASolid) as e:
        open_mesh.contains(np.zeros((1, 3)))
    assert isinstance(e.value, texgeo.Error)
    open_mesh.save(tmp_path / "open.obj")
    assert str(e.value) in cli_error("inclusion", tmp_path / "open.obj", "--random", 1)
    # Under allow_open: the winding number rule, as the CLI's --allow-open.
    assert open_mesh.contains([[0.1, 0.1, 0.1]], allow_open=True).shape == (1,)
    with pytest.raises(texgeo.InclusionError, match="unknown inclusion method"):
        cube().contains(np.zeros((1, 3)), "nope")
    with pytest.raises(texgeo.BooleanError, match="unknown operation"):
        texgeo.boolean(cube(), cube(), "merge")
    with pytest.raises(texgeo.BooleanError):
        texgeo.csg("a | b", a=cube())


@pytest.mark.parametrize(
    "vertices, faces, needle",
    [
        (np.zeros((3, 2)), [[0, 1, 2]], "shape"),
        ([[0, 0, np.nan], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]], "finite"),
        ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 3]], "outside"),
        ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, -1]], "outside"),
        ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.array([[0.0, 1.0, 2.0]]), "integer"),
        ([["a", "b", "c"]], [[0, 1, 2]], "numbers"),
        ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1]], "invalid mesh"),
    ],
)
def test_bad_arrays_raise(vertices, faces, needle):
    with pytest.raises(texgeo.MeshError, match=needle):
        texgeo.Mesh(vertices, faces)


def test_bad_points_raise():
    m = cube()
    for bad in [np.zeros((4, 2)), np.zeros(3), [[0, 0, np.inf]], [[1, 2, "x"]]]:
        with pytest.raises(texgeo.MeshError):
            m.contains(bad)
    with pytest.raises(texgeo.VoxelError):
        m.voxelize(0)
    with pytest.raises(texgeo.VoxelError):
        m.voxelize(2000)


def test_threads_do_not_change_answers():
    knot = texgeo.load("builtin:knot")
    points = np.random.default_rng(3).uniform(-3, 3, (5000, 3))
    texgeo.set_threads(1)
    one = knot.contains(points)
    texgeo.set_threads(3)
    assert np.array_equal(knot.contains(points), one)
    with pytest.raises(texgeo.Error):
        texgeo.set_threads(0)


def test_device_describes_the_cli_device():
    d = texgeo.device()
    want = json.loads(cli("info", "--json").stdout)
    assert d["device"]["name"] == want["device"]["name"]
