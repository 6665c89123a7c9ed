//! The bit volume: one bit per voxel, x fastest, then z, then y (SPEC §4.1), so a y
//! slice is a contiguous N×N plane of rows along x. Each row (j, k) starts on a 64-bit
//! word, so rows can be flipped span by span (XOR) and compared word by word.

use super::error::{Result, VoxelError};
use super::grid::{check_memory, check_resolution};

/// N³ occupancy bits. Padding bits at the end of each row are always zero, so two
/// volumes are equal iff their words are.
#[derive(Clone, PartialEq, Eq)]
pub struct Volume {
    n: usize,
    words_per_row: usize,
    words: Vec<u64>,
}

impl std::fmt::Debug for Volume {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Volume({}³, {} occupied)", self.n, self.count())
    }
}

impl Volume {
    /// An empty N³ volume; fails with a clear error (not an allocation failure) when the
    /// memory is not there.
    pub fn new(n: usize) -> Result<Volume> {
        check_resolution(n)?;
        let words_per_row = n.div_ceil(64);
        let len = n * n * words_per_row;
        check_memory("the bit volume", n, len as u64 * 8)?;
        let mut words = Vec::new();
        words.try_reserve_exact(len).map_err(|_| VoxelError::Memory {
            what: "the bit volume".into(),
            res: n,
            need_mib: crate::host::Mib::of(len as u64 * 8),
            have_mib: 0,
        })?;
        words.resize(len, 0);
        Ok(Volume { n, words_per_row, words })
    }

    pub fn n(&self) -> usize {
        self.n
    }

    fn row_start(&self, j: usize, k: usize) -> usize {
        (j * self.n + k) * self.words_per_row
    }

    /// Every word, rows in (j, k) order ([`Self::words_per_row`] words each).
    pub fn words(&self) -> &[u64] {
        &self.words
    }

    pub fn words_per_row(&self) -> usize {
        self.words_per_row
    }

    /// The words of row (j, k): bit i of the row is voxel (i, j, k).
    pub fn row(&self, j: usize, k: usize) -> &[u64] {
        let s = self.row_start(j, k);
        &self.words[s..s + self.words_per_row]
    }

    pub fn row_mut(&mut self, j: usize, k: usize) -> &mut [u64] {
        let s = self.row_start(j, k);
        &mut self.words[s..s + self.words_per_row]
    }

    pub fn get(&self, i: usize, j: usize, k: usize) -> bool {
        self.row(j, k)[i / 64] >> (i % 64) & 1 == 1
    }

    pub fn set(&mut self, i: usize, j: usize, k: usize, value: bool) {
        let w = &mut self.row_mut(j, k)[i / 64];
        let bit = 1u64 << (i % 64);
        if value { *w |= bit } else { *w &= !bit }
    }

    pub fn flip(&mut self, i: usize, j: usize, k: usize) {
        self.row_mut(j, k)[i / 64] ^= 1u64 << (i % 64);
    }

    /// Flips voxels i0..i1 of row (j, k) (`i1` is clamped to N).
    pub fn xor_span(&mut self, j: usize, k: usize, i0: usize, i1: usize) {
        let i1 = i1.min(self.n);
        if i0 >= i1 {
            return;
        }
        xor_bits(self.row_mut(j, k), i0, i1);
    }

    /// Number of occupied voxels.
    pub fn count(&self) -> u64 {
        self.words.iter().map(|w| w.count_ones() as u64).sum()
    }

    /// Occupied voxels of slice j.
    pub fn count_slice(&self, j: usize) -> u64 {
        let s = self.row_start(j, 0);
        self.words[s..s + self.n * self.words_per_row].iter().map(|w| w.count_ones() as u64).sum()
    }

    /// The voxels where `self` and `other` differ, as (i, j, k), at most `limit` of them.
    pub fn differences(&self, other: &Volume, limit: usize) -> Result<Vec<[usize; 3]>> {
        if self.n != other.n {
            return Err(VoxelError::Usage(format!("cannot compare a {}³ and a {}³ volume", self.n, other.n)));
        }
        let mut out = Vec::new();
        for j in 0..self.n {
            for k in 0..self.n {
                for (w, (a, b)) in self.row(j, k).iter().zip(other.row(j, k)).enumerate() {
                    let mut d = a ^ b;
                    while d != 0 && out.len() < limit {
                        out.push([w * 64 + d.trailing_zeros() as usize, j, k]);
                        d &= d - 1;
                    }
                }
            }
        }
        Ok(out)
    }

    /// Number of voxels where `self` and `other` differ.
    pub fn count_differences(&self, other: &Volume) -> Result<u64> {
        if self.n != other.n {
            return Err(VoxelError::Usage(format!("cannot compare a {}³ and a {}³ volume", self.n, other.n)));
        }
        Ok(self.words.iter().zip(&other.words).map(|(a, b)| (a ^ b).count_ones() as u64).sum())
    }

    /// Slice j as an N×N byte image (row k, column i), 255 where occupied.
    pub fn slice_pixels(&self, j: usize) -> Vec<u8> {
        let mut out = Vec::with_capacity(self.n * self.n);
        for k in 0..self.n {
            let row = self.row(j, k);
            out.extend((0..self.n).map(|i| if row[i / 64] >> (i % 64) & 1 == 1 { 255 } else { 0 }));
        }
        out
    }

    /// XORs a GPU layer into the volume: `texels` is an N×N R32UI image (row k, column
    /// i) whose bit b belongs to slice `first_slice + b` (32 slices per texel).
    pub fn xor_packed_slices(&mut self, first_slice: usize, texels: &[u32]) -> Result<()> {
        let n = self.n;
        if texels.len() != n * n || first_slice >= n {
            return Err(VoxelError::Usage(format!(
                "a packed layer of {} texels at slice {first_slice} does not fit a {n}³ volume",
                texels.len()
            )));
        }
        let slices = (n - first_slice).min(32);
        let mut block = [0u32; 32];
        for k in 0..n {
            for i0 in (0..n).step_by(32) {
                let len = (n - i0).min(32);
                block[..len].copy_from_slice(&texels[k * n + i0..k * n + i0 + len]);
                block[len..].fill(0);
                if block.iter().all(|&w| w == 0) {
                    continue;
                }
                transpose32(&mut block);
                // block[b] now holds slice b's bits for x = i0..i0+32.
                for (b, &bits) in block.iter().enumerate().take(slices) {
                    if bits != 0 {
                        let row = self.row_mut(first_slice + b, k);
                        row[i0 / 64] ^= (bits as u64) << (i0 % 64);
                    }
                }
            }
        }
        Ok(())
    }
}

impl Volume {
    /// Layer `layer` of the GPU layout (the inverse of [`Volume::xor_packed_slices`]):
    /// N×N texels (row k, column i) whose bit b is voxel (i, 32·layer + b, k).
    pub fn packed_layer(&self, layer: usize) -> Vec<u32> {
        let n = self.n;
        let first = layer * 32;
        let slices = n.saturating_sub(first).min(32);
        let mut out = vec![0u32; n * n];
        let mut block = [0u32; 32];
        for k in 0..n {
            for i0 in (0..n).step_by(32) {
                for (b, word) in block.iter_mut().enumerate() {
                    *word =
                        if b < slices { (self.row(first + b, k)[i0 / 64] >> (i0 % 64)) as u32 } else { 0 };
                }
                if block.iter().all(|&w| w == 0) {
                    continue;
                }
                transpose32(&mut block);
                let len = (n - i0).min(32);
                out[k * n + i0..k * n + i0 + len].copy_from_slice(&block[..len]);
            }
        }
        out
    }
}

/// Slices j0..j1 of a volume, borrowed mutably: what one task of [`Volume::par_slabs`]
/// writes.
pub struct Slab<'a> {
    n: usize,
    words_per_row: usize,
    /// First slice (j) of the slab.
    pub j0: usize,
    words: &'a mut [u64],
}

impl Slab<'_> {
    /// The slices this slab holds.
    pub fn slices(&self) -> std::ops::Range<usize> {
        self.j0..self.j0 + self.words.len() / (self.n * self.words_per_row)
    }

    /// The words of row (j, k), j inside the slab.
    pub fn row_mut(&mut self, j: usize, k: usize) -> &mut [u64] {
        let s = ((j - self.j0) * self.n + k) * self.words_per_row;
        &mut self.words[s..s + self.words_per_row]
    }

    /// Flips voxels i0..i1 of row (j, k) (`i1` is clamped to N).
    pub fn xor_span(&mut self, j: usize, k: usize, i0: usize, i1: usize) {
        let i1 = i1.min(self.n);
        if i0 < i1 {
            xor_bits(self.row_mut(j, k), i0, i1);
        }
    }
}

impl Volume {
    /// Runs `work` on slabs of `slab` consecutive y slices in parallel (rayon's global
    /// pool). Each slab is written by one task only, so the result does not depend on the
    /// number of threads as long as `work` on a slab does not.
    pub fn par_slabs(&mut self, slab: usize, work: impl Fn(Slab<'_>) + Sync + Send) {
        use rayon::prelude::*;
        let (n, wpr) = (self.n, self.words_per_row);
        let slab = slab.max(1);
        self.words
            .par_chunks_mut(slab * n * wpr)
            .enumerate()
            .for_each(|(s, words)| work(Slab { n, words_per_row: wpr, j0: s * slab, words }));
    }
}

/// Slices per task of the parallel rasterizers: about 64 slabs, so two to a few dozen
/// cores all get work and each task's setup is amortized over many rows.
pub fn slab_height(n: usize) -> usize {
    n.div_ceil(64).max(1)
}

/// Which items fall in which slab: `ranges` gives each item's slices (empty: none), the
/// result lists, per slab of `slab` slices, the items meeting it, in item order.
pub fn slab_lists(
    n: usize,
    slab: usize,
    ranges: impl Iterator<Item = std::ops::Range<usize>>,
) -> Vec<Vec<u32>> {
    let mut lists = vec![Vec::new(); n.div_ceil(slab).max(1)];
    for (item, r) in ranges.enumerate() {
        if r.start >= r.end {
            continue;
        }
        for list in &mut lists[r.start / slab..=(r.end - 1) / slab] {
            list.push(item as u32);
        }
    }
    lists
}

/// Flips bits i0..i1 of a row of words.
pub(crate) fn xor_bits(row: &mut [u64], i0: usize, i1: usize) {
    let (w0, w1) = (i0 / 64, (i1 - 1) / 64);
    let lo = !0u64 << (i0 % 64);
    let hi = !0u64 >> (63 - (i1 - 1) % 64);
    if w0 == w1 {
        row[w0] ^= lo & hi;
    } else {
        row[w0] ^= lo;
        for w in &mut row[w0 + 1..w1] {
            *w = !*w;
        }
        row[w1] ^= hi;
    }
}

/// Transposes a 32×32 bit matrix in place: afterwards bit r of word c is what bit c of
/// word r was (block swaps of 16, 8, 4, 2, 1).
pub(crate) fn transpose32(a: &mut [u32; 32]) {
    let mut s = 16;
    let mut m: u32 = 0x0000_FFFF;
    while s > 0 {
        let mut r = 0;
        while r < 32 {
            if r & s == 0 {
                let t = ((a[r] >> s) ^ a[r + s]) & m;
                a[r + s] ^= t;
                a[r] ^= t << s;
            }
            r += 1;
        }
        s >>= 1;
        m ^= m << s;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::Rng;

    #[test]
    fn transpose_matches_naive() {
        let mut rng = Rng::new(3);
        let mut a = [0u32; 32];
        for w in &mut a {
            *w = rng.next_u64() as u32;
        }
        let orig = a;
        transpose32(&mut a);
        for (r, row) in orig.iter().enumerate() {
            for (c, col) in a.iter().enumerate() {
                assert_eq!(col >> r & 1, row >> c & 1, "r {r} c {c}");
            }
        }
    }

    #[test]
    fn spans_flip_exactly_their_bits() {
        for n in [1usize, 5, 63, 64, 65, 130] {
            let mut v = Volume::new(n).unwrap();
            let mut naive = vec![false; n];
            let mut rng = Rng::new(n as u64);
            for _ in 0..50 {
                let a = rng.below(n as u64 + 1) as usize;
                let b = rng.below(n as u64 + 1) as usize;
                let (a, b) = (a.min(b), a.max(b));
                v.xor_span(0, 0, a, b);
                for x in &mut naive[a..b] {
                    *x = !*x;
                }
            }
            for (i, &x) in naive.iter().enumerate() {
                assert_eq!(v.get(i, 0, 0), x, "n {n} i {i}");
            }
            assert_eq!(v.count(), naive.iter().filter(|&&x| x).count() as u64);
        }
    }

    #[test]
    fn packed_layers_land_on_their_slices() {
        let n = 37;
        let mut v = Volume::new(n).unwrap();
        let mut texels = vec![0u32; n * n];
        texels[3 * n + 5] = 1 | 1 << 4; // (i 5, k 3): slices 32 and 36
        texels[n * n - 1] = 1 << 2; // (i 36, k 36): slice 34
        v.xor_packed_slices(32, &texels).unwrap();
        assert!(v.get(5, 32, 3) && v.get(5, 36, 3) && v.get(36, 34, 36));
        assert_eq!(v.count(), 3);
        for (n, why) in
            [(0, "resolution 0 is outside 1..=1024"), (100_000, "resolution 100000 is outside 1..=1024 (a")]
        {
            let e = Volume::new(n).unwrap_err();
            assert!(matches!(e, VoxelError::Resolution { res, .. } if res == n), "{e}");
            assert!(e.to_string().starts_with(why), "{e}");
        }
    }
}
