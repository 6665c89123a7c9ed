//! Hash maps and sets for the geometry's bookkeeping: foldhash (fast on the small integer
//! keys used here) with its fixed seed, so that a walk over a map visits its entries in the
//! same order in every run. The output repair and the constrained triangulation walk maps;
//! with a per-process random seed the same input could give a different (equally valid)
//! output file from one run to the next.

pub use foldhash::{HashMapExt, HashSetExt};

/// `std::collections::HashMap` with foldhash's fixed seed.
pub type HashMap<K, V> = std::collections::HashMap<K, V, foldhash::fast::FixedState>;

/// `std::collections::HashSet` with foldhash's fixed seed.
pub type HashSet<K> = std::collections::HashSet<K, foldhash::fast::FixedState>;
