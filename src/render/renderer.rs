//! The renderer: a scene becomes GPU buffers once ([`Renderer::prepare`]); each picture
//! is one render pass into an RGBA8 target with a depth buffer — triangles with indexed
//! draws, then every edge, polyline piece and point as an instanced screen-space quad —
//! resolved when multisampled and read back by an image copy.

use std::collections::HashSet;

use glam::{DMat4, DVec3};

use super::camera::Camera;
use super::colour::{Rgba, pack};
use super::error::{RenderError, Result};
use super::picture::Picture;
use super::scene::{Colours, Scene, SceneMesh, Shading};
use crate::gpu::{
    Attachment, Blend, Buffer, Context, DepthTest, Load, Pipeline, PipelineDesc, Pod, Raster, Recorder,
    Shader, Targets, TexFormat, Texture, Topology, shaders,
};
use crate::mesh::triangulate::{newell_normal, polygon_or_fan};

/// A vertex of `glsl/render/mesh.vert`.
#[derive(Clone, Copy, Debug, Default)]
#[repr(C)]
struct Vertex {
    position: [f32; 3],
    normal: [f32; 3],
    colour: u32,
}

// SAFETY: #[repr(C)], 4-byte fields only: no padding, every bit pattern valid.
unsafe impl Pod for Vertex {}

/// A segment instance of `glsl/render/line.vert`.
#[derive(Clone, Copy, Debug, Default)]
#[repr(C)]
struct Segment {
    a: [f32; 3],
    b: [f32; 3],
    colour: u32,
    width: f32,
}

// SAFETY: as for Vertex.
unsafe impl Pod for Segment {}

/// `ViewBlock` of `glsl/render/view.glsl`.
#[derive(Clone, Copy, Debug, Default)]
#[repr(C)]
struct ViewBlock {
    proj: [f32; 16],
    view: [f32; 16],
    viewport: [f32; 4],
}

// SAFETY: as for Vertex.
unsafe impl Pod for ViewBlock {}

/// How far lines move towards the eye, as a fraction of their eye distance, so edges win
/// the depth test against the faces they bound.
const LINE_BIAS: f32 = 1e-3;

/// What a picture looks at and how big it is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    pub camera: Camera,
    pub width: u32,
    pub height: u32,
    pub background: Rgba,
}

impl View {
    /// The default three-quarter view of `scene`, framed to fit.
    pub fn fit(scene: &Scene, width: u32, height: u32) -> Result<View> {
        let (lo, hi) = scene.bounds().ok_or_else(|| RenderError::Usage("the scene is empty".into()))?;
        let aspect = f64::from(width.max(1)) / f64::from(height.max(1));
        Ok(View {
            camera: Camera::fit(lo, hi, Camera::YAW, Camera::PITCH, aspect),
            width,
            height,
            background: super::colour::BACKGROUND,
        })
    }
}

struct GpuMesh {
    vertices: Buffer,
    indices: Buffer,
    count: u32,
    shading: Shading,
}

/// A scene uploaded for drawing (see [`Renderer::prepare`]); draw it from any camera.
pub struct Prepared {
    meshes: Vec<GpuMesh>,
    segments: Option<(Buffer, u32)>,
    /// Positions are uploaded relative to this point (the bounding-box centre).
    origin: DVec3,
    bounds: (DVec3, DVec3),
    triangles: usize,
    segment_count: usize,
}

impl Prepared {
    /// The scene's bounding box.
    pub fn bounds(&self) -> (DVec3, DVec3) {
        self.bounds
    }

    /// Triangles drawn.
    pub fn triangles(&self) -> usize {
        self.triangles
    }

    /// Line segments and points drawn (wireframe edges, polyline pieces, points).
    pub fn segments(&self) -> usize {
        self.segment_count
    }
}

/// The render targets of one picture size.
struct Frame {
    size: [u32; 2],
    colour: Texture,
    /// The single-sample picture a multisampled `colour` resolves into.
    resolve: Option<Texture>,
    depth: Texture,
}

impl Frame {
    fn output(&self) -> &Texture {
        self.resolve.as_ref().unwrap_or(&self.colour)
    }
}

/// Draws prepared scenes into pictures. Pipelines, targets and the readback buffer are
/// made once and reused while the picture size stays the same.
pub struct Renderer {
    ctx: Context,
    samples: u32,
    mesh: Pipeline,
    lines: Pipeline,
    block: Buffer,
    frame: Option<Frame>,
    readback: Option<Buffer>,
}

impl Renderer {
    /// A renderer drawing with `samples` samples per pixel (1 or 4 are the usual; the
    /// device must offer it).
    pub fn new(ctx: &Context, samples: u32) -> Result<Renderer> {
        let raster = |depth| Raster { depth, samples };
        // Both draw triangles into one RGBA8 target.
        let desc = |vertex: &'static Shader, fragment: &'static Shader| {
            PipelineDesc::new(vertex, fragment, Topology::Triangles, &[TexFormat::Rgba8], Blend::Replace)
        };
        let (mesh_vs, mesh_fs) = (&shaders::render::MESH_VERT, &shaders::render::MESH_FRAG);
        let mesh = Pipeline::with_raster(ctx, &desc(mesh_vs, mesh_fs), &raster(DepthTest::Less))?;
        let (line_vs, line_fs) = (&shaders::render::LINE_VERT, &shaders::render::LINE_FRAG);
        let line_desc = desc(line_vs, line_fs).per_instance(&[0, 1, 2, 3]);
        let lines = Pipeline::with_raster(ctx, &line_desc, &raster(DepthTest::LessOrEqual))?;
        let block = Buffer::host(ctx, std::mem::size_of::<ViewBlock>() as u64, "render view")?;
        Ok(Renderer { ctx: ctx.clone(), samples, mesh, lines, block, frame: None, readback: None })
    }

    pub fn samples(&self) -> u32 {
        self.samples
    }

    /// Uploads `scene`: triangulated faces with normals and colours, and every line
    /// segment and point as one instance list.
    pub fn prepare(&self, scene: &Scene) -> Result<Prepared> {
        let bounds = scene.bounds().unwrap_or((DVec3::ZERO, DVec3::ZERO));
        let origin = (bounds.0 + bounds.1) * 0.5;
        let rel = |p: DVec3| (p - origin).as_vec3().to_array();
        let mut meshes = Vec::new();
        let mut segments = Vec::new();
        let mut triangles = 0;
        for item in &scene.meshes {
            item.check()?;
            let (vertices, indices) = mesh_geometry(item, origin);
            triangles += indices.len() / 3;
            if !indices.is_empty() {
                let count = u32::try_from(indices.len())
                    .map_err(|_| RenderError::Usage("a mesh of more than 2^32 triangle corners".into()))?;
                meshes.push(GpuMesh {
                    vertices: Buffer::with_data(&self.ctx, &vertices, "render vertices")?,
                    indices: Buffer::with_data(&self.ctx, &indices, "render indices")?,
                    count,
                    shading: item.shading,
                });
            }
            if let Some(c) = item.wireframe {
                let mut seen = HashSet::with_capacity(item.mesh.num_faces() * 2);
                let p = item.mesh.positions();
                for face in item.mesh.faces() {
                    for (i, &a) in face.iter().enumerate() {
                        let b = face[(i + 1) % face.len()];
                        if seen.insert((a.min(b), a.max(b))) {
                            segments.push(segment(
                                rel(p[a as usize]),
                                rel(p[b as usize]),
                                c,
                                item.edge_width,
                            ));
                        }
                    }
                }
            }
        }
        for line in &scene.lines {
            let n = line.points.len();
            let pieces = if line.closed && n > 2 { n } else { n.saturating_sub(1) };
            for i in 0..pieces {
                let (a, b) = (line.points[i], line.points[(i + 1) % n]);
                segments.push(segment(rel(a), rel(b), line.colour, line.width));
            }
        }
        for set in &scene.points {
            segments.extend(set.positions.iter().map(|&p| segment(rel(p), rel(p), set.colour, set.size)));
        }
        let segment_count = segments.len();
        let segments = if segments.is_empty() {
            None
        } else {
            let n = u32::try_from(segments.len())
                .map_err(|_| RenderError::Usage("more than 2^32 line segments".into()))?;
            // Padding to one segment per quad corner: the validation layer's synchronization
            // check (1.3.239) sizes an instanced binding's read by the vertex count (6), and
            // would see a short buffer's read run into its neighbour in the same memory block.
            segments.resize(segments.len().max(6), Segment::default());
            Some((Buffer::with_data(&self.ctx, &segments, "render segments")?, n))
        };
        Ok(Prepared { meshes, segments, origin, bounds, triangles, segment_count })
    }

    /// Records the picture of `prepared` seen by `view` into `rec` and returns the
    /// single-sample RGBA8 texture holding it (valid until the next call). One picture per
    /// submission: the camera block is rewritten by each call.
    pub fn record<'a>(
        &'a mut self,
        rec: &mut Recorder,
        prepared: &'a Prepared,
        view: &View,
    ) -> Result<&'a Texture> {
        let (w, h) = (view.width, view.height);
        let max = self.ctx.info().max_image_2d;
        if w == 0 || h == 0 || w > max || h > max {
            return Err(RenderError::Usage(format!(
                "a {w}×{h} picture (each side 1..={max} on this device)"
            )));
        }
        if self.frame.as_ref().is_none_or(|f| f.size != [w, h]) {
            self.frame = None;
            let s = self.samples;
            self.frame = Some(Frame {
                size: [w, h],
                colour: Texture::target(&self.ctx, TexFormat::Rgba8, w, h, s, "picture")?,
                resolve: if s > 1 {
                    Some(Texture::target(&self.ctx, TexFormat::Rgba8, w, h, 1, "picture resolve")?)
                } else {
                    None
                },
                depth: Texture::target(&self.ctx, TexFormat::Depth32F, w, h, s, "picture depth")?,
            });
        }
        let block = view_block(prepared, view);
        self.block.write_slice(0, &[block])?;
        let Some(frame) = self.frame.as_ref() else {
            return Err(RenderError::Usage("picture targets were not created".into()));
        };
        let bg = view.background.map(|c| f32::from(c) / 255.0);
        let colour = [Attachment::new(&frame.colour, Load::Float(bg))];
        let resolve: Vec<&Texture> = frame.resolve.iter().collect();
        let targets = Targets {
            colour: &colour,
            resolve: &resolve,
            depth: Some(Attachment::new(&frame.depth, Load::Float([1.0; 4]))),
        };
        let (mesh, lines, block) = (&self.mesh, &self.lines, &self.block);
        rec.render_into(targets, None, &[], |pass| {
            if !prepared.meshes.is_empty() {
                pass.bind(mesh)?;
                pass.uniform(0, block)?;
                for m in &prepared.meshes {
                    let shading: u32 = match m.shading {
                        Shading::Flat => 0,
                        Shading::Smooth => 1,
                        Shading::Unlit => 2,
                    };
                    pass.push(&[shading])?;
                    pass.vertex_buffers(&m.vertices, None)?;
                    pass.index_buffer(&m.indices)?;
                    pass.draw_indexed(0..m.count, 0..1)?;
                }
            }
            if let Some((segments, n)) = &prepared.segments {
                pass.bind(lines)?;
                pass.uniform(0, block)?;
                pass.vertex_buffers_at(None, Some((segments, 0)))?;
                pass.draw(0..6, 0..*n)?;
            }
            Ok(())
        })?;
        Ok(frame.output())
    }

    /// Draws `prepared` seen by `view` and reads the picture back.
    pub fn render(&mut self, prepared: &Prepared, view: &View) -> Result<Picture> {
        let bytes = u64::from(view.width) * u64::from(view.height) * 4;
        let readback = match self.readback.take() {
            Some(b) if b.size() == bytes => b,
            _ => Buffer::readback_for(&self.ctx, bytes)?,
        };
        let ctx = self.ctx.clone();
        let mut failure = None;
        let result = ctx.submit(|rec| {
            let out = match self.record(rec, prepared, view) {
                Ok(out) => out,
                Err(RenderError::Gpu(e)) => return Err(e),
                Err(e) => {
                    let message = e.to_string();
                    failure = Some(e);
                    return Err(crate::gpu::GpuError::Usage(message));
                }
            };
            rec.readback_into(out, 0..1, [0, 0, view.width, view.height], &readback, 0)
        });
        if let Some(e) = failure {
            return Err(e);
        }
        result?;
        let picture = Picture::new(view.width, view.height, readback.bytes()?.to_vec());
        self.readback = Some(readback);
        picture
    }
}

fn segment(a: [f32; 3], b: [f32; 3], colour: Rgba, width: f32) -> Segment {
    Segment { a, b, colour: pack(colour), width: width.max(0.0) }
}

/// The camera block: projection with clip planes around the scene's bounding sphere, and
/// the view matrix from the scene's origin.
fn view_block(prepared: &Prepared, view: &View) -> ViewBlock {
    let (lo, hi) = prepared.bounds;
    let centre = (lo + hi) * 0.5;
    let radius = (hi - lo).length() * 0.5;
    let (near, far) = view.camera.clip_planes(centre, radius.max(view.camera.distance * 1e-6));
    let aspect = f64::from(view.width) / f64::from(view.height);
    let proj = view.camera.projection(aspect, near, far);
    let model_view = view.camera.view() * DMat4::from_translation(prepared.origin);
    ViewBlock {
        proj: proj.as_mat4().to_cols_array(),
        view: model_view.as_mat4().to_cols_array(),
        viewport: [view.width as f32, view.height as f32, LINE_BIAS, 0.0],
    }
}

/// Vertices and triangle indices of one mesh: shared vertices, or one copy per face
/// corner when colours are per face.
fn mesh_geometry(item: &SceneMesh, origin: DVec3) -> (Vec<Vertex>, Vec<u32>) {
    let mesh = &item.mesh;
    let p = mesh.positions();
    let mut normals = vec![DVec3::ZERO; mesh.num_vertices()];
    let mut corners = Vec::new();
    let mut triangles: Vec<[usize; 3]> = Vec::new();
    let mut face_triangles: Vec<(usize, usize)> = Vec::with_capacity(mesh.num_faces());
    for face in mesh.faces() {
        corners.clear();
        corners.extend(face.iter().map(|&v| p[v as usize]));
        let n = newell_normal(corners.iter().copied());
        for &v in face {
            normals[v as usize] += n;
        }
        let start = triangles.len();
        triangles.extend(polygon_or_fan(&corners).into_iter().map(|t| t.map(|i| i as usize)));
        face_triangles.push((start, triangles.len()));
    }
    let vertex = |v: usize, colour: Rgba| Vertex {
        position: (p[v] - origin).as_vec3().to_array(),
        normal: normals[v].normalize_or_zero().as_vec3().to_array(),
        colour: pack(colour),
    };
    let shared = |colour: &dyn Fn(usize) -> Rgba| {
        let vertices = (0..mesh.num_vertices()).map(|v| vertex(v, colour(v))).collect();
        let mut indices = Vec::with_capacity(triangles.len() * 3);
        for (f, face) in mesh.faces().enumerate() {
            let (a, b) = face_triangles[f];
            for t in &triangles[a..b] {
                indices.extend(t.iter().map(|&c| face[c]));
            }
        }
        (vertices, indices)
    };
    match &item.colours {
        Colours::Uniform(c) => shared(&|_| *c),
        Colours::PerVertex(c) => shared(&|v| c[v]),
        Colours::PerFace(colours) => {
            let mut vertices = Vec::with_capacity(mesh.face_parts().1.len());
            let mut indices = Vec::with_capacity(triangles.len() * 3);
            for (f, face) in mesh.faces().enumerate() {
                let base = vertices.len() as u32;
                vertices.extend(face.iter().map(|&v| vertex(v as usize, colours[f])));
                let (a, b) = face_triangles[f];
                for t in &triangles[a..b] {
                    indices.extend(t.iter().map(|&c| base + c as u32));
                }
            }
            (vertices, indices)
        }
    }
}
