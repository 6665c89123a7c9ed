//! Assembly of the refined mesh from the last fragment stream (SPEC §5.4; the thesis'
//! "se descarta el anillo externo"): each fragment keeps only its owned region, and
//! vertices are welded *topologically*, by the coarse-mesh element they lie on, never by
//! position.
//!
//! After `j` fragment levels every coarse quad is a G × G grid of quads (G = 2^(j+1)),
//! whose four corner quarters are owned by the fragments at its four corners. The output
//! is numbered by coarse element, so it is closed and manifold whenever the coarse mesh
//! is, whatever the positions:
//!
//! - coarse vertex v → vertex v;
//! - edge e, point t ∈ (0, G) steps from its first vertex → `V + e·(G−1) + t − 1`;
//! - face f, grid point (i, j) with 0 < i, j < G in the frame of its corner 0 (i towards
//!   corner 1, j towards corner 3) → `V + E·(G−1) + f·(G−1)² + (j−1)·(G−1) + i − 1`.
//!
//! Each position is gathered from the fragment that owns it (points shared by two or four
//! owned regions are taken from one of them; at a non-manifold vertex or edge, from one
//! of its fans). Faces and positions are filled in parallel (rayon's global pool) over
//! blocks of coarse faces and edges.
//!
//! Faces come out in OpenSubdiv's order: coarse face by coarse face, and inside one, the
//! quadtree of its refinement (each quad's four children in corner order), each quad
//! starting at its corner towards the coarse face's corner 0 — so face `i` of the result
//! is OpenSubdiv's face `i` with the same rotation, which gives the refinement's own
//! vertex correspondence (`compare`). Faces under holes are left out; their vertices stay.

use glam::DVec3;

use crate::mesh::Mesh;

use super::cpu;
use super::fragment::{Built, Class, FragmentMesh, StreamLayout, sharp_edges};
use super::topology::Topology;
use super::{Result, SubdivError, Surface};

/// Builds the refined mesh from `stream`, the last fragment stream after `levels`
/// fragment levels, in which every fragment holds its owned region (`2^levels` rings).
/// `position` reads one stream entry.
pub fn assemble<T: Sync>(
    fragments: &FragmentMesh,
    stream: &[T],
    levels: u32,
    position: impl Fn(&T) -> DVec3 + Sync,
) -> Result<Mesh> {
    let layout = fragments.layout(levels, levels, 1);
    let grid = Grid::for_stream(fragments, &layout, stream.len(), levels)?;
    // Faces: a G × G grid of quads per coarse face not under a hole, in face order.
    let kept: Vec<u32> = (0..grid.topo.num_faces() as u32).filter(|&f| !fragments.is_hole(f)).collect();
    let indices = grid.face_indices(&kept, levels);
    let owners = Owners { fragments, layout: &layout, stream, position, n: grid.g / 2 };
    let positions = grid.positions(&owners);
    let offsets = quad_offsets(indices.len() / 4);
    Ok(Mesh::from_parts(positions, offsets, indices)?)
}

/// Offsets of `quads` faces of four vertices each.
fn quad_offsets(quads: usize) -> Vec<usize> {
    let mut offsets = vec![0usize; quads + 1];
    for_each_block(&mut offsets, 1, |first, block| {
        for (k, o) in block.iter_mut().enumerate() {
            *o = 4 * (first + k);
        }
    });
    offsets
}

/// Reads each output point from the fragment that owns it: the stream entries of the
/// owned regions, `n` rings each.
struct Owners<'a, T, P> {
    fragments: &'a FragmentMesh,
    layout: &'a StreamLayout,
    stream: &'a [T],
    position: P,
    n: u32,
}

impl<T: Sync, P: Fn(&T) -> DVec3 + Sync> Owners<'_, T, P> {
    /// Where the owned region of sector s of fragment f starts, and its class.
    fn sector(&self, (f, s): (u32, u32)) -> (u64, Class, u32) {
        let class = self.fragments.fragments()[f as usize].class;
        (self.fragments.fragment_start(self.layout, f), class, s)
    }

    /// The point (a, b) of a sector's owned region.
    fn at(&self, (start, class, s): (u64, Class, u32), a: u32, b: u32) -> DVec3 {
        (self.position)(&self.stream[(start + class.index(s, a.into(), b.into())) as usize])
    }

    /// Coarse vertex v: the centre of its fragment.
    fn vertices(&self, out: &mut [DVec3]) {
        for (v, out) in out.iter_mut().enumerate() {
            *out = match self.fragments.fragment_of(v as u32) {
                Some(f) => self.at(self.sector((f, 0)), 0, 0),
                // A vertex no face uses stays where it is.
                None => self.fragments.isolated_position(v as u32),
            };
        }
    }

    /// The G − 1 points inside each coarse edge: the first half from the spoke of the
    /// fragment at its first vertex, the second from the one at its second.
    fn edges(&self, out: &mut [DVec3]) {
        let (n, g) = (self.n, 2 * self.n);
        let per_edge = (g - 1) as usize;
        for_each_block(out, per_edge, |first, block| {
            for (k, out) in block.chunks_exact_mut(per_edge).enumerate() {
                let e = (first + k) as u32;
                let (first_half, second_half) = out.split_at_mut(n as usize);
                let s0 = self.sector(self.fragments.spoke_along(e, 0));
                for (t, p) in (1..=n).zip(first_half.iter_mut()) {
                    *p = self.at(s0, t, 0);
                }
                let s1 = self.sector(self.fragments.spoke_along(e, 1));
                for (t, p) in (n + 1..g).zip(second_half.iter_mut()) {
                    *p = self.at(s1, g - t, 0);
                }
            }
        });
    }

    /// The (G − 1)² points inside each coarse face, a quarter from the fragment at each
    /// of its corners.
    fn faces(&self, out: &mut [DVec3]) {
        let g = 2 * self.n as usize;
        let per_face = (g - 1) * (g - 1);
        for_each_block(out, per_face, |first, block| {
            for (k, out) in block.chunks_exact_mut(per_face).enumerate() {
                let h0 = self.fragments.coarse().face_half_edges((first + k) as u32).start;
                for m in 0..4 {
                    self.quarter(h0 + m, m, out);
                }
            }
        });
    }

    /// The quarter at corner m of a face (`h`: its half-edge from that corner): sector s
    /// of the fragment centred there. Its points off the spokes (a, b ≥ 1) are, ring by
    /// ring, the entries t ≥ 1 of the sector's 2r consecutive entries: read in storage
    /// order, written at their (i, j) in the face's frame.
    fn quarter(&self, h: u32, m: u32, out: &mut [DVec3]) {
        let g = 2 * self.n as usize;
        let side = g - 1;
        let (start, class, s) = self.sector(self.fragments.corner_sector(h));
        for r in 1..=u64::from(self.n) {
            let ring = start + 1 + class.ring_offset(r) + u64::from(s) * 2 * r;
            let entries = &self.stream[(ring + 1) as usize..(ring + 2 * r) as usize];
            for (t, texel) in (1..2 * r as usize).zip(entries) {
                let r = r as usize;
                let (a, b) = if t <= r { (r, t) } else { (2 * r - t, r) };
                let (i, j) = match m {
                    0 => (a, b),
                    1 => (g - b, a),
                    2 => (g - a, g - b),
                    _ => (b, g - a),
                };
                out[(j - 1) * side + i - 1] = (self.position)(texel);
            }
        }
    }
}

/// The cells (i, j) of a 2^depth × 2^depth grid in quadtree order: at each depth the four
/// children in corner order (0: (0, 0), 1: +i, 2: +i +j, 3: +j).
fn quadtree_order(depth: u32) -> Vec<(u32, u32)> {
    let mut order = vec![(0u32, 0u32)];
    for _ in 0..depth {
        order = order
            .iter()
            .flat_map(|&(i, j)| [(0, 0), (1, 0), (1, 1), (0, 1)].map(|(di, dj)| (2 * i + di, 2 * j + dj)))
            .collect();
    }
    order
}

/// Output vertex numbering of the (G + 1)² grid points of a coarse face.
struct Grid<'a> {
    topo: &'a Topology,
    g: u32,
    nv: u32,
    /// First id of face-interior points.
    face0: u32,
}

impl<'a> Grid<'a> {
    /// The numbering of the mesh `stream` refines after `levels` fragment levels, once the
    /// stream is known to hold every owned region and the result to fit 32-bit indices.
    fn for_stream(
        fragments: &'a FragmentMesh,
        layout: &StreamLayout,
        entries: usize,
        levels: u32,
    ) -> Result<Grid<'a>> {
        let owned = 1u64 << levels;
        let radius = layout.radius;
        if owned > u64::from(radius) || (entries as u64) < layout.total {
            return Err(SubdivError::Fragment(format!(
                "a stream of {entries} entries at ring radius {radius} cannot hold {owned} owned rings ({} entries needed)",
                layout.total
            )));
        }
        let topo = fragments.coarse();
        let g = 2 * owned;
        let (nv, ne, nf) = (topo.num_vertices() as u64, topo.num_edges() as u64, topo.num_faces() as u64);
        let vertices = nv + ne * (g - 1) + nf * (g - 1) * (g - 1);
        let quads = nf * g * g;
        if vertices >= u64::from(u32::MAX) || 4 * quads >= u64::from(u32::MAX) {
            return Err(SubdivError::TooLarge { level: fragments.cpu_levels() + levels, vertices });
        }
        Ok(Grid { topo, g: g as u32, nv: nv as u32, face0: (nv + ne * (g - 1)) as u32 })
    }

    /// The quads of the `kept` faces, each face's grid in OpenSubdiv's quadtree order.
    fn face_indices(&self, kept: &[u32], levels: u32) -> Vec<u32> {
        let order = quadtree_order(levels + 1);
        let g = self.g as usize;
        let per_face = 4 * g * g;
        let mut indices = vec![0u32; kept.len() * per_face];
        for_each_block(&mut indices, per_face, |first, block| {
            let mut ids = Vec::new();
            for (k, out) in block.chunks_exact_mut(per_face).enumerate() {
                self.face_ids(kept[first + k], &mut ids);
                let row = g + 1;
                for (q, &(i, j)) in order.iter().enumerate() {
                    let c = j as usize * row + i as usize;
                    out[4 * q..4 * q + 4].copy_from_slice(&[
                        ids[c],
                        ids[c + 1],
                        ids[c + 1 + row],
                        ids[c + row],
                    ]);
                }
            }
        });
        indices
    }

    /// Every output position, gathered from the fragment that owns it: coarse vertices,
    /// then edge points, then face points.
    fn positions<T: Sync, P: Fn(&T) -> DVec3 + Sync>(&self, owners: &Owners<'_, T, P>) -> Vec<DVec3> {
        let side = self.g as usize - 1;
        let mut positions = vec![DVec3::ZERO; self.face0 as usize + self.topo.num_faces() * side * side];
        let (vertex_part, rest) = positions.split_at_mut(self.nv as usize);
        let (edge_part, face_part) = rest.split_at_mut((self.face0 - self.nv) as usize);
        owners.vertices(vertex_part);
        owners.edges(edge_part);
        owners.faces(face_part);
        positions
    }

    /// Ids of the grid points of face `f`, row by row (j outer, i inner).
    fn face_ids(&self, f: u32, ids: &mut Vec<u32>) {
        let g = self.g;
        let row = g as usize + 1;
        ids.clear();
        ids.resize(row * row, 0);
        let h0 = self.topo.face_half_edges(f).start;
        // Side m runs from corner m to corner m + 1; point t steps from corner m is point
        // t or g − t of its edge, depending on the edge's orientation.
        let sides: [(u32, bool); 4] = std::array::from_fn(|m| {
            let h = h0 + m as u32;
            let e = self.topo.edge(h);
            (self.nv + e * (g - 1), !self.topo.is_reversed(h))
        });
        let side = |m: usize, t: u32| {
            let (first, forward) = sides[m];
            first + if forward { t } else { g - t } - 1
        };
        let corner = |m: u32| self.topo.origin(h0 + m);
        let g_us = g as usize;
        ids[0] = corner(0);
        ids[g_us] = corner(1);
        ids[g_us * row] = corner(3);
        ids[g_us * row + g_us] = corner(2);
        for t in 1..g {
            let t_us = t as usize;
            ids[t_us] = side(0, t);
            ids[t_us * row + g_us] = side(1, t);
            ids[g_us * row + t_us] = side(2, g - t);
            ids[t_us * row] = side(3, g - t);
        }
        let interior = self.face0 + f * (g - 1) * (g - 1);
        for j in 1..g_us {
            let first = interior + (j as u32 - 1) * (g - 1);
            for (i, id) in ids[j * row + 1..j * row + g_us].iter_mut().enumerate() {
                *id = first + i as u32;
            }
        }
    }
}

/// Runs `work(first_item, block)` over `out` cut into blocks of whole `item_len`-long
/// items, a few per thread of rayon's global pool; each item is written by one call, so
/// the result does not depend on the number of threads.
fn for_each_block<T: Send>(out: &mut [T], item_len: usize, work: impl Fn(usize, &mut [T]) + Sync) {
    use rayon::prelude::*;
    if item_len == 0 || out.is_empty() {
        return;
    }
    let items = out.len() / item_len;
    let per_block = items.div_ceil(4 * rayon::current_num_threads().max(1)).max(1);
    out.par_chunks_mut(per_block * item_len).enumerate().for_each(|(b, block)| work(b * per_block, block));
}

/// The whole fragment-mesh algorithm on the CPU in f64 (base level, [`FragmentMesh::refine_stream`] per level, assembly): the GPU path's arithmetic without a GPU, to
/// test the layout, rules and welding exactly. Levels the fragments cannot reach are
/// refined by [`cpu::refine_surface`].
pub fn refine(surface: &Surface, level: u32) -> Result<cpu::Refined> {
    let fragments = match FragmentMesh::build(surface, level)? {
        Built::Fragments(f) => f,
        Built::Cpu(_) => return cpu::refine_surface(surface, level),
    };
    let levels = level - fragments.cpu_levels();
    let mut stream = fragments.base_stream(levels, 1, |p| [p.x, p.y, p.z, 1.0], |d| d.map(f64::from));
    for j in 0..levels {
        stream = fragments.refine_stream(&stream, j, levels);
    }
    let mesh = assemble(&fragments, &stream, levels, |p| DVec3::new(p[0], p[1], p[2]))?;
    Ok(cpu::Refined { mesh, sharp_edges: sharp_edges(&fragments, levels) })
}
