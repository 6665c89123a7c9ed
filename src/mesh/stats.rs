//! What `texgeo mesh stats` reports about a mesh, in one value: the checks of
//! [`validate`](super::validate), the solidity verdict and the measures. `--json` prints
//! it, and Python's `Mesh.stats()` returns it.

use serde::Serialize;

use super::covering::Covering;
use super::frame::Frame;
use super::solidity::{Defect, Solidity};
use super::{Mesh, Report};

#[derive(Clone, Debug, Serialize)]
pub struct Stats {
    /// Counts: vertices, faces, face degrees, edges and their defects, components, χ.
    #[serde(flatten)]
    pub report: Report,
    pub closed: bool,
    pub oriented: bool,
    pub manifold: bool,
    /// Total genus of a closed oriented manifold.
    pub genus: Option<i64>,
    pub shells: usize,
    /// Inward-facing shells inside another.
    pub cavities: usize,
    /// A valid solid (SPEC §2's rule).
    pub solid: bool,
    /// Why it is not a solid: the first defect (absent for a solid).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    /// Every defect, in the rule's order.
    pub defects: Vec<String>,
    /// The bounding box's minimum and maximum corners.
    pub bbox: [[f64; 3]; 2],
    pub area: f64,
    /// Signed tetrahedra (Alg. 3-1); `None` when the surface is not closed and oriented.
    pub volume: Option<f64>,
    /// The centroid of the enclosed volume (when there is one).
    pub centroid: Option<[f64; 3]>,
    /// The centroid of the face vertices, weighted by face (thesis §3.6.1).
    pub face_centroid: Option<[f64; 3]>,
}

impl Stats {
    /// The stats of `mesh` from its report and solidity check. Measured in the mesh's frame
    /// (scale-free), reported in its units.
    pub fn new(mesh: &Mesh, report: Report, solidity: &Solidity) -> Stats {
        let frame = Frame::of(&[mesh]);
        let c = Covering::new(&frame.mesh_in_ref(mesh));
        let (lo, hi) = mesh.bounds();
        // + 0.0: an empty sum is −0.
        let volume = solidity.volume.map(|v| v + 0.0);
        Stats {
            closed: report.is_closed(),
            oriented: report.is_oriented(),
            manifold: report.is_manifold(),
            genus: report.genus(),
            report,
            shells: solidity.shells.len(),
            cavities: solidity.cavities(),
            solid: solidity.is_solid(),
            reason: solidity.defects.first().map(Defect::to_string),
            defects: solidity.defects.iter().map(Defect::to_string).collect(),
            bbox: [lo.to_array(), hi.to_array()],
            area: solidity.area + 0.0,
            volume,
            centroid: volume.and_then(|_| c.centroid()).map(|g| frame.point_out(g).to_array()),
            face_centroid: c.face_weighted_centroid().map(|g| frame.point_out(g).to_array()),
        }
    }

    /// The stats of `mesh`, unless its measures overflow f64 (then the error says so).
    pub fn of(mesh: &Mesh) -> Result<Stats, Defect> {
        let solidity = super::solidity::check(mesh);
        if let Some(d @ Defect::Overflow { .. }) = solidity.defects.first() {
            return Err(d.clone());
        }
        Ok(Stats::new(mesh, mesh.report(), &solidity))
    }
}
