//! The irradiance probes: the relight pass and the lookup on the GPU against their CPU twins
//! (`irradiance_probes::reference`, on hikari-math's SH product, convolution, boost and
//! deringing), tetrahedral point location and interior weights against brute force, the
//! upload's NaN guard, and the update budget. A synthetic sky SH and a small synthetic bake
//! (two grid tiles and a mesh of 2x2x2 cubes split into 6 tetrahedra each) keep the CPU
//! driver fast.

use crate::common;

use common::probes::{kuhn_mesh, synthetic_bake, synthetic_sky, tile};

use glam::Vec3;
use hikari_math::sh::{Sh, ShL2Rgb};
use hikari_probes::{Bake, BakeSettings, GridTile, HULL, ProbeSh, SceneKey, TILE_PROBE_COUNT};
use hikari_render::graph::GraphRuntime;
use hikari_render::pipeline::ComputePipeline;
use hikari_render::shader;
use hikari_render::techniques::clouds::{self, CloudParams, settings::CloudsSettings};
use hikari_render::techniques::irradiance_probes::gpu_data::{
    PROBES_INTERIOR_MASK, PROBES_PRESENT, ProbeGpuData, ProbeLookupParams,
};
use hikari_render::techniques::irradiance_probes::settings::IrradianceProbesSettings;
use hikari_render::techniques::irradiance_probes::{RelightParams, budget, gaunt_table, reference};
use hikari_render::wgpu::{self, util::DeviceExt};
use rand::rngs::SmallRng;
use rand::{Rng, SeedableRng};

fn buffer(ctx: &hikari_render::GpuContext, name: &str, bytes: &[u8]) -> wgpu::Buffer {
    ctx.device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(name),
            contents: bytes,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        })
}

fn sh_of(v: &[[f32; 4]]) -> ShL2Rgb {
    Sh::new(std::array::from_fn(|k| Vec3::from_slice(&v[k][..3])))
}

/// Runs `relight.wgsl` over every probe of `data` and returns the irradiance buffer.
fn run_relight(
    ctx: &hikari_render::GpuContext,
    pipeline: &ComputePipeline,
    data: &ProbeGpuData,
    sky: &ShL2Rgb,
    params: &RelightParams,
    clouds: Option<CloudParams>,
) -> Vec<[f32; 4]> {
    let all = budget::FrameWork {
        tiles: (0..data.tiles.len()).collect(),
        meshes: (0..data.meshes.len()).collect(),
    };
    let chunks = budget::chunks(data, &all);
    let mut sky_buf = [[0.0f32; 4]; 18];
    for (b, c) in sky_buf.iter_mut().zip(&sky.coeffs) {
        *b = c.extend(0.0).to_array();
    }
    let sky_b = buffer(ctx, "sky.sh", bytemuck::cast_slice(&sky_buf));
    let gaunt = buffer(ctx, "gaunt", bytemuck::cast_slice(&gaunt_table()));
    let chunk_b = buffer(ctx, "chunks", bytemuck::cast_slice(&chunks));
    let probes = buffer(ctx, "probes", bytemuck::cast_slice(&data.probe_data));
    let out = buffer(ctx, "irradiance", &vec![0u8; data.probe_data.len() * 16]);
    let positions = buffer(ctx, "positions", bytemuck::cast_slice(&data.positions));
    let mut p = *params;
    p.config[0] = chunks.len() as u32;
    let mut rt = GraphRuntime::new();
    let mut g = rt.begin_frame(ctx);
    let sky_b = g.import_buffer("sky.sh", &sky_b);
    let gaunt = g.import_buffer("gaunt", &gaunt);
    let chunk_b = g.import_buffer("chunks", &chunk_b);
    let probes = g.import_buffer("probes", &probes);
    let out = g.import_buffer("irradiance_probes.irradiance", &out);
    let positions = g.import_buffer("positions", &positions);
    let clouds = match clouds {
        Some(c) => clouds::shadow_lookup(&mut g, c).unwrap(),
        None => clouds::disabled_lookup(&mut g).unwrap(),
    };
    g.pass("irradiance_probes.relight")
        .constants(&p)
        .read(sky_b)
        .read(gaunt)
        .read(chunk_b)
        .read(probes)
        .write(out)
        .read(positions)
        .set(clouds)
        .dispatch(pipeline, [chunks.len() as u32, 1, 1])
        .unwrap();
    g.readback(out);
    let r = g.execute().unwrap();
    bytemuck::pod_collect_to_vec(r.buffer("irradiance_probes.irradiance").unwrap())
}

fn settings_with(f: impl FnOnce(&mut IrradianceProbesSettings)) -> IrradianceProbesSettings {
    let mut s = IrradianceProbesSettings::default();
    f(&mut s);
    s
}

/// The relight pass against `reference::relight_probe` for every probe of the synthetic bake,
/// with each part on and off. Tolerance: 2e-3 of the probe's largest band-0 coefficient (f32
/// sums in another order; deringing's Newton steps). With deringing on, the window strength
/// is a choice among eight: at most 1 % of probes may land on the neighbouring strength,
/// within 15 % of their band-0 coefficient.
#[test]
fn relight_matches_the_cpu_twin() {
    let ctx = common::gpu_context();
    let mut lib = shader::library(shader::capabilities_for(ctx.features)).unwrap();
    let pipeline = ComputePipeline::new(
        &ctx,
        &mut lib,
        "irradiance_probes/relight.wgsl",
        "main",
        &[],
    )
    .unwrap();
    let data = ProbeGpuData::new(&synthetic_bake(17));
    let mut rng = SmallRng::seed_from_u64(0x1E1_1600);
    let sun = hikari_scene::Sun {
        direction: Vec3::new(0.5, 0.6, -0.3).normalize(),
        illuminance_lux: 90_000.0,
        color: Vec3::new(1.0, 0.95, 0.85),
    };
    // Clouds over the probes, whose shadow darkens the sun bounce (twin:
    // clouds::reference::cloud_shadow_at at each probe).
    let overcast = CloudParams::new(
        &CloudsSettings {
            coverage: 0.7,
            ..CloudsSettings::default()
        },
        "clear",
        Some(&sun),
        0.0,
        true,
    );
    let shade = |p: Vec3| clouds::reference::cloud_shadow_at(&overcast, p);
    let mean_shade = data
        .positions
        .iter()
        .map(|p| shade(Vec3::from_slice(&p[..3])))
        .sum::<f32>()
        / data.positions.len() as f32;
    assert!(
        mean_shade < 0.9,
        "the clouds should shadow the probes: {mean_shade}"
    );
    let cases = [
        ("everything", settings_with(|_| {})),
        ("everything under clouds", settings_with(|_| {})),
        ("no dering", settings_with(|s| s.dering = false)),
        (
            "no boost, no dering",
            settings_with(|s| {
                s.boost = false;
                s.dering = false;
            }),
        ),
        (
            "sky only",
            settings_with(|s| {
                s.bounce = false;
                s.sun_bounce = false;
                s.boost = false;
                s.dering = false;
            }),
        ),
    ];
    for (name, s) in cases {
        let sky = synthetic_sky(&mut rng);
        let params = RelightParams::new(Some(&sun), &s, 0);
        let clouded = name.ends_with("under clouds");
        let gpu = run_relight(
            &ctx,
            &pipeline,
            &data,
            &sky,
            &params,
            clouded.then_some(overcast),
        );
        let cpu = if clouded {
            reference::relight_all_shadowed(&data, &sky, &params, &shade)
        } else {
            reference::relight_all(&data, &sky, &params)
        };
        let mut outliers = 0;
        let mut worst = 0.0f32;
        for (p, want) in cpu.iter().enumerate() {
            let got = sh_of(&gpu[p * 9..p * 9 + 9]);
            let scale = want.coeffs[0].abs().max_element().max(1.0);
            let err = (0..9)
                .map(|k| (got.coeffs[k] - want.coeffs[k]).abs().max_element())
                .fold(0.0f32, f32::max)
                / scale;
            assert!(err.is_finite(), "{name}: probe {p} not finite");
            if err > 2e-3 {
                outliers += 1;
                assert!(
                    s.dering && err < 0.15,
                    "{name}: probe {p}: relative error {err}: gpu {got:?} cpu {want:?}"
                );
            } else {
                worst = worst.max(err);
            }
        }
        assert!(
            outliers * 100 <= cpu.len(),
            "{name}: {outliers} of {} probes off by more than 2e-3",
            cpu.len()
        );
        eprintln!("{name}: worst relative error {worst:.2e}, {outliers} dering outliers");
    }
}

/// The relight's physics in closed form: an open-sky probe (visibility = the SH of 1) under a
/// constant sky L has irradiance pi L on every normal; a probe with zero visibility and no
/// bounce has none.
#[test]
fn relight_of_open_and_closed_probes_in_closed_form() {
    let s = settings_with(|s| {
        s.bounce = false;
        s.sun_bounce = false;
    });
    let params = RelightParams::new(None, &s, 0);
    let l = Vec3::new(1000.0, 2000.0, 3000.0);
    let c0 = 2.0 * std::f32::consts::PI.sqrt();
    let sky: ShL2Rgb = Sh::new(std::array::from_fn(|k| {
        if k == 0 { l * c0 } else { Vec3::ZERO }
    }));
    let open = Sh::new(std::array::from_fn(|k| if k == 0 { c0 } else { 0.0 }));
    let e = reference::relight_probe(&sky, &open, &ShL2Rgb::zero(), &params);
    for n in [
        Vec3::X,
        Vec3::Y,
        Vec3::NEG_Y,
        Vec3::new(0.3, -0.5, 0.8).normalize(),
    ] {
        let got = e.eval(n);
        let want = std::f32::consts::PI * l;
        assert!(
            (got - want).abs().max_element() < 1e-3 * want.max_element(),
            "{got} vs {want}"
        );
    }
    let closed = reference::relight_probe(&sky, &Sh::zero(), &ShL2Rgb::zero(), &params);
    assert!(closed.coeffs.iter().all(|c| c.abs().max_element() < 1e-6));
}

/// The lookup (`hikari::irradiance_probes` through `lookup_check.wgsl`) against
/// `reference::irradiance_at`, at random points in and around the mesh and over the grid,
/// with random normals and masks; tolerance 1e-3 of the value (plus 1e-3 lux).
/// Runs `lookup_check.wgsl` at `queries` (two vec4 per point: position, normal and mask).
fn gpu_lookup(
    ctx: &hikari_render::GpuContext,
    pipeline: &ComputePipeline,
    data: &ProbeGpuData,
    lp: &ProbeLookupParams,
    flat: &[[f32; 4]],
    queries: &[[f32; 4]],
) -> Vec<[f32; 4]> {
    let count = queries.len() / 2;
    let q = buffer(ctx, "queries", bytemuck::cast_slice(queries));
    let out = buffer(ctx, "results", &vec![0u8; count * 16]);
    let irr = buffer(ctx, "irradiance", bytemuck::cast_slice(flat));
    let pos = buffer(ctx, "positions", bytemuck::cast_slice(&data.positions));
    let topo = buffer(ctx, "topology", bytemuck::cast_slice(&data.topology));
    let mut rt = GraphRuntime::new();
    let mut g = rt.begin_frame(ctx);
    let (q, out) = (
        g.import_buffer("queries", &q),
        g.import_buffer("results", &out),
    );
    let irr = g.import_buffer("irradiance", &irr);
    let pos = g.import_buffer("positions", &pos);
    let topo = g.import_buffer("topology", &topo);
    let set = g
        .binding_set("irradiance_probes")
        .constants(lp)
        .read(irr)
        .read(pos)
        .read(topo)
        .finish();
    g.pass("test.lookup")
        .read(q)
        .write(out)
        .set(set)
        .dispatch_threads(pipeline, [count as u32, 1, 1])
        .unwrap();
    g.readback(out);
    let r = g.execute().unwrap();
    let got: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(r.buffer("results").unwrap());
    got
}

#[test]
fn lookup_matches_the_cpu_twin() {
    let ctx = common::gpu_context();
    let mut lib = shader::library(shader::capabilities_for(ctx.features)).unwrap();
    let pipeline = ComputePipeline::new(
        &ctx,
        &mut lib,
        "irradiance_probes/lookup_check.wgsl",
        "main",
        &[],
    )
    .unwrap();
    let data = ProbeGpuData::new(&synthetic_bake(5));
    let mut rng = SmallRng::seed_from_u64(99);
    let sky = synthetic_sky(&mut rng);
    let params = RelightParams::new(None, &IrradianceProbesSettings::default(), 0);
    let irradiance = reference::relight_all(&data, &sky, &params);
    let flat: Vec<[f32; 4]> = irradiance
        .iter()
        .flat_map(|sh| sh.coeffs.map(|c| c.extend(0.0).to_array()))
        .collect();
    let mut queries = Vec::new();
    let mut points = Vec::new();
    for i in 0..512 {
        let p = if i % 2 == 0 {
            Vec3::new(
                rng.random_range(38.0..52.0),
                rng.random_range(0.0..14.0),
                rng.random_range(48.0..62.0),
            )
        } else {
            Vec3::new(
                rng.random_range(-20.0..420.0),
                rng.random_range(-5.0..40.0),
                rng.random_range(-20.0..220.0),
            )
        };
        let n = Vec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        )
        .normalize_or(Vec3::Y);
        let mask = [0.0, 1.0, 0.5, rng.random_range(0.0..1.0)][i % 4];
        queries.push(p.extend(0.0).to_array());
        queries.push(n.extend(mask).to_array());
        points.push((p, n, mask));
    }
    for interior_mask in [true, false] {
        let mut lp: ProbeLookupParams = data.params;
        lp.grid[3] = 0.8;
        if interior_mask {
            lp.grid_size[3] |= PROBES_INTERIOR_MASK;
        }
        let got = gpu_lookup(&ctx, &pipeline, &data, &lp, &flat, &queries);
        let mut covered = 0;
        for (i, (p, n, mask)) in points.iter().enumerate() {
            let want = reference::irradiance_at(&data, &lp, &irradiance, *p, *n, *mask);
            let g4 = got[i];
            match want {
                None => assert_eq!(g4, [0.0; 4], "point {p}: the twin finds no probe"),
                Some(e) => {
                    covered += 1;
                    assert_eq!(g4[3], 1.0, "point {p}: the GPU finds no probe");
                    let d = (Vec3::from_slice(&g4[..3]) - e).abs().max_element();
                    assert!(
                        d <= 1e-3 * e.max_element() + 1e-3,
                        "point {p} n {n} mask {mask}: gpu {g4:?} cpu {e}"
                    );
                }
            }
        }
        assert!(covered > 300, "only {covered} of the points are covered");
    }
}

/// Walking the adjacency finds a tetrahedron holding the point whenever brute force over all
/// tetrahedra finds one (and none when it finds none), and the interpolated, interior-masked
/// value agrees with brute force's: barycentrics from a direct 4x4 solve, weights times w for
/// interior probes and 1 - w for exterior ones, renormalised, the plain barycentrics where
/// that leaves nothing.
#[test]
fn point_location_and_interior_weights_match_brute_force() {
    let bake = synthetic_bake(3);
    let data = ProbeGpuData::new(&bake);
    let mesh = &bake.meshes[0];
    let slot = data.meshes[0];
    let value = |p: usize| (p as f32 * 0.37).sin();
    let mut rng = SmallRng::seed_from_u64(4);
    let (mut inside, mut outside) = (0, 0);
    for _ in 0..4000 {
        let p = Vec3::new(
            rng.random_range(39.0..51.0),
            rng.random_range(1.0..13.0),
            rng.random_range(49.0..61.0),
        );
        let mask: f32 = [0.0, 1.0, rng.random_range(0.0..1.0)][rng.random_range(0..3)];
        // Brute force: every tetrahedron, barycentrics by Gaussian elimination in f64.
        let mut found = None;
        for tet in &mesh.tets {
            let v: Vec<glam::DVec3> = tet
                .iter()
                .map(|&i| glam::DVec3::from(mesh.positions[i as usize].map(f64::from)))
                .collect();
            let m = glam::DMat3::from_cols(v[0] - v[3], v[1] - v[3], v[2] - v[3]);
            let b = m.inverse() * (p.as_dvec3() - v[3]);
            let bary = [b.x, b.y, b.z, 1.0 - b.x - b.y - b.z];
            if bary.iter().all(|&x| x >= -1e-9) {
                found = Some((*tet, bary));
                break;
            }
        }
        let walked = reference::locate(&data, 0, p);
        match found {
            None => {
                outside += 1;
                assert!(
                    walked.is_none(),
                    "{p}: the walk found a tetrahedron brute force did not"
                );
            }
            Some((tet, bary)) => {
                inside += 1;
                assert!(
                    walked.is_some(),
                    "{p}: the walk lost a point inside tetrahedra"
                );
                let masked: Vec<f64> = (0..4)
                    .map(|k| {
                        let interior = mesh.interior[tet[k] as usize];
                        bary[k].max(0.0) * f64::from(if interior { mask } else { 1.0 - mask })
                    })
                    .collect();
                let sum: f64 = masked.iter().sum();
                let weights: Vec<f64> = if sum > 1e-6 {
                    masked.iter().map(|w| w / sum).collect()
                } else {
                    bary.iter().map(|w| w.max(0.0)).collect()
                };
                let want: f64 = (0..4)
                    .map(|k| weights[k] * f64::from(value(tet[k] as usize)))
                    .sum();
                let w = reference::mesh_weights(&data, 0, p).unwrap();
                let w = reference::masked_weights(&w, &data, mask);
                let got: f32 = w
                    .iter()
                    .map(|&(g, wk)| wk * value((g - slot.first_probe) as usize))
                    .sum();
                assert!(
                    (f64::from(got) - want).abs() < 1e-4,
                    "{p} mask {mask}: walked {got} brute force {want}"
                );
            }
        }
    }
    assert!(
        inside > 2000 && outside > 500,
        "{inside} inside, {outside} outside"
    );
}

/// NaN and Inf in a bake (possible in memory; files with them are refused) become 0 at upload.
#[test]
fn non_finite_numbers_in_a_bake_become_zero() {
    let mut bake = synthetic_bake(8);
    bake.tiles[0].probes[5].sky_visibility[2] = f32::NAN;
    bake.tiles[1].probes[0].bounced_sky_visibility[4][1] = f32::INFINITY;
    bake.tiles[0].ground_heights_m[3] = f32::NEG_INFINITY;
    bake.meshes[0].probes[2].sky_visibility[0] = f32::NAN;
    let data = ProbeGpuData::new(&bake);
    // The infinite ground height reaches the three layers of its column.
    assert_eq!(data.replaced_non_finite, 6);
    assert!(data.probe_data.iter().flatten().all(|x| x.is_finite()));
    assert!(data.positions.iter().flatten().all(|x| x.is_finite()));
    assert_eq!(data.probe_data[5 * 9 + 2][3], 0.0);
    assert_eq!(data.probe_data[(TILE_PROBE_COUNT) * 9 + 4][1], 0.0);
    let mesh_probe = data.meshes[0].first_probe as usize + 2;
    assert_eq!(data.probe_data[mesh_probe * 9][3], 0.0);
    let sky = synthetic_sky(&mut SmallRng::seed_from_u64(1));
    let params = RelightParams::new(None, &IrradianceProbesSettings::default(), 0);
    for sh in reference::relight_all(&data, &sky, &params) {
        assert!(sh.coeffs.iter().all(|c| c.is_finite()));
    }
    assert_ne!(data.params.grid_size[3] & PROBES_PRESENT, 0);
}

/// The talk's budget: everything on the first relight; afterwards the round robin's tiles plus
/// the 3x3 around the camera, one mesh a frame, and every tile within ceil(tiles / per) frames.
#[test]
fn the_update_budget_follows_the_talk() {
    let mut rng = SmallRng::seed_from_u64(2);
    let settings = BakeSettings::with_rays(8);
    let mut bake = Bake::new(SceneKey::default(), settings);
    for z in 0..10 {
        for x in 0..10 {
            bake.tiles
                .push(tile(&mut rng, [x, z], settings.grid_spacing_m));
        }
    }
    bake.meshes.push(kuhn_mesh(&mut rng, Vec3::ZERO, 1.0, 1));
    bake.meshes
        .push(kuhn_mesh(&mut rng, Vec3::ONE * 3.0, 1.0, 1));
    let data = ProbeGpuData::new(&bake);
    let s = IrradianceProbesSettings {
        tiles_per_frame: 16,
        ..Default::default()
    };
    let first = budget::frame_work(&data, 0, [0.0, 0.0], &s);
    assert_eq!((first.tiles.len(), first.meshes.len()), (100, 2));
    // The camera over tile (4, 6): its 3x3 neighbours are always in.
    let cam = data.tiles[6 * 10 + 4].centre_xz;
    let mut seen = [false; 100];
    for update in 1..=7u64 {
        let w = budget::frame_work(&data, update, cam, &s);
        assert_eq!(w.meshes, vec![(update % 2) as usize]);
        for dz in -1..=1i32 {
            for dx in -1..=1i32 {
                let t = ((6 + dz) * 10 + 4 + dx) as usize;
                assert!(
                    w.tiles.contains(&t),
                    "update {update}: camera tile {t} missing"
                );
            }
        }
        assert!(w.tiles.len() <= 16 + 9);
        for t in w.tiles {
            seen[t] = true;
        }
    }
    assert!(
        seen.iter().all(|&s| s),
        "the round robin missed tiles in 7 frames"
    );
    let chunks = budget::chunks(&data, &first);
    let total: u32 = chunks.iter().map(|c| c[1]).sum();
    assert_eq!(total as usize, data.probe_count());
    assert!(chunks.iter().all(|c| c[1] >= 1 && c[1] <= budget::CHUNK));
}

/// A bake that covers `scene` with one tile (spacing stretched to fit) whose probes all have
/// visibility `visibility` (an SH of a constant) and no bounce.
fn covering_bake(scene: &hikari_scene::Scene, visibility: f32) -> Bake {
    let (lo, hi) = scene.bounds().unwrap();
    let extent = (hi - lo).max_element() + 4.0;
    let mut settings = BakeSettings::with_rays(1);
    settings.grid_spacing_m = extent / 15.0;
    settings.layer_heights_m = [0.0, 0.5 * extent, extent];
    let mut bake = Bake::new(SceneKey::default(), settings);
    let mut probe = ProbeSh::default();
    probe.sky_visibility[0] = visibility * 2.0 * std::f32::consts::PI.sqrt();
    bake.tiles.push(GridTile {
        tile: [0, 0],
        origin_xz: [lo.x - 2.0, lo.z - 2.0],
        ground_heights_m: vec![lo.y - 2.0; 256],
        probes: vec![probe; TILE_PROBE_COUNT],
        interior: vec![false; TILE_PROBE_COUNT],
    });
    bake.complete = true;
    bake
}

/// The frame with a bake: the first frame relights every probe as the twin does from the
/// frame's own sky SH (read back), and surfaces take their ambient light from the probes: a
/// bake of closed probes (no sky visible, no bounce) darkens every lit pixel that only ambient
/// light reaches, and an open bake (visibility 1) lights the frame about as the unoccluded
/// sky's SH does (within 15 %: the two dering different functions).
#[test]
fn the_frame_takes_ambient_light_from_the_probes() {
    let ctx = common::gpu_context();
    let scene = hikari_scene::builtin::boxes();
    let mut fs = common::small_frame_settings(&scene, 64, 48);
    // One renderer draws three different lightings in a row: TAA would blend them.
    fs.settings.taa.enabled = false;
    fs.settings.sky.enabled = true;
    fs.settings.sky.table_quality = 0;
    fs.settings.sky.ambient_specular_scale = 0.0;
    fs.settings.direct_lighting.sun = false;
    fs.settings.direct_lighting.punctual = false;
    fs.settings.direct_lighting.emissive = false;
    fs.settings.irradiance_probes.sun_bounce = false;
    fs.settings.irradiance_probes.boost = false;
    let mut r = hikari_render::Renderer::new(ctx, &scene).unwrap();
    r.runtime.set_dumps(vec![
        "sky.sh".into(),
        "irradiance_probes.irradiance".into(),
        "gbuffer.depth".into(),
        "irradiance_probes.pixels".into(),
    ]);
    let mut render = |bake: Option<&Bake>| {
        r.set_probe_bake(bake).unwrap();
        let f = r.render(&fs, true).unwrap();
        let hdr = f.hdr.unwrap();
        let sky: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(f.result.buffer("sky.sh").unwrap());
        let irr: Vec<[f32; 4]> =
            bytemuck::pod_collect_to_vec(f.result.buffer("irradiance_probes.irradiance").unwrap());
        let depth = f.result.image("gbuffer.depth").unwrap().clone();
        // The per-pixel dump: covered (alpha 1) exactly where there is a surface, once a bake
        // is there; black where the probes see no sky.
        if let Some(b) = bake {
            let pixels = f.result.image("irradiance_probes.pixels").unwrap();
            let open = b.tiles[0].probes[0].sky_visibility[0] > 0.0;
            for y in 0..48 {
                for x in 0..64 {
                    let e = pixels.pixel(x, y);
                    let surface = depth.pixel(x, y)[0] > 0.0;
                    assert_eq!(e[3], if surface { 1.0 } else { 0.0 }, "pixel {x},{y}");
                    if surface {
                        assert_eq!(open, e[0] + e[1] + e[2] > 0.0, "pixel {x},{y}: {e:?}");
                    }
                }
            }
        }
        let px: Vec<(Vec3, bool)> = (0..48)
            .flat_map(|y| (0..64).map(move |x| (x, y)))
            .map(|(x, y)| {
                (
                    Vec3::from_slice(&hdr.pixel(x, y)[..3]),
                    depth.pixel(x, y)[0] > 0.0,
                )
            })
            .collect();
        (px, sky, irr)
    };
    let (plain, _, _) = render(None);
    let closed_bake = covering_bake(&scene, 0.0);
    let (closed, _, _) = render(Some(&closed_bake));
    let open_bake = covering_bake(&scene, 1.0);
    let (open, sky, irr) = render(Some(&open_bake));

    // The relit buffer against the twin, from the sky SH the frame used (raw coefficients).
    let data = ProbeGpuData::new(&open_bake);
    let sky_sh = sh_of(&sky[..9]);
    let params = RelightParams::new(None, &fs.settings.irradiance_probes, 0);
    let want = reference::relight_all(&data, &sky_sh, &params);
    for (p, w) in want.iter().enumerate() {
        let got = sh_of(&irr[p * 9..p * 9 + 9]);
        let scale = w.coeffs[0].abs().max_element().max(1.0);
        for k in 0..9 {
            let d = (got.coeffs[k] - w.coeffs[k]).abs().max_element();
            assert!(
                d <= 2e-3 * scale,
                "probe {p} coefficient {k}: {got:?} vs {w:?}"
            );
        }
    }

    let surfaces: Vec<usize> = (0..plain.len()).filter(|&i| plain[i].1).collect();
    assert!(
        surfaces.len() > 200,
        "too few surface pixels: {}",
        surfaces.len()
    );
    let lum = |c: Vec3| c.dot(Vec3::new(0.2126, 0.7152, 0.0722));
    let (mut sum_plain, mut sum_open) = (0.0f64, 0.0f64);
    for &i in &surfaces {
        assert!(
            lum(closed[i].0) <= 1e-3 * lum(plain[i].0) + 1e-3,
            "pixel {i}: closed probes still light it: {} vs {}",
            closed[i].0,
            plain[i].0
        );
        sum_plain += f64::from(lum(plain[i].0));
        sum_open += f64::from(lum(open[i].0));
    }
    assert!(sum_plain > 0.0);
    let ratio = sum_open / sum_plain;
    // Not equal: the sky's ambient derings the sky's radiance SH, the probes their irradiance
    // SH (a weaker window, so more contrast between up and down); a lost factor (pi, the
    // weather's balance) or a missing lookup would be far outside this.
    assert!(
        (ratio - 1.0).abs() < 0.15,
        "open probes vs the unoccluded sky: ratio {ratio}"
    );
}

/// The grid's weights reproduce any function linear in x, y and z exactly (bilinear across
/// columns, linear along each column between its own layer heights, whatever the ground under
/// each column), at random points inside the grid; and they sum to 1.
#[test]
fn grid_weights_reproduce_linear_functions() {
    let data = ProbeGpuData::new(&synthetic_bake(11));
    let f = |p: Vec3| 3.0 + 0.7 * p.x - 1.3 * p.y + 0.4 * p.z;
    let [x0, z0, spacing, _] = data.params.grid;
    let (cols_x, cols_z) = (data.params.grid_size[0], data.params.grid_size[1]);
    let mut rng = SmallRng::seed_from_u64(12);
    for _ in 0..2000 {
        let p = Vec3::new(
            x0 + rng.random_range(0.0..(cols_x - 1) as f32 * spacing),
            // Above every column's lowest layer (ground < 4 m, + 1.5 m) and below its highest.
            rng.random_range(5.6..29.9),
            z0 + rng.random_range(0.0..(cols_z - 1) as f32 * spacing),
        );
        let w = reference::grid_weights(&data, p);
        let sum: f32 = w.iter().map(|x| x.1).sum();
        assert!((sum - 1.0).abs() < 1e-5, "{p}: weights sum to {sum}");
        let got: f32 = w
            .iter()
            .map(|&(k, wk)| wk * f(Vec3::from_slice(&data.positions[k as usize][..3])))
            .sum();
        assert!((got - f(p)).abs() < 2e-3, "{p}: {got} vs {}", f(p));
    }
}

/// A point on a face of the synthetic mesh's bounds (the cube (40, 2, 50) + [0, 10]³) and
/// that face's inward normal.
fn point_on_mesh_face(rng: &mut SmallRng) -> (Vec3, Vec3) {
    let (lo, hi) = (Vec3::new(40.0, 2.0, 50.0), Vec3::new(50.0, 12.0, 60.0));
    let axis = rng.random_range(0..3);
    let upper = rng.random_bool(0.5);
    let mut p = Vec3::new(
        rng.random_range(lo.x + 0.5..hi.x - 0.5),
        rng.random_range(lo.y + 0.5..hi.y - 0.5),
        rng.random_range(lo.z + 0.5..hi.z - 0.5),
    );
    p[axis] = if upper { hi[axis] } else { lo[axis] };
    let mut inward = Vec3::ZERO;
    inward[axis] = if upper { -1.0 } else { 1.0 };
    (p, inward)
}

/// The mesh blends into the grid at its bounds: on the CPU twin, the interpolated value is
/// continuous across every face of the mesh's bounds (a jump of the mesh's and the grid's
/// difference without the blend), is the mesh's alone deeper than the margin, and in the
/// margin is `a` x mesh + (1 - a) x grid with `a` the depth over the margin (computed here
/// from the cube's known corners); on the GPU, irradiance in the margin matches the twin and
/// is continuous across the faces too.
#[test]
fn the_mesh_blends_into_the_grid_at_its_bounds() {
    let data = ProbeGpuData::new(&synthetic_bake(11));
    let value = |p: u32| (p as f32 * 0.37).sin();
    // A masked, renormalised mean of `value` over weights `w`.
    let mean = |w: &[(u32, f32)], mask: f32| -> f32 {
        let w = reference::masked_weights(w, &data, mask);
        w.iter().map(|&(k, wk)| wk * value(k)).sum()
    };
    let field = |p: Vec3, mask: f32| -> f32 {
        let w = reference::blended_weights(&data, p, mask);
        w.iter().map(|&(k, wk)| wk * value(k)).sum()
    };
    let mut rng = SmallRng::seed_from_u64(12);
    let mut largest_mesh_grid_gap = 0.0f32;
    for i in 0..600 {
        let mask = [0.0, 1.0, 0.5, 0.3][i % 4];
        let (on, inward) = point_on_mesh_face(&mut rng);
        let inside = on + 1e-3 * inward;
        let outside = on - 1e-3 * inward;
        let (fi, fo) = (field(inside, mask), field(outside, mask));
        assert!(
            (fi - fo).abs() < 5e-3,
            "{on} mask {mask}: {fi} inside, {fo} outside"
        );
        let mesh_only = mean(&reference::mesh_weights(&data, 0, inside).unwrap(), mask);
        largest_mesh_grid_gap = largest_mesh_grid_gap.max((mesh_only - fo).abs());

        let depth: f32 = rng.random_range(0.0..1.5);
        let p = on + depth * inward;
        let grid = mean(&reference::grid_weights(&data, p), mask);
        let mesh = mean(&reference::mesh_weights(&data, 0, p).unwrap(), mask);
        // The depth below the nearest face (maybe not the one `p` was pushed in from).
        let (lo, hi) = (Vec3::new(40.0, 2.0, 50.0), Vec3::new(50.0, 12.0, 60.0));
        let nearest = (p - lo).min(hi - p).min_element();
        let a = (nearest / reference::BLEND_MARGIN_M).min(1.0);
        let want = a * mesh + (1.0 - a) * grid;
        let got = field(p, mask);
        assert!(
            (got - want).abs() < 1e-3,
            "{p} depth {nearest} mask {mask}: blended {got}, want {want}"
        );
    }
    // Without the blend the faces would show this jump.
    assert!(
        largest_mesh_grid_gap > 0.1,
        "the mesh and the grid agree at the faces ({largest_mesh_grid_gap}): the test shows nothing"
    );

    let ctx = common::gpu_context();
    let mut lib = shader::library(shader::capabilities_for(ctx.features)).unwrap();
    let pipeline = ComputePipeline::new(
        &ctx,
        &mut lib,
        "irradiance_probes/lookup_check.wgsl",
        "main",
        &[],
    )
    .unwrap();
    let sky = synthetic_sky(&mut rng);
    let params = RelightParams::new(None, &IrradianceProbesSettings::default(), 0);
    let irradiance = reference::relight_all(&data, &sky, &params);
    let flat: Vec<[f32; 4]> = irradiance
        .iter()
        .flat_map(|sh| sh.coeffs.map(|c| c.extend(0.0).to_array()))
        .collect();
    let mut lp: ProbeLookupParams = data.params;
    lp.grid_size[3] |= PROBES_INTERIOR_MASK;
    let mut queries = Vec::new();
    let mut points = Vec::new();
    for i in 0..256 {
        let (on, inward) = point_on_mesh_face(&mut rng);
        let n = Vec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        )
        .normalize_or(Vec3::Y);
        let mask = [0.0, 1.0, 0.5, 0.25][i % 4];
        // Pairs straddling the face, then a point in the margin.
        for p in [
            on + 1e-3 * inward,
            on - 1e-3 * inward,
            on + rng.random_range(0.0..1.2) * inward,
        ] {
            queries.push(p.extend(0.0).to_array());
            queries.push(n.extend(mask).to_array());
            points.push((p, n, mask));
        }
    }
    let got = gpu_lookup(&ctx, &pipeline, &data, &lp, &flat, &queries);
    for (i, (p, n, mask)) in points.iter().enumerate() {
        let want = reference::irradiance_at(&data, &lp, &irradiance, *p, *n, *mask)
            .expect("the synthetic bake covers the mesh's faces");
        let g = Vec3::from_slice(&got[i][..3]);
        assert_eq!(got[i][3], 1.0, "{p}: the GPU finds no probe");
        assert!(
            (g - want).abs().max_element() <= 1e-3 * want.max_element() + 1e-3,
            "{p} n {n} mask {mask}: gpu {g} cpu {want}"
        );
        if i % 3 == 1 {
            let inner = Vec3::from_slice(&got[i - 1][..3]);
            assert!(
                (g - inner).abs().max_element() <= 5e-3 * g.max_element().max(1.0),
                "{p}: gpu {inner} inside the face, {g} outside"
            );
        }
    }
}

/// The walk from the start grid finds every point inside the mesh in fewer steps, on
/// average, than a walk from the mesh's first tetrahedron (the old start, walked here the
/// same way: across the face opposite the most negative barycentric coordinate).
#[test]
fn the_walk_starts_near_the_point() {
    let mut rng = SmallRng::seed_from_u64(14);
    let mut bake = synthetic_bake(13);
    bake.meshes[0] = kuhn_mesh(&mut rng, Vec3::new(40.0, 2.0, 50.0), 2.5, 4);
    let data = ProbeGpuData::new(&bake);
    let slot = data.meshes[0];
    let adj = data.params.topology[2] as usize;
    let from_first = |p: Vec3| -> u32 {
        let mut t = slot.first_tet;
        for step in 1..=256 {
            let b = reference::barycentrics(&data, t, p).unwrap();
            let k = (0..4).min_by(|&i, &j| b[i].total_cmp(&b[j])).unwrap();
            if b[k] >= -reference::INSIDE_EPSILON {
                return step;
            }
            t = data.topology[adj + 4 * t as usize + k];
            assert_ne!(
                t, HULL,
                "{p}: the walk from the first tetrahedron left the mesh"
            );
        }
        256
    };
    let (mut grid_steps, mut first_steps) = (0u32, 0u32);
    for _ in 0..2000 {
        let p = Vec3::new(
            rng.random_range(40.1..49.9),
            rng.random_range(2.1..11.9),
            rng.random_range(50.1..59.9),
        );
        let (hit, n) = reference::locate_counting(&data, 0, p);
        assert!(hit.is_some(), "{p}: inside the mesh but not found");
        grid_steps += n;
        first_steps += from_first(p);
    }
    assert!(
        2 * grid_steps < first_steps,
        "{grid_steps} steps from the start grid, {first_steps} from the first tetrahedron"
    );
    println!(
        "walk steps over 2000 points: {grid_steps} from the start grid, {first_steps} from the first tetrahedron"
    );
}

/// `hikari bench probes`'s relight dispatches (`relight_bench`) relight what they say: every
/// probe they write equals the CPU twin's relight of the bake probe it was copied from (the
/// grid dispatch from the grid's probes in turn, the mesh dispatch from the meshes', the scene
/// mesh as it is), with the counts the bench prints. Deringing off: its strength choice is
/// checked in `relight_matches_the_cpu_twin`; here a wrong copy or chunk would differ by the
/// whole value. An empty bake and an empty workload are errors naming them.
#[test]
fn the_bench_dispatches_relight_copies_of_the_bake() {
    use hikari_render::techniques::irradiance_probes::IrradianceProbes;
    use hikari_render::techniques::irradiance_probes::relight_bench::{
        GRID_PASS, MESH_PASS, RelightBench, RelightBenchSpec, SCENE_MESH_PASS,
    };
    let ctx = common::gpu_context();
    let mut lib = shader::library(shader::capabilities_for(ctx.features)).unwrap();
    let technique = IrradianceProbes::new(&ctx, &mut lib).unwrap();
    let data = ProbeGpuData::new(&synthetic_bake(23));
    let mut rng = SmallRng::seed_from_u64(0xBE7C);
    let sky = synthetic_sky(&mut rng);
    let spec = RelightBenchSpec {
        grid_tiles: 3,
        mesh_probes: 100,
    };
    let bench = RelightBench::new(&ctx, &data, &spec, &sky.coeffs).unwrap();
    let plan: Vec<_> = bench
        .workloads
        .iter()
        .map(|w| (w.pass, w.probes, w.tiles, w.chunk_count))
        .collect();
    let mesh = data.meshes[0];
    assert_eq!(
        plan,
        vec![
            (GRID_PASS, 3 * 768, 3, 36),
            (MESH_PASS, 100, 0, 2),
            (SCENE_MESH_PASS, mesh.probes, 0, mesh.probes.div_ceil(64)),
        ]
    );

    let sun = hikari_scene::Sun {
        direction: Vec3::new(-0.4, 0.7, 0.2).normalize(),
        illuminance_lux: 80_000.0,
        color: Vec3::new(1.0, 0.9, 0.8),
    };
    let s = settings_with(|s| s.dering = false);
    let mut rt = GraphRuntime::new();
    let mut g = rt.begin_frame(&ctx);
    let out = technique
        .record_relight_bench(&mut g, &bench, Some(&sun), &s)
        .unwrap();
    g.readback(out);
    let r = g.execute().unwrap();
    let gpu: Vec<[f32; 4]> =
        bytemuck::pod_collect_to_vec(r.buffer("irradiance_probes.bench_irradiance").unwrap());

    let grid = data.tiles.len() * TILE_PROBE_COUNT;
    let total = data.probe_count();
    let mut sources: Vec<usize> = (0..3 * 768).map(|k| k % grid).collect();
    sources.extend((0..100).map(|k| grid + k % (total - grid)));
    sources.extend((0..mesh.probes as usize).map(|k| mesh.first_probe as usize + k));
    assert_eq!(gpu.len(), sources.len() * 9);
    let params = RelightParams::new(Some(&sun), &s, 0);
    for (o, &p) in sources.iter().enumerate() {
        let (v, b) = data.probe_sh(p);
        let want = reference::relight_probe(&sky, &v, &b, &params);
        let got = sh_of(&gpu[o * 9..o * 9 + 9]);
        let scale = want.coeffs[0].abs().max_element().max(1.0);
        let err = (0..9)
            .map(|k| (got.coeffs[k] - want.coeffs[k]).abs().max_element())
            .fold(0.0f32, f32::max)
            / scale;
        assert!(
            err < 2e-3,
            "output probe {o} (bake probe {p}): relative error {err}: gpu {got:?} cpu {want:?}"
        );
    }

    let empty = ProbeGpuData::new(&Bake::new(
        SceneKey::from_u64(1),
        BakeSettings::with_rays(1),
    ));
    let e = RelightBench::new(&ctx, &empty, &spec, &sky.coeffs)
        .err()
        .expect("an empty bake is refused")
        .to_string();
    assert!(e.contains("no probes"), "{e}");
    let none = RelightBenchSpec {
        grid_tiles: 0,
        mesh_probes: 5,
    };
    let e = RelightBench::new(&ctx, &data, &none, &sky.coeffs)
        .err()
        .expect("no grid tiles is refused")
        .to_string();
    assert!(e.contains("grid tiles"), "{e}");
}
