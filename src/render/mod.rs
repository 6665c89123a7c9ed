//! Offscreen pictures of meshes, headless: a [`Scene`] of meshes (coloured per mesh, per
//! vertex or per face; flat, smooth or unlit; with an optional wireframe), polylines and
//! points, seen by an orbit [`Camera`], drawn by the [`Renderer`] on texgeo's own Vulkan
//! plumbing into an RGBA8 target (optionally multisampled) with a depth buffer, and read
//! back as a [`Picture`] that writes itself to PNG.
//!
//! Everything that shows geometry uses it: `texgeo render`, the reproductions' figures,
//! and the interactive viewer, whose window shows exactly what this renders for the same
//! camera.
//!
//! ```no_run
//! use texgeo::gpu::Context;
//! use texgeo::mesh::procedural;
//! use texgeo::render::{Camera, Renderer, Scene, SceneMesh, View, colour};
//!
//! let ctx = Context::from_env()?;
//! let cube = procedural::cube();
//! let scene = Scene::new().with_mesh(SceneMesh::new(&cube, colour::SURFACE).wireframe(colour::EDGE));
//! let mut renderer = Renderer::new(&ctx, 4)?;
//! let prepared = renderer.prepare(&scene)?;
//! let view = View::fit(&scene, 640, 480)?;
//! renderer.render(&prepared, &view)?.save_png("cube.png")?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod boolean;
mod camera;
pub mod colour;
mod error;
mod look;
mod model;
mod picture;
mod renderer;
mod scene;
pub mod voxels;

pub use camera::Camera;
pub use colour::Rgba;
pub use error::{RenderError, Result};
pub use look::Look;
pub use model::{Content, Model};
pub use picture::Picture;
pub use renderer::{Prepared, Renderer, View};
pub use scene::{Colours, Points, Polyline, Scene, SceneMesh, Shading};
