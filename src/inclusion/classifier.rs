//! What every inclusion method is: a [`Classifier`] answering a [`Class`] per point, with
//! the cost of building it.

use std::time::Duration;

use glam::DVec3;

/// Where a point lies relative to a solid. The numbers are what the CLI writes.
#[repr(u8)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Class {
    #[default]
    Outside = 0,
    Inside = 1,
    OnBoundary = 2,
}

/// Preprocessing cost of a classifier (Tables 4-4, 4-7, 4-8): wall time to build it and
/// the heap bytes it holds (covering, per-tetra data and any index).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BuildStats {
    pub build_time: Duration,
    pub bytes: usize,
}

/// A point-in-solid test built for one mesh.
pub trait Classifier: Send + Sync {
    /// The method's name as the CLI spells it.
    fn name(&self) -> &str;
    fn classify(&self, p: DVec3) -> Class;
    /// Classifies every point on every core of the current rayon pool (`--threads`); each
    /// answer depends on its point alone, so the output is the same for any thread count.
    fn classify_all(&self, ps: &[DVec3]) -> Vec<Class> {
        use rayon::prelude::*;
        ps.par_iter().with_min_len(512).map(|&p| self.classify(p)).collect()
    }
    fn build_stats(&self) -> BuildStats;
}

/// Heap bytes of a vector's buffer.
pub(crate) fn vec_bytes<T>(v: &Vec<T>) -> usize {
    v.capacity() * std::mem::size_of::<T>()
}
