//! The renderer's targets: the depth buffer (the nearer of two boxes wins whatever the
//! draw order) and multisampling (interior pixels keep their exact colour after the
//! resolve, edge pixels blend), pixel by pixel against the boxes' projections computed
//! on the CPU by the same camera.

use glam::DVec3;

use super::{Check, Needs, Step, Stop};
use crate::gpu::Context;
use crate::mesh::procedural;
use crate::render::{Camera, Picture, Renderer, Rgba, Scene, SceneMesh, Shading, View};

const RED: Rgba = [255, 0, 0, 255];
const GREEN: Rgba = [0, 255, 0, 255];
const BLACK: Rgba = [0, 0, 0, 255];
const SIZE: [u32; 2] = [160, 120];

pub(super) fn checks() -> Vec<Check> {
    vec![
        Check {
            name: "render-depth",
            what: "depth target: the nearer box covers the farther in either draw order, 1 sample",
            needs: Needs { texture: SIZE[0], ..Needs::default() },
            run: |ctx| boxes(ctx, 1),
        },
        Check {
            name: "render-msaa",
            what: "4× multisampled colour and depth targets, resolved: exact interiors, blended edges",
            needs: Needs { texture: SIZE[0], samples: 4, ..Needs::default() },
            run: |ctx| boxes(ctx, 4),
        },
    ]
}

/// The far box [−1, 1]³ (red) and a small near box in front of it (green), looking along
/// −z, in both draw orders; then the pair turned, for the edge pixels.
fn boxes(ctx: &Context, samples: u32) -> Step {
    let far = procedural::box_between(DVec3::splat(-1.0), DVec3::splat(1.0));
    let near = procedural::box_between(DVec3::new(-0.3, -0.3, 1.5), DVec3::new(0.3, 0.3, 2.1));
    let mut renderer = Renderer::new(ctx, samples)?;
    let [w, h] = SIZE;
    let view_of = |scene: &Scene, yaw: f64| -> Result<View, Stop> {
        let (lo, hi) = scene.bounds().ok_or_else(|| Stop::error("an empty scene"))?;
        let camera = Camera::fit(lo, hi, yaw.to_radians(), 0.0, f64::from(w) / f64::from(h));
        Ok(View { camera, width: w, height: h, background: BLACK })
    };
    for (order, far_first) in [("far box drawn first", true), ("near box drawn first", false)] {
        let (a, b) = (
            SceneMesh::new(&far, RED).shading(Shading::Unlit),
            SceneMesh::new(&near, GREEN).shading(Shading::Unlit),
        );
        let scene = if far_first {
            Scene::new().with_mesh(a).with_mesh(b)
        } else {
            Scene::new().with_mesh(b).with_mesh(a)
        };
        let view = view_of(&scene, 0.0)?;
        let prepared = renderer.prepare(&scene)?;
        let picture = renderer.render(&prepared, &view)?;
        // Looking along −z, each box's silhouette is its front face.
        let rect = |lo: DVec3, hi: DVec3| -> Result<[f64; 4], Stop> {
            let mut r = [f64::MAX, f64::MAX, f64::MIN, f64::MIN];
            for p in [lo, DVec3::new(hi.x, lo.y, lo.z), DVec3::new(lo.x, hi.y, lo.z), hi] {
                let q = view
                    .camera
                    .project(p, w, h)
                    .ok_or_else(|| Stop::error("a box corner behind the camera"))?;
                r = [r[0].min(q.x), r[1].min(q.y), r[2].max(q.x), r[3].max(q.y)];
            }
            Ok(r)
        };
        let far_rect = rect(DVec3::new(-1.0, -1.0, 1.0), DVec3::splat(1.0))?;
        let near_rect = rect(DVec3::new(-0.3, -0.3, 2.1), DVec3::new(0.3, 0.3, 2.1))?;
        let within = |r: [f64; 4], x: f64, y: f64, m: f64| {
            x > r[0] + m && x < r[2] - m && y > r[1] + m && y < r[3] - m
        };
        let (mut green, mut red, mut black) = (0, 0, 0);
        for y in 0..h {
            for x in 0..w {
                let (cx, cy) = (f64::from(x) + 0.5, f64::from(y) + 0.5);
                let expected = if within(near_rect, cx, cy, 1.0) {
                    green += 1;
                    GREEN
                } else if within(far_rect, cx, cy, 1.0) && !within(near_rect, cx, cy, -1.0) {
                    red += 1;
                    RED
                } else if !within(far_rect, cx, cy, -1.0) {
                    black += 1;
                    BLACK
                } else {
                    continue; // within a pixel of an edge
                };
                same_pixel(&picture, order, x, y, expected)?;
            }
        }
        if green < 100 || red < 100 || black < 100 {
            return Err(Stop::error(format!(
                "{order}: the case covers too few pixels ({green} near, {red} far, {black} background)"
            )));
        }
    }
    // Turned by 20°, the silhouettes' edges cross pixels: resolved from 4 samples some
    // pixels blend two colours; from 1 sample none does.
    let scene = Scene::new()
        .with_mesh(SceneMesh::new(&far, RED).shading(Shading::Unlit))
        .with_mesh(SceneMesh::new(&near, GREEN).shading(Shading::Unlit));
    let prepared = renderer.prepare(&scene)?;
    let picture = renderer.render(&prepared, &view_of(&scene, 20.0)?)?;
    let blended = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .filter(|&(x, y)| ![RED, GREEN, BLACK].contains(&picture.pixel(x, y)))
        .count();
    match (samples, blended) {
        (1, 0) => Ok(()),
        (1, n) => Err(Stop::mismatch("turned boxes, 1 sample: pixels of a blended colour", 0, n)),
        (_, 0) => {
            Err(Stop::mismatch("turned boxes, 4 samples: pixels of a blended colour on the edges", "some", 0))
        }
        _ => Ok(()),
    }
}

fn same_pixel(picture: &Picture, case: &str, x: u32, y: u32, expected: Rgba) -> Step {
    let got = picture.pixel(x, y);
    if got == expected {
        Ok(())
    } else {
        Err(Stop::mismatch(format!("{case}, pixel ({x}, {y})"), expected, got))
    }
}
