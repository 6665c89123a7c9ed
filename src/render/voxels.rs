//! Voxel volumes as meshes for pictures: every face of an occupied voxel whose neighbour
//! is empty (or outside the grid) becomes a quad, coloured like its voxel — the volume's
//! boundary, drawn with far fewer triangles than instanced cubes would need.

use glam::DVec3;

use super::colour::Rgba;
use super::error::{RenderError, Result};
use crate::mesh::Mesh;
use crate::voxel::{Grid, Volume};

/// Most boundary quads a picture takes (about 1.4 GB of vertex data beyond this).
pub const MAX_FACES: usize = 1 << 24;

/// The six face directions: axis and side.
const DIRECTIONS: [(usize, bool); 6] = [(0, false), (0, true), (1, false), (1, true), (2, false), (2, true)];

/// The boundary quads of `volume` on `grid`, outward-oriented, with the colour
/// `colour(i, j, k)` of the voxel each belongs to (one colour per face).
pub fn surface(
    grid: &Grid,
    volume: &Volume,
    colour: impl Fn(usize, usize, usize) -> Rgba,
) -> Result<(Mesh, Vec<Rgba>)> {
    let n = volume.n();
    if grid.n != n {
        return Err(RenderError::Usage(format!("a {}³ grid with a {n}³ volume", grid.n)));
    }
    let occupied = |i: isize, j: isize, k: isize| {
        let r = 0..n as isize;
        r.contains(&i) && r.contains(&j) && r.contains(&k) && volume.get(i as usize, j as usize, k as usize)
    };
    let mut positions = Vec::new();
    let mut faces = Vec::new();
    let mut colours = Vec::new();
    let h = grid.h();
    for j in 0..n {
        for k in 0..n {
            for i in 0..n {
                if !volume.get(i, j, k) {
                    continue;
                }
                let at = [i as isize, j as isize, k as isize];
                for (axis, positive) in DIRECTIONS {
                    let mut nb = at;
                    nb[axis] += if positive { 1 } else { -1 };
                    if occupied(nb[0], nb[1], nb[2]) {
                        continue;
                    }
                    if faces.len() == MAX_FACES {
                        return Err(RenderError::Usage(format!(
                            "the volume's boundary has more than {MAX_FACES} voxel faces; use a lower resolution"
                        )));
                    }
                    // The face's corners on the lattice, counter-clockwise seen from outside.
                    let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                    let mut corner = [i, j, k];
                    corner[axis] += usize::from(positive);
                    let at = |du: usize, dv: usize| {
                        let mut c = corner;
                        c[u] += du;
                        c[v] += dv;
                        grid.min + DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64) * h
                    };
                    let base = positions.len() as u32;
                    let quad = if positive {
                        [at(0, 0), at(1, 0), at(1, 1), at(0, 1)]
                    } else {
                        [at(0, 0), at(0, 1), at(1, 1), at(1, 0)]
                    };
                    positions.extend(quad);
                    faces.push(vec![base, base + 1, base + 2, base + 3]);
                    colours.push(colour(i, j, k));
                }
            }
        }
    }
    Ok((Mesh::new(positions, faces)?, colours))
}

/// The colour of voxel (i, j, k) in aspect slices as `voxel::aspect::render` makes them
/// (slice j is N×N RGBA8, x right, z down); `fallback` where a slice is missing.
pub fn aspect_colour(
    slices: &[Vec<u8>],
    n: usize,
    fallback: Rgba,
) -> impl Fn(usize, usize, usize) -> Rgba + '_ {
    move |i, j, k| {
        let o = (k * n + i) * 4;
        match slices.get(j).and_then(|s| s.get(o..o + 4)) {
            Some(c) => [c[0], c[1], c[2], 255],
            None => fallback,
        }
    }
}
