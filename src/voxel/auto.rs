//! `--method auto`: the fastest exact method for this device, solid and resolution,
//! chosen from cost models fitted to measured times (every method gives the same
//! volume, so the choice only changes the time).
//!
//! Each method's time is modelled from a few counts of the solid on the grid, in voxel
//! units: T covering triangles, C row crossings (the triangles' (y, z)-projected area),
//! S tetra-slices (Σ over tetras of the slices they span), P tetra spans (the tetras'
//! (y, z)-projected area: the rows their cross-sections cover), F surface slab pieces
//! (Σ over triangles of the slices they span) and the N³ voxels. The coefficients below
//! were fitted to the single-thread times of the README's Table 5-2 (`texgeo bench
//! voxelize`: `builtin:knot`, 1 200 triangles, and `armadillo.off`, 52 000, at 128³ and
//! 512³) on this project's reference machine (2-core AMD EPYC, lavapipe = llvmpipe
//! 15.0.6, Mesa 22.3.6); the device start (`GPU_START`) is the wall time of
//! `texgeo voxelize builtin:cube --res 8 --method zoned`. They
//! reproduce those times to within a factor of about 1.5, enough to order methods whose
//! times differ by 2× or more, as they do there.
//!
//! CPU methods run on rayon's global pool, so their modelled time is divided by the
//! threads it has (at 90 % efficiency). GPU methods pay the device start, their draws
//! and the exact fallback near the surface; on a device that is not a CPU (a real GPU,
//! which the reference machine does not have) the draws are taken as free, a lower
//! bound, so a GPU method is only chosen where even free draws would win.

use super::Method;

/// Counts of a solid on a grid that the cost models use (voxel units).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Counts {
    pub n: usize,
    /// Covering triangles.
    pub triangles: f64,
    /// Row crossings: the covering's (y, z)-projected area.
    pub crossings: f64,
    /// Tetra-slices: Σ over tetras of the slices they span.
    pub tetra_slices: f64,
    /// Tetra spans: Σ over tetras of their (y, z)-projected area.
    pub tetra_spans: f64,
    /// Surface slab pieces: Σ over triangles of the slices they span.
    pub slab_pieces: f64,
}

impl Counts {
    /// The counts of `solid` on `grid` (one pass over the covering).
    pub fn new(solid: &super::Solid, grid: &super::Grid) -> Counts {
        let o = grid.to_grid(solid.apex);
        let yz = |a: glam::DVec3, b: glam::DVec3, c: glam::DVec3| {
            ((b.y - a.y) * (c.z - a.z) - (b.z - a.z) * (c.y - a.y)).abs() * 0.5
        };
        let mut c = Counts { n: grid.n, triangles: solid.triangles.len() as f64, ..Counts::default() };
        for t in &solid.triangles {
            let [a, b, t2] = t.map(|p| grid.to_grid(p));
            let face = yz(a, b, t2);
            c.crossings += face;
            // A tetra's projection is covered twice by its four faces' projections.
            c.tetra_spans += 0.5 * (face + yz(o, a, b) + yz(o, b, t2) + yz(o, t2, a));
            let (lo, hi) = (a.y.min(b.y).min(t2.y), a.y.max(b.y).max(t2.y));
            c.slab_pieces += hi - lo + 1.0;
            c.tetra_slices += hi.max(o.y) - lo.min(o.y) + 1.0;
        }
        c
    }

    fn voxels(&self) -> f64 {
        (self.n as f64).powi(3)
    }
}

/// Fitted costs, seconds per unit (see the module docs for the measurement).
mod cost {
    /// scanline: per slab piece (a triangle's rows in one slice), per crossing (exact
    /// parity, row flips), per voxel (clearing, word flips).
    pub const SCANLINE: [f64; 3] = [8.0e-8, 1.0e-7, 3.0e-11];
    /// cpu: per tetra-slice (Table 5-1 section), per tetra span, per crossing (the exact
    /// fallback with the f64 rasterizer's narrow band).
    pub const CPU: [f64; 3] = [4.3e-8, 1.9e-8, 7.0e-8];
    /// The exact fallback of the GPU methods (their wider band), per crossing; it runs on
    /// one thread.
    pub const FALLBACK: f64 = 2.0e-7;
    /// Opening the device and building the pipeline.
    pub const GPU_START: f64 = 0.08;
    /// Readback: the 32-slices-per-texel layers into the volume, per voxel.
    pub const READBACK: f64 = 7.0e-11;
    /// lavapipe draws: pgpu, zoned and fgpu per tetra-slice, fang per slab piece.
    pub const PGPU_DRAW: f64 = 3.7e-7;
    pub const ZONED_DRAW: f64 = 2.0e-7;
    pub const FGPU_DRAW: f64 = 2.0e-7;
    pub const FANG_DRAW: f64 = 3.2e-7;
}

/// The device the GPU methods would run on, as far as the model cares.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Device {
    /// No Vulkan device (or not asked for): CPU methods only.
    None,
    /// A software rasterizer on the CPU (lavapipe): the fitted draw costs.
    Cpu,
    /// A real GPU: draws taken as free (a lower bound).
    Gpu,
}

impl Device {
    /// The kind of `ctx`'s device (`None`: no device open).
    pub fn of(ctx: Option<&crate::gpu::Context>) -> Device {
        match ctx {
            None => Device::None,
            Some(c) if c.info().kind == "cpu" => Device::Cpu,
            Some(_) => Device::Gpu,
        }
    }
}

/// The modelled time of `method` in seconds, on `threads` threads of rayon's pool.
pub fn estimate(method: Method, c: &Counts, device: Device, threads: usize) -> Option<f64> {
    let par = 1.0 / (0.9 * threads.max(1) as f64).max(1.0);
    let fallback = cost::FALLBACK * c.crossings;
    let gpu = |draw: f64| -> Option<f64> {
        let draw = match device {
            Device::None => return None,
            Device::Cpu => draw,
            Device::Gpu => 0.0,
        };
        Some(cost::GPU_START + draw + cost::READBACK * c.voxels() + fallback)
    };
    match method {
        Method::Scanline => {
            let [t, x, v] = cost::SCANLINE;
            Some((t * c.slab_pieces + x * c.crossings + v * c.voxels()) * par)
        }
        Method::Cpu => {
            let [s, p, x] = cost::CPU;
            Some((s * c.tetra_slices + p * c.tetra_spans + x * c.crossings) * par)
        }
        Method::Pgpu => gpu(cost::PGPU_DRAW * c.tetra_slices),
        Method::Zoned => gpu(cost::ZONED_DRAW * c.tetra_slices),
        Method::Fgpu => gpu(cost::FGPU_DRAW * c.tetra_slices),
        Method::Fang => gpu(cost::FANG_DRAW * c.slab_pieces),
    }
}

/// What `--method auto` decided, and the estimates behind it.
#[derive(Clone, Debug)]
pub struct Plan {
    pub method: Method,
    /// Every method the device can run, with its modelled seconds, fastest first.
    pub estimates: Vec<(Method, f64)>,
    pub counts: Counts,
}

impl Plan {
    /// The fastest method by the models. With `Device::None` only CPU methods count; a
    /// caller that has no device open can first ask with [`Device::Gpu`] (draws free): if
    /// a CPU method still wins, no device is needed at all.
    pub fn choose(counts: Counts, device: Device, threads: usize) -> Plan {
        let mut estimates: Vec<(Method, f64)> = Method::ALL
            .iter()
            .filter_map(|&m| estimate(m, &counts, device, threads).map(|t| (m, t)))
            .collect();
        // Ties (equal estimates) go to the earlier method of `Method::ALL`: a stable sort.
        estimates.sort_by(|a, b| a.1.total_cmp(&b.1));
        let method = estimates.first().map_or(Method::Scanline, |e| e.0);
        Plan { method, estimates, counts }
    }

    /// "scanline (model 42 ms; cpu 310 ms, …)".
    pub fn describe(&self) -> String {
        let ms = |t: f64| format!("{:.0} ms", t * 1e3);
        let others: Vec<String> =
            self.estimates.iter().skip(1).map(|&(m, t)| format!("{m} {}", ms(t))).collect();
        let own = self.estimates.first().map_or_else(String::new, |&(_, t)| ms(t));
        format!("{} (model {own}; {})", self.method, others.join(", "))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::procedural;
    use crate::voxel::{Grid, Solid};

    #[test]
    fn counts_grow_as_the_geometry_says() {
        let mesh = procedural::by_name("sphere").unwrap();
        let solid = Solid::new(&mesh).unwrap();
        let c64 = Counts::new(&solid, &Grid::for_mesh(&mesh, 64).unwrap());
        let c128 = Counts::new(&solid, &Grid::for_mesh(&mesh, 128).unwrap());
        // Projected areas grow with N², slices with N.
        let r = c128.crossings / c64.crossings;
        assert!((r - 4.0).abs() < 1e-9, "{r}");
        assert!(c128.tetra_slices > 1.8 * c64.tetra_slices && c128.tetra_slices < 2.0 * c64.tetra_slices);
        // A sphere filling the cube: its (y, z) shadow is about π(N/2)², seen twice.
        let shadow = 2.0 * std::f64::consts::PI * 32.0 * 32.0;
        assert!((c64.crossings / shadow - 1.0).abs() < 0.1, "{} vs {shadow}", c64.crossings);
    }

    #[test]
    fn the_choice_is_the_smallest_estimate_and_needs_a_device_for_gpu_methods() {
        let mesh = procedural::by_name("knot").unwrap();
        let solid = Solid::new(&mesh).unwrap();
        let c = Counts::new(&solid, &Grid::for_mesh(&mesh, 128).unwrap());
        let none = Plan::choose(c, Device::None, 2);
        assert!(none.estimates.iter().all(|(m, _)| !m.uses_gpu()));
        for device in [Device::None, Device::Cpu, Device::Gpu] {
            let plan = Plan::choose(c, device, 2);
            let best = plan.estimates.iter().map(|e| e.1).fold(f64::INFINITY, f64::min);
            assert_eq!(plan.estimates[0], (plan.method, best));
            assert!(plan.describe().starts_with(plan.method.name()));
        }
    }
}
