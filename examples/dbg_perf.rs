use std::time::Instant;
use texgeo::inclusion::gpu::*;
use texgeo::inclusion::tetragrid::TetraGrid;
use texgeo::inclusion::*;
fn main() {
    let path = std::env::args().nth(1).unwrap();
    let mesh = texgeo::mesh::formats::read(&path).unwrap();
    let ctx = texgeo::gpu::Context::from_env().unwrap();
    let (lo, hi) = mesh.bounds();
    let mut rng = texgeo::random::Rng::new(1);
    let pts = rng.points_in_box(1000, lo, hi);
    let ft = FeitoTorres::new(&mesh).unwrap();
    let t = Instant::now();
    let want = ft.classify_all(&pts);
    println!("cpu {:.1} ms", t.elapsed().as_secs_f64() * 1e3);
    let g = TetraGrid::new(FeitoTorres::new(&mesh).unwrap(), 32).unwrap();
    let t = Instant::now();
    let w2 = g.classify_all(&pts);
    println!("tetragrid {:.2} ms", t.elapsed().as_secs_f64() * 1e3);
    assert_eq!(w2, want);
    for batch in [64u32, 128, 256] {
        for groups in [32u32, 64] {
            let mut gpu = GpuInclusion::new(
                &ctx,
                TetraGrid::new(FeitoTorres::new(&mesh).unwrap(), 32).unwrap(),
                GpuOptions { batch, groups_per_draw: groups, phase2: Phase2::Gpu },
            )
            .unwrap();
            gpu.classify_all(&pts).unwrap();
            let t = Instant::now();
            let got = gpu.classify_all(&pts).unwrap();
            let el = t.elapsed();
            assert_eq!(got, want);
            println!(
                "gpu batch {batch} groups {groups}: {:.1} ms  {:?}",
                el.as_secs_f64() * 1e3,
                gpu.stats()
            );
        }
    }
    for batch in [16u32, 32, 64, 128] {
        let mut gpu =
            GpuGridInclusion::new(&ctx, TetraGrid::new(FeitoTorres::new(&mesh).unwrap(), 32).unwrap(), batch)
                .unwrap();
        gpu.classify_all(&pts).unwrap();
        let t = Instant::now();
        let got = gpu.classify_all(&pts).unwrap();
        let el = t.elapsed();
        assert_eq!(got, want);
        println!("gpu+grid batch {batch}: {:.1} ms  {:?}", el.as_secs_f64() * 1e3, gpu.stats());
    }
}
