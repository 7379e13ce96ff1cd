//! Volumetric haze: the CPU twin against independent results (Simpson quadrature of the
//! density, the geometric slicing, the phase function's normalisation and mean cosine, the
//! B-spline's linear precision, the closed form of a homogeneous medium), and the GPU passes
//! against the twin and the closed form, with NaN and infinite inputs.

use crate::common;

use glam::{Vec3, Vec4};
use half::f16;
use hikari_math::sh::Sh;
use hikari_render::graph::GraphRuntime;
use hikari_render::scene::upload::LightGpu;
use hikari_render::shader;
use hikari_render::techniques::haze::reference::{self as twin, HazeLightInputs};
use hikari_render::techniques::haze::settings::HazeSettings;
use hikari_render::techniques::haze::{
    HAZE_DENSITY_AA, HAZE_LOCAL_LIGHTS, HAZE_SKY, HAZE_SKY_OCCLUSION, HAZE_SUN_SHADOWS,
    HAZE_TRICUBIC, Haze, HazeInputs, HazeParams,
};
use hikari_render::techniques::irradiance_probes::gpu_data::{ProbeGpuData, ProbeLookupParams};
use hikari_render::techniques::irradiance_probes::{self, RelightParams};
use hikari_render::techniques::sky::SkyAmbientParams;
use hikari_render::techniques::sun_shadows;
use hikari_render::view::View;
use hikari_scene::{Camera, Sun};
use rand::{Rng, SeedableRng, rngs::SmallRng};

fn params_with(s: &HazeSettings, sun: Option<&Sun>, lights: u32) -> HazeParams {
    HazeParams::new(s, "clear", sun, lights, 0.01, 100_000.0)
}

/// [`layered`] on a grid of 16 x 10 x 24 froxels to 2 km, small enough for the twins.
fn small_grid() -> HazeSettings {
    HazeSettings {
        grid_width: 16,
        grid_height: 10,
        slices: 24,
        far_m: 2000.0,
        slice_growth: 1.25,
        ..layered()
    }
}

fn layered() -> HazeSettings {
    HazeSettings {
        density: 3e-3,
        falloff_m: 25.0,
        height_m: 4.0,
        layer_density: 0.02,
        layer_top_density: 0.001,
        layer_height_m: 6.0,
        layer_thickness_m: 2.5,
        ..HazeSettings::default()
    }
}

/// Simpson's rule in f64 over `n` (even) intervals of the twin's point density.
fn simpson_depth(p: &HazeParams, o: Vec3, d: Vec3, len: f32, n: usize) -> f64 {
    let h = f64::from(len) / n as f64;
    let f = |i: usize| {
        let t = h * i as f64;
        f64::from(twin::density(
            p,
            (f64::from(o.y) + t * f64::from(d.y)) as f32,
        ))
    };
    let mut sum = f(0) + f(n);
    for i in 1..n {
        sum += f(i) * if i % 2 == 1 { 4.0 } else { 2.0 };
    }
    sum * h / 3.0
}

#[test]
fn optical_depth_matches_simpson_quadrature_of_the_density() {
    let p = params_with(&layered(), None, 0);
    let cases = [
        // Level, through the layer's middle and below it.
        (Vec3::new(0.0, 6.0, 0.0), Vec3::X, 300.0),
        (Vec3::new(0.0, 1.0, 0.0), Vec3::Z, 50.0),
        // Steep up and down, crossing both layers.
        (Vec3::new(0.0, 0.5, 0.0), Vec3::new(0.1, 1.0, 0.0), 200.0),
        (Vec3::new(0.0, 80.0, 0.0), Vec3::new(0.0, -1.0, 0.3), 79.0),
        // Long and shallow: 100 km rising 1 in 1000.
        (
            Vec3::new(0.0, 2.0, 0.0),
            Vec3::new(1.0, 0.001, 0.0),
            100_000.0,
        ),
        // Nearly level, a hair above and below.
        (Vec3::new(0.0, 5.0, 0.0), Vec3::new(1.0, 1e-6, 0.0), 1000.0),
        (Vec3::new(0.0, 5.0, 0.0), Vec3::new(1.0, -2e-4, 0.0), 1000.0),
    ];
    for (o, d, len) in cases {
        let d = d.normalize();
        let got = f64::from(twin::optical_depth(&p, o, d, len));
        let want = simpson_depth(&p, o, d, len, 200_000);
        assert!(
            (got - want).abs() <= 2e-4 * want + 1e-7,
            "from {o} along {d} for {len} m: closed form {got}, quadrature {want}"
        );
    }
    assert_eq!(twin::optical_depth(&p, Vec3::ZERO, Vec3::Y, 0.0), 0.0);
}

#[test]
fn slices_grow_geometrically_from_near_to_far() {
    let s = HazeSettings::default();
    let p = params_with(&s, None, 0);
    let n = s.slices as f32;
    assert!((twin::slice_depth(&p, 0.0) - s.near_m).abs() < 1e-6);
    let far = twin::slice_depth(&p, n);
    assert!(
        (far - s.far_m).abs() < 1e-3 * s.far_m,
        "last boundary {far}"
    );
    for k in 1..s.slices - 1 {
        let t0 = twin::slice_depth(&p, k as f32) - twin::slice_depth(&p, k as f32 - 1.0);
        let t1 = twin::slice_depth(&p, k as f32 + 1.0) - twin::slice_depth(&p, k as f32);
        assert!(
            (t1 / t0 - s.slice_growth).abs() < 2e-3,
            "slice {k}: {t1} / {t0}"
        );
    }
    // The talk's numbers: 64 slices from 10 cm to 100 km, each 20 % thicker.
    assert!((twin::slice_depth(&p, 1.0) - 0.1 - 0.1708).abs() < 1e-3);
    for z in [0.1, 0.5, 3.0, 47.0, 1234.0, 99_000.0] {
        let back = twin::slice_depth(&p, twin::slice_of_depth(&p, z));
        assert!((back - z).abs() < 1e-4 * z, "{z} -> {back}");
    }
}

#[test]
fn hg_phase_integrates_to_one_with_mean_cosine_g() {
    for g in [-0.5f32, 0.0, 0.3, 0.6, 0.9] {
        // Midpoint rule in cos theta (the phase depends on it alone): 2 pi dmu.
        let n = 200_000;
        let (mut total, mut mean) = (0.0f64, 0.0f64);
        for i in 0..n {
            let mu = -1.0 + (i as f64 + 0.5) * 2.0 / n as f64;
            let p = f64::from(twin::hg_phase(mu as f32, g))
                * 2.0
                * std::f64::consts::PI
                * (2.0 / n as f64);
            total += p;
            mean += p * mu;
        }
        assert!((total - 1.0).abs() < 1e-3, "g {g}: integral {total}");
        assert!(
            (mean - f64::from(g)).abs() < 2e-3,
            "g {g}: mean cosine {mean}"
        );
    }
}

fn small_params(tricubic: bool) -> HazeParams {
    let s = HazeSettings {
        grid_width: 6,
        grid_height: 5,
        slices: 7,
        tricubic,
        ..HazeSettings::default()
    };
    params_with(&s, None, 0)
}

#[test]
fn bspline_sampling_reproduces_a_linear_ramp_inside_the_grid() {
    for tricubic in [true, false] {
        let p = small_params(tricubic);
        let ramp = |c: Vec3| Vec4::new(1.0 + 0.5 * c.x - 0.25 * c.y + 2.0 * c.z, c.x, c.y, c.z);
        let mut grid = vec![Vec4::ZERO; 6 * 5 * 7];
        for k in 0..7 {
            for j in 0..5 {
                for i in 0..6 {
                    grid[twin::froxel_index(&p, i, j, k)] =
                        ramp(Vec3::new(i as f32, j as f32, k as f32));
                }
            }
        }
        let weights = twin::bspline_weights(0.37);
        assert!((weights.iter().sum::<f32>() - 1.0).abs() < 1e-6);
        // Texel coordinates at least one texel from every edge, where no tap is clamped.
        for c in [
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::new(2.3, 1.7, 3.9),
            Vec3::new(3.99, 2.01, 4.5),
        ] {
            let uvw = (c + 0.5) / Vec3::new(6.0, 5.0, 7.0);
            let got = twin::sample(&p, &grid, uvw, tricubic);
            let want = ramp(c);
            assert!(
                (got - want).abs().max_element() < 1e-4,
                "tricubic {tricubic} at {c}: {got} vs {want}"
            );
        }
    }
}

#[test]
fn a_homogeneous_medium_composites_to_its_closed_form() {
    // Constant L_i along every ray: L / alpha is exactly c L_i, so the pixel's own alpha gives
    // lit e^(-sigma d) + c L_i (1 - e^(-sigma d)).
    let s = HazeSettings {
        density: 0.02,
        falloff_m: 100_000.0,
        grid_width: 8,
        grid_height: 6,
        slices: 16,
        ..HazeSettings::default()
    };
    let p = params_with(&s, None, 0);
    let view = View::new(&test_camera(), 32, 24);
    let li = Vec3::new(0.3, 0.5, 0.7);
    let light = vec![li; 8 * 6 * 16];
    let grid = twin::integrate(&p, &view, &light);
    let lit = Vec3::new(2.0, 1.0, 0.5);
    for (pixel, z) in [([3u32, 4u32], 2.0f32), ([16, 12], 35.0), ([30, 20], 400.0)] {
        let depth = view.forward_near[3] / z;
        let got = twin::composite_pixel(&p, &view, &grid, pixel, depth, lit);
        let (_, dist, _) = twin::pixel_extent(&p, &view, pixel, depth);
        // sigma: the density at the camera's height times the weather's factor 1.
        let sigma = 0.02 * (-(view.position[1]) / 100_000.0f32).exp();
        let t = (-sigma * dist).exp();
        let want = lit * t + li / p.scatter[2] * (1.0 - t);
        assert!(
            ((got - want) / want).abs().max_element() < 1e-3,
            "pixel {pixel:?}: {got} vs {want}"
        );
    }
}

fn test_camera() -> Camera {
    Camera {
        position: Vec3::new(0.0, 3.0, 10.0),
        target: Vec3::new(0.0, 1.0, 0.0),
        vfov_deg: 60.0,
        near: 0.1,
        ..Camera::default()
    }
}

fn half(v: f32) -> f32 {
    f16::from_f32(v).to_f32()
}

struct GpuRun {
    light: Vec<Vec4>,
    grid: Vec<Vec4>,
    radiance: Vec<Vec4>,
}

/// Relit irradiance probes for the lookup: their layout, the lookup's parameters and one
/// irradiance SH (9 RGB coefficients, lux) a probe.
struct Probes {
    data: ProbeGpuData,
    params: ProbeLookupParams,
    irradiance: Vec<hikari_math::sh::ShL2Rgb>,
}

/// Runs the three passes on `depth` and `lit` (W x H, f32 and f16 inputs) with the shadows
/// off and the given sky SH (9 RGB coefficients), lights and probes (none: no probe covers
/// anything).
#[allow(clippy::too_many_arguments)]
fn run_gpu(
    ctx: &hikari_render::GpuContext,
    params: &HazeParams,
    view: &View,
    size: [u32; 2],
    depth: &[f32],
    lit: &[[f32; 4]],
    sky_sh: &Sh<Vec3, 9>,
    lights: &[LightGpu],
    probes: Option<&Probes>,
) -> GpuRun {
    let settings = HazeSettings::default();
    run_gpu_frames(
        ctx,
        &settings,
        &[(*view, *params)],
        size,
        depth,
        lit,
        sky_sh,
        lights,
        probes,
    )
    .pop()
    .unwrap()
}

/// [`run_gpu`] for one frame a view, the graph's history kept from frame to frame.
#[allow(clippy::too_many_arguments)]
fn run_gpu_frames(
    ctx: &hikari_render::GpuContext,
    settings: &HazeSettings,
    frames: &[(View, HazeParams)],
    [w, h]: [u32; 2],
    depth: &[f32],
    lit: &[[f32; 4]],
    sky_sh: &Sh<Vec3, 9>,
    lights: &[LightGpu],
    probes: Option<&Probes>,
) -> Vec<GpuRun> {
    let mut lib = shader::library(shader::capabilities_for(ctx.features)).unwrap();
    let haze = Haze::new(ctx, &mut lib).unwrap();
    let depth_tex = common::texture_with_data(
        ctx,
        wgpu::TextureFormat::R32Float,
        w,
        h,
        bytemuck::cast_slice(depth),
    );
    let halves: Vec<f16> = lit.iter().flatten().map(|&v| f16::from_f32(v)).collect();
    let lit_tex = common::texture_with_data(
        ctx,
        wgpu::TextureFormat::Rgba16Float,
        w,
        h,
        bytemuck::cast_slice(&halves),
    );
    use wgpu::util::DeviceExt;
    // `sky.sh` holds 9 raw then 9 deringed coefficients; the haze reads the deringed ones.
    let mut sh = vec![[0f32; 4]; 18];
    for (i, c) in sky_sh.coeffs.iter().enumerate() {
        sh[9 + i] = c.extend(0.0).to_array();
    }
    let sh_buf = ctx
        .device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("test.sky_sh"),
            contents: bytemuck::cast_slice(&sh),
            usage: wgpu::BufferUsages::STORAGE,
        });
    let mut light_data = lights.to_vec();
    if light_data.is_empty() {
        light_data.push(bytemuck::Zeroable::zeroed());
    }
    let light_buf = ctx
        .device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("test.lights"),
            contents: bytemuck::cast_slice(&light_data),
            usage: wgpu::BufferUsages::STORAGE,
        });
    let probe_bufs = probes.map(|p| {
        let flat: Vec<[f32; 4]> = p
            .irradiance
            .iter()
            .flat_map(|sh| sh.coeffs.map(|c| c.extend(0.0).to_array()))
            .collect();
        let buf = |name: &str, bytes: &[u8]| {
            ctx.device
                .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(name),
                    contents: bytes,
                    usage: wgpu::BufferUsages::STORAGE,
                })
        };
        (
            buf("test.irradiance", bytemuck::cast_slice(&flat)),
            buf("test.positions", bytemuck::cast_slice(&p.data.positions)),
            buf("test.topology", bytemuck::cast_slice(&p.data.topology)),
        )
    });
    let mut rt = GraphRuntime::new();
    let mut runs = Vec::new();
    let mut state = hikari_render::techniques::haze::HazeState::default();
    for (view, params) in frames {
        let mut g = rt.begin_frame(ctx);
        let probe_set = match (probes, &probe_bufs) {
            (Some(p), Some((irr, pos, topo))) => {
                let irr = g.import_buffer("irradiance_probes.irradiance", irr);
                let pos = g.import_buffer("irradiance_probes.positions", pos);
                let topo = g.import_buffer("irradiance_probes.topology", topo);
                g.binding_set("irradiance_probes")
                    .constants(&p.params)
                    .read(irr)
                    .read(pos)
                    .read(topo)
                    .finish()
            }
            _ => irradiance_probes::absent_lookup(&mut g).unwrap(),
        };
        let depth = g.import_texture("test.depth", &depth_tex);
        let lit = g.import_texture("test.lit", &lit_tex);
        let sh = g.import_buffer("sky.sh", &sh_buf);
        let lights = g.import_buffer("scene.lights", &light_buf);
        let shadows = sun_shadows::unshadowed_lookup(&mut g).unwrap();
        let clouds = hikari_render::techniques::clouds::disabled_lookup(&mut g).unwrap();
        let sky_ambient = g
            .binding_set("sky_ambient")
            .constants(&SkyAmbientParams {
                balance: [1.0, 1.0, 0.0, 0.0],
            })
            .read(sh)
            .finish();
        let cx = hikari_render::FrameContext::for_view(*view, g.frame_index());
        let out = haze
            .record(
                &mut g,
                &mut state,
                &cx,
                settings,
                params,
                &HazeInputs {
                    depth,
                    lit,
                    lights,
                    shadows,
                    sky_ambient,
                    clouds,
                    probes: probe_set,
                },
            )
            .unwrap();
        g.readback(out.light);
        g.readback(out.grid);
        g.readback(out.radiance);
        let r = g.execute().unwrap();
        let get = |name: &str| -> Vec<Vec4> {
            r.image(name)
                .unwrap()
                .rgba
                .iter()
                .map(|v| Vec4::from_array(*v))
                .collect()
        };
        runs.push(GpuRun {
            light: get("haze.light"),
            grid: get("haze.grid"),
            radiance: get("haze.radiance"),
        });
    }
    runs
}

fn rel_err(got: Vec3, want: Vec3, floor: f32) -> f32 {
    ((got - want).abs() / want.abs().max(Vec3::splat(floor))).max_element()
}

#[test]
fn gpu_passes_match_their_cpu_twin() {
    let ctx = common::gpu_context();
    let (w, h) = (64u32, 40u32);
    let mut rng = SmallRng::seed_from_u64(7);
    let view = View::new(&test_camera(), w, h);
    let sun = Sun {
        direction: Vec3::new(0.4, 0.5, -0.6).normalize(),
        illuminance_lux: 90_000.0,
        color: Vec3::new(1.05, 1.0, 0.93),
    };
    let lights = vec![
        LightGpu {
            position_range: [1.0, 1.5, 2.0, f32::MAX],
            direction_kind: [0.0, 0.0, 0.0, 0.0],
            intensity: [400.0, 300.0, 200.0, 0.0],
            spot: [0.0, 0.0, -1.0, 0.0],
        },
        LightGpu {
            position_range: [-2.0, 4.0, -3.0, 30.0],
            direction_kind: [0.0, -1.0, 0.0, 1.0],
            intensity: [2000.0, 2000.0, 2500.0, 0.0],
            // Cone from cos 0.9 (outer) to cos 0.95 (inner).
            spot: [20.0, -18.0, -1.0, 0.0],
        },
    ];
    let mut sky_sh = Sh::<Vec3, 9>::zero();
    sky_sh.coeffs[0] = Vec3::new(9000.0, 12000.0, 16000.0);
    for c in sky_sh.coeffs.iter_mut().skip(1) {
        *c = Vec3::new(
            rng.random_range(-2000.0..2000.0),
            rng.random_range(-2000.0..2000.0),
            rng.random_range(-2000.0..2000.0),
        );
    }
    let s = small_grid();
    let mut depth: Vec<f32> = (0..w * h)
        .map(|_| {
            if rng.random_bool(0.15) {
                0.0
            } else {
                view.forward_near[3] / 10f32.powf(rng.random_range(-0.5..3.0))
            }
        })
        .collect();
    depth[3] = f32::NAN;
    depth[4] = f32::INFINITY;
    let mut lit: Vec<[f32; 4]> = (0..w * h)
        .map(|_| {
            [
                10f32.powf(rng.random_range(0.0..4.0)),
                10f32.powf(rng.random_range(0.0..4.0)),
                10f32.powf(rng.random_range(0.0..4.0)),
                1.0,
            ]
        })
        .collect();
    lit[5] = [f32::NAN, f32::INFINITY, -1.0, 1.0];
    for (flags_off, label) in [
        (0u32, "default"),
        (HAZE_DENSITY_AA | HAZE_TRICUBIC, "plain"),
    ] {
        let mut params = params_with(&s, Some(&sun), lights.len() as u32);
        params.grid[3] &= !(HAZE_SUN_SHADOWS | flags_off);
        assert!(params.grid[3] & HAZE_SKY != 0 && params.grid[3] & HAZE_LOCAL_LIGHTS != 0);
        let gpu = run_gpu(
            &ctx,
            &params,
            &view,
            [w, h],
            &depth,
            &lit,
            &sky_sh,
            &lights,
            None,
        );

        // haze.light against the twin, which stores f32: the GPU rounds to f16.
        let vis = |_: Vec3| 1.0;
        let inputs = HazeLightInputs {
            sky_sh: &sky_sh,
            lights: &lights,
            sun_visibility: &vis,
            sky_visibility: &vis,
        };
        let want = twin::light_grid(&params, &view, &inputs);
        let mut worst = 0f32;
        for (i, (g, w)) in gpu.light.iter().zip(&want).enumerate() {
            let e = rel_err(g.truncate(), *w, 1e-3);
            assert!(e < 4e-3, "{label} light froxel {i}: {g} vs {w}");
            worst = worst.max(e);
        }
        eprintln!("{label}: haze.light worst relative difference {worst}");

        // haze.integrate from the GPU's own light grid.
        let light_in: Vec<Vec3> = gpu.light.iter().map(|v| v.truncate()).collect();
        let want = twin::integrate(&params, &view, &light_in);
        for (i, (g, w)) in gpu.grid.iter().zip(&want).enumerate() {
            let e =
                rel_err(g.truncate(), w.truncate(), 1e-3).max((g.w - w.w).abs() / 1e-2f32.max(w.w));
            assert!(e < 4e-3, "{label} grid froxel {i}: {g} vs {w}");
        }

        // haze.composite from the GPU's grid and the f16 inputs.
        let mut worst = 0f32;
        for y in 0..h {
            for x in 0..w {
                let i = (y * w + x) as usize;
                let l = Vec3::new(half(lit[i][0]), half(lit[i][1]), half(lit[i][2]));
                let want = twin::composite_pixel(&params, &view, &gpu.grid, [x, y], depth[i], l);
                let got = gpu.radiance[i].truncate();
                assert!(got.is_finite(), "{label} pixel {x},{y}: {got}");
                // The sampler's filtering and the f16 store.
                let e = rel_err(got, want, 1.0);
                assert!(
                    e < 1e-2,
                    "{label} pixel {x},{y} (depth {}): {got} vs {want}",
                    depth[i]
                );
                worst = worst.max(e);
            }
        }
        eprintln!("{label}: haze.composite worst relative difference {worst}");
        // The NaN pixel entered as black and left finite.
        let nan_px = gpu.radiance[5];
        assert!(nan_px.truncate().is_finite() && nan_px.x < 1e5, "{nan_px}");
    }
}

/// The talk's temporal filtering: the second frame lights each froxel at its jittered point
/// and blends it with the first frame's grid read where the froxel's centre was, the camera
/// having moved; the twin does the same from the GPU's first grid.
#[test]
fn gpu_temporal_filter_matches_its_twin() {
    let ctx = common::gpu_context();
    let (w, h) = (32u32, 24u32);
    let cam0 = test_camera();
    let cam1 = Camera {
        position: cam0.position + Vec3::new(0.4, 0.1, -0.3),
        ..cam0.clone()
    };
    let views = [
        View::new(&cam0, w, h),
        View::with_previous(&cam1, &cam0, w, h),
    ];
    let sun = Sun {
        direction: Vec3::new(0.4, 0.5, -0.6).normalize(),
        illuminance_lux: 90_000.0,
        color: Vec3::new(1.05, 1.0, 0.93),
    };
    let lights = vec![LightGpu {
        position_range: [1.0, 1.5, 2.0, f32::MAX],
        direction_kind: [0.0, 0.0, 0.0, 0.0],
        intensity: [400.0, 300.0, 200.0, 0.0],
        spot: [0.0, 0.0, -1.0, 0.0],
    }];
    let mut sky_sh = Sh::<Vec3, 9>::zero();
    sky_sh.coeffs[0] = Vec3::new(9000.0, 12000.0, 16000.0);
    sky_sh.coeffs[2] = Vec3::new(3000.0, 3500.0, 4000.0);
    let s = small_grid();
    let mut p0 = params_with(&s, Some(&sun), lights.len() as u32);
    p0.grid[3] &= !HAZE_SUN_SHADOWS;
    // The second frame metered at half the light: its grid's storage scale doubles, and the
    // history must be rescaled to it.
    let p1 = HazeParams {
        scatter: [
            p0.scatter[0],
            p0.scatter[1],
            2.0 * p0.scatter[2],
            p0.scatter[3],
        ],
        ..p0
    };
    let depth = vec![0.0f32; (w * h) as usize];
    let lit = vec![[1.0f32, 1.0, 1.0, 1.0]; (w * h) as usize];
    let frames = [(views[0], p0), (views[1], p1)];
    let run = |s: &HazeSettings| {
        run_gpu_frames(
            &ctx,
            s,
            &frames,
            [w, h],
            &depth,
            &lit,
            &sky_sh,
            &lights,
            None,
        )
    };
    let gpu = run(&s);
    // The same with the history weighing nothing: this frame's jittered light alone.
    let alone = run(&HazeSettings {
        temporal_blend: 0.0,
        ..s.clone()
    });
    let vis = |_: Vec3| 1.0;
    let inputs = HazeLightInputs {
        sky_sh: &sky_sh,
        lights: &lights,
        sun_visibility: &vis,
        sky_visibility: &vis,
    };
    let jitter = twin::jitter(1);
    assert!(jitter.truncate().length() > 0.1 && jitter != twin::jitter(0));
    let current = twin::light_grid_jittered(&p1, &views[1], &inputs, jitter);
    let want = twin::temporal(
        &p1,
        &views[1],
        &current,
        &gpu[0].light,
        s.temporal_blend,
        2.0,
    );
    let (mut worst, mut blended, mut fresh) = (0f32, 0, 0);
    let [gw, gh, gn, _] = p1.grid;
    for k in 0..gn {
        for j in 0..gh {
            for i in 0..gw {
                let at = twin::froxel_index(&p1, i, j, k);
                let own = alone[1].light[at].truncate();
                let e = rel_err(own, current[at], 1e-3);
                assert!(
                    e < 4e-3,
                    "froxel ({i}, {j}, {k}) alone: {own} vs {}",
                    current[at]
                );
                let got = gpu[1].light[at].truncate();
                let e = rel_err(got, want[at], 1e-3);
                assert!(
                    e < 1e-2,
                    "froxel ({i}, {j}, {k}): {got} vs {} (current {})",
                    want[at],
                    current[at]
                );
                worst = worst.max(e);
                if twin::reproject(&p1, &views[1], i, j, k).is_some() {
                    blended += 1;
                } else {
                    fresh += 1;
                }
            }
        }
    }
    eprintln!(
        "temporal: worst relative difference {worst}; {blended} froxels blended, {fresh} fresh"
    );
    // The move leaves froxels of both kinds, and the blend must matter where it happens.
    assert!(blended > 1000 && fresh > 50);
    let moved = current
        .iter()
        .zip(&want)
        .filter(|(c, w)| rel_err(**c, **w, 1e-3) > 0.02)
        .count();
    assert!(
        moved > 500,
        "only {moved} froxels differ from this frame's own light"
    );
}

#[test]
fn gpu_homogeneous_sunlit_medium_matches_the_closed_form() {
    let ctx = common::gpu_context();
    let (w, h) = (64u32, 48u32);
    let view = View::new(&test_camera(), w, h);
    let sun = Sun {
        direction: Vec3::new(-0.3, 0.4, -0.8).normalize(),
        illuminance_lux: 100_000.0,
        color: Vec3::ONE,
    };
    let s = HazeSettings {
        density: 0.01,
        falloff_m: 100_000.0,
        anisotropy: 0.3,
        sky: false,
        sun_shadows: false,
        local_lights: false,
        grid_width: 32,
        grid_height: 24,
        slices: 32,
        far_m: 5000.0,
        ..HazeSettings::default()
    };
    let params = params_with(&s, Some(&sun), 0);
    let depth: Vec<f32> = (0..w * h)
        .map(|i| view.forward_near[3] / (1.0 + (i % 97) as f32 * 3.0))
        .collect();
    let lit = vec![[500.0f32, 1000.0, 2000.0, 1.0]; (w * h) as usize];
    let gpu = run_gpu(
        &ctx,
        &params,
        &view,
        [w, h],
        &depth,
        &lit,
        &Sh::zero(),
        &[],
        None,
    );
    let cam = Vec3::from_slice(&view.position[..3]);
    let mut worst = 0f32;
    // Away from the image's border, where the B-spline's clamped taps see no other directions.
    for y in 4..h - 4 {
        for x in 4..w - 4 {
            let i = (y * w + x) as usize;
            let (v, dist, _) = twin::pixel_extent(&params, &view, [x, y], depth[i]);
            let sigma = 0.01 * (-cam.y / 100_000.0f32).exp();
            let t = (-sigma * dist).exp();
            let li = 100_000.0 * 0.9 * twin::hg_phase(sun.direction.dot(v), 0.3);
            let want = Vec3::from_slice(&lit[i][..3]) * t + Vec3::splat(li * (1.0 - t));
            let got = gpu.radiance[i].truncate();
            let e = rel_err(got, want, 1.0);
            worst = worst.max(e);
            assert!(e < 2e-2, "pixel {x},{y}: {got} vs {want}");
        }
    }
    eprintln!("homogeneous medium: worst relative difference {worst}");
}

/// The talk's haze AO: the sky's light in `haze.light` times the sky visibility the
/// irradiance probes give at each froxel, against the twin, which looks the probes up with
/// `irradiance_probes::reference::irradiance_at` (the lookup's own twin) and applies
/// `probe_sky_visibility`. Probes: a synthetic bake (two grid tiles and a tetrahedral mesh of
/// random sky visibility) relit by a random sky on the CPU; a camera whose froxels cross the
/// mesh and the grid. Tolerance as the twin test's (the f16 store), 4e-3. Also: the occlusion
/// darkens some froxels by more than a half and leaves those beyond the probes alone, and
/// with the setting off the probes change nothing.
#[test]
fn gpu_sky_light_is_occluded_by_the_probes_sky_visibility() {
    let ctx = common::gpu_context();
    let (w, h) = (32u32, 24u32);
    let camera = Camera {
        position: Vec3::new(45.0, 6.0, 20.0),
        target: Vec3::new(45.0, 3.0, 55.0),
        vfov_deg: 60.0,
        near: 0.1,
        ..Camera::default()
    };
    let view = View::new(&camera, w, h);
    let mut rng = SmallRng::seed_from_u64(11);
    let sky = common::probes::synthetic_sky(&mut rng);
    let data = ProbeGpuData::new(&common::probes::synthetic_bake(5));
    let relight = RelightParams::new(None, &Default::default(), 0);
    let irradiance = irradiance_probes::reference::relight_all(&data, &sky, &relight);
    let mut lookup = data.params;
    lookup.grid[3] = 1.0;
    let probes = Probes {
        data,
        params: lookup,
        irradiance,
    };
    let s = HazeSettings {
        grid_width: 16,
        grid_height: 12,
        slices: 32,
        far_m: 400.0,
        slice_growth: 1.15,
        sun: false,
        local_lights: false,
        ..layered()
    };
    let depth = vec![0.0f32; (w * h) as usize];
    let lit = vec![[0.0f32; 4]; (w * h) as usize];
    let balance = 1.0;
    let visibility = |x: Vec3| {
        let e = irradiance_probes::reference::average_irradiance_at(
            &probes.data,
            &probes.params,
            &probes.irradiance,
            x,
            twin::AIR_INTERIOR_MASK,
        );
        twin::probe_sky_visibility(e, &sky, balance)
    };
    let unoccluded = |_: Vec3| 1.0;
    let no_sun = |_: Vec3| 1.0;
    let mut lit_light = None;
    for occlusion in [true, false] {
        let mut params = params_with(&s, None, 0);
        assert!(params.grid[3] & HAZE_SKY != 0);
        assert_ne!(params.grid[3] & HAZE_SKY_OCCLUSION, 0, "on by default");
        if !occlusion {
            params.grid[3] &= !HAZE_SKY_OCCLUSION;
        }
        let gpu = run_gpu(
            &ctx,
            &params,
            &view,
            [w, h],
            &depth,
            &lit,
            &sky,
            &[],
            Some(&probes),
        );
        let inputs = HazeLightInputs {
            sky_sh: &sky,
            lights: &[],
            sun_visibility: &no_sun,
            sky_visibility: if occlusion { &visibility } else { &unoccluded },
        };
        let want = twin::light_grid(&params, &view, &inputs);
        for (i, (g, w)) in gpu.light.iter().zip(&want).enumerate() {
            let e = rel_err(g.truncate(), *w, 1e-3);
            assert!(e < 4e-3, "occlusion {occlusion}, froxel {i}: {g} vs {w}");
        }
        if occlusion {
            lit_light = Some(gpu.light);
        } else {
            // Against the unoccluded grid: some froxels lose more than half their sky light,
            // and the far ones, beyond every probe, keep all of it.
            let occluded = lit_light.take().unwrap();
            let ratios: Vec<f32> = occluded
                .iter()
                .zip(&gpu.light)
                .filter(|(_, u)| u.y > 1e-3)
                .map(|(o, u)| o.y / u.y)
                .collect();
            let dark = ratios.iter().filter(|r| **r < 0.5).count();
            let open = ratios.iter().filter(|r| **r > 0.999).count();
            eprintln!(
                "{dark} froxels under half lit, {open} untouched, of {}",
                ratios.len()
            );
            assert!(dark > 100 && open > 100, "{dark} dark, {open} open");
        }
    }
}
