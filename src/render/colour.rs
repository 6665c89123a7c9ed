//! Colours of pictures: RGBA8, the palettes texgeo's figures use, and vertex valences
//! (the 2010 thesis' Figs. 27–30 colour subdivided meshes by valence).

use std::collections::HashSet;

use crate::mesh::Mesh;

/// Red, green, blue, alpha (alpha is ignored: surfaces are opaque).
pub type Rgba = [u8; 4];

/// Default surface colour.
pub const SURFACE: Rgba = [190, 196, 210, 255];
/// Default wireframe colour.
pub const EDGE: Rgba = [30, 34, 44, 255];
/// Default background.
pub const BACKGROUND: Rgba = [24, 26, 32, 255];
/// Two operands and a result (Booleans): first, second, and the cut curve.
pub const FIRST: Rgba = [214, 120, 80, 255];
pub const SECOND: Rgba = [90, 150, 220, 255];
pub const CURVE: Rgba = [250, 220, 60, 255];

/// A crease edge by its sharpness: from yellow (barely sharp) through orange to red
/// (10 or more: infinitely sharp), so semi-sharp creases read apart from sharp ones.
pub fn crease_colour(sharpness: f32) -> Rgba {
    let t = (sharpness / 10.0).clamp(0.0, 1.0);
    let mix = |a: f32, b: f32| (a + (b - a) * t).round() as u8;
    [mix(255.0, 235.0), mix(225.0, 40.0), mix(60.0, 40.0), 255]
}

/// The colour of a vertex of valence `k`: regular vertices (4) neutral, extraordinary
/// ones bright and distinct, so they stand out in a refined mesh.
pub fn valence_colour(k: usize) -> Rgba {
    match k {
        0..=2 => [40, 200, 200, 255],
        3 => [230, 60, 50, 255],
        4 => [200, 200, 200, 255],
        5 => [60, 190, 70, 255],
        6 => [60, 90, 230, 255],
        7 => [210, 70, 210, 255],
        _ => [240, 200, 40, 255],
    }
}

/// The valence of every vertex: how many distinct vertices share an edge with it.
pub fn valences(mesh: &Mesh) -> Vec<usize> {
    let mut edges = HashSet::with_capacity(mesh.num_faces() * 2);
    let mut valence = vec![0; mesh.num_vertices()];
    for face in mesh.faces() {
        for (i, &a) in face.iter().enumerate() {
            let b = face[(i + 1) % face.len()];
            if a != b && edges.insert((a.min(b), a.max(b))) {
                valence[a as usize] += 1;
                valence[b as usize] += 1;
            }
        }
    }
    valence
}

/// One colour per vertex, by valence (see [`valence_colour`]).
pub fn by_valence(mesh: &Mesh) -> Vec<Rgba> {
    valences(mesh).into_iter().map(valence_colour).collect()
}

/// Packs a colour as the shaders read it (`unpackUnorm4x8`: red in the low byte).
pub(crate) fn pack(c: Rgba) -> u32 {
    u32::from_le_bytes(c)
}
