//! `--method auto`: the fastest exact method for the mesh and the number of points, from
//! cost models measured on this project's reference machine (2 cores, see README) and kept
//! here beside the measurements that produced them. Every candidate is exact (they all
//! give the same answers), so the choice only changes the time.
//!
//! The GPU methods are not candidates: on lavapipe they are slower than the CPU ones at
//! every size measured (README, Table 4-9: on armadillo `gpu` costs ~52 µs and
//! `gpu+tetragrid` ~6 µs per point against well under 1 µs for the voxel space; `texgeo
//! bench scale`), and on other devices texgeo has no measurement to base a choice on. They
//! stay selectable by name. Nor are the other CPU methods: in `texgeo bench scale` on
//! armadillo (2026-12-02, build included) the voxel space was 4.5× faster than bvh at
//! 1 000 points and 5.5× at 1 M (bvh with its ray test: 0.29 µs per point after a 51 ms
//! build, against 0.06 µs overall), 2.7–3× faster than octants and 4.5–4.9× than
//! tetragrid at 1 000 points, and its per-point cost is the lowest.

use super::method::Method;

/// What `auto` picked and why (printed on stderr by the command).
#[derive(Clone, Debug, PartialEq)]
pub struct Pick {
    pub method: Method,
    /// The voxel-space grid size, when that is the method.
    pub resolution: Option<usize>,
    /// Predicted seconds (build + classification).
    pub predicted: f64,
}

impl std::fmt::Display for Pick {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.method)?;
        if let Some(n) = self.resolution {
            write!(f, " ({n}³ cells)")?;
        }
        write!(f, ", predicted {:.1} ms", self.predicted * 1e3)
    }
}

/// Voxel-space cost model (seconds), triangles `t`, points `p`, grid side `n`.
///
/// Fitted to single-thread runs of the voxel space on `builtin:knot` (1 200 triangles) and
/// `armadillo.off` (52 000) at 1 k … 1 M points and n = 8 … 256 on the 2-core reference
/// machine. The build terms were fitted again on 2026-12-02 after the labelling became a
/// parity walk per row (armadillo, 2 threads, quiet machine): 12 ms at n = 16, 21 at 64,
/// 29 at 96, 46 at 128, 114 at 192. Whole `texgeo inclusion --method voxel-space --grid n`
/// runs then measured, for 1 M points, 208–236 ms at n = 64, 205–249 at 96 (the model's
/// pick) and 262–266 at 128; for 1 000 points 21.6 ms at 16, 21.0–27.3 at 24 (the pick)
/// and 20.8–21.7 at 32 — the model's picks are within noise of the measured minimum.
fn voxel_space_cost(t: f64, p: f64, n: f64) -> f64 {
    let (build, per_point) = voxel_space_model(t, n);
    build + p * per_point
}

/// (build seconds, seconds per point) of the voxel space.
fn voxel_space_model(t: f64, n: f64) -> (f64, f64) {
    // Build: rasterizing the triangles, the scanline labels (rows × crossings) and the
    // n³ cell array. Query: O(1) in labelled cells; in surface cells (a fraction ∝ area·n²
    // / n³ of a uniform sample) an exact test over about t / n² triangles.
    let build = 2.0e-4 + 2.0e-7 * t + 2.75e-9 * n * n * n + 1.0e-8 * t.sqrt() * n * n;
    let surface_fraction = (6.0 / n).min(1.0);
    let per_point = 1.5e-8 + surface_fraction * (1.0e-7 + 3.0e-9 * t / (n * n) * 8.0);
    (build, per_point)
}

/// The voxel-space grid size that minimises its modelled cost.
pub fn voxel_space_resolution(triangles: usize, points: usize) -> usize {
    let (t, p) = (triangles as f64, points.max(1) as f64);
    (3..=9)
        .map(|e| 1usize << e)
        .chain([24, 48, 96, 192, 384])
        .min_by(|&a, &b| voxel_space_cost(t, p, a as f64).total_cmp(&voxel_space_cost(t, p, b as f64)))
        .unwrap_or(32)
}

/// Picks the method for a mesh of `triangles` covering triangles and `points` query
/// points (0 = unknown: a few).
pub fn choose(triangles: usize, points: usize) -> Pick {
    let points = if points == 0 { 64 } else { points };
    let n = voxel_space_resolution(triangles, points);
    let predicted = voxel_space_cost(triangles as f64, points as f64, n as f64);
    Pick { method: Method::VoxelSpace, resolution: Some(n), predicted }
}
