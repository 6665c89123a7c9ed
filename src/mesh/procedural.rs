//! Built-in models, so every algorithm runs with no download (SPEC §7). All are closed and
//! consistently oriented (counter-clockwise seen from outside, so the signed volume is
//! positive), and manifold unless stated.

use std::collections::HashMap;
use std::f64::consts::TAU;

use glam::DVec3;

use super::Mesh;

/// The names [`by_name`] knows.
pub const BUILTIN_NAMES: &[&str] =
    &["cube", "tetrahedron", "pyramid", "sphere", "torus", "knot", "two-cubes", "cavity", "l-prism", "star"];

/// A built-in model by name (see [`BUILTIN_NAMES`]), with default parameters:
/// `sphere` = `sphere(16, 32)`, `torus` = `torus(1.0, 0.4, 32, 16)`.
pub fn by_name(name: &str) -> Option<Mesh> {
    Some(match name {
        "cube" => cube(),
        "tetrahedron" => tetrahedron(),
        "pyramid" => pyramid(),
        "sphere" => sphere(16, 32),
        "torus" => torus(1.0, 0.4, 32, 16),
        "knot" => torus_knot(),
        "two-cubes" => two_cubes_sharing_edge(),
        "cavity" => cube_with_cavity(),
        "l-prism" => l_prism(),
        "star" => star_prism(),
        _ => return None,
    })
}

/// A prism of height `height` over the counter-clockwise polygon `outline` (in the xy
/// plane, extruded along +z), its two caps kept as whole n-gons: the solid for tests of
/// polygon faces (a non-convex outline gives negative covering triangles). `None` for an
/// outline of fewer than 3 points or a non-finite coordinate.
pub fn prism(outline: &[(f64, f64)], height: f64) -> Option<Mesh> {
    let n = u32::try_from(outline.len()).ok().filter(|&n| n >= 3)?;
    let mut positions: Vec<DVec3> = outline.iter().map(|&(x, y)| DVec3::new(x, y, 0.0)).collect();
    positions.extend(outline.iter().map(|&(x, y)| DVec3::new(x, y, height)));
    let mut faces = vec![(0..n).rev().collect::<Vec<_>>(), (n..2 * n).collect()];
    for i in 0..n {
        let j = (i + 1) % n;
        faces.push(vec![i, j, n + j, n + i]);
    }
    Mesh::new(positions, faces).ok()
}

/// The L-shaped prism [0,4]×[0,1] ∪ [0,1]×[1,3], height 1, with its two non-convex
/// hexagon caps kept whole (their covering fans have negative triangles).
pub fn l_prism() -> Mesh {
    let outline = [(0.0, 0.0), (4.0, 0.0), (4.0, 1.0), (1.0, 1.0), (1.0, 3.0), (0.0, 3.0)];
    prism(&outline, 1.0).unwrap_or_else(|| unreachable!("the L outline is a valid polygon"))
}

/// A five-pointed star prism, height 1: outer radius 2, inner radius 0.8, its caps kept as
/// whole non-convex 10-gons that no fan from one of their vertices covers (a tip sees
/// past the neighbouring notches), for triangulation tests.
pub fn star_prism() -> Mesh {
    let outline: Vec<(f64, f64)> = (0..10)
        .map(|i| {
            let r = if i % 2 == 0 { 2.0 } else { 0.8 };
            let t = TAU * f64::from(i) / 10.0 + TAU / 4.0;
            (r * t.cos(), r * t.sin())
        })
        .collect();
    prism(&outline, 1.0).unwrap_or_else(|| unreachable!("the star outline is a valid polygon"))
}

/// Builds a mesh from data this module made (always valid).
fn mesh(positions: Vec<DVec3>, faces: Vec<Vec<u32>>) -> Mesh {
    Mesh::new(positions, faces).unwrap_or_else(|e| unreachable!("procedural mesh is invalid: {e}"))
}

/// The axis-aligned box [lo, hi]: 8 vertices, 6 quads.
pub fn box_between(lo: DVec3, hi: DVec3) -> Mesh {
    // Vertex i has x from bit 0, y from bit 1, z from bit 2 (0 = lo, 1 = hi).
    let positions = (0..8)
        .map(|i| {
            DVec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            )
        })
        .collect();
    let faces = vec![
        vec![0, 4, 6, 2], // −x
        vec![1, 3, 7, 5], // +x
        vec![0, 1, 5, 4], // −y
        vec![2, 6, 7, 3], // +y
        vec![0, 2, 3, 1], // −z
        vec![4, 5, 7, 6], // +z
    ];
    mesh(positions, faces)
}

/// The box [0, 4]³ with its corner (4, 4, 4) raised to (4, 4, 6): its top quad is not
/// planar, so its surface is the fan from its centroid (2, 2, 4.5), which is exact here
/// (as are the corners in f32), for tests that every command and export uses that surface.
pub fn bent_box() -> Mesh {
    let b = box_between(DVec3::ZERO, DVec3::splat(4.0));
    let mut positions = b.positions().to_vec();
    positions[7].z = 6.0;
    mesh(positions, b.faces().map(<[u32]>::to_vec).collect())
}

/// The cube [−1, 1]³: 8 vertices, 6 quads.
pub fn cube() -> Mesh {
    box_between(DVec3::splat(-1.0), DVec3::splat(1.0))
}

/// A regular tetrahedron inscribed in the cube [−1, 1]³.
pub fn tetrahedron() -> Mesh {
    let positions = vec![
        DVec3::new(1.0, 1.0, 1.0),
        DVec3::new(1.0, -1.0, -1.0),
        DVec3::new(-1.0, 1.0, -1.0),
        DVec3::new(-1.0, -1.0, 1.0),
    ];
    mesh(positions, vec![vec![0, 1, 2], vec![0, 3, 1], vec![0, 2, 3], vec![1, 3, 2]])
}

/// The octahedron |x−o.x| + |y−o.y| + |z−o.z| ≤ r: 6 vertices, 8 triangles.
pub fn octahedron(o: DVec3, r: f64) -> Mesh {
    let positions = vec![
        o + DVec3::X * r,
        o - DVec3::X * r,
        o + DVec3::Y * r,
        o - DVec3::Y * r,
        o + DVec3::Z * r,
        o - DVec3::Z * r,
    ];
    let faces = [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]];
    mesh(positions, faces.iter().map(|f| f.to_vec()).collect())
}

/// A cone over a regular `sides`-gon in z = 0 (its base one n-gon), apex (0, 0, 1), sides
/// triangulated: the apex has valence `sides` (high-valence subdivision cases).
pub fn cone(sides: u32) -> Mesh {
    let mut positions: Vec<DVec3> = (0..sides)
        .map(|i| {
            let a = TAU * f64::from(i) / f64::from(sides);
            DVec3::new(a.cos(), a.sin(), 0.0)
        })
        .collect();
    positions.push(DVec3::new(0.0, 0.0, 1.0));
    let mut faces: Vec<Vec<u32>> = (0..sides).map(|i| vec![i, (i + 1) % sides, sides]).collect();
    faces.push((0..sides).rev().collect());
    mesh(positions, faces)
}

/// Two fans around the z axis over one ring: `sides` ring vertices on the unit circle in
/// z = 0 (≥ 3), every top triangle sharing the apex (0, 0, `top`) and every bottom one the
/// apex (0, 0, −`bottom`); `2 · sides` triangles. With `bottom` = 0 the bottom is a flat
/// fan around the ring's centre (a cone with a fanned base). The apexes have valence
/// `sides` and, with many sides, every triangle is a long sliver whose box overlaps those
/// of the other fan: the worst case for a box-based self-intersection test.
/// `top` must be positive and `bottom` non-negative.
pub fn bicone(sides: u32, top: f64, bottom: f64) -> Mesh {
    let sides = sides.max(3);
    let mut positions: Vec<DVec3> = (0..sides)
        .map(|i| {
            let a = TAU * f64::from(i) / f64::from(sides);
            DVec3::new(a.cos(), a.sin(), 0.0)
        })
        .collect();
    positions.push(DVec3::new(0.0, 0.0, top));
    positions.push(DVec3::new(0.0, 0.0, 0.0 - bottom));
    let (apex, nadir) = (sides, sides + 1);
    let mut faces: Vec<Vec<u32>> = (0..sides).map(|i| vec![i, (i + 1) % sides, apex]).collect();
    faces.extend((0..sides).map(|i| vec![(i + 1) % sides, i, nadir]));
    mesh(positions, faces)
}

/// A cylinder of long slivers: a prism of height `height` over the regular `sides`-gon
/// on the unit circle (≥ 3), each side quad split along a diagonal into two triangles
/// that span the whole height, each cap fanned from its centre; `4 · sides` triangles.
/// With many sides and a tall prism the side triangles are long parallel slivers whose
/// boxes overlap along their whole length, and the cap centres have valence `sides`.
/// `height` must be positive.
pub fn sliver_cylinder(sides: u32, height: f64) -> Mesh {
    let sides = sides.max(3);
    let ring = |z: f64| {
        (0..sides).map(move |i| {
            let a = TAU * f64::from(i) / f64::from(sides);
            DVec3::new(a.cos(), a.sin(), z)
        })
    };
    let mut positions: Vec<DVec3> = ring(0.0).chain(ring(height)).collect();
    positions.extend([DVec3::ZERO, DVec3::new(0.0, 0.0, height)]);
    let (bottom, top) = (2 * sides, 2 * sides + 1);
    let mut faces: Vec<Vec<u32>> = Vec::with_capacity(4 * sides as usize);
    for i in 0..sides {
        let j = (i + 1) % sides;
        faces.extend([vec![i, j, sides + j], vec![i, sides + j, sides + i], vec![j, i, bottom]]);
        faces.push(vec![sides + i, sides + j, top]);
    }
    mesh(positions, faces)
}

/// A square pyramid: base [−1, 1]² at z = −1, apex (0, 0, 1); one quad and 4 triangles.
pub fn pyramid() -> Mesh {
    let positions = vec![
        DVec3::new(-1.0, -1.0, -1.0),
        DVec3::new(1.0, -1.0, -1.0),
        DVec3::new(1.0, 1.0, -1.0),
        DVec3::new(-1.0, 1.0, -1.0),
        DVec3::new(0.0, 0.0, 1.0),
    ];
    let faces = vec![vec![0, 3, 2, 1], vec![0, 1, 4], vec![1, 2, 4], vec![2, 3, 4], vec![3, 0, 4]];
    mesh(positions, faces)
}

/// The unit UV sphere: `rings` latitude bands (≥ 2) of `segments` faces (≥ 3); triangles
/// at the poles (z = ±1), quads elsewhere.
pub fn sphere(rings: usize, segments: usize) -> Mesh {
    let (rings, segments) = (rings.max(2), segments.max(3));
    let mut positions = vec![DVec3::Z];
    for i in 1..rings {
        let theta = std::f64::consts::PI * i as f64 / rings as f64;
        for j in 0..segments {
            let phi = TAU * j as f64 / segments as f64;
            positions.push(DVec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()));
        }
    }
    positions.push(DVec3::NEG_Z);
    let south = (positions.len() - 1) as u32;
    // Vertex j of latitude circle i (1 ≤ i < rings).
    let at = |i: usize, j: usize| (1 + (i - 1) * segments + j % segments) as u32;
    let mut faces = Vec::new();
    for j in 0..segments {
        faces.push(vec![0, at(1, j), at(1, j + 1)]);
    }
    for i in 1..rings - 1 {
        for j in 0..segments {
            faces.push(vec![at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    for j in 0..segments {
        faces.push(vec![south, at(rings - 1, j + 1), at(rings - 1, j)]);
    }
    mesh(positions, faces)
}

/// A torus around the z axis: tube centre at distance `major`, tube radius `minor`,
/// `nu` quads around the axis and `nv` around the tube (each ≥ 3); every vertex has
/// valence 4. Genus 1, Euler characteristic 0.
pub fn torus(major: f64, minor: f64, nu: usize, nv: usize) -> Mesh {
    let (nu, nv) = (nu.max(3), nv.max(3));
    let mut positions = Vec::with_capacity(nu * nv);
    for i in 0..nu {
        let u = TAU * i as f64 / nu as f64;
        for j in 0..nv {
            let v = TAU * j as f64 / nv as f64;
            let ring = major + minor * v.cos();
            positions.push(DVec3::new(ring * u.cos(), ring * u.sin(), minor * v.sin()));
        }
    }
    let at = |i: usize, j: usize| ((i % nu) * nv + j % nv) as u32;
    let mut faces = Vec::with_capacity(nu * nv);
    for i in 0..nu {
        for j in 0..nv {
            faces.push(vec![at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    mesh(positions, faces)
}

/// A tube of radius 0.4 around the (2,3) torus knot (the trefoil) on the torus of radii
/// 2 and 1: 75 rings of 8 vertices, 600 vertices and exactly 1200 triangles, like the
/// 2006 thesis' "Torusknot" (which has 808 vertices: its seams were not welded).
/// Closed, manifold, genus 1; strands stay ≥ 1.66 apart, so the tube does not
/// self-intersect.
pub fn torus_knot() -> Mesh {
    torus_knot_tube(75, 8)
}

/// The same (2,3) torus-knot tube with `along` rings of `around` vertices:
/// `2 · along · around` triangles (e.g. 400 × 8 = 6400, the size of CGAL's knot1.off).
/// Both counts are clamped to at least 3.
pub fn torus_knot_tube(along: usize, around: usize) -> Mesh {
    let (along, around) = (along.max(3), around.max(3));
    const TUBE: f64 = 0.4;
    let (p, q, big, small) = (2.0, 3.0, 2.0, 1.0);
    let curve = |t: f64| {
        let ring = big + small * (q * t).cos();
        DVec3::new(ring * (p * t).cos(), ring * (p * t).sin(), small * (q * t).sin())
    };
    let tangent = |t: f64| {
        let ring = big + small * (q * t).cos();
        let dring = -small * q * (q * t).sin();
        DVec3::new(
            dring * (p * t).cos() - ring * p * (p * t).sin(),
            dring * (p * t).sin() + ring * p * (p * t).cos(),
            small * q * (q * t).cos(),
        )
        .normalize()
    };
    let mut positions = Vec::with_capacity(along * around);
    for i in 0..along {
        let t = TAU * i as f64 / along as f64;
        let (c, tan) = (curve(t), tangent(t));
        // The direction away from the z axis is never along the tangent (the curve always
        // turns around the axis), so this frame is well defined and periodic.
        let radial = DVec3::new(c.x, c.y, 0.0).normalize();
        let n = (radial - radial.dot(tan) * tan).normalize();
        let b = tan.cross(n);
        for j in 0..around {
            let psi = TAU * j as f64 / around as f64;
            positions.push(c + TUBE * (psi.cos() * n + psi.sin() * b));
        }
    }
    let at = |i: usize, j: usize| ((i % along) * around + j % around) as u32;
    let mut faces = Vec::with_capacity(2 * along * around);
    for i in 0..along {
        for j in 0..around {
            // With (tangent, n, b) right-handed, going around j then along i faces outward.
            let (a, b, c, d) = (at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i + 1, j));
            faces.push(vec![a, b, c]);
            faces.push(vec![a, c, d]);
        }
    }
    mesh(positions, faces)
}

/// The cubes [0,1]³ and [1,2]×[1,2]×[0,1], sharing the edge x = y = 1 (and its two
/// vertices): closed and oriented, but that edge has four faces, so NOT manifold.
pub fn two_cubes_sharing_edge() -> Mesh {
    welded(&[
        box_between(DVec3::ZERO, DVec3::ONE),
        box_between(DVec3::new(1.0, 1.0, 0.0), DVec3::new(2.0, 2.0, 1.0)),
    ])
}

/// The cube [−2, 2]³ with a cubic cavity [−1, 1]³ (the inner cube's faces reversed, so
/// they face into the cavity): two components, Euler characteristic 4, volume 56.
pub fn cube_with_cavity() -> Mesh {
    let inner = box_between(DVec3::splat(-1.0), DVec3::splat(1.0));
    let reversed =
        mesh(inner.positions().to_vec(), inner.faces().map(|f| f.iter().rev().copied().collect()).collect());
    welded(&[box_between(DVec3::splat(-2.0), DVec3::splat(2.0)), reversed])
}

/// The union of `parts`, with vertices at bitwise-equal positions merged.
fn welded(parts: &[Mesh]) -> Mesh {
    let mut positions = Vec::new();
    let mut ids: HashMap<[u64; 3], u32> = HashMap::new();
    let mut faces = Vec::new();
    for part in parts {
        let map: Vec<u32> = part
            .positions()
            .iter()
            .map(|p| {
                *ids.entry(p.to_array().map(f64::to_bits)).or_insert_with(|| {
                    positions.push(*p);
                    (positions.len() - 1) as u32
                })
            })
            .collect();
        faces.extend(part.faces().map(|f| f.iter().map(|&i| map[i as usize]).collect::<Vec<_>>()));
    }
    mesh(positions, faces)
}
