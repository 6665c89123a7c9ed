//! The result as it is written: checked the way an operand is, once its points are
//! rounded to f64, and repaired where the rounding alone made it invalid.
//!
//! The selected triangles bound a valid solid exactly, but the intersection points among
//! their corners are stored rounded to f64. Where the surfaces meet at a tiny angle (a
//! copy turned by 1e-6°) the slivers between them are thinner than that rounding near
//! the cut curve, and a few of their triangles come to cross a neighbour or lose their
//! area. So every regularized result is checked with the operand checks' exact tests
//! ([`crate::mesh::intersect`]), restricted to what rounding can have changed:
//!
//! - faces that cross: only pairs with a *changed* triangle (one that is not an uncut
//!   input triangle). Uncut triangles of one operand do not cross (the operand was
//!   checked) and uncut ones of different operands were found apart by the refinement's
//!   exact tests;
//! - faces with no area, among the changed triangles;
//! - edges of more than two faces, one of them changed, around which the faces do not
//!   alternate in direction in their exact order about the edge (the operand check's fold
//!   test, [`folded_edges`]): rounding alone can turn a tiny piece hanging on such an edge
//!   inside out (the winding number −1 or 2 beside it) without making faces cross;
//! - the operand rule's volume, per shell and for the whole result.
//!
//! Closedness is checked by the caller. Nesting and orientation of shells are those of
//! the exact result: rounding could change them only by making faces cross.
//!
//! **Repair.** Points that round to one position are one point (as when the file is read
//! back): triangles left without three distinct corners go, and so do pairs that come to
//! coincide with opposite orientations (exactly distinct slivers thinner than an ulp).
//! The corners of crossing or flat triangles are snapped onto any point within a few
//! ulps ([`snap_distance`]; the lowest id stays: A's vertices, then B's, then
//! intersection points), with the same clean-up: nearly coincident points of the two
//! operands (a copy turned a quarter in floating point) then meet instead of crossing.
//! A corner within those few ulps of an edge it is not on (a point that lay on an edge of
//! the other operand before rounding, in a result used again against the solid that cut
//! it) splits that edge there, in every triangle on it, where that leaves fewer crossings
//! and triangles without area around it ([`local_split`]); the pieces that come to
//! coincide with opposite orientations then cancel, uncut input triangles among them.
//! Then, for every crossing pair or flat triangle, its shortest edge with an
//! intersection point at one end is collapsed if it is shorter than [`COLLAPSE`] × the
//! operands' diagonal: the intersection point moves onto the other end. Only where its
//! triangles have no such edge does an edge between two input vertices go (the two
//! operands' vertices a hair apart, as where a result is used again against the solid
//! that cut it): either onto the other. A flat triangle with no such edge (a corner on its opposite edge) is
//! removed by splitting its neighbour across that edge at the corner. A collapse keeps every directed edge balanced — the triangles on the
//! edge vanish and their other edges pair up — so the result stays closed and oriented;
//! two triangles that come to coincide with opposite orientations cancel. The moved
//! triangles are checked again, for a few rounds. A crossing that none of this removes
//! (rounding put it there by an ulp) goes by moving one of the intersection points among
//! its triangles' corners to a neighbouring f64 position, each coordinate by an ulp or two,
//! where the exact tests around that point find nothing crossing ([`nudge`]); then
//! everything is checked again (a point none of whose positions helped is not tried again
//! while the triangles around it stay as they were: the tests would answer the same).
//! Where a crossing is still left, the flat region at it
//! that holds faces of both orientations (a sheet between a face and a reversed copy of it
//! a hair off its plane: a result used again against the solid that cut it carries that
//! solid's faces with rounded corners) is rebuilt as a pocket is, its new triangles' cover
//! counted by winding numbers across the region's outline instead of at their centroids
//! (a sliver between corners in line within an ulp has a centroid that rounds out of it);
//! where its outline's edges cross in the plane, first with its corners a few ulps apart
//! snapped together and its outline's edges split at the corners a few ulps beside them.
//! Each such rebuild is made only where it leaves fewer crossings and triangles without
//! area around it ([`Repair::sheets`]). Past those, the sheets are rebuilt once more
//! keeping their own edges that meet none of their others in the plane (a fresh diagonal
//! beside a corner in line within an ulp with two others may pass over a thin wedge
//! hinged at that corner), and any edge of a crossing triangle up to [`COLLAPSE`] × the
//! diagonal is collapsed, not only the shortest: each again only where it leaves fewer
//! defects around it. Past all of these, the sheets once more, each where the splits of
//! its outline cut the triangles of the sheet beside it (across a crease of the outline)
//! and leave them crossing rebuilt together with that sheet (and so on for up to three),
//! all of them made only where together they leave fewer defects
//! ([`Repair::joined_sheets`]). Past those, a corner of a crossing triangle is merged with
//! any point at most [`COLLAPSE`] × the diagonal from it, joined to it by an edge of other
//! triangles or by none (a vertex of one operand and its turned copy in the other a hair
//! apart, where needles of both lie along each other; a corner of a face and of its
//! reversed copy a hair off its plane), nearest first, the way a collapse goes and only
//! where it leaves fewer defects around it ([`Repair::merged`]). Past those, the sheets
//! once more, each with every intersection point within [`COLLAPSE`] × the diagonal of its
//! corners merged onto them first, all at once ([`Cleanup::merged_sheets`]): where a face's
//! plane passes within rounding of a vertex of the other operand (a result used again
//! against the solid that cut it: its vertices were intersection points on that solid's
//! faces), it cuts the edges at that vertex at points a hair from it, and the sheet's
//! outline crosses itself among them. A shell that encloses no
//! volume by the
//! operand rule (a sliver flattened by rounding), no wider than [`COLLAPSE`] × the
//! diagonal in every direction (a speck left of a sliver), or thinner on average (twice its
//! volume over its area) than a flat region's thickness, is dropped whole. A result the
//! repair changed gets the whole operand check once assembled (the caller,
//! [`InvalidResult::NotOperand`]). Anything still invalid is an error naming the faces and
//! the place: never a silently invalid result.
//!
//! **Folds.** A folded edge is a defect like a crossing: the points near the corners of
//! its faces are snapped, their shortest edge collapsed (past the sheets any of their
//! edges up to [`COLLAPSE`] × the diagonal, past those their corners merged with a point a
//! hair away), their intersection points moved by an ulp. A closed piece on a folded edge
//! (its faces joined across edges of exactly two faces and balanced among their own, so
//! that it hangs on the rest only by edges of more than two) that holds no volume worth
//! keeping, by the measures a shell is dropped by (no wider than [`COLLAPSE`] × the
//! diagonal, or thinner on average than a flat region), is dropped where that leaves fewer
//! defects around it, once no collapse applies ([`Cleanup::drop_pieces`]). Every "fewer
//! defects around it" above counts crossings, faces without area and folded edges
//! together; but for the ulp moves' and the drops' own tests, each side is counted as it is
//! once such pieces on its folded edges are dropped ([`count_near`]): a collapse that
//! removes a crossing and leaves a sliver beside it turned inside out is judged by what the
//! repair then makes of it.
//!
//! Past every other step, a closed piece on a folded edge that lies doubled over the rest —
//! inside the rest's solid facing out, or outside it facing in, so that the winding number
//! in it is 2 or −1, as counted from the exact order of the faces about each edge where it
//! hangs ([`doubled_at`]) — is dropped whatever its volume, the pieces on one edge together,
//! where that leaves fewer defects around them ([`Cleanup::drop_doubled`]): every point in
//! it is inside (or outside) with it and without it, so the solid keeps its points and only
//! loses a double cover. Rounding and the collapses around a sliver can leave such a piece
//! too thick to count as one of no volume: a lens 0.09 long and 2e-10 thick on average,
//! folded by nanometres over an edge of the rest into the solid.

use crate::mesh::hash::{HashMap, HashMapExt, HashSet, HashSetExt};

use glam::{DVec2, DVec3};
use rayon::prelude::*;

use super::input::{flatness_bound, is_flat};
use crate::exact::orient2d;
use crate::mesh::boxgrid::{Box3, BoxIndex, box_pairs};
use crate::mesh::covering::{order_about, signed_tetra_volume};
use crate::mesh::disjoint_sets::UnionFind;
use crate::mesh::frame::Frame;
use crate::mesh::intersect::{TriangleSoup, is_degenerate, soup_self_intersections_near, weld_by_position};
use crate::mesh::triangulate::{self, Projection};
use crate::mesh::validate::{Fold, folded_edges};

/// Longest edge a repair collapses, relative to the operands' bounding-box diagonal: far
/// below any feature of a real model (the volume moved is of the order of its square
/// times the sliver's length), far above the slivers' widths near the cut curve.
pub const COLLAPSE: f64 = 1e-7;

/// Rounds of snaps, splits and collapses before only ulp moves are left (each round
/// repairs every defect it can at once; one repair may uncover the next one beside it).
const ROUNDS: usize = 32;

/// Rounds of ulp moves before giving up.
const NUDGES: usize = 16;

/// The repairs past the snaps, splits and collapses, in the order they are tried once
/// those make no edit: each only where every one before it made none, at most its number
/// of times.
#[derive(Clone, Copy, Debug)]
enum LastResort {
    /// Folds no collapse removed: the closed pieces of no volume hanging on them
    /// ([`Cleanup::drop_pieces`]).
    DropPieces,
    /// Intersection points moved by an ulp or two ([`nudge`]).
    Nudge,
    /// The sheets at the crossings, each where it leaves fewer defects around it
    /// ([`Cleanup::rebuild_sheets`]).
    Sheets,
    /// The sheets keeping their own edges that cross none of their others ([`flatten`]),
    /// then the other short edges of the crossing triangles (and of those around a folded
    /// edge, [`Cleanup::collapse_longer`]).
    Longer,
    /// The sheets again, each rebuilt together with the sheets beside it where its
    /// outline's splits leave those crossing ([`Cleanup::join_sheets`]).
    Joined,
    /// A corner of a crossing triangle (or of one around a folded edge) merged with any
    /// point a hair away ([`Cleanup::merge_near`]).
    Merged,
    /// The sheets at the crossings with the intersection points a hair from their corners
    /// merged onto them first ([`Cleanup::merged_sheets`]).
    MergedSheets,
    /// The closed pieces on the folded edges that lie doubled over the rest, dropped
    /// whatever their volume: the solid's points stay ([`Cleanup::drop_doubled`]).
    Doubled,
}

const LAST_RESORTS: [(LastResort, usize); 8] = [
    (LastResort::DropPieces, ROUNDS),
    (LastResort::Nudge, NUDGES),
    (LastResort::Sheets, ROUNDS),
    (LastResort::Longer, ROUNDS),
    (LastResort::Joined, ROUNDS),
    (LastResort::Merged, ROUNDS),
    (LastResort::MergedSheets, ROUNDS),
    (LastResort::Doubled, ROUNDS),
];

/// How thin a region between two nearly coincident faces may be to count as flat, for
/// points with coordinates up to `max_abs` and operands of bounding-box diagonal
/// `diagonal`: far below any feature of a real model, far above the few ulps by which
/// rounding moves a point.
fn flat_thickness(max_abs: f64, diagonal: f64) -> f64 {
    (1e-12 * diagonal).max(64.0 * f64::EPSILON * max_abs)
}

/// How close (per coordinate) a point must be to a corner of a crossing or flat triangle
/// to be snapped onto it, for points with coordinates up to `max_abs`: a few ulps, the
/// distance rounding alone puts between exactly distinct points of a sub-ulp sliver.
fn snap_distance(max_abs: f64) -> f64 {
    64.0 * f64::EPSILON * max_abs
}

/// What the check found and the repair did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Repair {
    /// Triangles tested against the others (those that are not uncut input triangles).
    pub tested: usize,
    /// Crossing triangle pairs found after rounding, before any repair.
    pub crossings: usize,
    /// Triangles without area after rounding, before any repair.
    pub flat_triangles: usize,
    /// Edges of more than two triangles around which they do not alternate in direction
    /// after rounding, before any repair (a tiny piece hanging on the edge turned inside
    /// out: the operand check's fold test).
    pub folded_edges: usize,
    /// Points snapped onto a point a few ulps away (the corners of crossing or flat
    /// triangles: nearly coincident points of the two operands and the cut).
    pub snapped: usize,
    /// Edges split at a corner within a few ulps of them (a corner of a crossing or flat
    /// triangle that lay on the edge before rounding).
    pub split_edges: usize,
    /// Intersection points moved to a neighbouring f64 position (each coordinate by an ulp
    /// or two) where a crossing remained that no snap or collapse removed.
    pub ulp_moves: usize,
    /// Edges collapsed.
    pub collapsed_edges: usize,
    /// Triangles removed by the snaps and collapses (those left without area, pairs that
    /// coincide with opposite orientations).
    pub removed_triangles: usize,
    /// Flat regions rebuilt without their sliver (between two nearly coincident faces, too
    /// thin for f64 and too wide to collapse an edge of).
    pub pockets: usize,
    /// Triangles those regions had.
    pub pocket_triangles: usize,
    /// Sheets between a face and a reversed copy of it a hair off its plane (a result
    /// used again against the solid that cut it) rebuilt as one surface where nothing else
    /// removed a crossing at their edge: the flat region counted by winding numbers
    /// instead of at the centroids of its new triangles (slivers thinner than the rounding
    /// of a centroid, between corners in line within an ulp), its outline first snapped
    /// and split where its corners lie a few ulps from each other or from its edges (those
    /// snaps and splits are counted with the others).
    pub sheets: usize,
    /// Triangles those sheets had.
    pub sheet_triangles: usize,
    /// Of those sheets, the ones rebuilt together with the sheet before them, where its
    /// outline's splits left crossings in this one beside it (across a crease of the
    /// outline).
    pub joined_sheets: usize,
    /// Of those sheets, the ones rebuilt with the intersection points a hair from their
    /// corners (within [`COLLAPSE`] × the diagonal) merged onto them first, where their
    /// outline crossed itself among such points (those merges are counted with
    /// [`Repair::merged`]).
    pub merged_sheets: usize,
    /// Points merged with a point a hair away, past every other repair (a corner of a
    /// crossing triangle and a point it shares no edge with, or an edge of triangles
    /// beside it: the two operands' vertices and the cut a hair apart, along needles of
    /// both, or a corner of a face and of its reversed copy a hair off its plane).
    pub merged: usize,
    /// Long flat triangles (a corner on the opposite edge once rounded) removed by
    /// splitting the neighbour across that edge at the corner.
    pub flipped: usize,
    /// Shells dropped because they enclose no volume (or are specks no wider than the
    /// longest edge a repair collapses, or sheets thinner on average than a flat region).
    pub dropped_shells: usize,
    /// Closed pieces hanging on the rest by edges of more than two triangles, dropped
    /// where their faces did not alternate about such an edge: pieces that hold no volume
    /// worth keeping by the same measures as a dropped shell.
    pub dropped_pieces: usize,
    /// Closed pieces on a folded edge that lie inside the rest facing out, or outside it
    /// facing in (the winding number 2 or −1 in them, [`doubled_at`]), dropped past every
    /// other repair whatever their volume: the solid holds the same points without them.
    pub doubled_pieces: usize,
    /// Farthest any point moved.
    pub moved: f64,
}

impl Repair {
    /// True when the result was written as selected.
    pub fn is_clean(&self) -> bool {
        self.crossings == 0
            && self.flat_triangles == 0
            && self.folded_edges == 0
            && self.removed_triangles == 0
            && self.split_edges == 0
            && self.pockets == 0
            && self.sheets == 0
            && self.merged_sheets == 0
            && self.flipped == 0
            && self.merged == 0
            && self.dropped_shells == 0
            && self.dropped_pieces == 0
            && self.doubled_pieces == 0
    }
}

impl std::fmt::Display for Repair {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} triangles tested, {} crossing pairs, {} triangles without area and {} folded edges after rounding, {} points snapped, \
             {} edges split at a corner beside them, {} points moved by an ulp or two, {} edges collapsed, {} triangles removed by the snaps and collapses, points moved at most {:e}, {} flat slivers removed \
             ({} triangles rebuilt), {} sheets between opposite faces rebuilt ({} triangles, {} together with the sheet beside them, \
             {} with the points a hair from their corners merged first), {} long flat triangles split away, {} points merged with one a hair away, {} flat shells dropped, \
             {} flat pieces hanging on a folded edge dropped, {} pieces lying doubled over the rest dropped",
            self.tested,
            self.crossings,
            self.flat_triangles,
            self.folded_edges,
            self.snapped,
            self.split_edges,
            self.ulp_moves,
            self.collapsed_edges,
            self.removed_triangles,
            self.moved,
            self.pockets,
            self.pocket_triangles,
            self.sheets,
            self.sheet_triangles,
            self.joined_sheets,
            self.merged_sheets,
            self.flipped,
            self.merged,
            self.dropped_shells,
            self.dropped_pieces,
            self.doubled_pieces
        )
    }
}

/// Why a result could not be made valid.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum InvalidResult {
    #[error(
        "faces {a} and {b} cross near ({}, {}, {}) once rounded to f64, and no snap, short-edge collapse or ulp move there removes it",
        near.x, near.y, near.z
    )]
    Crossing { a: usize, b: usize, near: DVec3 },
    #[error(
        "face {face} near ({}, {}, {}) has no area once rounded to f64, and no snap, short-edge collapse or ulp move there removes it",
        near.x, near.y, near.z
    )]
    Flat { face: usize, near: DVec3 },
    #[error(
        "the faces around the edge at ({}, {}, {}) do not alternate in direction once rounded to f64 \
         (a tiny piece hanging on the edge turned inside out), and no snap, short-edge collapse, ulp move \
         or drop of a piece without volume there removes it",
        near.x, near.y, near.z
    )]
    Folded { near: DVec3 },
    #[error("it encloses no volume once rounded to f64 (volume {volume}) but is not empty")]
    NoVolume { volume: f64 },
    #[error("once rounded to f64 and repaired it is not a solid texgeo accepts as an operand: {reason}")]
    NotOperand { reason: String },
}

impl InvalidResult {
    /// The same, with its place and volume given in the operands' units.
    pub fn out_of(self, frame: Frame) -> InvalidResult {
        match self {
            InvalidResult::Crossing { a, b, near } => {
                InvalidResult::Crossing { a, b, near: frame.point_out(near) }
            }
            InvalidResult::Flat { face, near } => InvalidResult::Flat { face, near: frame.point_out(near) },
            InvalidResult::Folded { near } => InvalidResult::Folded { near: frame.point_out(near) },
            InvalidResult::NoVolume { volume } => {
                InvalidResult::NoVolume { volume: frame.volume_out(volume) }
            }
            InvalidResult::NotOperand { reason } => InvalidResult::NotOperand { reason },
        }
    }
}

/// The triangles to write, for each the index in the selection it comes from, and what
/// was done.
#[derive(Clone, Debug)]
pub struct Finished {
    /// The points, as given except those moved by an ulp or two ([`Repair::ulp_moves`]).
    pub positions: Vec<DVec3>,
    pub triangles: Vec<[u32; 3]>,
    pub origin: Vec<u32>,
    pub repair: Repair,
}

/// Checks (and repairs) the result triangles `tris` over `points`, whose ids from
/// `first_new` on are intersection points. `changed[t]` is false for uncut input
/// triangles; `diagonal` is the operands' bounding-box diagonal.
///
/// Points are welded by position; then, round by round until no triangle crosses
/// another or has no area: snaps of nearby points, splits of neighbours across flat
/// triangles, rebuilt pockets around crossings, collapses of short edges, and past the
/// last round ulp moves. Flat shells are dropped at the end.
pub fn finish(
    points: &[DVec3],
    first_new: u32,
    tris: &[[u32; 3]],
    changed: &[bool],
    diagonal: f64,
) -> Result<Finished, InvalidResult> {
    if tris.is_empty() {
        let repair = Repair::default();
        return Ok(Finished {
            positions: points.to_vec(),
            triangles: Vec::new(),
            origin: Vec::new(),
            repair,
        });
    }
    let mut c = Cleanup::new(points, first_new, tris, changed, diagonal);
    // Welding is a collapse of edges of length zero: the same clean-up (among the changed
    // triangles: uncut ones of one operand do not coincide with another's).
    collapse(&mut c.soup, &mut c.origin, &mut c.changed, &HashMap::new(), false, &mut c.repair);
    // How often each last resort made an edit.
    let mut tried = [0; LAST_RESORTS.len()];
    for round in 0.. {
        let found = c.defects();
        if round == 0 {
            c.repair.crossings = found.crossings.len();
            c.repair.flat_triangles = found.flat.len();
            c.repair.folded_edges = found.folds.len();
        }
        if found.is_empty() {
            break;
        }
        let more = round < ROUNDS;
        if more && (c.snap(&found) || c.split_edges(&found)) {
            continue;
        }
        let plan = c.plan(&found);
        if more && (c.split_neighbours(&plan.long_flat) || c.rebuild_pockets(&plan.wide)) {
            continue;
        }
        // Past the last round no collapse is planned: the ulp moves get their turn below.
        let map = if more { c.choose_collapses(plan.edges) } else { HashMap::new() };
        if map.is_empty() {
            let err = plan.stuck.unwrap_or_else(|| c.first_error(&found));
            // The first last resort that makes an edit, each at most its number of times.
            let made = LAST_RESORTS.iter().zip(&mut tried).any(|(&(resort, most), tried)| {
                let made = *tried < most && c.last_resort(resort, &found);
                *tried += usize::from(made);
                made
            });
            if made {
                continue;
            }
            return Err(err);
        }
        c.collapse(&map);
    }
    c.finished()
}

/// What the check after rounding finds among the changed triangles: pairs that cross,
/// triangles without area, and edges of more than two triangles around which they do not
/// alternate in direction (the operand check's fold test, [`folded_edges`]).
struct Defects {
    crossings: Vec<(usize, usize)>,
    flat: Vec<usize>,
    folds: Vec<Fold>,
}

impl Defects {
    fn is_empty(&self) -> bool {
        self.crossings.is_empty() && self.flat.is_empty() && self.folds.is_empty()
    }

    /// The triangles of each defect: a crossing pair, a flat triangle, the triangles
    /// around a folded edge; in that order.
    fn groups(&self) -> impl Iterator<Item = Vec<usize>> + '_ {
        let crossings = self.crossings.iter().map(|&(a, b)| vec![a, b]);
        let flat = self.flat.iter().map(|&f| vec![f]);
        crossings.chain(flat).chain(self.folds.iter().map(|f| f.triangles.clone()))
    }

    /// The triangles of every defect ([`Defects::groups`]), one after the other.
    fn faces(&self) -> impl Iterator<Item = usize> + '_ {
        let crossings = self.crossings.iter().flat_map(|&(a, b)| [a, b]);
        crossings
            .chain(self.flat.iter().copied())
            .chain(self.folds.iter().flat_map(|f| f.triangles.iter().copied()))
    }

    /// The triangles of the crossings and then of the folds, as groups: those whose other
    /// short edges and nearby points the last resorts try.
    fn crossing_groups(&self) -> impl Iterator<Item = Vec<usize>> + '_ {
        let crossings = self.crossings.iter().map(|&(a, b)| vec![a, b]);
        crossings.chain(self.folds.iter().map(|f| f.triangles.clone()))
    }
}

/// The result triangles while [`finish`] repairs them: the soup, each triangle's origin
/// and whether it changed, what was done, and the distances the repairs work within.
struct Cleanup {
    soup: TriangleSoup,
    origin: Vec<u32>,
    changed: Vec<bool>,
    repair: Repair,
    /// Ids from here on are intersection points (they may move; input points may not).
    first_new: u32,
    /// The longest edge a collapse may remove.
    limit: f64,
    /// How far from its plane a corner of a flat region may lie.
    thickness: f64,
    /// Points within this distance (per coordinate) of a defect's corner snap together.
    snap: f64,
    /// The points for which [`nudge`] found no position, with the triangles around them
    /// then: with the same triangles it finds none again.
    unmoved: Unmoved,
}

/// Which points [`Cleanup::sheet_edit`] joins to a sheet's corners before it rebuilds it
/// ([`Cleanup::sheet_snaps`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Corners {
    /// The points within a few ulps, counted as snaps.
    Snapped,
    /// The intersection points within the collapse limit ([`Cleanup::merged_sheets`]),
    /// counted as merges.
    Merged,
}

/// Per point, the triangles around it (as [`sub_soup`] gives them) where [`nudge`] found no
/// position for it.
type Unmoved = HashMap<u32, (Vec<[u32; 3]>, Vec<DVec3>)>;

/// What one round found to do about the defects: short edges to collapse (length,
/// keep, gone), crossings and flat triangles without one, and the error to give if
/// nothing helps.
struct Plan {
    edges: Vec<(f64, u32, u32)>,
    wide: Vec<(usize, usize)>,
    long_flat: Vec<usize>,
    stuck: Option<InvalidResult>,
}

/// Sheets rebuilt on a copy of the soup ([`Cleanup::sheet_edit`]): the copy, the points
/// to count defects at (the regions' corners and the points snapped onto them), and what
/// was done.
struct SheetEdit {
    soup: TriangleSoup,
    origin: Vec<u32>,
    changed: Vec<bool>,
    at: Vec<u32>,
    snaps: HashMap<u32, u32>,
    splits: usize,
    removed: usize,
    rebuilt: usize,
}

impl SheetEdit {
    /// `next`, made on this edit's copy, joined to it.
    fn join(&mut self, next: SheetEdit) {
        self.soup = next.soup;
        self.origin = next.origin;
        self.changed = next.changed;
        self.at.extend(next.at);
        self.at.sort_unstable();
        self.at.dedup();
        self.snaps.extend(next.snaps);
        self.splits += next.splits;
        self.removed += next.removed;
        self.rebuilt += next.rebuilt;
    }
}

impl Cleanup {
    fn new(points: &[DVec3], first_new: u32, tris: &[[u32; 3]], changed: &[bool], diagonal: f64) -> Cleanup {
        // Points are identified by position, as when the file is read back.
        let weld = weld_by_position(points);
        let soup = TriangleSoup {
            positions: points.to_vec(),
            triangles: tris.iter().map(|t| t.map(|v| weld[v as usize])).collect(),
            face_of: (0..tris.len() as u32).collect(),
            failed: Vec::new(),
        };
        let changed = changed.to_vec();
        let repair = Repair { tested: changed.iter().filter(|&&c| c).count(), ..Repair::default() };
        let max_abs = points.iter().fold(0.0f64, |m, p| m.max(p.abs().max_element()));
        Cleanup {
            soup,
            origin: (0..tris.len() as u32).collect(),
            changed,
            repair,
            first_new,
            limit: COLLAPSE * diagonal,
            thickness: flat_thickness(max_abs, diagonal),
            snap: snap_distance(max_abs),
            unmoved: Unmoved::new(),
        }
    }

    /// Makes `resort`'s edits; true when it made any (everything is checked again).
    fn last_resort(&mut self, resort: LastResort, found: &Defects) -> bool {
        let crossings = &found.crossings;
        match resort {
            LastResort::DropPieces => self.drop_pieces(&found.folds),
            LastResort::Nudge => {
                nudge(&mut self.soup, found, self.first_new, &mut self.unmoved, &mut self.repair)
            }
            LastResort::Sheets => self.rebuild_sheets(crossings, false),
            LastResort::Longer => self.rebuild_sheets(crossings, true) || self.collapse_longer(found),
            LastResort::Joined => self.join_sheets(crossings, Corners::Snapped),
            LastResort::Merged => self.merge_near(found),
            LastResort::MergedSheets => self.merged_sheets(crossings),
            LastResort::Doubled => self.drop_doubled(found),
        }
    }

    fn is_new(&self, v: u32) -> bool {
        v >= self.first_new
    }

    /// The measures of the pieces [`Cleanup::drop_pieces`] drops, for [`count_near`].
    fn pieces(&self) -> Pieces {
        Some((self.limit, self.thickness))
    }

    /// The changed triangles that cross another, those without area, and the edges with a
    /// changed triangle around which the triangles do not alternate in direction (uncut
    /// input triangles alone are as exact as the operands).
    fn defects(&self) -> Defects {
        let ((crossings, flat), folds) = rayon::join(
            || {
                let crossings = soup_self_intersections_near(&self.soup, &self.changed, usize::MAX);
                let flat: Vec<usize> = (0..self.soup.triangles.len())
                    .into_par_iter()
                    .filter(|&t| self.changed[t] && is_degenerate(self.soup.triangle(t)))
                    .collect();
                (crossings, flat)
            },
            || {
                let changed = |on: &[usize]| on.iter().any(|&t| self.changed[t]);
                folded_edges(&self.soup.positions, &self.soup.triangles, changed)
            },
        );
        Defects { crossings, flat, folds }
    }

    /// The error to give for the first of the defects found.
    fn first_error(&self, found: &Defects) -> InvalidResult {
        if let Some(x) = found.crossings.first() {
            return self.crossing(x);
        }
        if let Some(&f) = found.flat.first() {
            return self.flat_face(f);
        }
        let near = found.folds.first().map_or(DVec3::ZERO, |f| {
            (self.soup.positions[f.a as usize] + self.soup.positions[f.b as usize]) / 2.0
        });
        InvalidResult::Folded { near }
    }

    fn crossing(&self, &(a, b): &(usize, usize)) -> InvalidResult {
        InvalidResult::Crossing { a, b, near: self.soup.triangle(a).iter().sum::<DVec3>() / 3.0 }
    }

    fn flat_face(&self, face: usize) -> InvalidResult {
        InvalidResult::Flat { face, near: self.soup.triangle(face).iter().sum::<DVec3>() / 3.0 }
    }

    /// Snaps the points near the defects' corners together; true when any moved.
    fn snap(&mut self, found: &Defects) -> bool {
        let map = snap_map(&self.soup, found.faces(), self.snap);
        if map.is_empty() {
            return false;
        }
        for (&gone, &keep) in &map {
            let d = self.soup.positions[gone as usize].distance(self.soup.positions[keep as usize]);
            self.repair.moved = self.repair.moved.max(d);
        }
        self.repair.snapped += map.len();
        self.collapse(&map);
        true
    }

    /// The shortest collapsible edge of `faces` (at most `limit` long): (length, the end
    /// kept, the end that goes). Edges with an intersection point at an end come first;
    /// an edge between two input vertices (of the two operands, a hair apart, as where a
    /// result is used again against the solid that cut it) only where there is none.
    fn shortest_edge(&self, faces: &[usize]) -> Option<(f64, u32, u32)> {
        let length =
            |(p, q): (u32, u32)| self.soup.positions[p as usize].distance(self.soup.positions[q as usize]);
        let edges = || {
            faces.iter().flat_map(|&f| {
                let t = self.soup.triangles[f];
                (0..3).map(move |k| (t[k], t[(k + 1) % 3]))
            })
        };
        let with_new =
            edges().any(|(p, q)| (self.is_new(p) || self.is_new(q)) && length((p, q)) <= self.limit);
        edges()
            .filter(|&(p, q)| !with_new || self.is_new(p) || self.is_new(q))
            .map(|(p, q)| {
                let (keep, gone) = if self.is_new(p) == self.is_new(q) {
                    (p.min(q), p.max(q))
                } else if !self.is_new(p) {
                    (p, q)
                } else {
                    (q, p)
                };
                (length((p, q)), keep, gone)
            })
            .filter(|e| e.0 <= self.limit)
            .min_by(|x, y| x.0.total_cmp(&y.0).then((x.1, x.2).cmp(&(y.1, y.2))))
    }

    /// Per defect, the shortest collapsible edge of its triangles, or the defect set
    /// aside (with the first such crossing as the error to give; a folded edge without one
    /// is left to the stages past the collapses).
    fn plan(&self, found: &Defects) -> Plan {
        let mut plan = Plan { edges: Vec::new(), wide: Vec::new(), long_flat: Vec::new(), stuck: None };
        for c in &found.crossings {
            match self.shortest_edge(&[c.0, c.1]) {
                Some(e) => plan.edges.push(e),
                None => {
                    plan.stuck = plan.stuck.or_else(|| Some(self.crossing(c)));
                    plan.wide.push(*c);
                }
            }
        }
        for &f in &found.flat {
            match self.shortest_edge(&[f]) {
                Some(e) => plan.edges.push(e),
                None => plan.long_flat.push(f),
            }
        }
        plan.edges.extend(found.folds.iter().filter_map(|f| self.shortest_edge(&f.triangles)));
        plan
    }

    /// Flat triangles without a short edge: one corner lies on the opposite edge once
    /// rounded; the neighbour across that edge is split there instead, which covers the
    /// same area. True when any was split (everything is checked again).
    fn split_neighbours(&mut self, long_flat: &[usize]) -> bool {
        if long_flat.is_empty() {
            return false;
        }
        let by_edge = edge_faces(&self.soup);
        let mut gone = vec![false; self.soup.triangles.len()];
        let mut added = Vec::new();
        for &f in long_flat {
            if let Some((g, pieces)) =
                split_neighbour(&self.soup, &by_edge, f).filter(|x| !gone[f] && !gone[x.0])
            {
                gone[f] = true;
                gone[g] = true;
                added.extend(pieces.map(|t| (t, self.origin[g])));
                self.repair.flipped += 1;
            }
        }
        self.replace(&gone, added)
    }

    /// Crossings without a short edge: the flat region around them is rebuilt without
    /// its sliver. True when any was (everything is checked again).
    fn rebuild_pockets(&mut self, wide: &[(usize, usize)]) -> bool {
        if wide.is_empty() {
            return false;
        }
        let by_edge = edge_faces(&self.soup);
        let mut gone = vec![false; self.soup.triangles.len()];
        let mut added = Vec::new();
        for &(a, b) in wide {
            if gone[a] || gone[b] {
                continue;
            }
            // The region in the plane of either triangle.
            let Some(f) = [a, b].into_iter().find_map(|seed| {
                flatten(&self.soup, &by_edge, &self.origin, seed, self.thickness, false, false)
                    .filter(|f| f.removed.contains(&a) && f.removed.contains(&b))
            }) else {
                continue;
            };
            if f.removed.iter().any(|&t| gone[t]) {
                continue;
            }
            self.repair.pockets += 1;
            self.repair.pocket_triangles += f.take_into(&mut gone, &mut added);
        }
        self.replace(&gone, added)
    }

    /// The last resort for crossings that no snap, split, pocket, collapse or ulp move
    /// removed: the flat region in the plane of either triangle where it holds faces of
    /// both orientations (a sheet between a face and another's reversed copy a hair off
    /// its plane: a result used again against the solid that cut it carries that solid's
    /// faces with rounded corners) or both triangles, rebuilt as a pocket is but with its
    /// cover counted by winding numbers ([`flatten`]), where that leaves fewer crossings
    /// and triangles without area around it ([`local_rebuild`]). True when any was.
    fn rebuild_sheets(&mut self, crossings: &[(usize, usize)], keep: bool) -> bool {
        let by_edge = edge_faces(&self.soup);
        let boxes = BoxIndex::new(self.soup.boxes());
        let mut gone = vec![false; self.soup.triangles.len()];
        let mut added = Vec::new();
        for &(a, b) in crossings {
            if gone[a] || gone[b] {
                continue;
            }
            for seed in [a, b] {
                let Some(f) = flatten(&self.soup, &by_edge, &self.origin, seed, self.thickness, true, keep)
                else {
                    continue;
                };
                let both = f.removed.contains(&a) && f.removed.contains(&b);
                if !(both || f.opposed) || f.removed.iter().any(|&t| gone[t]) {
                    continue;
                }
                let (before, after) = local_rebuild(&self.soup, &boxes, &f, self.pieces());
                if after >= before {
                    continue;
                }
                self.repair.sheets += 1;
                self.repair.sheet_triangles += f.take_into(&mut gone, &mut added);
                break;
            }
        }
        if self.replace(&gone, added) {
            return true;
        }
        // None could be rebuilt as it is: its outline's corners in line within an ulp cross
        // each other's edges in the plane. The first whose outline, split at those corners
        // (in every triangle on the edge), can be rebuilt, where that leaves fewer defects.
        crossings.iter().any(|&(a, b)| {
            [a, b].into_iter().any(|seed| self.split_sheet(&by_edge, &boxes, seed, keep, 0, Corners::Snapped))
        })
    }

    /// The last resort past every other: the sheets at the crossings with their outlines
    /// split ([`Cleanup::split_sheet`]), each together with up to three sheets beside it that
    /// the splits leave crossing, without and then with their own edges kept. True when one
    /// was rebuilt.
    fn join_sheets(&mut self, crossings: &[(usize, usize)], corners: Corners) -> bool {
        /// Sheets rebuilt after the first where the one before left crossings beside it.
        const JOINED: usize = 3;
        let by_edge = edge_faces(&self.soup);
        let boxes = BoxIndex::new(self.soup.boxes());
        [false, true].into_iter().any(|keep| {
            crossings.iter().any(|&(a, b)| {
                [a, b].into_iter().any(|seed| self.split_sheet(&by_edge, &boxes, seed, keep, JOINED, corners))
            })
        })
    }

    /// The sheet in the plane of triangle `seed` with the points within a few ulps of its
    /// corners snapped together ([`snap_map`]), its outline split at the corners beside
    /// its edges ([`outline_splits`]) and then rebuilt ([`flatten`] by winding numbers),
    /// made where that leaves fewer crossings and triangles without area at its corners
    /// than before. Where the splits leave crossings in the sheet beside it (across a crease
    /// of its outline, a sheet of its own whose triangles the splits cut), that sheet is
    /// rebuilt too, and so on for up to `most` more: all of them are made where together
    /// they leave fewer defects at their corners ([`Repair::joined_sheets`]). True when it
    /// was.
    fn split_sheet(
        &mut self,
        by_edge: &EdgeFaces,
        boxes: &BoxIndex,
        seed: usize,
        keep: bool,
        most: usize,
        corners: Corners,
    ) -> bool {
        let start = (self.soup.clone(), self.origin.clone(), self.changed.clone());
        let Some(mut edit) = self.sheet_edit(start, Some(by_edge), seed, keep, false, corners) else {
            return false;
        };
        let same = |_: &mut TriangleSoup, _: &mut Vec<u32>, _: &mut Vec<bool>, local: &[u32]| local.to_vec();
        for joined in 0..=most {
            // Defects at the regions' corners (and those snapped onto them) before and after.
            let mut used = HashSet::new();
            used.extend(edit.soup.triangles.iter().flatten().copied());
            let present: Vec<u32> = edit.at.iter().copied().filter(|v| used.contains(v)).collect();
            let before = local_defects(&self.soup, boxes, &edit.at, self.pieces(), same).0;
            let after =
                local_defects(&edit.soup, &BoxIndex::new(edit.soup.boxes()), &present, self.pieces(), same).0;
            if after < before {
                for (&gone, &keep) in &edit.snaps {
                    let d = self.soup.positions[gone as usize].distance(self.soup.positions[keep as usize]);
                    self.repair.moved = self.repair.moved.max(d);
                }
                match corners {
                    Corners::Snapped => self.repair.snapped += edit.snaps.len(),
                    Corners::Merged => {
                        self.repair.merged += edit.snaps.len();
                        self.repair.merged_sheets += 1 + joined;
                    }
                }
                self.repair.split_edges += edit.splits;
                self.repair.removed_triangles += edit.removed;
                self.repair.sheets += 1 + joined;
                self.repair.joined_sheets += joined;
                self.repair.sheet_triangles += edit.rebuilt;
                self.soup = edit.soup;
                self.origin = edit.origin;
                self.changed = edit.changed;
                return true;
            }
            if joined == most {
                break;
            }
            // The next sheet: at a triangle the edits left crossing another at their corners.
            let near: Vec<bool> = edit
                .soup
                .triangles
                .iter()
                .map(|t| t.iter().any(|v| present.binary_search(v).is_ok()))
                .collect();
            let mut crossing: Vec<usize> = soup_self_intersections_near(&edit.soup, &near, usize::MAX)
                .into_iter()
                .flat_map(|(a, b)| [a, b])
                .collect();
            crossing.sort_unstable();
            crossing.dedup();
            let Some(next) = crossing.into_iter().find_map(|t| {
                let state = (edit.soup.clone(), edit.origin.clone(), edit.changed.clone());
                self.sheet_edit(state, None, t, keep, true, corners)
            }) else {
                break;
            };
            edit.join(next);
        }
        false
    }

    /// [`Cleanup::split_sheet`]'s edit of one sheet, made on `state` (a copy of the soup,
    /// the origins and the changed flags, whose edge map is `by_edge` where given): its
    /// corners snapped, its outline split and the sheet rebuilt. `None` where the sheet
    /// cannot be rebuilt, or (unless `plain`) needs neither a snap nor a split.
    fn sheet_edit(
        &self,
        state: (TriangleSoup, Vec<u32>, Vec<bool>),
        by_edge: Option<&EdgeFaces>,
        seed: usize,
        keep: bool,
        plain: bool,
        corners: Corners,
    ) -> Option<SheetEdit> {
        let (mut soup, mut origin, mut changed) = state;
        let region = match by_edge {
            Some(by_edge) => flat_region(&soup, by_edge, seed, self.thickness)?,
            None => flat_region(&soup, &edge_faces(&soup), seed, self.thickness)?,
        };
        let region_tris: Vec<[u32; 3]> = region.iter().map(|&t| soup.triangles[t]).collect();
        let mut scratch = Repair::default();
        // Corners a few ulps apart first (two that differ only across the plane are one
        // point in its projection): snapped together, as at a defect.
        let snaps = self.sheet_snaps(&soup, &region, corners);
        collapse(&mut soup, &mut origin, &mut changed, &snaps, true, &mut scratch);
        let find = |soup: &TriangleSoup, tris: Vec<[u32; 3]>| {
            let index: HashMap<[u32; 3], usize> =
                soup.triangles.iter().enumerate().map(|(k, &t)| (t, k)).collect();
            tris.into_iter().find_map(|t| index.get(&t).copied())
        };
        let snapped = |t: [u32; 3]| t.map(|v| snaps.get(&v).copied().unwrap_or(v));
        let start = find(&soup, region_tris.iter().map(|&t| snapped(t)).collect())?;
        let region = flat_region(&soup, &edge_faces(&soup), start, self.thickness)?;
        let splits = outline_splits(&soup, &region, self.snap);
        if splits.is_empty() && snaps.is_empty() && !plain {
            return None;
        }
        let before_splits = soup.clone();
        for &(edge, at) in &splits {
            split_edges(&mut soup, &mut origin, &mut changed, &HashMap::from_iter([(edge, at)]));
            collapse(&mut soup, &mut origin, &mut changed, &HashMap::new(), true, &mut scratch);
        }
        // The seed, or another triangle of the region, as it is after the splits.
        let start = find(&soup, region.iter().map(|&t| before_splits.triangles[t]).collect())?;
        let f = flatten(&soup, &edge_faces(&soup), &origin, start, self.thickness, true, keep)?;
        if !f.opposed {
            return None;
        }
        let (mut gone, mut added) = (vec![false; soup.triangles.len()], Vec::new());
        let rebuilt = f.take_into(&mut gone, &mut added);
        replace_marked(&mut soup, &mut origin, &mut changed, &gone, added);
        let mut at: Vec<u32> = region.iter().flat_map(|&t| before_splits.triangles[t]).collect();
        at.extend(snaps.keys());
        at.sort_unstable();
        at.dedup();
        Some(SheetEdit {
            soup,
            origin,
            changed,
            at,
            snaps,
            splits: splits.len(),
            removed: scratch.removed_triangles,
            rebuilt,
        })
    }

    /// The snaps [`Cleanup::sheet_edit`] makes at a sheet's corners before it is rebuilt:
    /// every point within `snap` (per coordinate) of one of them onto the lowest id of its
    /// cluster ([`snap_map`]); for [`Corners::Merged`], every intersection point within
    /// `limit` of one of them, the same way, where that moves it at most `limit` (input
    /// vertices stay).
    fn sheet_snaps(&self, soup: &TriangleSoup, region: &[usize], corners: Corners) -> HashMap<u32, u32> {
        if corners == Corners::Snapped {
            return snap_map(soup, region.iter().copied(), self.snap);
        }
        let mut map = snap_map(soup, region.iter().copied(), self.limit);
        let positions = &soup.positions;
        map.retain(|&gone, &mut keep| {
            self.is_new(gone) && positions[gone as usize].distance(positions[keep as usize]) <= self.limit
        });
        map
    }

    /// The last resort past every other: the sheets at the crossings rebuilt as
    /// [`Cleanup::join_sheets`] rebuilds them, each with every intersection point within
    /// `limit` of its corners merged onto them first, all at once ([`Cleanup::sheet_snaps`];
    /// the lowest id of a cluster stays: an input vertex where it has one).
    ///
    /// Where a face's plane passes within rounding of a vertex of the other operand — in a
    /// result used again against the solid that cut it, whose vertices were intersection
    /// points on that solid's faces, rounded — the plane cuts every edge at that vertex at a
    /// point a hair from it, at a grazing angle. Rounded, those points and the vertex lie in
    /// any order in the sheet's plane, its outline crosses itself among them, and the
    /// sheet cannot be rebuilt; merging any one of them alone leaves the outline crossing
    /// ([`Cleanup::merge_near`] finds no merge that leaves fewer defects). Merged
    /// together, they are one corner, and the outline no longer crosses itself there (where
    /// it still does, the sheet is not rebuilt and nothing is made). Each merge moves an
    /// intersection point at most `limit`, as a collapse does, and keeps every directed edge
    /// balanced (the result stays closed and oriented); the rebuild changes the volume by no
    /// more than the operand rule's flatness ([`flatten`]); and the whole edit is made only
    /// where it leaves fewer defects at the sheet's corners than before, as every edit past
    /// the collapses. True when one was made.
    fn merged_sheets(&mut self, crossings: &[(usize, usize)]) -> bool {
        self.join_sheets(crossings, Corners::Merged)
    }

    /// The last resort for crossings (and folded edges) past the sheets: any edge of their
    /// triangles at most `limit` long, not only the shortest ([`Cleanup::plan`]), shortest
    /// first, collapsed the way that leaves the fewest defects around it
    /// ([`Cleanup::collapse_way`], as a round's collapses), where that is fewer than before.
    /// True when one was.
    fn collapse_longer(&mut self, found: &Defects) -> bool {
        let boxes = BoxIndex::new(self.soup.boxes());
        for faces in found.crossing_groups() {
            let edges: Vec<(f64, u32, u32)> = faces
                .iter()
                .flat_map(|&f| {
                    let t = self.soup.triangles[f];
                    (0..3).map(move |k| (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3])))
                })
                .map(|(p, q)| {
                    (self.soup.positions[p as usize].distance(self.soup.positions[q as usize]), p, q)
                })
                .filter(|e| e.0 <= self.limit)
                .collect();
            if self.collapse_first(&boxes, edges) {
                self.repair.collapsed_edges += 1;
                return true;
            }
        }
        false
    }

    /// Collapses the first of `pairs` (length, p, q), shortest first, that
    /// [`Cleanup::collapse_way`] takes; true when one was.
    fn collapse_first(&mut self, boxes: &BoxIndex, mut pairs: Vec<(f64, u32, u32)>) -> bool {
        pairs.sort_by(|x, y| x.0.total_cmp(&y.0).then((x.1, x.2).cmp(&(y.1, y.2))));
        pairs.dedup();
        for (length, p, q) in pairs {
            if let Some((_, keep, gone)) = self.collapse_way(boxes, p, q) {
                self.repair.moved = self.repair.moved.max(length);
                self.collapse(&HashMap::from_iter([(gone, keep)]));
                return true;
            }
        }
        false
    }

    /// The last resort past the joined sheets: a corner of a crossing triangle (or of one
    /// around a folded edge) and any point at most `limit` from it, not only along the crossing triangles' own edges
    /// ([`Cleanup::collapse_longer`]): one it shares no edge with (the two operands'
    /// vertices and the cut a hair apart, where a needle of one lies along a needle of the
    /// other) or an edge of triangles beside them (a corner of a face and of its reversed
    /// copy a hair off its plane, where the sheet between them cannot be rebuilt), nearest
    /// first, merged the way that leaves the fewest crossings and triangles without
    /// area around it ([`Cleanup::collapse_way`]), where that is fewer than before. True
    /// when one was.
    fn merge_near(&mut self, found: &Defects) -> bool {
        let boxes = BoxIndex::new(self.soup.boxes());
        let grid = UsedGrid::new(&self.soup, self.limit);
        for faces in found.crossing_groups() {
            let mut corners: Vec<u32> = faces.iter().flat_map(|&f| self.soup.triangles[f]).collect();
            corners.sort_unstable();
            corners.dedup();
            let positions = &self.soup.positions;
            let mut pairs = Vec::new();
            for &v in &corners {
                let p = positions[v as usize];
                for w in grid.near(p) {
                    let d = p.distance(positions[w as usize]);
                    if w != v && d <= self.limit {
                        pairs.push((d, v.min(w), v.max(w)));
                    }
                }
            }
            if self.collapse_first(&boxes, pairs) {
                self.repair.merged += 1;
                return true;
            }
        }
        false
    }

    /// Folded edges that no snap or collapse removed: a closed piece on such an edge — its
    /// triangles joined to each other across edges of exactly two triangles, every edge of
    /// it balanced among its own, so that it hangs on the rest only by edges of more than
    /// two — that holds no volume worth keeping, by the measures a shell left by a repair is
    /// dropped by ([`Shape::is_leftover`]: no wider than the longest edge a collapse
    /// removes, or thinner on average than a flat region), is dropped where that leaves
    /// fewer defects around it (rounding turned it inside out, or left it beside a part
    /// facing its way). Smallest volume first, none sharing a point with one dropped
    /// before (so each is judged on the triangles around it as they stay). Removing a
    /// closed piece leaves every other edge balanced. True when any was.
    fn drop_pieces(&mut self, folds: &[Fold]) -> bool {
        if folds.is_empty() {
            return false;
        }
        let by_edge = edge_faces(&self.soup);
        let mut seen = HashSet::new();
        let mut pieces: Vec<(f64, Vec<usize>)> = Vec::new();
        for &t in folds.iter().flat_map(|f| &f.triangles) {
            if seen.contains(&t) {
                continue;
            }
            let Some(piece) = hanging_piece(&self.soup, &by_edge, t) else {
                continue;
            };
            seen.extend(piece.iter().copied());
            let shape = Shape::of(&self.soup, &piece);
            if shape.is_leftover(self.limit, self.thickness) {
                pieces.push((shape.volume.abs(), piece));
            }
        }
        pieces.sort_by(|x, y| x.0.total_cmp(&y.0).then_with(|| x.1.cmp(&y.1)));
        let dropped = self.drop_where_fewer(pieces.into_iter().map(|(_, piece)| piece));
        self.repair.dropped_pieces += dropped.len();
        !dropped.is_empty()
    }

    /// Drops each of `sets` of triangles (closed pieces), in order, where that leaves fewer
    /// defects around it ([`local_defects`]) and it shares no point with one dropped before
    /// (so each is judged on the triangles around it as they stay); the places in `sets` of
    /// those dropped.
    fn drop_where_fewer(&mut self, sets: impl IntoIterator<Item = Vec<usize>>) -> Vec<usize> {
        let boxes = BoxIndex::new(self.soup.boxes());
        let mut busy = HashSet::new();
        let mut gone = vec![false; self.soup.triangles.len()];
        let mut dropped = Vec::new();
        for (k, set) in sets.into_iter().enumerate() {
            let mut at: Vec<u32> = set.iter().flat_map(|&t| self.soup.triangles[t]).collect();
            at.sort_unstable();
            at.dedup();
            if at.iter().any(|v| busy.contains(v)) {
                continue;
            }
            let (before, after) =
                local_defects(&self.soup, &boxes, &at, None, |sub, origin, changed, local| {
                    // The set's triangles in the sub-soup, by their corners.
                    let id = |v: u32| at.binary_search(&v).ok().map(|k| local[k]);
                    let marked = copies_in(&sub.triangles, set.iter().map(|&t| self.soup.triangles[t]), id);
                    replace_marked(sub, origin, changed, &marked, Vec::new());
                    local.to_vec()
                });
            if after >= before {
                continue;
            }
            busy.extend(at);
            for &t in &set {
                gone[t] = true;
            }
            dropped.push(k);
        }
        self.replace(&gone, Vec::new());
        dropped
    }

    /// Folded edges that nothing else removed: the closed pieces on them ([`hanging_piece`])
    /// that lie doubled over the rest. About each edge of more than two triangles where
    /// such a piece hangs, the winding number is counted from the faces' exact order
    /// ([`doubled_at`]): where the other faces there (or all but those of other pieces
    /// doubled with it) alternate, and the piece's lie together between two of them with
    /// its first face running the way of the rest's face before it, the winding number in
    /// the piece is 2 (a piece facing out, inside the rest's solid) or −1 (facing in,
    /// outside it). A piece found so about every such edge where the order decides (and at
    /// one at least), whose faces cross none, and whose volume, where it is not flat by the
    /// operand rule, has the sign its faces there give it, adds nothing to the solid: every
    /// point in it is inside with it and without it (winding number 2, then 1) or outside
    /// (−1, then 0), so dropping it keeps the solid's points whatever its volume (only the
    /// signed volume, which counted those points twice, changes by the piece's own). This
    /// is what rounding and the repairs around a sliver can leave: a thin piece (the torus'
    /// A ⊖ B with a copy turned 1e-6°, then ⊖ A: a lens 0.09 long and 2e-10 thick on
    /// average) folded over an edge of the rest by nanometres, too thick to be dropped as a
    /// piece of no volume. The pieces on one folded edge are dropped together (two pieces,
    /// one facing out in the solid and one facing in outside it, each leave the edge folded
    /// alone), each group where that leaves fewer defects around it, none sharing a point
    /// with one dropped before. Removing closed pieces leaves every other edge balanced.
    /// True when any was.
    fn drop_doubled(&mut self, found: &Defects) -> bool {
        if found.folds.is_empty() {
            return false;
        }
        let by_edge = edge_faces(&self.soup);
        // The pieces of the triangles on the folded edges and on the other edges of more
        // than two triangles of those pieces, as they are asked for, each with the sign of
        // its volume (0 where it is flat by the operand rule: no sign to go by).
        let mut pieces: Vec<(Vec<usize>, i32)> = Vec::new();
        let mut piece_of: HashMap<usize, Option<usize>> = HashMap::new();
        let mut find = |t: usize, pieces: &mut Vec<(Vec<usize>, i32)>| -> Option<usize> {
            if let Some(&p) = piece_of.get(&t) {
                return p;
            }
            let Some(piece) = hanging_piece(&self.soup, &by_edge, t) else {
                piece_of.insert(t, None);
                return None;
            };
            let shape = Shape::of(&self.soup, &piece);
            let sign = if shape.is_flat() { 0 } else { shape.volume.signum() as i32 };
            let k = pieces.len();
            piece_of.extend(piece.iter().map(|&u| (u, Some(k))));
            pieces.push((piece, sign));
            Some(k)
        };
        let mut candidates: Vec<usize> = Vec::new();
        for f in &found.folds {
            candidates.extend(f.triangles.iter().filter_map(|&t| find(t, &mut pieces)));
        }
        candidates.sort_unstable();
        candidates.dedup();
        let crossing: HashSet<usize> = found.crossings.iter().flat_map(|&(a, b)| [a, b]).collect();
        // Per edge of more than two triangles, each piece's verdict there.
        let mut verdicts: HashMap<(u32, u32), Vec<(usize, bool)>> = HashMap::new();
        let mut qualifies: HashSet<usize> = HashSet::new();
        for &k in &candidates {
            if pieces[k].0.iter().any(|t| crossing.contains(t)) {
                continue;
            }
            let mut edges: Vec<(u32, u32)> = pieces[k]
                .0
                .iter()
                .flat_map(|&t| {
                    let tri = self.soup.triangles[t];
                    (0..3).map(move |i| (tri[i].min(tri[(i + 1) % 3]), tri[i].max(tri[(i + 1) % 3])))
                })
                .filter(|e| by_edge[e].len() > 2)
                .collect();
            edges.sort_unstable();
            edges.dedup();
            let (mut any, mut against) = (false, false);
            for e in edges {
                let at = verdicts.entry(e).or_insert_with(|| {
                    let faces = &by_edge[&e];
                    let ids: Vec<Option<usize>> = faces.iter().map(|&t| find(t, &mut pieces)).collect();
                    let signs: Vec<i32> = pieces.iter().map(|p| p.1).collect();
                    doubled_at(&self.soup, e, faces, &ids, &signs).unwrap_or_default()
                });
                for &(_, doubled) in at.iter().filter(|v| v.0 == k) {
                    any |= doubled;
                    against |= !doubled;
                }
            }
            if any && !against {
                qualifies.insert(k);
            }
        }
        // The qualifying pieces on one folded edge go together.
        let mut groups = UnionFind::new(pieces.len());
        for f in &found.folds {
            let on: Vec<usize> = f
                .triangles
                .iter()
                .filter_map(|t| piece_of.get(t).copied().flatten())
                .filter(|k| qualifies.contains(k))
                .collect();
            for w in on.windows(2) {
                groups.union(w[0] as u32, w[1] as u32);
            }
        }
        let mut by_root: HashMap<u32, Vec<usize>> = HashMap::new();
        for k in (0..pieces.len()).filter(|k| qualifies.contains(k)) {
            by_root.entry(groups.find(k as u32)).or_default().push(k);
        }
        let mut groups: Vec<Vec<usize>> = by_root.into_values().collect();
        groups.sort_unstable();
        let sets =
            groups.iter().map(|group| group.iter().flat_map(|&k| pieces[k].0.iter().copied()).collect());
        let dropped = self.drop_where_fewer(sets);
        self.repair.doubled_pieces += dropped.iter().map(|&g| groups[g].len()).sum::<usize>();
        !dropped.is_empty()
    }

    /// Replaces the triangles marked in `gone` by `added`; false when none is marked.
    fn replace(&mut self, gone: &[bool], added: Vec<([u32; 3], u32)>) -> bool {
        if !gone.iter().any(|&g| g) {
            return false;
        }
        replace_marked(&mut self.soup, &mut self.origin, &mut self.changed, gone, added);
        true
    }

    /// The collapses of one round, shortest edge first: each point takes part in one,
    /// and goes the way after which the triangles around it cross the fewest others — if
    /// that is fewer than before ([`Cleanup::collapse_way`]).
    fn choose_collapses(&mut self, mut edges: Vec<(f64, u32, u32)>) -> HashMap<u32, u32> {
        edges.sort_by(|x, y| x.0.total_cmp(&y.0).then((x.1, x.2).cmp(&(y.1, y.2))));
        let mut map: HashMap<u32, u32> = HashMap::new();
        let mut busy = HashSet::new();
        let boxes = BoxIndex::new(if edges.is_empty() { Vec::new() } else { self.soup.boxes() });
        for (length, keep, gone) in edges {
            if busy.contains(&keep) || busy.contains(&gone) {
                continue;
            }
            let Some((_, keep, gone)) = self.collapse_way(&boxes, keep, gone) else {
                continue;
            };
            busy.insert(keep);
            busy.insert(gone);
            map.insert(gone, keep);
            self.repair.collapsed_edges += 1;
            self.repair.moved = self.repair.moved.max(length);
        }
        map
    }

    /// The way to collapse the edge `p` `q` that leaves the fewest crossings and triangles
    /// without area around it, if fewer than before: (those left, the end kept, the end
    /// that goes). An intersection point goes onto an input vertex; between two of a kind,
    /// either way, `q` onto `p` first (the first of two that leave as few).
    fn collapse_way(&self, boxes: &BoxIndex, p: u32, q: u32) -> Option<(usize, u32, u32)> {
        let ways: &[(u32, u32)] = match (self.is_new(p), self.is_new(q)) {
            (true, false) => &[(q, p)],
            (false, true) => &[(p, q)],
            _ => &[(p, q), (q, p)],
        };
        ways.iter()
            .filter_map(|&(keep, gone)| {
                let (before, after) = local_crossings(&self.soup, boxes, keep, gone, self.pieces());
                (after < before).then_some((after, keep, gone))
            })
            .min_by_key(|w| w.0)
    }

    fn collapse(&mut self, map: &HashMap<u32, u32>) {
        collapse(&mut self.soup, &mut self.origin, &mut self.changed, map, true, &mut self.repair);
    }

    /// Splits the edges that pass within a few ulps of a corner of the defects' triangles
    /// ([`edge_splits`]) at that corner, each only where it leaves fewer defects around it
    /// than before (as a collapse); faces that then coincide with opposite orientations
    /// cancel. True when any edge was split.
    fn split_edges(&mut self, found: &Defects) -> bool {
        let candidates = edge_splits(&self.soup, found.faces(), self.snap);
        if candidates.is_empty() {
            return false;
        }
        let boxes = BoxIndex::new(self.soup.boxes());
        let pieces = self.pieces();
        let mut chosen: Vec<((u32, u32), u32)> = candidates
            .into_par_iter()
            .filter(|&(edge, at)| {
                let (before, after) = local_split(&self.soup, &boxes, edge, at, pieces);
                after < before
            })
            .collect();
        if chosen.is_empty() {
            return false;
        }
        chosen.sort_unstable();
        self.repair.split_edges += chosen.len();
        split_edges(&mut self.soup, &mut self.origin, &mut self.changed, &chosen.into_iter().collect());
        self.collapse(&HashMap::new());
        true
    }

    /// The repaired triangles in their origins' order, flat shells dropped.
    fn finished(mut self) -> Result<Finished, InvalidResult> {
        if self.repair.pockets > 0 {
            // Rebuilt triangles go back among those of their origin: A's faces first.
            let mut order: Vec<usize> = (0..self.origin.len()).collect();
            order.sort_by_key(|&k| self.origin[k]);
            self.soup.triangles = order.iter().map(|&k| self.soup.triangles[k]).collect();
            self.origin = order.iter().map(|&k| self.origin[k]).collect();
        }
        // Specks and sheets are what a repair leaves of a sliver; a result that needed none
        // keeps every shell that encloses volume, however small next to the operands.
        let leftovers = (!self.repair.is_clean()).then_some((self.limit, self.thickness));
        drop_flat_shells(&mut self.soup, &mut self.origin, leftovers, &mut self.repair)?;
        Ok(Finished {
            positions: self.soup.positions,
            triangles: self.soup.triangles,
            origin: self.origin,
            repair: self.repair,
        })
    }
}

/// The points the soup's triangles use, in a hash of cells `width` wide: every point
/// within `width` (per coordinate) of p lies in p's cell or one beside it.
struct UsedGrid {
    width: f64,
    cells: HashMap<[i64; 3], Vec<u32>>,
}

impl UsedGrid {
    fn new(soup: &TriangleSoup, width: f64) -> UsedGrid {
        let mut grid = UsedGrid { width, cells: HashMap::new() };
        let mut used = vec![false; soup.positions.len()];
        for t in &soup.triangles {
            for &v in t {
                if !std::mem::replace(&mut used[v as usize], true) {
                    grid.cells.entry(grid.cell(soup.positions[v as usize])).or_default().push(v);
                }
            }
        }
        grid
    }

    fn cell(&self, p: DVec3) -> [i64; 3] {
        (p / self.width).floor().as_i64vec3().to_array()
    }

    /// The points in p's cell and the 26 beside it.
    fn near(&self, p: DVec3) -> impl Iterator<Item = u32> + '_ {
        let [x, y, z] = self.cell(p);
        (-1..=1)
            .flat_map(move |i| (-1..=1).flat_map(move |j| (-1..=1).map(move |k| [x + i, y + j, z + k])))
            .flat_map(|key| self.cells.get(&key).into_iter().flatten().copied())
    }
}

/// The snaps for the corners of `faces`: every point of the soup within `snap` (per
/// coordinate) of such a corner joins its cluster, and each cluster goes onto its lowest
/// id. Points already at one position are one point (welded), so every snap moves one.
fn snap_map(soup: &TriangleSoup, faces: impl Iterator<Item = usize>, snap: f64) -> HashMap<u32, u32> {
    let grid = UsedGrid::new(soup, snap);
    let mut sets = UnionFind::new(soup.positions.len());
    let mut members = std::collections::BTreeSet::new();
    for f in faces {
        for v in soup.triangles[f] {
            let p = soup.positions[v as usize];
            for w in grid.near(p) {
                if w != v && (soup.positions[w as usize] - p).abs().max_element() <= snap {
                    sets.union(v, w);
                    members.insert(v);
                    members.insert(w);
                }
            }
        }
    }
    let mut lowest: HashMap<u32, u32> = HashMap::new();
    for &v in &members {
        let root = sets.find(v);
        lowest.entry(root).or_insert(v); // members ascend: the first is the lowest
    }
    members
        .into_iter()
        .filter_map(|v| {
            let keep = lowest[&sets.find(v)];
            (keep != v).then_some((v, keep))
        })
        .collect()
}

/// The edges to split for the corners of `faces`: an edge of the soup that passes within
/// `snap` (per coordinate) of such a corner, strictly between its ends and not within
/// `snap` of either (those are snaps), with the corner to split it at (a point that lay on
/// the edge before rounding: a corner of a result used again against the solid that cut
/// it). Nearest first, and none that shares a point with one taken before (so no triangle
/// has two of them, and no split point is on another split edge).
fn edge_splits(
    soup: &TriangleSoup,
    faces: impl Iterator<Item = usize>,
    snap: f64,
) -> HashMap<(u32, u32), u32> {
    let mut corners: Vec<u32> = faces.flat_map(|f| soup.triangles[f]).collect();
    corners.sort_unstable();
    corners.dedup();
    if corners.is_empty() {
        return HashMap::new();
    }
    let boxes = soup.boxes();
    let within = |a: DVec3, b: DVec3| (a - b).abs().max_element() <= snap;
    // Candidates from the grid, with room to spare; the test below decides.
    let reach = DVec3::splat(2.0 * snap);
    let around: Vec<Box3> = corners
        .iter()
        .map(|&v| (soup.positions[v as usize] - reach, soup.positions[v as usize] + reach))
        .collect();
    let mut found: Vec<(f64, (u32, u32), u32)> = box_pairs(&around, Some(&boxes))
        .into_par_iter()
        .flat_map_iter(|(i, t)| {
            let (v, t) = (corners[i as usize], t as usize);
            let (x, tri) = (soup.positions[v as usize], soup.triangles[t]);
            let mut hits = Vec::new();
            let (lo, hi) = boxes[t];
            if !((lo - x).max_element() > snap || (x - hi).max_element() > snap || tri.contains(&v)) {
                for k in 0..3 {
                    let (p, q) = (tri[k], tri[(k + 1) % 3]);
                    let (pp, pq) = (soup.positions[p as usize], soup.positions[q as usize]);
                    let d = pq - pp;
                    let s = (x - pp).dot(d) / d.length_squared();
                    if !(s > 0.0 && s < 1.0) || within(x, pp) || within(x, pq) {
                        continue;
                    }
                    let off = (x - (pp + s * d)).abs().max_element();
                    if off <= snap {
                        hits.push((off, (p.min(q), p.max(q)), v));
                    }
                }
            }
            hits
        })
        .collect();
    found.sort_by(|x, y| x.0.total_cmp(&y.0).then((x.1, x.2).cmp(&(y.1, y.2))));
    let mut busy = HashSet::new();
    let mut splits = HashMap::new();
    for (_, (p, q), v) in found {
        if busy.contains(&p) || busy.contains(&q) || busy.contains(&v) {
            continue;
        }
        busy.extend([p, q, v]);
        splits.insert((p, q), v);
    }
    splits
}

/// Splits every triangle with an edge in `splits` (ends in increasing order) at the point
/// given for it (no triangle has two): each use of the edge becomes a path through the
/// point, so every directed edge stays balanced. Pieces with a repeated corner (of a
/// triangle whose own corner is the split point) are left to [`collapse`] to remove.
fn split_edges(
    soup: &mut TriangleSoup,
    origin: &mut Vec<u32>,
    changed: &mut Vec<bool>,
    splits: &HashMap<(u32, u32), u32>,
) {
    let n = soup.triangles.len();
    let (mut triangles, mut origins, mut flags) =
        (Vec::with_capacity(n), Vec::with_capacity(n), Vec::with_capacity(n));
    for (t, &tri) in soup.triangles.iter().enumerate() {
        let on = (0..3).find_map(|k| {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            splits.get(&(a.min(b), a.max(b))).map(|&m| (k, m))
        });
        match on {
            Some((k, m)) => {
                let (a, b, c) = (tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]);
                for piece in [[a, m, c], [m, b, c]] {
                    triangles.push(piece);
                    origins.push(origin[t]);
                    flags.push(true);
                }
            }
            None => {
                triangles.push(tri);
                origins.push(origin[t]);
                flags.push(changed[t]);
            }
        }
    }
    soup.triangles = triangles;
    *origin = origins;
    *changed = flags;
    soup.face_of = (0..soup.triangles.len() as u32).collect();
}

/// For a flat triangle f (a, b, m) whose corner m lies strictly inside its edge ab once
/// rounded: the neighbour g = (b, a, c) across ab, when it is the only one, and g split at
/// m into (b, m, c) and (m, a, c), which replace f and g with the same surface.
fn split_neighbour(soup: &TriangleSoup, by_edge: &EdgeFaces, f: usize) -> Option<(usize, [[u32; 3]; 2])> {
    let tri = soup.triangles[f];
    let pos = soup.triangle(f);
    let length = |k: usize| pos[k].distance(pos[(k + 1) % 3]);
    let k = (0..3).max_by(|&i, &j| length(i).total_cmp(&length(j)))?;
    let (a, b, m) = (tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]);
    let (pa, pb, pm) = (pos[k], pos[(k + 1) % 3], pos[(k + 2) % 3]);
    // Strictly between: a corner at an end is a collapse, not a split.
    if pm == pa || pm == pb || (pm - pa).dot(pb - pa) <= 0.0 || (pm - pb).dot(pa - pb) <= 0.0 {
        return None;
    }
    let around = by_edge.get(&(a.min(b), a.max(b)))?;
    let [x, y] = around.as_slice() else { return None };
    let g = if *x == f { *y } else { *x };
    let other = soup.triangles[g];
    let j = (0..3).find(|&j| other[j] == b && other[(j + 1) % 3] == a)?;
    let c = other[(j + 2) % 3];
    if c == m {
        return None;
    }
    Some((g, [[b, m, c], [m, a, c]]))
}

/// The piece of triangle `seed`: the triangles joined to it across edges of exactly two
/// triangles, where every edge of theirs is balanced among them (a closed surface of its
/// own, hanging on the rest only by edges of more than two); `None` where it is not closed,
/// or beyond [`hanging_piece`]'s limit (the rest of a result).
fn hanging_piece(soup: &TriangleSoup, by_edge: &EdgeFaces, seed: usize) -> Option<Vec<usize>> {
    /// Beyond this many triangles the search gives up: not a piece of no volume.
    const MOST: usize = 4096;
    let mut piece = vec![seed];
    let mut seen = HashSet::from_iter([seed]);
    let mut next = 0;
    let mut balance: HashMap<(u32, u32), i32> = HashMap::new();
    while next < piece.len() {
        let tri = soup.triangles[piece[next]];
        next += 1;
        for k in 0..3 {
            let (p, q) = (tri[k], tri[(k + 1) % 3]);
            *balance.entry((p.min(q), p.max(q))).or_default() += if p < q { 1 } else { -1 };
            let [x, y] = by_edge.get(&(p.min(q), p.max(q)))?.as_slice() else {
                continue;
            };
            for t in [*x, *y] {
                if seen.insert(t) {
                    piece.push(t);
                    if piece.len() > MOST {
                        return None;
                    }
                }
            }
        }
    }
    balance.values().all(|&b| b == 0).then(|| {
        piece.sort_unstable();
        piece
    })
}

/// For each closed piece on the edge `edge` (ends in increasing order), whether it lies
/// doubled over the rest about it: `faces` the triangles on the edge, `ids` the piece of
/// each (`None`: in none), `signs` each piece's volume's sign (0: flat, no sign to go by).
/// Taken in their exact order about the edge ([`order_about`]), passing a face changes the
/// winding number by one, down for one that runs along the edge's direction, up for one
/// against it. For a set of the pieces, the rest is every other face; where the rest's
/// faces alternate (two at least), the winding number of the rest alone is 1 after one
/// running against the edge and 0 after one along it, and a piece's faces together between
/// two of the rest's, alternating, add to it 1 (a piece facing out: its first face runs
/// against the edge) or −1 (facing in) between its first and last face — where that sign
/// is its volume's: the piece is outside itself beyond them. So the winding number in the
/// piece there is 2 or −1, the piece doubled over the rest, exactly when its first face
/// runs the way of the rest's face before it. A piece is doubled when it is so in a set
/// all of whose pieces are (two pieces on one edge, one inside facing out and one outside
/// facing in, leave the rest alternating only together). `None` where the order does not
/// decide (faces at one angle or all in one plane) or more than six pieces meet there.
fn doubled_at(
    soup: &TriangleSoup,
    (lo, hi): (u32, u32),
    faces: &[usize],
    ids: &[Option<usize>],
    signs: &[i32],
) -> Option<Vec<(usize, bool)>> {
    /// Beyond this many pieces on one edge, the sets of them are not tried.
    const MOST: usize = 6;
    // Whether each face runs lo → hi, and its third corner.
    let uses: Vec<(DVec3, bool)> = faces
        .iter()
        .map(|&t| {
            let tri = soup.triangles[t];
            let k = tri.iter().position(|&v| v == lo).unwrap_or(0);
            let third = tri.into_iter().find(|&v| v != lo && v != hi).unwrap_or(lo);
            (soup.positions[third as usize], tri[(k + 1) % 3] == hi)
        })
        .collect();
    let mut on: Vec<usize> = ids.iter().flatten().copied().collect();
    on.sort_unstable();
    on.dedup();
    if on.is_empty() || on.len() > MOST {
        return None;
    }
    let order = order_about(soup.positions[lo as usize], soup.positions[hi as usize], &uses)?;
    let n = order.len();
    let along = |i: usize| uses[order[i % n]].1;
    // Each face's piece as a bit of the sets.
    let bit = |i: usize| ids[order[i % n]].map_or(0u32, |p| 1 << on.partition_point(|&q| q < p));
    let mut doubled = 0u32;
    for set in 1..1u32 << on.len() {
        let rest: Vec<usize> = (0..n).filter(|&i| bit(i) & set == 0).collect();
        if rest.len() < 2 || (0..rest.len()).any(|j| along(rest[j]) == along(rest[(j + 1) % rest.len()])) {
            continue;
        }
        // From the first face of the rest, once round.
        let start = rest[0];
        let (mut before, mut seen, mut i) = (along(start), 0u32, start + 1);
        let all = loop {
            if i >= start + n {
                break true;
            }
            let b = bit(i);
            if b & set == 0 {
                before = along(i);
                i += 1;
                continue;
            }
            let run = (i..start + n).take_while(|&j| bit(j) == b).count();
            let piece = on[b.trailing_zeros() as usize];
            let sign = if along(i) { -1 } else { 1 };
            let alternates = run % 2 == 0 && (i..i + run - 1).all(|j| along(j) != along(j + 1));
            // Its faces in two runs: others lie between them.
            if seen & b != 0
                || !alternates
                || along(i) != before
                || (signs[piece] != 0 && signs[piece] != sign)
            {
                break false;
            }
            seen |= b;
            i += run;
        };
        if all {
            doubled |= set;
        }
    }
    Some(on.iter().enumerate().map(|(k, &p)| (p, doubled & (1 << k) != 0)).collect())
}

/// The measures of a set of triangles by which a repair's leftover is told: the signed
/// volume they enclose (from the centre of their own box: from one far away, the rounding
/// of each term would outweigh a sheet's volume), their box and their area.
struct Shape {
    volume: f64,
    lo: DVec3,
    hi: DVec3,
    area: f64,
}

impl Shape {
    fn of(soup: &TriangleSoup, triangles: &[usize]) -> Shape {
        let mut shape = Shape { volume: 0.0, lo: DVec3::INFINITY, hi: DVec3::NEG_INFINITY, area: 0.0 };
        for &t in triangles {
            shape.add(soup.triangle(t));
        }
        for &t in triangles {
            shape.add_volume(soup.triangle(t));
        }
        shape
    }

    /// Adds a triangle to the box and the area.
    fn add(&mut self, [a, b, c]: [DVec3; 3]) {
        self.lo = self.lo.min(a.min(b).min(c));
        self.hi = self.hi.max(a.max(b).max(c));
        self.area += 0.5 * (b - a).cross(c - a).length();
    }

    /// Adds a triangle's volume, from the centre of the box (once the box is complete).
    fn add_volume(&mut self, [a, b, c]: [DVec3; 3]) {
        self.volume += signed_tetra_volume((self.lo + self.hi) * 0.5, a, b, c);
    }

    /// Encloses no volume by the operand rule ([`is_flat`]).
    fn is_flat(&self) -> bool {
        is_flat(self.volume, self.lo, self.hi)
    }

    /// What a repair leaves of a sliver: flat, no wider than `speck` (the longest edge a
    /// repair collapses) in every direction, or a mean thickness (twice its volume over its
    /// area) of at most `thickness` (a sheet between two nearly coincident surfaces, too
    /// thin for f64).
    fn is_leftover(&self, speck: f64, thickness: f64) -> bool {
        self.is_flat()
            || (self.hi - self.lo).max_element() <= speck
            || 2.0 * self.volume.abs() <= thickness * self.area
    }
}

/// The triangles on each edge (ends in increasing order).
type EdgeFaces = HashMap<(u32, u32), Vec<usize>>;

fn edge_faces(soup: &TriangleSoup) -> EdgeFaces {
    let mut by_edge = EdgeFaces::new();
    for (t, tri) in soup.triangles.iter().enumerate() {
        for k in 0..3 {
            let (p, q) = (tri[k], tri[(k + 1) % 3]);
            by_edge.entry((p.min(q), p.max(q))).or_default().push(t);
        }
    }
    by_edge
}

/// The triangles connected to triangle `seed` by edges with every corner within
/// `thickness` of its plane, the seed first; `None` beyond [`flat_region`]'s limit.
fn flat_region(soup: &TriangleSoup, by_edge: &EdgeFaces, seed: usize, thickness: f64) -> Option<Vec<usize>> {
    /// Beyond this many triangles in one plane the search gives up (quadratic coverage).
    const MOST: usize = 4096;
    let [a, b, c] = soup.triangle(seed);
    let unit = (b - a).cross(c - a).try_normalize()?;
    let within = |t: usize| soup.triangle(t).iter().all(|&p| (p - a).dot(unit).abs() <= thickness);
    let mut region = vec![seed];
    let mut seen = HashSet::from_iter([seed]);
    let mut next = 0;
    while next < region.len() {
        let tri = soup.triangles[region[next]];
        next += 1;
        for k in 0..3 {
            let (p, q) = (tri[k], tri[(k + 1) % 3]);
            for &t in by_edge.get(&(p.min(q), p.max(q)))? {
                if !seen.contains(&t) && within(t) {
                    seen.insert(t);
                    region.push(t);
                    if region.len() > MOST {
                        return None;
                    }
                }
            }
        }
    }
    Some(region)
}

/// The splits that put each corner of a flat region's outline (its edges left after
/// opposite ones cancel) that lies within `snap` (per coordinate) of one of the outline's
/// edges, strictly between its ends, onto that edge: (edge, corner) in the order to make
/// them, each edge one of the outline's once the splits before it are made.
fn outline_splits(soup: &TriangleSoup, region: &[usize], snap: f64) -> Vec<((u32, u32), u32)> {
    let mut balance: HashMap<(u32, u32), i32> = HashMap::new();
    for &t in region {
        let tri = soup.triangles[t];
        for k in 0..3 {
            let (p, q) = (tri[k], tri[(k + 1) % 3]);
            *balance.entry((p.min(q), p.max(q))).or_default() += if p < q { 1 } else { -1 };
        }
    }
    let mut outline: Vec<(u32, u32)> = balance.into_iter().filter(|e| e.1 != 0).map(|e| e.0).collect();
    let mut corners: Vec<u32> = outline.iter().flat_map(|&(p, q)| [p, q]).collect();
    corners.sort_unstable();
    corners.dedup();
    let within = |a: DVec3, b: DVec3| (a - b).abs().max_element() <= snap;
    let mut splits = Vec::new();
    while splits.len() < corners.len() {
        outline.sort_unstable();
        let found = outline.iter().enumerate().find_map(|(k, &(p, q))| {
            let (pp, pq) = (soup.positions[p as usize], soup.positions[q as usize]);
            let d = pq - pp;
            corners.iter().find_map(|&v| {
                let x = soup.positions[v as usize];
                let s = (x - pp).dot(d) / d.length_squared();
                let beside = v != p
                    && v != q
                    && s > 0.0
                    && s < 1.0
                    && !within(x, pp)
                    && !within(x, pq)
                    && within(x, pp + s * d);
                beside.then_some((k, v))
            })
        });
        let Some((k, v)) = found else { break };
        let (p, q) = outline.swap_remove(k);
        outline.extend([(p.min(v), p.max(v)), (v.min(q), v.max(q))]);
        splits.push(((p, q), v));
    }
    splits
}

/// A flat region rebuilt without its sliver: the triangles it removes and those it adds.
struct Flattened {
    removed: Vec<usize>,
    /// New triangles, each with the origin of a removed triangle it lies on.
    added: Vec<([u32; 3], u32)>,
    /// Whether the removed triangles face both ways in the plane (a sheet between a face
    /// and a reversed copy of it).
    opposed: bool,
}

impl Flattened {
    /// Marks the removed triangles in `gone` and moves the new ones to `added`; the
    /// number removed.
    fn take_into(self, gone: &mut [bool], added: &mut Vec<([u32; 3], u32)>) -> usize {
        for &t in &self.removed {
            gone[t] = true;
        }
        added.extend(self.added);
        self.removed.len()
    }
}

/// Rebuilds the flat region around triangle `seed`, if it holds a sliver: the triangles
/// connected to it by edges with every corner within `thickness` of its plane are replaced
/// by a triangulation, in the plane's projection, of where they cover the plane a net once
/// (bounded by their boundary edges left after opposite edges cancel). Nearly coincident
/// faces kept from both operands (one's face outside the other, the other's inside the
/// one, a hair apart) cover the plane once from each side: the sliver between them goes,
/// and the region's boundary, where it joins the rest of the surface, stays edge for edge
/// (closed and oriented). `None` when the new triangles would not have that boundary, or
/// the change of volume is not negligible.
///
/// The cover of a new triangle is counted at its centroid; `by_winding` counts it instead
/// as the winding number of the region's boundary around it ([`windings`]): a sliver
/// between corners in line within an ulp may have a centroid that rounds onto or out of
/// it, where the winding number is still exact. `keep_edges` (by winding number) makes the
/// region's own edges between corners of its boundary that meet no other of its edges or
/// corners in the plane edges of the triangulation too: the region's triangles away from
/// its sliver stay as they were (a fresh diagonal beside a corner in line within an ulp
/// with two others may pass over a thin wedge hinged at that corner).
fn flatten(
    soup: &TriangleSoup,
    by_edge: &EdgeFaces,
    origin: &[u32],
    seed: usize,
    thickness: f64,
    by_winding: bool,
    keep_edges: bool,
) -> Option<Flattened> {
    let [a, b, c] = soup.triangle(seed);
    let normal = (b - a).cross(c - a);
    let proj = Projection::along(normal)?;
    let region = flat_region(soup, by_edge, seed, thickness)?;
    let flat: Vec<[DVec2; 3]> = region.iter().map(|&t| soup.triangle(t).map(|p| proj.apply(p))).collect();
    let side: Vec<i32> = flat.iter().map(|f| i32::from(orient2d(f[0], f[1], f[2]))).collect();
    // Net cover at x: +1 per face of the seed's side holding it, −1 per face of the other,
    // and the first face holding it.
    let cover = |x: DVec2| -> (i32, Option<usize>) {
        let holding = |k: &usize| {
            side[*k] != 0
                && (0..3).all(|e| i32::from(orient2d(flat[*k][e], flat[*k][(e + 1) % 3], x)) == side[*k])
        };
        let mut holders = (0..region.len()).filter(holding);
        let first = holders.next();
        (first.into_iter().chain(holders).map(|k| side[k]).sum(), first)
    };
    // The region's boundary: directed edges whose opposites do not cancel them.
    let net = |tris: &mut dyn Iterator<Item = [u32; 3]>| -> HashMap<(u32, u32), i32> {
        let mut balance: HashMap<(u32, u32), i32> = HashMap::new();
        for tri in tris {
            for k in 0..3 {
                let (p, q) = (tri[k], tri[(k + 1) % 3]);
                *balance.entry((p.min(q), p.max(q))).or_default() += if p < q { 1 } else { -1 };
            }
        }
        balance.retain(|_, b| *b != 0);
        balance
    };
    let boundary = net(&mut region.iter().map(|&t| soup.triangles[t]));
    if boundary.values().any(|b| b.abs() != 1) {
        return None;
    }
    let mut ids: Vec<u32> = boundary.keys().flat_map(|&(p, q)| [p, q]).collect();
    ids.sort_unstable();
    ids.dedup();
    let local = |v: u32| ids.binary_search(&v).map(|i| i as u32).unwrap_or(u32::MAX);
    let points: Vec<DVec2> = ids.iter().map(|&v| proj.apply(soup.positions[v as usize])).collect();
    let mut constraints: Vec<[u32; 2]> = boundary.keys().map(|&(p, q)| [local(p), local(q)]).collect();
    if keep_edges {
        constraints.extend(kept_edges(soup, &region, &proj, &boundary, &ids));
    }
    let cdt = triangulate::cdt(&points, &[], &constraints).ok()?;
    let along = |p: u32, q: u32| {
        let b = boundary.get(&(ids[p.min(q) as usize], ids[p.max(q) as usize])).copied().unwrap_or(0);
        if p < q { b } else { -b }
    };
    let winding = if by_winding { Some(windings(&cdt.triangles, along, boundary.len())?) } else { None };
    let mut added = Vec::new();
    for (i, t) in cdt.triangles.into_iter().enumerate() {
        let f = t.map(|v| points[v as usize]);
        let (centroid, first) = cover((f[0] + f[1] + f[2]) / 3.0);
        // By winding number, a triangle with no region triangle holding its centroid takes
        // the seed's origin.
        let held = if by_winding { first.or(Some(0)) } else { first };
        match (winding.as_ref().map_or(centroid, |w| w[i]), held) {
            (0, _) => {}
            (1, Some(k)) => added.push((t.map(|v| ids[v as usize]), origin[region[k]])),
            (-1, Some(k)) => added.push(([t[0], t[2], t[1]].map(|v| ids[v as usize]), origin[region[k]])),
            _ => return None,
        }
    }
    if net(&mut added.iter().map(|a| a.0)) != boundary {
        return None;
    }
    let (lo, hi) = region
        .iter()
        .flat_map(|&t| soup.triangle(t))
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| (lo.min(p), hi.max(p)));
    let apex = (lo + hi) * 0.5;
    let volume = |tri: [u32; 3]| {
        let [a, b, c] = tri.map(|v| soup.positions[v as usize]);
        signed_tetra_volume(apex, a, b, c)
    };
    let change: f64 = region.iter().map(|&t| volume(soup.triangles[t])).sum::<f64>()
        - added.iter().map(|a| volume(a.0)).sum::<f64>();
    let opposed = side.contains(&1) && side.contains(&-1);
    is_flat(change, lo, hi).then_some(Flattened { removed: region, added, opposed })
}

/// The edges of a flat region's triangles (by ids local to `ids`, the corners of its
/// boundary) that are not on the boundary, join two of its corners, and meet no other edge
/// of the region nor any corner in the plane's projection but at their ends; none for a
/// region of more than [`kept_edges`]' limit.
fn kept_edges(
    soup: &TriangleSoup,
    region: &[usize],
    proj: &Projection,
    boundary: &HashMap<(u32, u32), i32>,
    ids: &[u32],
) -> Vec<[u32; 2]> {
    /// Beyond this many triangles the edges are not compared (quadratic).
    const MOST: usize = 256;
    if region.len() > MOST {
        return Vec::new();
    }
    let mut edges: Vec<(u32, u32)> = region
        .iter()
        .flat_map(|&t| {
            let tri = soup.triangles[t];
            (0..3).map(move |k| (tri[k].min(tri[(k + 1) % 3]), tri[k].max(tri[(k + 1) % 3])))
        })
        .collect();
    edges.sort_unstable();
    edges.dedup();
    let at = |v: u32| proj.apply(soup.positions[v as usize]);
    let sign = |a: DVec2, b: DVec2, c: DVec2| i32::from(orient2d(a, b, c));
    // Whether c lies on the closed segment a b (exactly, in the projection).
    let on = |a: DVec2, b: DVec2, c: DVec2| {
        sign(a, b, c) == 0 && c.cmpge(a.min(b)).all() && c.cmple(a.max(b)).all()
    };
    let meet = |(p, q): (u32, u32), (r, s): (u32, u32)| {
        let (a, b, c, d) = (at(p), at(q), at(r), at(s));
        let shared = [r, s].iter().filter(|v| **v == p || **v == q).count();
        match shared {
            2 => false,
            // One end shared: they meet elsewhere only when in line and overlapping.
            1 => {
                let (o, x, y) = if r == p || r == q {
                    (c, if r == p { b } else { a }, d)
                } else {
                    (d, if s == p { b } else { a }, c)
                };
                sign(o, x, y) == 0 && (x - o).dot(y - o) > 0.0
            }
            _ => {
                let (o1, o2) = (sign(a, b, c), sign(a, b, d));
                let (o3, o4) = (sign(c, d, a), sign(c, d, b));
                (o1 * o2 < 0 && o3 * o4 < 0) || on(a, b, c) || on(a, b, d) || on(c, d, a) || on(c, d, b)
            }
        }
    };
    let local = |v: u32| ids.binary_search(&v).ok().map(|i| i as u32);
    edges
        .iter()
        .filter(|e| !boundary.contains_key(e))
        .filter_map(|&(p, q)| {
            let (lp, lq) = (local(p)?, local(q)?);
            let (a, b) = (at(p), at(q));
            let clear = edges.iter().all(|&e| e == (p, q) || !meet((p, q), e))
                && ids.iter().all(|&v| v == p || v == q || !on(a, b, at(v)));
            clear.then_some([lp, lq])
        })
        .collect()
}

/// The winding number of a boundary around each triangle of a triangulation of its
/// points (counter-clockwise triangles covering their convex hull): `along(p, q)` is the
/// boundary's multiplicity on the directed edge p → q (of `edges` boundary edges). Outside
/// the hull it is 0, and across each edge, from the triangle on its left to the one on its
/// right, it drops by the multiplicity there. `None` when a boundary edge is not an edge
/// of the triangulation, or the count disagrees with itself.
fn windings(triangles: &[[u32; 3]], along: impl Fn(u32, u32) -> i32, edges: usize) -> Option<Vec<i32>> {
    let mut left: HashMap<(u32, u32), usize> = HashMap::new();
    for (i, t) in triangles.iter().enumerate() {
        for k in 0..3 {
            left.insert((t[k], t[(k + 1) % 3]), i);
        }
    }
    let on_boundary =
        left.keys().filter(|&&(p, q)| (p < q || !left.contains_key(&(q, p))) && along(p, q) != 0).count();
    if on_boundary != edges {
        return None;
    }
    let mut winding: Vec<Option<i32>> = vec![None; triangles.len()];
    let mut stack = Vec::new();
    let set = |winding: &mut Vec<Option<i32>>, stack: &mut Vec<usize>, i: usize, w: i32| match winding[i] {
        Some(x) => x == w,
        None => {
            winding[i] = Some(w);
            stack.push(i);
            true
        }
    };
    for (i, t) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (p, q) = (t[k], t[(k + 1) % 3]);
            if !left.contains_key(&(q, p)) && !set(&mut winding, &mut stack, i, along(p, q)) {
                return None;
            }
        }
    }
    while let Some(i) = stack.pop() {
        let t = triangles[i];
        let w = winding[i]?;
        for k in 0..3 {
            let (p, q) = (t[k], t[(k + 1) % 3]);
            if let Some(&j) = left.get(&(q, p)) {
                if !set(&mut winding, &mut stack, j, w - along(p, q)) {
                    return None;
                }
            }
        }
    }
    winding.into_iter().collect()
}

/// Marks the triangles of a sub-soup (`sub`, over its local ids) that are the soup's
/// triangles `of` (over soup ids, `id` mapping them to local ones), found by their
/// corners in order: as many marked as there are such copies among `of`.
fn copies_in(
    sub: &[[u32; 3]],
    of: impl Iterator<Item = [u32; 3]>,
    id: impl Fn(u32) -> Option<u32>,
) -> Vec<bool> {
    let mut wanted: HashMap<[u32; 3], usize> = HashMap::new();
    for t in of {
        if let [Some(a), Some(b), Some(c)] = t.map(&id) {
            *wanted.entry([a, b, c]).or_default() += 1;
        }
    }
    sub.iter()
        .map(|t| match wanted.get_mut(t) {
            Some(n) if *n > 0 => {
                *n -= 1;
                true
            }
            _ => false,
        })
        .collect()
}

/// Crossings and triangles without area at the corners of a flat region before and after
/// it is rebuilt ([`flatten`]): its triangles and their neighbours against those whose
/// boxes meet theirs.
fn local_rebuild(soup: &TriangleSoup, boxes: &BoxIndex, f: &Flattened, pieces: Pieces) -> (usize, usize) {
    let mut at: Vec<u32> = f.removed.iter().flat_map(|&t| soup.triangles[t]).collect();
    at.sort_unstable();
    at.dedup();
    local_defects(soup, boxes, &at.clone(), pieces, |sub, origin, changed, local| {
        let id = |v: u32| at.binary_search(&v).ok().map(|k| local[k]);
        // The region's triangles in the sub-soup, by their corners.
        let gone = copies_in(&sub.triangles, f.removed.iter().map(|&t| soup.triangles[t]), id);
        let added: Vec<([u32; 3], u32)> = f
            .added
            .iter()
            .filter_map(|&(t, o)| match t.map(id) {
                [Some(a), Some(b), Some(c)] => Some(([a, b, c], o)),
                _ => None,
            })
            .collect();
        replace_marked(sub, origin, changed, &gone, added);
        local.to_vec()
    })
}

/// Crossings and triangles without area at `gone` and `keep` before and after `gone`
/// collapses onto `keep`: their triangles against those whose boxes meet theirs.
fn local_crossings(
    soup: &TriangleSoup,
    boxes: &BoxIndex,
    keep: u32,
    gone: u32,
    pieces: Pieces,
) -> (usize, usize) {
    // The collapse moves the triangles at `gone` towards `keep`, inside their box.
    local_defects(soup, boxes, &[keep, gone], pieces, |sub, origin, changed, local| {
        let (k, g) = (local[0], local[1]);
        collapse(sub, origin, changed, &HashMap::from_iter([(g, k)]), true, &mut Repair::default());
        vec![k]
    })
}

/// Crossings and triangles without area at the ends of `edge` and at `at` before and after
/// the edge is split at `at` (and faces that then coincide with opposite orientations
/// cancel): their triangles against those whose boxes meet theirs.
fn local_split(
    soup: &TriangleSoup,
    boxes: &BoxIndex,
    edge: (u32, u32),
    at: u32,
    pieces: Pieces,
) -> (usize, usize) {
    local_defects(soup, boxes, &[edge.0, edge.1, at], pieces, |sub, origin, changed, local| {
        let (p, q) = (local[0], local[1]);
        let splits = HashMap::from_iter([((p.min(q), p.max(q)), local[2])]);
        split_edges(sub, origin, changed, &splits);
        collapse(sub, origin, changed, &HashMap::new(), true, &mut Repair::default());
        local.to_vec()
    })
}

/// Defects at the points `at` before and after `edit` ([`found_near`]: crossings,
/// triangles without area and folded edges; with `pieces`, each count as it is once the
/// pieces of no volume hanging on its folded edges are dropped, [`count_near`]), made on
/// the triangles whose boxes meet the box of those at `at` (as a soup of their own: `edit`
/// gets it with the points' ids in it, and returns the points to count at after).
fn local_defects(
    soup: &TriangleSoup,
    boxes: &BoxIndex,
    at: &[u32],
    pieces: Pieces,
    edit: impl FnOnce(&mut TriangleSoup, &mut Vec<u32>, &mut Vec<bool>, &[u32]) -> Vec<u32>,
) -> (usize, usize) {
    // A triangle at a point has a box that holds the point.
    let (lo, hi) = at
        .iter()
        .flat_map(|&v| {
            let p = soup.positions[v as usize];
            boxes.meeting(&(p, p)).into_iter().filter(move |&t| soup.triangles[t].contains(&v))
        })
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), t| {
            (lo.min(boxes.boxes()[t].0), hi.max(boxes.boxes()[t].1))
        });
    let (mut sub, ids) = sub_soup(soup, boxes, lo, hi);
    let count = |sub: &TriangleSoup, at: &[u32]| {
        let near: Vec<bool> = sub.triangles.iter().map(|t| t.iter().any(|v| at.contains(v))).collect();
        count_near(sub, &near, pieces)
    };
    let local: Vec<u32> = at.iter().map(|v| ids[v]).collect();
    let before = count(&sub, &local);
    let mut origin: Vec<u32> = (0..sub.triangles.len() as u32).collect();
    let mut changed = vec![true; sub.triangles.len()];
    let after = edit(&mut sub, &mut origin, &mut changed, &local);
    (before, count(&sub, &after))
}

/// The measures of a piece a repair may drop, (speck, thickness) as in [`Shape::is_leftover`],
/// where defects are counted as they are once the pieces of no volume hanging on folded
/// edges are dropped ([`count_near`]); `None` to count them as they are.
type Pieces = Option<(f64, f64)>;

/// How many defects [`found_near`] finds; with `pieces`, the fewer of that and of those left
/// once every closed piece of no volume on one of its folded edges ([`hanging_piece`],
/// [`Shape::is_leftover`]) is dropped, as [`Cleanup::drop_pieces`] drops them: an edit that
/// leaves such a piece turned inside out (a collapse that removes a crossing beside a
/// sliver) is judged by what the repair makes of it, and so is the state before it.
fn count_near(sub: &TriangleSoup, near: &[bool], pieces: Pieces) -> usize {
    let found = found_near(sub, near);
    let Some((speck, thickness)) = pieces else {
        return found.len();
    };
    if !found.iter().any(|d| matches!(d, Local::Folded(..))) {
        return found.len();
    }
    let folds = folded_edges(&sub.positions, &sub.triangles, |on| on.iter().any(|&t| near[t]));
    let by_edge = edge_faces(sub);
    let mut gone = vec![false; sub.triangles.len()];
    for &t in folds.iter().flat_map(|f| &f.triangles) {
        if gone[t] {
            continue;
        }
        if let Some(piece) = hanging_piece(sub, &by_edge, t)
            && Shape::of(sub, &piece).is_leftover(speck, thickness)
        {
            for p in piece {
                gone[p] = true;
            }
        }
    }
    if !gone.contains(&true) {
        return found.len();
    }
    let mut rest = sub.clone();
    let (mut origin, mut changed) = (vec![0; sub.triangles.len()], vec![true; sub.triangles.len()]);
    let near_rest: Vec<bool> = near.iter().zip(&gone).filter(|(_, g)| !**g).map(|(n, _)| *n).collect();
    replace_marked(&mut rest, &mut origin, &mut changed, &gone, Vec::new());
    found.len().min(found_near(&rest, &near_rest).len())
}

/// A defect [`found_near`] counts.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Local {
    /// Two triangles that cross.
    Crossing(usize, usize),
    /// A triangle without area.
    Flat(usize),
    /// An edge around which the triangles do not alternate in direction.
    Folded(u32, u32),
}

/// The defects of `sub` at the triangles marked `near`, in order: pairs with such a
/// triangle that cross, such triangles without area, and edges of such triangles around
/// which the triangles do not alternate in direction ([`folded_edges`]: every triangle on
/// an edge of a triangle in `sub` whose corners lie in the box it was cut out for is in it
/// too, so the test sees all of them).
fn found_near(sub: &TriangleSoup, near: &[bool]) -> Vec<Local> {
    let crossings = soup_self_intersections_near(sub, near, usize::MAX);
    let mut found: Vec<Local> = crossings.into_iter().map(|(a, b)| Local::Crossing(a, b)).collect();
    found.extend(
        (0..sub.triangles.len()).filter(|&t| near[t] && is_degenerate(sub.triangle(t))).map(Local::Flat),
    );
    let folds = folded_edges(&sub.positions, &sub.triangles, |on| on.iter().any(|&t| near[t]));
    found.extend(folds.into_iter().map(|f| Local::Folded(f.a, f.b)));
    found.sort_unstable();
    found
}

/// The triangles of `soup` whose boxes meet the box `lo`..`hi`, as a soup of their own
/// (triangle k of it is `local[k]`), and the ids of their corners in it.
fn sub_soup(
    soup: &TriangleSoup,
    boxes: &BoxIndex,
    lo: DVec3,
    hi: DVec3,
) -> (TriangleSoup, HashMap<u32, u32>) {
    let local = boxes.meeting(&(lo, hi));
    let mut sub = TriangleSoup {
        positions: Vec::new(),
        triangles: Vec::with_capacity(local.len()),
        face_of: (0..local.len() as u32).collect(),
        failed: Vec::new(),
    };
    let mut ids: HashMap<u32, u32> = HashMap::new();
    for &t in &local {
        let tri = soup.triangles[t].map(|v| {
            *ids.entry(v).or_insert_with(|| {
                sub.positions.push(soup.positions[v as usize]);
                sub.positions.len() as u32 - 1
            })
        });
        sub.triangles.push(tri);
    }
    (sub, ids)
}

/// `x` moved by `k` ulps (up for k > 0), across zero as well.
fn step_ulps(x: f64, k: i64) -> f64 {
    // f64s in order as integers: the bits of a positive one, minus those of a negative one.
    let bits = x.to_bits() as i64;
    let ordinal = (if bits < 0 { -(bits & i64::MAX) } else { bits }) + k;
    if ordinal < 0 {
        f64::from_bits(ordinal.unsigned_abs() | (1 << 63))
    } else {
        f64::from_bits(ordinal as u64)
    }
}

/// The f64 positions around `p`, nearest first: each coordinate moved by up to one ulp
/// (26 positions), then by up to two (98 more).
fn neighbour_positions(p: DVec3) -> Vec<DVec3> {
    let mut steps: Vec<[i64; 3]> = Vec::with_capacity(124);
    for i in -2..=2i64 {
        for j in -2..=2i64 {
            for k in -2..=2i64 {
                if (i, j, k) != (0, 0, 0) {
                    steps.push([i, j, k]);
                }
            }
        }
    }
    let reach = |s: &[i64; 3]| s.iter().map(|d| d.abs()).max().unwrap_or(0);
    let size = |s: &[i64; 3]| s.iter().map(|d| d.abs()).sum::<i64>();
    steps.sort_by_key(|s| (reach(s), size(s), *s));
    steps
        .into_iter()
        .map(|[i, j, k]| DVec3::new(step_ulps(p.x, i), step_ulps(p.y, j), step_ulps(p.z, k)))
        .collect()
}

/// The last resort for crossings (and triangles without area, and folded edges) that no
/// snap or collapse removed: rounding put them there by an ulp, so one of the intersection
/// points among their corners (ids from `first_new` on) goes to a neighbouring f64 position
/// ([`neighbour_positions`], nearest first) — the first one after which, by the exact
/// tests over the triangles at that point against those whose boxes meet theirs
/// ([`found_near`]), no triangle there crosses another or has no area and no edge there is
/// folded; failing that, the first one after which fewer defects are left and none that
/// was not there before. Never onto another point's position (the file
/// read back would make them one). The topology does not change, so the result stays
/// closed and oriented. True when a point moved (the caller checks everything again).
/// A point for which no position was found, with the same triangles around it as then
/// (`unmoved`), is not tried again: the tests would give the same answer.
fn nudge(
    soup: &mut TriangleSoup,
    found: &Defects,
    first_new: u32,
    unmoved: &mut Unmoved,
    repair: &mut Repair,
) -> bool {
    let key = |p: DVec3| (p + DVec3::ZERO).to_array().map(f64::to_bits);
    let mut star: HashMap<u32, Vec<usize>> = HashMap::new();
    let mut taken = HashSet::new();
    for (t, tri) in soup.triangles.iter().enumerate() {
        for &v in tri {
            star.entry(v).or_default().push(t);
            taken.insert(key(soup.positions[v as usize]));
        }
    }
    let mut boxes = BoxIndex::new(soup.boxes());
    let mut moved = HashSet::new();
    for faces in found.groups() {
        let mut corners: Vec<u32> =
            faces.iter().flat_map(|&f| soup.triangles[f]).filter(|&v| v >= first_new).collect();
        corners.sort_unstable();
        corners.dedup();
        for v in corners {
            if moved.contains(&v) {
                continue;
            }
            let p = soup.positions[v as usize];
            let around = &star[&v];
            // Every candidate lies within two ulps per coordinate.
            let reach = |k: i64| DVec3::new(step_ulps(p.x, k), step_ulps(p.y, k), step_ulps(p.z, k));
            let (lo, hi) = around.iter().fold((reach(-2), reach(2)), |(lo, hi), &t| {
                (lo.min(boxes.boxes()[t].0), hi.max(boxes.boxes()[t].1))
            });
            let (mut sub, ids) = sub_soup(soup, &boxes, lo, hi);
            if unmoved.get(&v).is_some_and(|(t, p)| *t == sub.triangles && *p == sub.positions) {
                continue;
            }
            let at = ids[&v];
            let near: Vec<bool> = sub.triangles.iter().map(|t| t.contains(&at)).collect();
            let defects = |sub: &TriangleSoup| found_near(sub, &near);
            let before = defects(&sub);
            if before.is_empty() {
                continue; // an earlier move here removed them
            }
            let mut fewer = None;
            let mut clean = None;
            for q in neighbour_positions(p) {
                if taken.contains(&key(q)) {
                    continue;
                }
                sub.positions[at as usize] = q;
                let after = defects(&sub);
                if after.is_empty() {
                    clean = Some(q);
                    break;
                }
                if fewer.is_none()
                    && after.len() < before.len()
                    && after.iter().all(|d| before.binary_search(d).is_ok())
                {
                    fewer = Some(q);
                }
            }
            let Some(q) = clean.or(fewer) else {
                sub.positions[at as usize] = p;
                unmoved.insert(v, (sub.triangles, sub.positions));
                continue;
            };
            taken.remove(&key(p));
            taken.insert(key(q));
            soup.positions[v as usize] = q;
            for &t in around {
                let [a, b, c] = soup.triangle(t);
                boxes.set(t, (a.min(b).min(c), a.max(b).max(c)));
            }
            moved.insert(v);
            repair.ulp_moves += 1;
            repair.moved = repair.moved.max(p.distance(q));
            if clean.is_some() {
                break;
            }
        }
    }
    !moved.is_empty()
}

/// Applies `map` (point → the point it collapses onto) to every triangle, removes the
/// triangles left without three distinct corners and pairs of opposite coinciding
/// triangles (with `uncut_too`, an uncut input triangle with a changed one too), and marks
/// every triangle at a kept point changed.
fn collapse(
    soup: &mut TriangleSoup,
    origin: &mut Vec<u32>,
    changed: &mut Vec<bool>,
    map: &HashMap<u32, u32>,
    uncut_too: bool,
    repair: &mut Repair,
) {
    let kept: HashSet<u32> = map.values().copied().collect();
    let before = soup.triangles.len();
    let mut next = Vec::with_capacity(before);
    for (k, t) in soup.triangles.iter().enumerate() {
        let t = t.map(|v| map.get(&v).copied().unwrap_or(v));
        if t[0] == t[1] || t[1] == t[2] || t[2] == t[0] {
            continue;
        }
        next.push((t, origin[k], changed[k] || t.iter().any(|v| kept.contains(v))));
    }
    // Coinciding triangles with opposite orientations cancel (their edges balance).
    // Changed triangles by their sorted corners (then by place): coinciding ones in a run.
    let sorted = |t: [u32; 3]| {
        let mut key = t;
        key.sort_unstable();
        key
    };
    let mut by_corners: Vec<([u32; 3], bool, usize)> = next
        .iter()
        .enumerate()
        .filter(|(_, (_, _, c))| *c)
        .map(|(k, (t, _, _))| (sorted(*t), false, k))
        .collect();
    by_corners.sort_unstable();
    // A face of one operand that was a face of the other reversed, in a result used again
    // against that other, meets it again once a split or snap has made their corners one
    // (after the changed ones of its run).
    if uncut_too && !by_corners.is_empty() {
        let uncut: Vec<([u32; 3], bool, usize)> = next
            .iter()
            .enumerate()
            .filter(|(_, (t, _, c))| !*c && by_corners.binary_search_by(|x| x.0.cmp(&sorted(*t))).is_ok())
            .map(|(k, (t, _, _))| (sorted(*t), true, k))
            .collect();
        by_corners.extend(uncut);
        by_corners.sort_unstable();
    }
    let mut gone = vec![false; next.len()];
    let parity = |t: [u32; 3]| {
        // Even rotations of the sorted corners give one orientation, odd ones the other.
        let m = t.iter().position(|v| *v == *t.iter().min().unwrap_or(&0)).unwrap_or(0);
        t[(m + 1) % 3] < t[(m + 2) % 3]
    };
    for group in by_corners.chunk_by(|x, y| x.0 == y.0).filter(|g| g.len() > 1) {
        let (up, down): (Vec<usize>, Vec<usize>) =
            group.iter().map(|x| x.2).partition(|&k| parity(next[k].0));
        for (&u, &d) in up.iter().zip(&down) {
            gone[u] = true;
            gone[d] = true;
        }
    }
    soup.triangles.clear();
    origin.clear();
    changed.clear();
    for ((t, o, c), g) in next.into_iter().zip(gone) {
        if !g {
            soup.triangles.push(t);
            origin.push(o);
            changed.push(c);
        }
    }
    soup.face_of = (0..soup.triangles.len() as u32).collect();
    repair.removed_triangles += before - soup.triangles.len();
}

/// Removes the triangles marked in `gone` and appends `added` (each with the input face it
/// came from) as changed ones.
fn replace_marked(
    soup: &mut TriangleSoup,
    origin: &mut Vec<u32>,
    changed: &mut Vec<bool>,
    gone: &[bool],
    added: Vec<([u32; 3], u32)>,
) {
    let keep: Vec<bool> = gone.iter().map(|g| !g).collect();
    retain_marked(&mut soup.triangles, &keep);
    retain_marked(origin, &keep);
    retain_marked(changed, &keep);
    for (t, o) in added {
        soup.triangles.push(t);
        origin.push(o);
        changed.push(true);
    }
    soup.face_of = (0..soup.triangles.len() as u32).collect();
}

/// Keeps the items of `v` whose flag in `keep` is set.
fn retain_marked<T>(v: &mut Vec<T>, keep: &[bool]) {
    let mut k = 0;
    v.retain(|_| {
        k += 1;
        keep[k - 1]
    });
}

/// Drops every shell that encloses no volume by the operand rule and, after a repair
/// (`leftovers` = (speck, thickness)), every shell no wider than `speck` (the longest edge
/// a repair collapses) in every direction or whose mean thickness (twice its volume over
/// its area) is at most `thickness` (a sheet between two nearly coincident surfaces, too
/// thin for f64): what rounding left of a sliver, whose orientation it may have turned.
/// Then applies the rule to what is left.
fn drop_flat_shells(
    soup: &mut TriangleSoup,
    origin: &mut Vec<u32>,
    leftovers: Option<(f64, f64)>,
    repair: &mut Repair,
) -> Result<(), InvalidResult> {
    let mut sets = UnionFind::new(soup.positions.len());
    for t in &soup.triangles {
        sets.union(t[0], t[1]);
        sets.union(t[0], t[2]);
    }
    // Per shell root: its volume, box and area.
    let mut shells: HashMap<u32, Shape> = HashMap::new();
    let roots: Vec<u32> = soup.triangles.iter().map(|t| sets.find(t[0])).collect();
    let empty = || Shape { volume: 0.0, lo: DVec3::INFINITY, hi: DVec3::NEG_INFINITY, area: 0.0 };
    for (t, &r) in roots.iter().enumerate() {
        shells.entry(r).or_insert_with(empty).add(soup.triangle(t));
    }
    for (t, r) in roots.iter().enumerate() {
        if let Some(shell) = shells.get_mut(r) {
            shell.add_volume(soup.triangle(t));
        }
    }
    let flat: HashSet<u32> = shells
        .iter()
        .filter(|(_, s)| {
            s.is_flat() || leftovers.is_some_and(|(speck, thickness)| s.is_leftover(speck, thickness))
        })
        .map(|(&r, _)| r)
        .collect();
    if !flat.is_empty() {
        repair.dropped_shells = flat.len();
        let keep: Vec<bool> = roots.iter().map(|r| !flat.contains(r)).collect();
        retain_marked(&mut soup.triangles, &keep);
        retain_marked(origin, &keep);
    }
    let volume: f64 = shells.iter().filter(|(r, _)| !flat.contains(r)).map(|(_, s)| s.volume).sum();
    let bound = flatness_bound(shells.iter().filter(|(r, _)| !flat.contains(r)).map(|(_, s)| (s.lo, s.hi)));
    if !soup.triangles.is_empty() && volume.abs() <= bound {
        return Err(InvalidResult::NoVolume { volume });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::procedural;

    fn triangles(m: &crate::mesh::Mesh) -> Vec<[u32; 3]> {
        TriangleSoup::new(m).triangles
    }

    #[test]
    fn a_clean_result_is_left_alone() {
        let cube = procedural::cube();
        let tris = triangles(&cube);
        let changed = vec![true; tris.len()];
        let done = finish(cube.positions(), 0, &tris, &changed, 1.0).unwrap();
        assert_eq!(done.triangles, tris);
        assert_eq!(done.origin, (0..tris.len() as u32).collect::<Vec<_>>());
        assert!(done.repair.is_clean() && done.repair.collapsed_edges == 0, "{}", done.repair);
    }

    #[test]
    fn crossing_shells_without_a_short_edge_are_an_error() {
        // Two overlapping cubes as one closed, oriented surface: their faces cross, and
        // every edge is long.
        let cube = procedural::cube();
        let n = cube.num_vertices() as u32;
        let mut points = cube.positions().to_vec();
        points.extend(cube.positions().iter().map(|&p| p + DVec3::splat(0.5)));
        let mut tris = triangles(&cube);
        tris.extend(triangles(&cube).iter().map(|t| t.map(|v| v + n)));
        let changed = vec![true; tris.len()];
        let e = finish(&points, 0, &tris, &changed, 4.0).unwrap_err();
        assert!(matches!(e, InvalidResult::Crossing { .. }), "{e}");
        // Marked unchanged, the same triangles are not tested (they are trusted).
        let unchanged = vec![false; tris.len()];
        assert!(finish(&points, 0, &tris, &unchanged, 4.0).is_ok());
    }
}
