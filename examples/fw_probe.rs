use glam::DVec3;
use texgeo::inclusion::fast_winding::FastWinding;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let mesh = texgeo::mesh::formats::read(&args[1]).unwrap();
    let n: usize = args[2].parse().unwrap();
    let fw = FastWinding::new(&mesh, 0).unwrap();
    let (lo, hi) = mesh.bounds();
    let pts = texgeo::random::Rng::new(1).points_in_box(n, lo, hi);
    let mut tiers = std::collections::BTreeMap::new();
    let t = std::time::Instant::now();
    let mut errsum = 0.0;
    for &p in &pts {
        let (_, tier) = fw.classify_point(p);
        *tiers.entry(format!("{tier:?}")).or_insert(0) += 1;
        errsum += fw.estimate(p).err;
    }
    println!("{:?} {:.2} us/pt, mean err {}", tiers, t.elapsed().as_secs_f64() * 1e6 / n as f64, errsum / n as f64);
    for tol in [1e-2, 1e-3, 2e-4, 1e-5] {
        let t = std::time::Instant::now();
        let mut e = 0.0; let mut und = 0;
        for &p in &pts { let x = fw.tree().winding(p, tol); e += x.err; if x.decides(0.0).is_none() { und += 1; } }
        println!("tol {tol}: {:.2} us/pt, mean err {:.4}, undecided {}", t.elapsed().as_secs_f64() * 1e6 / n as f64, e / n as f64, und);
    }
    let t = std::time::Instant::now();
    for &p in &pts[..200] { std::hint::black_box(fw.tree().direct(p)); }
    println!("direct {:.1} us/pt", t.elapsed().as_secs_f64() * 1e6 / 200.0);
    let _ = DVec3::ZERO;
}
