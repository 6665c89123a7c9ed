//! Octant indexing (§4.3.2.3): with the apex at the solid's centre, the coordinate planes
//! through it cut space into 8 octants; a tetra lies in the octants its base triangle
//! touches, so a point is tested only against the tetras of its own octant.
//!
//! The mask of every tetra (the octants its base triangle's box grown by ε touches) is
//! computed with the tetra itself ([`super::tetra::TetraPlanes::octants`]) and checked by
//! its verdict too, so this index skips exactly the tetras the plain loop finds outside.
//! The thesis scans all tetras and ANDs a 6-bit code; here each octant keeps its own list,
//! which is the same test done once per tetra at build time.

use std::time::Instant;

use glam::DVec3;

use super::classifier::{BuildStats, Class, Classifier, vec_bytes};
use super::cpu::FeitoTorres;
use super::tetra::{CompactPlanes, octant_bit};

/// Feito-Torres over the tetras of the point's octant.
#[derive(Clone, Debug)]
pub struct Octants {
    ft: FeitoTorres,
    /// Tetras of octant k are `ids[start[k]..start[k + 1]]`.
    start: [u32; 9],
    ids: Vec<u32>,
    compact: Vec<CompactPlanes>,
    index_stats: BuildStats,
}

impl Octants {
    pub fn new(ft: FeitoTorres) -> Octants {
        let start_time = Instant::now();
        let mut start = [0u32; 9];
        let mut ids = Vec::new();
        for k in 0..8 {
            ids.extend(
                ft.tetras()
                    .iter()
                    .enumerate()
                    .filter(|(_, t)| t.octants >> k & 1 == 1)
                    .map(|(i, _)| i as u32),
            );
            start[k + 1] = ids.len() as u32;
        }
        let compact = ft.compact_planes();
        let bytes = vec_bytes(&ids) + size_of_val(&start) + vec_bytes(&compact);
        let index_stats = BuildStats { build_time: start_time.elapsed(), bytes };
        Octants { ft, start, ids, compact, index_stats }
    }

    pub fn base(&self) -> &FeitoTorres {
        &self.ft
    }

    pub fn index_stats(&self) -> BuildStats {
        self.index_stats
    }

    /// The tetras of octant `k` (bit index as in [`octant_bit`]).
    pub fn octant_tetras(&self, k: usize) -> &[u32] {
        &self.ids[self.start[k] as usize..self.start[k + 1] as usize]
    }
}

impl Classifier for Octants {
    fn name(&self) -> &str {
        "octants"
    }

    fn classify(&self, p: DVec3) -> Class {
        let k = octant_bit(p - self.ft.apex()).trailing_zeros() as usize;
        self.ft.classify_among_compact(p, self.octant_tetras(k).iter().copied(), &self.compact)
    }

    fn build_stats(&self) -> BuildStats {
        let base = self.ft.build_stats();
        BuildStats {
            build_time: base.build_time + self.index_stats.build_time,
            bytes: base.bytes + self.index_stats.bytes,
        }
    }
}
