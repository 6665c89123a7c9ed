"""texgeo from Python: exact point-in-solid tests, solid voxelization, Catmull-Clark
subdivision and Boolean operations on NumPy arrays.

Every function calls the same library as the ``texgeo`` command line and gives its
answers: ``Mesh.contains`` the labels of ``texgeo inclusion``, ``Mesh.voxelize`` the
voxels of ``texgeo voxelize``, ``Mesh.subdivide`` the mesh of ``texgeo subdivide``,
``boolean`` and ``csg`` the solids of ``texgeo boolean`` and ``texgeo csg``.

>>> import texgeo, numpy as np
>>> torus = texgeo.load("builtin:torus")
>>> torus.contains(np.array([[1.0, 0, 0], [0, 0, 0]]))
array([1, 0], dtype=uint8)

Errors raise :class:`Error` or one of its subclasses with the CLI's one-line message.
The Vulkan device is opened once per process, on first use, and only by the methods
that need it (``TEXGEO_DEVICE`` chooses it, as for the CLI). The GIL is released while
texgeo works; :func:`set_threads` sizes its thread pool.
"""

from __future__ import annotations

import json as _json
import os as _os

import numpy as _np

from . import _texgeo
from ._texgeo import (
    BooleanError,
    DeviceError,
    Error,
    InclusionError,
    MeshError,
    NotASolid,
    SubdivisionError,
    VoxelError,
)

__all__ = [
    "Mesh",
    "Voxels",
    "load",
    "boolean",
    "csg",
    "device",
    "set_threads",
    "builtins",
    "OPERATIONS",
    "Error",
    "MeshError",
    "NotASolid",
    "DeviceError",
    "InclusionError",
    "VoxelError",
    "SubdivisionError",
    "BooleanError",
]

#: The Boolean operations :func:`boolean` takes.
OPERATIONS = ("union", "intersection", "difference", "symmetric-difference")


def _float_rows(array, what: str) -> _np.ndarray:
    """``array`` as a C-contiguous (n, 3) float64 array, or MeshError."""
    try:
        a = _np.asarray(array)
    except Exception as e:  # ragged lists and other objects NumPy refuses
        raise MeshError(f"{what}: not an array of numbers ({e})") from None
    if a.dtype.kind not in "fiu" or a.dtype == _np.bool_:
        raise MeshError(f"{what}: expected numbers, got an array of {a.dtype}")
    if a.ndim != 2 or a.shape[1] != 3:
        raise MeshError(f"{what}: expected an (n, 3) array, got shape {a.shape}")
    a = _np.ascontiguousarray(a, dtype="<f8")
    if not _np.isfinite(a).all():
        row = int(_np.argwhere(~_np.isfinite(a))[0][0])
        raise MeshError(f"{what}: row {row} has a coordinate that is not a finite number")
    return a


def _faces(faces):
    """(offsets, int64 index bytes) of an (m, k) int array or a list of index sequences."""
    if isinstance(faces, _np.ndarray) and faces.ndim == 2:
        if faces.dtype.kind not in "iu":
            raise MeshError(f"faces: expected integer indices, got an array of {faces.dtype}")
        m, k = faces.shape
        flat = _np.ascontiguousarray(faces.reshape(-1), dtype="<i8")
        return [i * k for i in range(m + 1)], flat.tobytes()
    offsets = [0]
    parts = []
    try:
        for face in faces:
            f = _np.asarray(face)
            if f.ndim != 1 or (f.size and f.dtype.kind not in "iu"):
                raise MeshError(f"faces: face {len(parts)} is not a sequence of integer indices")
            parts.append(_np.ascontiguousarray(f, dtype="<i8"))
            offsets.append(offsets[-1] + f.size)
    except TypeError:
        raise MeshError("faces: expected an (m, k) integer array or a list of index sequences") from None
    flat = _np.concatenate(parts) if parts else _np.zeros(0, dtype="<i8")
    return offsets, flat.tobytes()


def _from_bytes(data, dtype, shape) -> _np.ndarray:
    return _np.frombuffer(data, dtype=dtype).reshape(shape)


class Mesh:
    """A polygon mesh: ``Mesh(vertices, faces)`` or :func:`load`.

    ``vertices`` is an (n, 3) float array; ``faces`` an (m, k) integer array or a list of
    index sequences (polygons, counter-clockwise seen from outside). Coordinates must be
    finite and indices in range, else :class:`MeshError`.
    """

    __slots__ = ("_raw",)

    def __init__(self, vertices, faces):
        v = _float_rows(vertices, "vertices")
        offsets, indices = _faces(faces)
        self._raw = _texgeo.RawMesh.from_arrays(v.tobytes(), offsets, indices)

    @classmethod
    def _wrap(cls, raw) -> "Mesh":
        mesh = cls.__new__(cls)
        mesh._raw = raw
        return mesh

    def __repr__(self) -> str:
        return f"<texgeo.Mesh: {self._raw.num_vertices} vertices, {self._raw.num_faces} faces>"

    @property
    def vertices(self) -> _np.ndarray:
        """The (n, 3) float64 vertex positions (a copy)."""
        return _from_bytes(self._raw.vertices(), "<f8", (self._raw.num_vertices, 3))

    def triangles(self) -> _np.ndarray:
        """The faces as a (t, 3) int64 array: planar polygons triangulated in their plane
        as ``texgeo mesh convert`` does for STL, over the same vertices."""
        data = self._raw.triangles()
        return _from_bytes(data, "<i8", (len(data) // 24, 3))

    def polygons(self) -> list:
        """The faces as a list of int64 arrays of vertex indices."""
        offsets, indices = self._raw.face_parts()
        o = _np.frombuffer(offsets, dtype="<i8")
        idx = _np.frombuffer(indices, dtype="<i8")
        return [idx[o[i] : o[i + 1]].copy() for i in range(len(o) - 1)]

    def save(self, path) -> None:
        """Writes the mesh (.obj .off .ply .stl, by extension), atomically."""
        self._raw.save(_os.fspath(path))

    def stats(self) -> dict:
        """What ``texgeo mesh stats --json`` prints: counts, ``closed``, ``oriented``,
        ``manifold``, ``solid`` (and ``reason`` when it is not), ``volume`` (None when the
        surface is not closed), ``area``, ``bbox``, centroids."""
        return _json.loads(self._raw.stats_json())

    @property
    def volume(self):
        """The enclosed volume (signed tetrahedra), or None when the surface is not closed
        and consistently oriented."""
        return self.stats()["volume"]

    @property
    def area(self) -> float:
        """The surface area."""
        return self.stats()["area"]

    def contains(self, points, method: str = "auto", *, allow_open: bool = False,
                 flip_inverted: bool = False) -> _np.ndarray:
        """Classifies points like ``texgeo inclusion``: an (N,) uint8 array, 0 outside,
        1 inside, 2 on the boundary.

        ``points`` is any (N, 3) float array. ``method`` is one of the CLI's (``auto``
        picks the fastest exact one; every method gives the same answers). A mesh that is
        not a solid raises :class:`NotASolid` unless ``allow_open`` (then inside iff the
        generalized winding number is at least ½).
        """
        p = _float_rows(points, "points")
        labels, _ = self._raw.contains(p.tobytes(), method, allow_open, flip_inverted)
        return _np.frombuffer(labels, dtype=_np.uint8)

    def voxelize(self, res: int, method: str = "auto", *, allow_open: bool = False,
                 flip_inverted: bool = False) -> "Voxels":
        """Solid voxelization like ``texgeo voxelize``: ``res``³ voxels over the mesh's
        bounding cube; a voxel is occupied iff its centre is inside."""
        if isinstance(res, bool) or not isinstance(res, (int, _np.integer)):
            raise VoxelError(f"res must be a whole number, not {res!r}")
        if res < 1:
            raise VoxelError(f"resolution {res} is outside 1..=1024")
        return Voxels(self._raw.voxelize(int(res), method, allow_open, flip_inverted))

    def subdivide(self, level: int, method: str = "gpu", boundary: str | None = None,
                  crease_angle: float | None = None, crease_sharpness: float = 10.0) -> "Mesh":
        """Catmull-Clark subdivision like ``texgeo subdivide``: ``method`` ``gpu``
        (fragment meshes) or ``cpu`` (the f64 reference). The sharp-feature tags of the OBJ
        file the mesh was loaded from are honoured; ``boundary`` (none, edge-only,
        edge-and-corner) overrides its ``t interpolateboundary``; ``crease_angle`` also
        creases every edge whose faces meet at more than that many degrees."""
        if isinstance(level, bool) or not isinstance(level, (int, _np.integer)) or level < 0:
            raise SubdivisionError(f"level must be a whole number ≥ 0, not {level!r}")
        return Mesh._wrap(self._raw.subdivide(int(level), method, boundary, crease_angle, crease_sharpness))

    def __or__(self, other: "Mesh") -> "Mesh":
        return boolean(self, other, "union")

    def __and__(self, other: "Mesh") -> "Mesh":
        return boolean(self, other, "intersection")

    def __sub__(self, other: "Mesh") -> "Mesh":
        return boolean(self, other, "difference")

    def __xor__(self, other: "Mesh") -> "Mesh":
        return boolean(self, other, "symmetric-difference")


class Voxels:
    """A solid voxelization: ``occupied`` an (N, N, N) bool array indexed ``[x, y, z]``;
    voxel (i, j, k)'s centre is ``origin + (i + ½, j + ½, k + ½) · pitch``."""

    __slots__ = ("_raw", "occupied", "origin", "pitch", "method")

    def __init__(self, raw):
        self._raw = raw
        n = raw.n
        self.occupied = _np.frombuffer(raw.occupied(), dtype=_np.bool_).reshape(n, n, n)
        #: The bounding cube's minimum corner, (3,) float64.
        self.origin = _np.array(raw.origin, dtype=_np.float64)
        #: The cube's side / N.
        self.pitch = float(raw.pitch)
        #: The method that ran.
        self.method = raw.method

    def __repr__(self) -> str:
        n = self.occupied.shape[0]
        return f"<texgeo.Voxels: {n}³, {int(self.occupied.sum())} occupied, method {self.method}>"

    def save(self, path) -> None:
        """Writes ``.binvox``, or ``.npy`` (this bool array; the grid in a ``.json`` of the
        same stem beside it), atomically."""
        self._raw.save(_os.fspath(path))


def load(path) -> Mesh:
    """Reads a mesh (.obj .off .ply .stl; an OBJ's sharp-feature tags are kept for
    :meth:`Mesh.subdivide`) or a built-in model ``"builtin:NAME"`` (see :func:`builtins`),
    placed by the transform steps after ``@`` if any, as ``texgeo csg`` takes them:
    ``load("part.off@rotate z 90; translate 1 0 0")``."""
    return Mesh._wrap(_texgeo.load(_os.fspath(path)))


def builtins() -> list:
    """The names of the built-in models (``load("builtin:NAME")``)."""
    return list(_texgeo.builtins())


def boolean(a: Mesh, b: Mesh, op: str, *, method: str = "octants",
            allow_self_intersections: bool = False) -> Mesh:
    """A Boolean operation on two closed solids, like ``texgeo boolean``: ``op`` one of
    ``union``, ``intersection``, ``difference`` (a − b), ``symmetric-difference``. The
    operators ``a | b``, ``a & b``, ``a - b``, ``a ^ b`` call it."""
    if not isinstance(a, Mesh) or not isinstance(b, Mesh):
        raise BooleanError("boolean: both operands must be texgeo.Mesh")
    return Mesh._wrap(_texgeo.boolean_op(a._raw, b._raw, op, method, allow_self_intersections))


def csg(expr: str, *, method: str = "octants", allow_self_intersections: bool = False,
        **operands: Mesh) -> Mesh:
    """A CSG expression over named solids, like ``texgeo csg``:
    ``csg("(a | b) - c", a=m1, b=m2, c=m3)``. ``|`` union, ``&`` intersection, ``-``
    difference, ``^`` symmetric difference, with Python's precedence."""
    for name, m in operands.items():
        if not isinstance(m, Mesh):
            raise BooleanError(f"csg: operand {name} is not a texgeo.Mesh")
    names = list(operands)
    return Mesh._wrap(_texgeo.csg(expr, names, [operands[n]._raw for n in names], method,
                                  allow_self_intersections))


def device() -> dict:
    """The Vulkan device texgeo uses (``texgeo info --json``), opened if it was not."""
    return _json.loads(_texgeo.device_json())


def set_threads(n: int) -> None:
    """Runs texgeo's CPU work on ``n`` threads from now on (default: every core); the
    answers do not depend on it."""
    if isinstance(n, bool) or not isinstance(n, (int, _np.integer)):
        raise Error(f"set_threads: expected a whole number, not {n!r}")
    _texgeo.set_threads(int(n))
