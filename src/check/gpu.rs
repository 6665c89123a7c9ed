//! The GPU core's passes: the 2×2 reduction (Alg. 4-3) against an exact integer sum,
//! and XOR rasterization with logic op against the CPU scanline rasterizer, whose
//! half-open spans give the same texels as the GPU's top-left rule.

use super::{Check, Needs, Step, Stop, first_difference};
use crate::gpu::{Context, Reducer, TexFormat, Texture, XorRaster, reduce_sum};
use crate::random::Rng;
use crate::report::bench::xor::cpu_xor;

pub(super) fn checks() -> Vec<Check> {
    vec![
        Check {
            name: "reduce-pow2",
            what: "2×2 reduction of integer texels, power-of-two sizes 1² … 256²",
            needs: Needs { texture: 256, ..Needs::default() },
            run: reduce_pow2,
        },
        Check {
            name: "reduce-npot",
            what: "2×2 reduction of other sizes (3×1, 1×5, 37×19, 129×257): odd edges padded",
            needs: Needs { texture: 257, ..Needs::default() },
            run: reduce_npot,
        },
        Check {
            name: "reduce-tiles",
            what: "tiled, layered reduction: one sum per tile and layer (inclusion phase 2)",
            needs: Needs { texture: 64, ..Needs::default() },
            run: reduce_tiles,
        },
        Check {
            name: "xor-parity",
            what: "XOR rasterization (R32UI, R8UI): overlaps cancel, against the CPU rasterizer",
            needs: Needs { logic_op: true, texture: 64, ..Needs::default() },
            run: xor_parity,
        },
        Check {
            name: "xor-top-left",
            what: "XOR rasterization ties: edges through texel centres follow the top-left rule",
            needs: Needs { logic_op: true, texture: 16, ..Needs::default() },
            run: xor_top_left,
        },
    ]
}

/// Random integers in [-range, range] as RGBA texels: every partial sum is exact in f32.
fn random_texels(rng: &mut Rng, n: usize, range: u64) -> Vec<[f32; 4]> {
    (0..n).map(|_| std::array::from_fn(|_| (rng.below(2 * range + 1) as i64 - range as i64) as f32)).collect()
}

/// The exact channel sums.
fn cpu_sum(data: &[[f32; 4]]) -> [f32; 4] {
    let mut s = [0i64; 4];
    for t in data {
        for c in 0..4 {
            s[c] += t[c] as i64;
        }
    }
    s.map(|v| v as f32)
}

fn reduce_sizes(ctx: &Context, sizes: &[(u32, u32)], seed: u64) -> Step {
    let mut rng = Rng::new(seed);
    for &(w, h) in sizes {
        let data = random_texels(&mut rng, (w * h) as usize, 100);
        let got = reduce_sum(ctx, &data, w, h)?;
        first_difference(&cpu_sum(&data), &got, |c| format!("{w}×{h}, channel {c}"))?;
    }
    Ok(())
}

fn reduce_pow2(ctx: &Context) -> Step {
    reduce_sizes(ctx, &[(1, 1), (2, 2), (4, 4), (64, 64), (256, 256)], 42)
}

fn reduce_npot(ctx: &Context) -> Step {
    reduce_sizes(ctx, &[(3, 1), (1, 5), (37, 19), (100, 3), (129, 257)], 7)
}

fn reduce_tiles(ctx: &Context) -> Step {
    let mut rng = Rng::new(99);
    // (width, height, tile width, tile height, layers): square, narrow and 1-texel tiles.
    for (w, h, tw, th, layers) in [(64u32, 32u32, 16u32, 8u32, 3u32), (2, 16, 2, 1, 8), (4, 8, 4, 2, 2)] {
        let tex = Texture::new_layered(ctx, TexFormat::Rgba32F, w, h, layers, "check tiles")?;
        let data: Vec<Vec<[f32; 4]>> =
            (0..layers).map(|_| random_texels(&mut rng, (w * h) as usize, 3)).collect();
        let mut reducer = Reducer::for_tiles(ctx, [w, h], [tw, th], layers)?;
        let (tx, ty) = (w / tw, h / th);
        let got = ctx
            .submit(|rec| {
                for (l, d) in data.iter().enumerate() {
                    rec.upload(&tex, l as u32, d)?;
                }
                let r = reducer.record_tiles(rec, &tex, [w, h], [tw, th])?;
                rec.readback_region(r, 0..layers, [0, 0, tx, ty])
            })?
            .to_vec::<[f32; 4]>()?;
        let mut expected = Vec::with_capacity(got.len());
        for layer in &data {
            for j in 0..ty as usize {
                for i in 0..tx as usize {
                    let tile: Vec<[f32; 4]> = (0..th as usize)
                        .flat_map(|y| {
                            let row = (j * th as usize + y) * w as usize + i * tw as usize;
                            layer[row..row + tw as usize].to_vec()
                        })
                        .collect();
                    expected.push(cpu_sum(&tile));
                }
            }
        }
        let per_layer = (tx * ty) as usize;
        first_difference(&expected, &got, |k| {
            let (l, t) = (k / per_layer, k % per_layer);
            format!("{w}×{h} in {tw}×{th} tiles, layer {l}, tile ({}, {})", t % tx as usize, t / tx as usize)
        })?;
    }
    Ok(())
}

/// The GPU's XOR raster of `tris` into an `n`×`n` target against the CPU's, texel by
/// texel, in both integer formats.
fn same_as_cpu(ctx: &Context, case: &str, n: u32, tris: &[[[f32; 2]; 3]]) -> Step {
    let expected = cpu_xor(n, tris);
    for format in [TexFormat::R32Ui, TexFormat::R8Ui] {
        let got = XorRaster::new(ctx, format)?.rasterize(ctx, n, n, tris, 1)?;
        first_difference(&expected, &got, |i| {
            format!("{case} ({format:?}), texel ({}, {})", i % n as usize, i / n as usize)
        })?;
    }
    Ok(())
}

fn xor_parity(ctx: &Context) -> Step {
    // Random triangles on the 1/256 sub-pixel grid, each drawn twice or once: the twice
    // drawn ones must cancel. Fans around texel centres share edges through centres.
    let mut rng = Rng::new(3);
    let snap = |v: f64| ((v * 256.0).round() / 256.0) as f32;
    let mut tris: Vec<[[f32; 2]; 3]> = (0..600)
        .map(|_| std::array::from_fn(|_| [snap(rng.range_f64(0.0, 64.0)), snap(rng.range_f64(0.0, 64.0))]))
        .collect();
    let doubled: Vec<_> = tris.iter().step_by(3).copied().collect();
    tris.extend(doubled);
    for k in 0..20 {
        let c = [10.5 + k as f32, 20.5];
        let a = [c[0] - 3.0, c[1] - 7.0];
        let b = [c[0] + 4.0, c[1] + 5.0];
        tris.push([c, a, b]);
        tris.push([c, b, [c[0] - 6.0, c[1] + 6.0]]);
    }
    same_as_cpu(ctx, "random triangles", 64, &tris)?;
    let expected = cpu_xor(64, &tris);
    if !(expected.contains(&0) && expected.contains(&1)) {
        return Err(Stop::error("the case sets no texel or every texel: nothing was compared"));
    }
    Ok(())
}

fn xor_top_left(ctx: &Context) -> Step {
    let n = 8.0;
    // A square split by a diagonal through the texel centres (0.5, 0.5), (1.5, 1.5), …,
    // with its outer edges through centres too: each centre flips once or not at all.
    let lower = [[0.5, 0.5], [n - 0.5, n - 0.5], [n - 0.5, 0.5]];
    let upper = [[0.5, 0.5], [0.5, n - 0.5], [n - 0.5, n - 0.5]];
    same_as_cpu(ctx, "diagonal through centres", 8, &[lower, upper])?;
    // A vertical shared edge through the centres x = 3.5: the whole target flips once.
    let tris = [
        [[0.0, 0.0], [3.5, 0.0], [3.5, 8.0]],
        [[0.0, 0.0], [3.5, 8.0], [0.0, 8.0]],
        [[3.5, 0.0], [8.0, 0.0], [8.0, 8.0]],
        [[3.5, 0.0], [8.0, 8.0], [3.5, 8.0]],
    ];
    same_as_cpu(ctx, "vertical edge through centres", 8, &tris)?;
    // A horizontal shared edge through the centres y = 2.5, and a vertex on a centre.
    let tris = [
        [[0.0, 0.0], [8.0, 0.0], [8.0, 2.5]],
        [[0.0, 0.0], [8.0, 2.5], [0.0, 2.5]],
        [[0.0, 2.5], [8.0, 2.5], [4.5, 6.5]],
    ];
    same_as_cpu(ctx, "horizontal edge through centres", 8, &tris)
}
