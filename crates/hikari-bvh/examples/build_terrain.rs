//! Builds the issue-5 terrain BLAS (708 x 708 vertex grid, ~1M triangles) and prints build
//! time (wall and CPU, fastest of each phase), node count, memory and the SAH cost of the tree
//! the kernel reads; then traces CPU rays (nodes and triangles visited per ray) as a check of
//! quality and correctness.
//!
//! `cargo run --release -p hikari-bvh --example build_terrain [-- --threads N --runs N --rays N]`
//! (`--rays 0` skips the rays; default 2^20). Without `--threads` the build runs on rayon's
//! global pool: `RAYON_NUM_THREADS=N` sizes it.

use glam::Vec3;
use hikari_bvh::rng::SplitMix64;
use hikari_bvh::{Blas, BuildOptions, Instance, Mesh, Ray, Tlas};
use std::time::Instant;

fn main() {
    let mut threads = 0usize;
    let mut runs = 5usize;
    let mut ray_count = 1usize << 20;
    let mut tlas_only = false;
    let args: Vec<String> = std::env::args().collect();
    let mut i = 1;
    while i < args.len() {
        match args[i].as_str() {
            "--threads" => threads = args.get(i + 1).and_then(|s| s.parse().ok()).unwrap_or(0),
            "--runs" => runs = args.get(i + 1).and_then(|s| s.parse().ok()).unwrap_or(5),
            "--rays" => ray_count = args.get(i + 1).and_then(|s| s.parse().ok()).unwrap_or(0),
            "--tlas-only" => {
                tlas_only = true;
                i += 1;
                continue;
            }
            _ => {}
        }
        i += 2;
    }
    let mesh = Mesh::terrain(708);
    for count in [959, 5000] {
        tlas_rebuild(count);
    }
    if tlas_only {
        return;
    }
    let options = BuildOptions {
        threads,
        ..Default::default()
    };
    let mut times = Vec::new();
    let mut cpu_times = Vec::new();
    let mut blas = None;
    let mut phase_min = [f64::INFINITY; 4];
    for _ in 0..runs.max(1) {
        let t0 = Instant::now();
        let c0 = process_cpu_ns();
        let b = Blas::from_mesh("terrain", &mesh, &options).expect("terrain builds");
        times.push(t0.elapsed().as_secs_f64() * 1e3);
        if let (Some(c0), Some(c1)) = (c0, process_cpu_ns()) {
            cpu_times.push((c1 - c0) as f64 * 1e-6);
        }
        let tm = &b.stats.timings;
        let phases = [tm.validate, tm.binary, tm.collapse, tm.triangles];
        for (m, p) in phase_min.iter_mut().zip(phases) {
            *m = m.min(p.as_secs_f64() * 1e3);
        }
        blas = Some(b);
    }
    cpu_times.sort_by(f64::total_cmp);
    let blas = blas.unwrap();
    times.sort_by(f64::total_cmp);
    let s = &blas.stats;
    println!(
        "terrain: {} triangles ({} skipped), {} vertices",
        s.triangles,
        s.skipped(),
        mesh.positions.len()
    );
    println!(
        "build ({} threads): min {:.1} ms, median {:.1} ms over {} runs",
        if threads == 0 {
            rayon::current_num_threads()
        } else {
            threads
        },
        times[0],
        times[times.len() / 2],
        times.len()
    );
    if let Some(c) = cpu_times.first() {
        // Other processes on a shared machine stretch wall time; CPU time is what the build costs.
        println!("build CPU time (all threads): min {c:.1} ms");
    }
    println!(
        "  fastest of each phase: validate {:.1} ms, binary SAH {:.1} ms, collapse {:.1} ms, triangles {:.1} ms",
        phase_min[0], phase_min[1], phase_min[2], phase_min[3]
    );
    let node_bytes = std::mem::size_of_val(blas.nodes.as_slice());
    let tri_bytes = std::mem::size_of_val(blas.triangles.as_slice());
    println!(
        "nodes: {} ({:.2} MiB), triangles: {:.2} MiB, total GPU {:.2} MiB, depth {}",
        s.nodes,
        node_bytes as f64 / (1 << 20) as f64,
        tri_bytes as f64 / (1 << 20) as f64,
        blas.gpu_bytes() as f64 / (1 << 20) as f64,
        s.depth
    );
    let mut leaves = 0usize;
    let mut internal = 0usize;
    for node in &blas.nodes {
        for slot in 0..8 {
            match node.slot_kind(slot) {
                hikari_bvh::layout::SlotKind::Leaf { .. } => leaves += 1,
                hikari_bvh::layout::SlotKind::Internal(_) => internal += 1,
                hikari_bvh::layout::SlotKind::Empty => {}
            }
        }
    }
    println!(
        "  {:.2} children per node ({:.2} leaves), {:.2} triangles per leaf",
        (leaves + internal) as f64 / s.nodes as f64,
        leaves as f64 / s.nodes as f64,
        s.triangles as f64 / leaves as f64
    );
    println!(
        "  {:.2} triangles per node, {:.1} bytes of nodes per triangle",
        s.triangles as f64 / s.nodes as f64,
        node_bytes as f64 / s.triangles as f64
    );
    let sah = hikari_bvh::sah_cost(&blas.nodes);
    println!(
        "  SAH cost {:.2} (node 1, triangle 1, areas of the decoded child boxes relative to \
         the root's), internal node area sum {:.2}",
        sah.total(),
        sah.nodes
    );
    if ray_count == 0 {
        return;
    }

    // Incoherent rays as in the bench: surface points 1 cm up, cosine directions around +y.
    let mut rng = SplitMix64::new(7);
    let n = ray_count;
    let rays: Vec<Ray> = (0..n)
        .map(|_| {
            let x = rng.range(-90.0, 90.0);
            let z = rng.range(-90.0, 90.0);
            let y = hikari_bvh::mesh::terrain_height(x, z) + 0.01;
            let u1 = rng.next_f32();
            let u2 = rng.next_f32();
            let r = u1.sqrt();
            let phi = std::f32::consts::TAU * u2;
            let d = Vec3::new(r * phi.cos(), (1.0 - u1).max(0.0).sqrt(), r * phi.sin());
            Ray::new(Vec3::new(x, y, z), d, 0.0, f32::INFINITY)
        })
        .collect();
    let mut stack = hikari_bvh::Stack::default();
    let t0 = Instant::now();
    let hits = rays
        .iter()
        .filter(|r| blas.intersect_with(r, &mut stack).is_some())
        .count();
    let dt = t0.elapsed().as_secs_f64();
    println!(
        "  closest hit: {:.2} nodes and {:.2} triangles per ray",
        stack.nodes_visited as f64 / n as f64,
        stack.prims_tested as f64 / n as f64
    );
    println!(
        "CPU closest hit, 1 thread: {} rays, {:.1}% hit, {:.2} Mrays/s",
        n,
        100.0 * hits as f64 / n as f64,
        n as f64 / dt / 1e6
    );
    let mut stack = hikari_bvh::Stack::default();
    let t0 = Instant::now();
    let occluded = rays
        .iter()
        .filter(|r| blas.occluded_with(&Ray { t_max: 5.0, ..**r }, &mut stack))
        .count();
    let dt = t0.elapsed().as_secs_f64();
    println!(
        "  any hit: {:.2} nodes and {:.2} triangles per ray",
        stack.nodes_visited as f64 / n as f64,
        stack.prims_tested as f64 / n as f64
    );
    println!(
        "CPU any hit (5 m), 1 thread: {:.1}% occluded, {:.2} Mrays/s",
        100.0 * occluded as f64 / n as f64,
        n as f64 / dt / 1e6
    );
}

/// TLAS rebuild over `count` instances of a few small BLAS scattered over the terrain: the
/// per-frame cost after culling.
fn tlas_rebuild(count: usize) {
    let blases: Vec<Blas> = (0..4)
        .map(|i| {
            Blas::from_mesh(
                "prop",
                &Mesh::random_soup(100 + i, 200, 1.0, 0.8),
                &BuildOptions::default(),
            )
            .unwrap()
        })
        .collect();
    let mut rng = SplitMix64::new(3);
    let instances: Vec<Instance> = (0..count)
        .map(|i| {
            let t = Vec3::new(rng.range(-90.0, 90.0), 0.0, rng.range(-90.0, 90.0));
            let r = glam::Quat::from_rotation_y(rng.range(0.0, 6.0));
            Instance::new(
                glam::Affine3A::from_rotation_translation(r, t),
                (i % blases.len()) as u32,
            )
        })
        .collect();
    let all: Vec<u32> = (0..count as u32).collect();
    // As the bench does: a fresh `Tlas::build` per frame, the previous TLAS dropped.
    let mut times = Vec::new();
    let mut tlas = Tlas::default();
    for _ in 0..1000 {
        let t0 = Instant::now();
        tlas = Tlas::build(&instances, &all, &blases).unwrap();
        times.push(t0.elapsed().as_secs_f64() * 1e6);
    }
    times.sort_by(f64::total_cmp);
    let sah = hikari_bvh::sah_cost(&tlas.nodes);
    println!(
        "TLAS rebuild, {} instances: median {:.1} us, min {:.1} us over {} rebuilds, {} nodes, depth {}, {:.1} KiB, \
         SAH cost {:.3} (nodes {:.3} + instances {:.3})",
        count,
        times[times.len() / 2],
        times[0],
        times.len(),
        tlas.stats.nodes,
        tlas.stats.depth,
        tlas.gpu_bytes() as f64 / 1024.0,
        sah.total(),
        sah.nodes,
        sah.prims
    );
}

/// CPU time of this process (all threads) from /proc, in ns; None where /proc is missing.
fn process_cpu_ns() -> Option<u64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the parenthesised command name; utime and stime are fields 14 and 15.
    let rest = &stat[stat.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: u64 = f.get(11)?.parse::<u64>().ok()? + f.get(12)?.parse::<u64>().ok()?;
    // USER_HZ is 100 on every Linux we run on.
    Some(ticks * 10_000_000)
}
