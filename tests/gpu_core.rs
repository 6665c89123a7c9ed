//! The GPU core: context, reduction and XOR rasterization on the default device
//! (lavapipe in `tools/test`), with validation on when `TEXGEO_VALIDATION=1`.

use texgeo::gpu::{Context, GpuError, TexFormat, Texture, XorRaster, reduce_sum};
use texgeo::random::Rng;

fn ctx() -> Context {
    Context::from_env().expect("a Vulkan device (run tools/setup)")
}

/// Random integers in [-range, range], as RGBA texels.
fn random_texels(rng: &mut Rng, n: usize, range: i64) -> Vec<[f32; 4]> {
    (0..n).map(|_| std::array::from_fn(|_| (rng.below(2 * range as u64 + 1) as i64 - range) as f32)).collect()
}

fn cpu_sum(data: &[[f32; 4]]) -> [f32; 4] {
    let mut s = [0i64; 4];
    for t in data {
        for c in 0..4 {
            s[c] += t[c] as i64;
        }
    }
    s.map(|v| v as f32)
}

#[test]
fn reduce_sum_is_exact_on_integer_data() {
    let ctx = ctx();
    let mut rng = Rng::new(42);
    for (w, h) in [(1, 1), (2, 2), (4, 4), (64, 64), (512, 512), (1024, 1024)] {
        let data = random_texels(&mut rng, w * h, 2);
        let gpu = reduce_sum(&ctx, &data, w as u32, h as u32).unwrap();
        assert_eq!(gpu, cpu_sum(&data), "{w}x{h}");
    }
}

#[test]
fn reduce_sum_pads_other_sizes() {
    let ctx = ctx();
    let mut rng = Rng::new(7);
    for (w, h) in [(3, 1), (1, 5), (37, 19), (100, 3), (129, 257)] {
        let data = random_texels(&mut rng, w * h, 100);
        let gpu = reduce_sum(&ctx, &data, w as u32, h as u32).unwrap();
        assert_eq!(gpu, cpu_sum(&data), "{w}x{h}");
    }
}

#[test]
fn reduce_sum_rejects_wrong_sizes() {
    let ctx = ctx();
    match reduce_sum(&ctx, &[[1.0; 4]; 3], 2, 2) {
        Err(GpuError::Usage(m)) => assert!(m.contains("3 texels given for a 2×2 texture"), "{m}"),
        other => panic!("expected a usage error, got {other:?}"),
    }
}

#[test]
fn xor_overlaps_cancel() {
    let ctx = ctx();
    for format in [TexFormat::R32Ui, TexFormat::R8Ui] {
        let xor = XorRaster::new(&ctx, format).unwrap();
        // The same triangle twice cancels; a third, disjoint one stays.
        let t = [[1.0, 1.0], [9.0, 1.0], [1.0, 9.0]];
        let u = [[10.0, 10.0], [15.0, 10.0], [15.0, 15.0]];
        let out = xor.rasterize(&ctx, 16, 16, &[t, t, u], 1).unwrap();
        let single = xor.rasterize(&ctx, 16, 16, &[u], 1).unwrap();
        assert_eq!(out, single, "{format:?}");
        assert!(single.contains(&1));
        // A texel covered by two different overlapping triangles is cleared.
        let a = [[0.0, 0.0], [16.0, 0.0], [0.0, 16.0]];
        let b = [[0.0, 0.0], [16.0, 0.0], [16.0, 16.0]];
        let both = xor.rasterize(&ctx, 16, 16, &[a, b], 1).unwrap();
        let only_a = xor.rasterize(&ctx, 16, 16, &[a], 1).unwrap();
        let only_b = xor.rasterize(&ctx, 16, 16, &[b], 1).unwrap();
        for i in 0..256 {
            assert_eq!(both[i], only_a[i] ^ only_b[i], "texel {i}");
        }
    }
}

/// lavapipe draws nothing of a 9-vertex triangle list whose last triangle is degenerate,
/// and cuts long draws into segments of 4095 vertices, so 4104 or 8199 vertices lose
/// triangles the same way; `RenderScope::draw` splits such draws. Degenerate triangles
/// are what the voxelizer's culled cross-sections are. Each real triangle here covers one
/// texel centre of its own, so every one of them must show.
#[test]
fn triangle_draws_lose_no_triangle() {
    let ctx = ctx();
    let xor = XorRaster::new(&ctx, TexFormat::R32Ui).unwrap();
    let n = 128u32;
    // Every pattern of real and degenerate triangles in draws of 1 to 5 triangles.
    for k in 1..=5usize {
        for pattern in 0..1u32 << k {
            let tris: Vec<_> = (0..k)
                .map(|t| {
                    let x = 3.0 * t as f32;
                    match pattern >> t & 1 {
                        1 => [[x + 0.1, 0.1], [x + 0.95, 0.1], [x + 0.1, 0.95]],
                        _ => [[0.0, 0.0]; 3],
                    }
                })
                .collect();
            let out = xor.rasterize(&ctx, 16, 16, &tris, 1).unwrap();
            let set = out.iter().filter(|&&v| v != 0).count();
            assert_eq!(set, pattern.count_ones() as usize, "{k} triangles, pattern {pattern:b}");
        }
    }
    let mut rng = Rng::new(7);
    for triangles in [1368, 2733, 4098, 1369, 1365] {
        for _ in 0..4 {
            let mut tris = Vec::with_capacity(triangles);
            let mut real = 0usize;
            for _ in 0..triangles {
                if rng.next_f64() < 0.5 {
                    let (x, y) = ((real % n as usize) as f32, (real / n as usize) as f32);
                    tris.push([[x + 0.1, y + 0.1], [x + 0.95, y + 0.1], [x + 0.1, y + 0.95]]);
                    real += 1;
                } else {
                    tris.push([[0.0, 0.0]; 3]);
                }
            }
            let out = xor.rasterize(&ctx, n, n, &tris, 1).unwrap();
            let set = out.iter().filter(|&&v| v != 0).count();
            assert_eq!(set, real, "{} vertices, {real} real triangles", 3 * triangles);
        }
    }
}

#[test]
fn shared_edge_centre_flips_exactly_once() {
    let ctx = ctx();
    let xor = XorRaster::new(&ctx, TexFormat::R32Ui).unwrap();
    // Two triangles forming a square split by a diagonal through texel centres
    // (0.5,0.5), (1.5,1.5), …: every centre on the diagonal is covered exactly once.
    let n = 8.0;
    let lower = [[0.5, 0.5], [n - 0.5, n - 0.5], [n - 0.5, 0.5]];
    let upper = [[0.5, 0.5], [0.5, n - 0.5], [n - 0.5, n - 0.5]];
    let out = xor.rasterize(&ctx, 8, 8, &[lower, upper], 1).unwrap();
    // Interior and diagonal centres: exactly one flip. (The outer boundary follows the
    // top-left rule: centres on the left/top edges are in, right/bottom out.)
    for j in 0..8 {
        for i in 0..8 {
            let v = out[j * 8 + i];
            assert!(v <= 1, "texel ({i},{j}) flipped {v} times");
            if i == j && i < 7 && i > 0 {
                assert_eq!(v, 1, "diagonal texel ({i},{j})");
            }
        }
    }
    // A vertical shared edge exactly through centres x = 3.5.
    let left = [[0.0, 0.0], [3.5, 0.0], [3.5, 8.0]];
    let left2 = [[0.0, 0.0], [3.5, 8.0], [0.0, 8.0]];
    let right = [[3.5, 0.0], [8.0, 0.0], [8.0, 8.0]];
    let right2 = [[3.5, 0.0], [8.0, 8.0], [3.5, 8.0]];
    let out = xor.rasterize(&ctx, 8, 8, &[left, left2, right, right2], 1).unwrap();
    assert!(out.iter().all(|&v| v == 1), "{out:?}");
}

#[test]
fn texture_round_trip_all_formats() {
    let ctx = ctx();
    let t = Texture::new_layered(&ctx, TexFormat::R32Ui, 5, 3, 2, "rt").unwrap();
    let l0: Vec<u32> = (0..15).collect();
    let l1: Vec<u32> = (100..115).collect();
    let out = ctx
        .submit(|rec| {
            rec.upload(&t, 0, &l0)?;
            rec.upload(&t, 1, &l1)?;
            rec.readback(&t)
        })
        .unwrap()
        .to_vec::<u32>()
        .unwrap();
    assert_eq!(&out[..15], &l0[..]);
    assert_eq!(&out[15..], &l1[..]);
}

/// Reduces a random `w`×`h`×`layers` texture in `tw`×`th` tiles on the GPU and checks
/// every tile sum against the CPU.
fn check_tiles(ctx: &Context, rng: &mut Rng, (w, h, tw, th, layers): (u32, u32, u32, u32, u32)) {
    use texgeo::gpu::Reducer;
    let tex = Texture::new_layered(ctx, TexFormat::Rgba32F, w, h, layers, "tiles").unwrap();
    let data: Vec<Vec<[f32; 4]>> = (0..layers).map(|_| random_texels(rng, (w * h) as usize, 3)).collect();
    let mut reducer = Reducer::for_tiles(ctx, [w, h], [tw, th], layers).unwrap();
    let (tx, ty) = (w / tw, h / th);
    let out = ctx
        .submit(|rec| {
            for (l, d) in data.iter().enumerate() {
                rec.upload(&tex, l as u32, d)?;
            }
            let r = reducer.record_tiles(rec, &tex, [w, h], [tw, th])?;
            rec.readback_region(r, 0..layers, [0, 0, tx, ty])
        })
        .unwrap()
        .to_vec::<[f32; 4]>()
        .unwrap();
    for l in 0..layers as usize {
        for j in 0..ty as usize {
            for i in 0..tx as usize {
                let tile: Vec<[f32; 4]> = (0..th as usize)
                    .flat_map(|y| {
                        let row = (j * th as usize + y) * w as usize + i * tw as usize;
                        data[l][row..row + tw as usize].to_vec()
                    })
                    .collect();
                let got = out[l * (tx * ty) as usize + j * tx as usize + i];
                assert_eq!(got, cpu_sum(&tile), "{w}x{h} in {tw}x{th} tiles, layer {l} tile ({i},{j})");
            }
        }
    }
    // Tiles that are not powers of two are refused.
    if tw > 2 {
        let refused = ctx.submit(|rec| reducer.record_tiles(rec, &tex, [w, h], [tw - 1, th]).map(|_| ()));
        assert!(matches!(&refused, Err(GpuError::Usage(m)) if m.contains("power of two")), "{refused:?}");
    }
}

#[test]
fn tiles_and_layers_reduce_independently() {
    let ctx = ctx();
    let mut rng = Rng::new(99);
    check_tiles(&ctx, &mut rng, (64, 32, 16, 8, 3));
}

#[test]
fn narrow_tiles_reduce_along_one_axis() {
    let ctx = ctx();
    let mut rng = Rng::new(5);
    for shape in [(2, 16, 2, 1, 8), (1, 16, 1, 1, 8), (4, 8, 4, 2, 2), (2, 8, 1, 2, 1)] {
        check_tiles(&ctx, &mut rng, shape);
    }
}

#[test]
fn xor_raster_equals_the_cpu_scanline_rasterizer() {
    // Random triangles with vertices on the 1/256 sub-pixel grid, many sharing edges
    // through texel centres (a fan around lattice points): the GPU's top-left rule and
    // the CPU's half-open rule must flip exactly the same centres.
    let ctx = ctx();
    let n = 64u32;
    let mut rng = Rng::new(3);
    let snap = |v: f64| ((v * 256.0).round() / 256.0) as f32;
    let mut tris: Vec<[[f32; 2]; 3]> = (0..1500)
        .map(|_| std::array::from_fn(|_| [snap(rng.range_f64(0.0, 64.0)), snap(rng.range_f64(0.0, 64.0))]))
        .collect();
    for k in 0..40 {
        let c = [10.5 + k as f32, 20.5];
        let a = [c[0] - 3.0, c[1] - 7.0];
        let b = [c[0] + 4.0, c[1] + 5.0];
        tris.push([c, a, b]);
        tris.push([c, b, [c[0] - 6.0, c[1] + 6.0]]);
    }
    let xor = XorRaster::new(&ctx, TexFormat::R32Ui).unwrap();
    let gpu = xor.rasterize(&ctx, n, n, &tris, 1).unwrap();
    let cpu = texgeo::report::bench::xor::cpu_xor(n, &tris);
    let differing: Vec<usize> = (0..gpu.len()).filter(|&i| gpu[i] != cpu[i]).take(5).collect();
    assert!(differing.is_empty(), "texels {differing:?} differ");
    assert!(cpu.contains(&1) && cpu.contains(&0));
}

#[test]
fn point_pass_puts_each_datum_on_its_own_texel() {
    use texgeo::gpu::{Blend, Datum, Scatter};
    let ctx = ctx();
    // Non-square, non-power-of-two target; every texel gets its own index as value.
    let (w, h) = (37u32, 11u32);
    let data: Vec<Datum> =
        (0..w * h).rev().map(|i| Datum { texel: i, value: [i as f32, -(i as f32), 1.0, 0.5] }).collect();
    let out = Scatter::new(&ctx, Blend::Replace).unwrap().scatter(&ctx, w, h, &data).unwrap();
    for (i, v) in out.iter().enumerate() {
        assert_eq!(*v, [i as f32, -(i as f32), 1.0, 0.5], "texel {i}");
    }
    // With additive blending, data on the same texel are summed (exactly, for integers).
    let data: Vec<Datum> =
        (0..1000).map(|k| Datum { texel: k % 7, value: [1.0, k as f32, 0.0, 0.0] }).collect();
    let out = Scatter::new(&ctx, Blend::Add).unwrap().scatter(&ctx, 4, 2, &data).unwrap();
    for (t, texel) in out.iter().enumerate().take(7) {
        let expect: f32 = (0..1000).filter(|k| k % 7 == t).map(|k| k as f32).sum();
        assert_eq!(texel[0], (0..1000).filter(|k| k % 7 == t).count() as f32);
        assert_eq!(texel[1], expect, "texel {t}");
    }
    assert_eq!(out[7], [0.0; 4]);
    let outside = Scatter::new(&ctx, Blend::Replace).unwrap().scatter(
        &ctx,
        4,
        2,
        &[Datum { texel: 8, value: [0.0; 4] }],
    );
    assert!(
        matches!(&outside, Err(GpuError::Usage(m)) if m == "texel 8 outside a 4×2 target"),
        "{outside:?}"
    );
}
