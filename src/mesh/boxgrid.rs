//! Overlapping box pairs by a uniform grid: the spatial index behind the Boolean
//! refinement's candidate pairs and the crossing test restricted to marked triangles.
//!
//! Every box is entered in the grid cells it touches (a counting sort by cell), and the
//! boxes sharing a cell are tested against each other. A pair is reported only by the
//! cell holding the lower corner of the two boxes' overlap, so it comes out once however
//! many cells they share. The cell side is the mean box extent (grown when the boxes
//! would make too many entries), so a cell holds a few triangles of each surface
//! crossing it, and only cells where the two sets meet give pairs — like the thesis'
//! octree over both meshes, whose leaves concentrate where the meshes meet (§6.4).
//!
//! The same grid answers queries by box ([`BoxIndex`]): the boxes meeting a given one,
//! from the cells it touches.

use glam::{DVec3, UVec3};
use rayon::prelude::*;

/// An axis-aligned box (lower corner, upper corner), closed: touching counts.
pub type Box3 = (DVec3, DVec3);

/// Entries per box allowed on average before the cells are made coarser.
const MAX_ENTRIES_PER_BOX: usize = 12;

fn overlaps(a: &Box3, b: &Box3) -> bool {
    a.0.cmple(b.1).all() && b.0.cmple(a.1).all()
}

struct Grid {
    origin: DVec3,
    inv: f64,
    dims: UVec3,
}

impl Grid {
    fn cell(&self, p: DVec3) -> UVec3 {
        // Non-negative, so truncation is floor (and cheaper than a libm call).
        let c = ((p - self.origin) * self.inv).max(DVec3::ZERO);
        c.as_uvec3().min(self.dims - UVec3::ONE)
    }

    fn key(&self, c: UVec3) -> u64 {
        (c.z as u64 * self.dims.y as u64 + c.y as u64) * self.dims.x as u64 + c.x as u64
    }

    fn cells_of(&self, b: &Box3) -> (UVec3, UVec3) {
        (self.cell(b.0), self.cell(b.1))
    }

    fn count(&self, b: &Box3) -> usize {
        let (lo, hi) = self.cells_of(b);
        let d = hi - lo + UVec3::ONE;
        d.x as usize * d.y as usize * d.z as usize
    }

    /// Calls `f` with every cell of the range `(lo, hi)` (by key), in key order.
    fn each_cell(&self, (lo, hi): (UVec3, UVec3), mut f: impl FnMut(usize)) {
        for z in lo.z..=hi.z {
            for y in lo.y..=hi.y {
                let row = self.key(UVec3::new(lo.x, y, z)) as usize;
                for c in row..=row + (hi.x - lo.x) as usize {
                    f(c);
                }
            }
        }
    }
}

/// Pairs of overlapping boxes: `(i, j)` with i < j within `a` when `b` is `None`, else
/// `(i, j)` with i in `a` and j in `b`, each once, in no particular order. Only the
/// region where both sets' boxes meet is gridded.
pub fn box_pairs(a: &[Box3], b: Option<&[Box3]>) -> Vec<(u32, u32)> {
    box_pairs_within(a, b, u64::MAX).unwrap_or_default()
}

/// [`box_pairs`]`(near, Some(all))` for a set `near` that lies along a part of `all`
/// (the changed triangles of a result among all of them): the boxes of `all` that share
/// no cell of a grid laid over `near` with a box of `near` overlap none of them and are
/// left out first, so the grid that pairs the rest is not laid over all of `all`.
pub fn box_pairs_near(near: &[Box3], all: &[Box3]) -> Vec<(u32, u32)> {
    let Some((region, entries)) = entries_in_region(near, None) else {
        return Vec::new();
    };
    let grid = fit_grid(&region, &entries);
    let cells = grid.dims.x as usize * grid.dims.y as usize * grid.dims.z as usize;
    let mut occupied = vec![false; cells];
    for (_, x) in &entries {
        grid.each_cell(grid.cells_of(&x.clamp_to(&region)), |c| occupied[c] = true);
    }
    // A box of `all` overlapping one of `near` shares a point with it inside `region`,
    // whose cell both boxes' (clamped) cell ranges hold: the cell of a point is monotone
    // in each coordinate.
    let kept: Vec<u32> = (0..all.len() as u32)
        .into_par_iter()
        .with_min_len(4096)
        .filter(|&j| {
            let x = &all[j as usize];
            let mut hit = false;
            if overlaps(x, &region) {
                grid.each_cell(grid.cells_of(&x.clamp_to(&region)), |c| hit |= occupied[c]);
            }
            hit
        })
        .collect();
    let boxes: Vec<Box3> = kept.iter().map(|&j| all[j as usize]).collect();
    let mut pairs = box_pairs(near, Some(&boxes));
    for p in &mut pairs {
        p.1 = kept[p.1 as usize];
    }
    pairs
}

/// [`box_pairs`], unless the grid would compare more than `max_tests` pairs of boxes
/// sharing a cell (counted from the cells' occupancy before any pair is compared): then
/// `None`. Boxes that pile up in a few cells whatever their size — a fan of slivers
/// around one vertex, long parallel slivers — make the grid quadratic, and this says so
/// for the price of counting.
pub fn box_pairs_within(a: &[Box3], b: Option<&[Box3]>, max_tests: u64) -> Option<Vec<(u32, u32)>> {
    let Some((region, all)) = entries_in_region(a, b) else {
        return Some(Vec::new());
    };
    let grid = fit_grid(&region, &all);
    let (start, entries, lows) = sort_by_cell(&grid, &region, &all, max_tests)?;
    let pairs = pairs_in_cells(&grid, &start, &entries, &lows, &all, b.is_some());
    Some(pairs.into_iter().map(|p| ((p >> 32) as u32, p as u32)).collect())
}

/// The region where pairs can be (the boxes' hull, or where the hulls of `a` and `b`
/// overlap) and the boxes inside it with their ids (`b`'s tagged in the top bit); `None`
/// when no pair can be.
fn entries_in_region<'x>(a: &'x [Box3], b: Option<&'x [Box3]>) -> Option<(Box3, Vec<(u32, &'x Box3)>)> {
    let hull = |boxes: &[Box3]| -> Box3 {
        boxes.iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), x| (lo.min(x.0), hi.max(x.1)))
    };
    let region = match b {
        None => hull(a),
        Some(b) => {
            let (ha, hb) = (hull(a), hull(b));
            (ha.0.max(hb.0), ha.1.min(hb.1))
        }
    };
    if a.is_empty() || region.0.cmpgt(region.1).any() || !region.0.is_finite() || !region.1.is_finite() {
        return None;
    }
    let inside = |x: &Box3| overlaps(x, &region);
    let all: Vec<(u32, &Box3)> = a
        .iter()
        .enumerate()
        .filter(|(_, x)| inside(x))
        .map(|(i, x)| (i as u32, x))
        .chain(b.into_iter().flat_map(|b| {
            b.iter().enumerate().filter(|(_, x)| inside(x)).map(|(j, x)| (j as u32 | 1 << 31, x))
        }))
        .collect();
    (!all.is_empty()).then_some((region, all))
}

/// The grid over `region`: cells of the boxes' mean extent, made coarser until there are
/// about as many cells as entries at most and few entries per box.
fn fit_grid(region: &Box3, all: &[(u32, &Box3)]) -> Grid {
    let extent = region.1 - region.0;
    let mean = all.iter().map(|(_, x)| (x.1 - x.0).max_element()).sum::<f64>() / all.len() as f64;
    let mut side = mean.max(extent.max_element() / 1e6).max(f64::MIN_POSITIVE);
    loop {
        let dims = ((extent / side).floor().as_uvec3() + UVec3::ONE).min(UVec3::splat(1 << 20));
        let grid = Grid { origin: region.0, inv: 1.0 / side, dims };
        let cells = dims.x as usize * dims.y as usize * dims.z as usize;
        let entries: usize =
            all.par_iter().with_min_len(4096).map(|(_, x)| grid.count(&x.clamp_to(region))).sum();
        if (entries <= MAX_ENTRIES_PER_BOX * all.len() && cells <= (4 * entries).max(1 << 16)) || cells == 1 {
            return grid;
        }
        side *= 1.5;
    }
}

/// Counting sort of the entries by cell: `entries[start[c]..start[c + 1]]` are the places
/// in `all` of cell c's boxes, in increasing order (4 bytes an entry, where a copy of the
/// box would take 56: a box is in 8 cells or so, and the copies were most of the grid's
/// memory traffic), and the cell of every box's (clamped) lower corner. `None` when the
/// cells would take more than `max_tests` pair tests.
fn sort_by_cell(
    grid: &Grid,
    region: &Box3,
    all: &[(u32, &Box3)],
    max_tests: u64,
) -> Option<(Vec<u32>, Vec<u32>, Vec<UVec3>)> {
    let cells = grid.dims.x as usize * grid.dims.y as usize * grid.dims.z as usize;
    let ranges: Vec<(UVec3, UVec3)> =
        all.par_iter().with_min_len(4096).map(|(_, x)| grid.cells_of(&x.clamp_to(region))).collect();
    // Cell c counted at `start[c + 2]`; once summed, `start[c + 1]` is where cell c's
    // entries begin, and as the cursor that fills them it ends where they end, which is
    // where cell c + 1's begin: no second array of cells (they are mostly empty, and
    // there are up to four per entry) is needed.
    let mut start = vec![0u32; cells + 2];
    for &r in &ranges {
        grid.each_cell(r, |c| start[c + 2] += 1);
    }
    let tests = start.iter().map(|&c| u64::from(c) * u64::from(c.saturating_sub(1)) / 2).sum::<u64>();
    if tests > max_tests {
        return None;
    }
    for i in 2..cells + 2 {
        start[i] += start[i - 1];
    }
    let mut entries = vec![0u32; start[cells + 1] as usize];
    for (k, &r) in ranges.iter().enumerate() {
        grid.each_cell(r, |c| {
            entries[start[c + 1] as usize] = k as u32;
            start[c + 1] += 1;
        });
    }
    start.truncate(cells + 1);
    Some((start, entries, ranges.into_iter().map(|r| r.0).collect()))
}

/// The overlapping pairs of each cell's boxes (ids packed high/low), each reported by the
/// cell of its overlap's lower corner only; with `two_sets`, pairs of one box of each set.
/// `lows[e]` is the cell of entry e's lower corner (clamped to the region): the cell of a
/// point is monotone in each coordinate, so the cell of the overlap's lower corner (the
/// larger of the two lower corners) is the larger of their cells, axis by axis, and a pair
/// that is not reported in this cell is passed over before its boxes are compared.
fn pairs_in_cells(
    grid: &Grid,
    start: &[u32],
    entries: &[u32],
    lows: &[UVec3],
    all: &[(u32, &Box3)],
    two_sets: bool,
) -> Vec<u64> {
    let cells = start.len() - 1;
    // `a`'s boxes come first in `all`.
    let in_a = all.partition_point(|(t, _)| t >> 31 == 0) as u32;
    // Most cells hold no box or one: no pair to look at there.
    (0..cells)
        .into_par_iter()
        .with_min_len(4096)
        .filter(|&cell| start[cell + 1] - start[cell] >= 2)
        .fold(Vec::new, |mut acc, cell| {
            let run = &entries[start[cell] as usize..start[cell + 1] as usize];
            // Two sets: a cell's boxes of `a` come before those of `b` (filled in the order
            // of `all`), and each box of `a` is compared with those of `b` only.
            let split = if two_sets { run.partition_point(|&e| e < in_a) } else { run.len() };
            let (dx, dy) = (grid.dims.x as usize, grid.dims.y as usize);
            let here = UVec3::new((cell % dx) as u32, (cell / dx % dy) as u32, (cell / (dx * dy)) as u32);
            for (k, &ex) in run.iter().enumerate() {
                let (tx, bx) = all[ex as usize];
                let low = lows[ex as usize];
                let others = match two_sets {
                    false => &run[k + 1..],
                    true if k < split => &run[split..],
                    true => break,
                };
                for &ey in others {
                    // Report from the cell of the overlap's lower corner only.
                    if low.max(lows[ey as usize]) != here {
                        continue;
                    }
                    let (ty, by) = all[ey as usize];
                    if !overlaps(bx, by) {
                        continue;
                    }
                    let (i, j) = if !two_sets {
                        (tx.min(ty), tx.max(ty))
                    } else if tx >> 31 == 0 {
                        (tx, ty & !(1 << 31))
                    } else {
                        (ty, tx & !(1 << 31))
                    };
                    acc.push((i as u64) << 32 | j as u64);
                }
            }
            acc
        })
        .reduce(Vec::new, |mut x, mut y| {
            if x.len() < y.len() {
                std::mem::swap(&mut x, &mut y);
            }
            x.extend(y);
            x
        })
}

/// The boxes meeting a query box, found in the grid cells it touches instead of by a scan
/// of all of them: the output repair asks this for every candidate edit, thousands on a
/// result of 100 k triangles. A box may change afterwards ([`BoxIndex::set`]); one that
/// leaves the cells it was entered in is tested by every query from then on.
pub struct BoxIndex {
    boxes: Vec<Box3>,
    /// None when there is no box (or none with finite corners).
    grid: Option<Grid>,
    /// Cell c's boxes are `entries[start[c]..start[c + 1]]`, by id.
    start: Vec<u32>,
    entries: Vec<u32>,
    /// The cells each box was entered in.
    cells: Vec<(UVec3, UVec3)>,
    /// Boxes that left their cells.
    moved: Vec<u32>,
}

impl BoxIndex {
    pub fn new(boxes: Vec<Box3>) -> BoxIndex {
        let mut index = BoxIndex {
            boxes,
            grid: None,
            start: Vec::new(),
            entries: Vec::new(),
            cells: Vec::new(),
            moved: Vec::new(),
        };
        let Some((region, all)) = entries_in_region(&index.boxes, None) else {
            // Nothing to grid: every box is tested by every query.
            index.moved = (0..index.boxes.len() as u32).collect();
            return index;
        };
        let grid = fit_grid(&region, &all);
        let Some((start, entries, _)) = sort_by_cell(&grid, &region, &all, u64::MAX) else {
            unreachable!("no bound on the tests")
        };
        // Entries are places in `all`; boxes outside the region (none with finite corners,
        // the region being their hull) are tested by every query.
        index.entries = entries.into_iter().map(|k| all[k as usize].0).collect();
        let mut entered = vec![false; index.boxes.len()];
        for (id, _) in &all {
            entered[*id as usize] = true;
        }
        index.moved = (0..index.boxes.len() as u32).filter(|&t| !entered[t as usize]).collect();
        index.cells = index.boxes.iter().map(|b| grid.cells_of(&b.clamp_to(&region))).collect();
        index.start = start;
        index.grid = Some(grid);
        index
    }

    pub fn boxes(&self) -> &[Box3] {
        &self.boxes
    }

    /// Box `t` is now `b`.
    pub fn set(&mut self, t: usize, b: Box3) {
        self.boxes[t] = b;
        if let Some(grid) = &self.grid
            && let Some(&(lo, hi)) = self.cells.get(t)
        {
            // A cell is monotone in each coordinate (clamped to the grid), so a box whose
            // cells lie among those it was entered in meets a query only where the query's
            // cells meet those.
            let (new_lo, new_hi) = grid.cells_of(&b);
            if new_lo.cmpge(lo).all() && new_hi.cmple(hi).all() {
                return;
            }
        }
        if !self.moved.contains(&(t as u32)) {
            self.moved.push(t as u32);
        }
    }

    /// The ids of the boxes meeting `query` (touching counts), in increasing order.
    pub fn meeting(&self, query: &Box3) -> Vec<usize> {
        let mut found: Vec<u32> = self.moved.clone();
        if let Some(grid) = &self.grid {
            grid.each_cell(grid.cells_of(query), |c| {
                found.extend_from_slice(&self.entries[self.start[c] as usize..self.start[c + 1] as usize]);
            });
        }
        found.sort_unstable();
        found.dedup();
        found.into_iter().map(|t| t as usize).filter(|&t| overlaps(&self.boxes[t], query)).collect()
    }
}

trait ClampTo {
    fn clamp_to(&self, region: &Box3) -> Box3;
}

impl ClampTo for Box3 {
    fn clamp_to(&self, region: &Box3) -> Box3 {
        (self.0.max(region.0), self.1.min(region.1))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::Rng;

    #[allow(clippy::needless_range_loop)]
    fn brute(a: &[Box3], b: Option<&[Box3]>) -> Vec<(u32, u32)> {
        let mut out = Vec::new();
        match b {
            None => {
                for i in 0..a.len() {
                    for j in i + 1..a.len() {
                        if overlaps(&a[i], &a[j]) {
                            out.push((i as u32, j as u32));
                        }
                    }
                }
            }
            Some(b) => {
                for i in 0..a.len() {
                    for j in 0..b.len() {
                        if overlaps(&a[i], &b[j]) {
                            out.push((i as u32, j as u32));
                        }
                    }
                }
            }
        }
        out
    }

    fn random_boxes(n: usize, seed: u64, offset: f64) -> Vec<Box3> {
        let mut rng = Rng::new(seed);
        (0..n)
            .map(|k| {
                let lo = rng.point_in_box(DVec3::splat(offset), DVec3::splat(offset + 10.0));
                // Mostly small boxes, a few large ones, some flat.
                let size = if k % 17 == 0 { 4.0 } else { 0.4 };
                let mut d = rng.point_in_box(DVec3::ZERO, DVec3::splat(size));
                if k % 5 == 0 {
                    d.z = 0.0;
                }
                (lo, lo + d)
            })
            .collect()
    }

    #[test]
    fn same_pairs_as_brute_force() {
        let a = random_boxes(600, 1, 0.0);
        let b = random_boxes(500, 2, 5.0);
        let sorted = |mut v: Vec<(u32, u32)>| {
            v.sort_unstable();
            v
        };
        assert_eq!(sorted(box_pairs(&a, None)), brute(&a, None));
        assert_eq!(sorted(box_pairs(&a, Some(&b))), brute(&a, Some(&b)));
        assert!(!brute(&a, Some(&b)).is_empty());
        // Touching boxes count; disjoint sets give nothing.
        let c = vec![(DVec3::ZERO, DVec3::ONE), (DVec3::ONE, DVec3::splat(2.0))];
        assert_eq!(box_pairs(&c, None), vec![(0, 1)]);
        let far = vec![(DVec3::splat(50.0), DVec3::splat(51.0))];
        assert_eq!(box_pairs(&c, Some(&far)), vec![]);
    }

    #[test]
    fn pairs_near_a_few_boxes_are_those_of_all_pairs() {
        let sorted = |mut v: Vec<(u32, u32)>| {
            v.sort_unstable();
            v
        };
        let all = random_boxes(3000, 4, 0.0);
        // A few boxes in one corner, touching some of `all` exactly at their faces.
        let mut near = random_boxes(60, 5, 0.0);
        near.iter_mut().for_each(|b| *b = (b.0 * 0.2, b.1 * 0.2));
        near.push((all[7].1, all[7].1 + DVec3::ONE));
        near.push((all[9].0 - DVec3::ONE, all[9].0));
        let want = brute(&near, Some(&all));
        assert!(want.contains(&(60, 7)) && want.contains(&(61, 9)) && want.len() > 20, "{want:?}");
        assert_eq!(sorted(box_pairs_near(&near, &all)), want);
        // Spread over all of them, and none.
        let spread = random_boxes(200, 6, 0.0);
        assert_eq!(sorted(box_pairs_near(&spread, &all)), brute(&spread, Some(&all)));
        assert_eq!(box_pairs_near(&[], &all), vec![]);
        assert_eq!(box_pairs_near(&near, &[]), vec![]);
    }

    #[test]
    fn an_index_finds_the_boxes_a_scan_finds() {
        let mut all = random_boxes(2000, 7, 0.0);
        let scan =
            |all: &[Box3], q: &Box3| (0..all.len()).filter(|&t| overlaps(&all[t], q)).collect::<Vec<_>>();
        let mut index = BoxIndex::new(all.clone());
        let queries: Vec<Box3> = random_boxes(300, 8, -1.0)
            .into_iter()
            .chain([all[3], (all[5].1, all[5].1), (DVec3::splat(-9.0), DVec3::splat(-8.0))])
            .collect();
        for q in &queries {
            assert_eq!(index.meeting(q), scan(&all, q));
        }
        // Boxes moved a little (within their cells) and far (out of them, and of the hull).
        for (t, shift) in [(3, 1e-9), (11, 3.0), (12, -20.0)] {
            let b = (all[t].0 + DVec3::splat(shift), all[t].1 + DVec3::splat(shift));
            all[t] = b;
            index.set(t, b);
        }
        for q in &queries {
            assert_eq!(index.meeting(q), scan(&all, q));
        }
        for t in [11, 12] {
            assert_eq!(index.meeting(&all[t]), scan(&all, &all[t]));
            assert!(index.meeting(&all[t]).contains(&t));
        }
        assert_eq!(BoxIndex::new(Vec::new()).meeting(&queries[0]), Vec::<usize>::new());
    }

    #[test]
    fn piled_up_boxes_are_refused_before_pairing() {
        // Boxes of a fan's slivers around the origin: all share the cells at the centre.
        let fan: Vec<Box3> = (0..400)
            .map(|k| {
                let a = std::f64::consts::TAU * f64::from(k) / 400.0;
                let p = DVec3::new(a.cos(), a.sin(), 0.0);
                (p.min(DVec3::ZERO), p.max(DVec3::ZERO))
            })
            .collect();
        assert_eq!(box_pairs_within(&fan, None, 40 * 400), None);
        assert_eq!(box_pairs_within(&fan, None, u64::MAX).map(|p| p.len()), Some(brute(&fan, None).len()));
        // Spread boxes pass the same bound, with the same pairs as without it.
        let spread = random_boxes(400, 3, 0.0);
        let mut within = box_pairs_within(&spread, None, 40 * 400).expect("few pairs per cell");
        within.sort_unstable();
        assert_eq!(within, brute(&spread, None));
    }
}
