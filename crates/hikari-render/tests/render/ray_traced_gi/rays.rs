//! Ray generation: directions, the packed hit words, the cosine lobe.

use super::*;

/// Tolerances: the noise and the hit word are integer functions, exact. Directions: Vulkan
/// allows sin/cos an absolute error of 2^-11 on [-π, π]; with normalisation 1e-3 is a few
/// times that, and a swapped or sign-flipped basis vector is hundreds of times over it.
/// Cosine: sqrt to 3 ulp. Albedo: a few roundings, 1e-6. Weight: see there.
#[test]
fn ray_generation_packing_and_albedo_match_the_cpu_twin() {
    let ctx = common::gpu_context();
    let mut lib = shader::library(shader::capabilities_for(ctx.features)).unwrap();
    let rtgi = RayTracedGi::new(&ctx, &mut lib).unwrap();
    let mut rng = SmallRng::seed_from_u64(18);
    let cases = 4096usize;
    let mut input = Vec::with_capacity(cases * 12);
    let mut expected = Vec::new();
    for k in 0..cases {
        let pixel = [rng.random_range(0..300u32), rng.random_range(0..300u32)];
        let frame = rng.random_range(0..1000u32);
        let distance = match k % 8 {
            0 => 7.0e4,  // past f16's range: clamped to 60000
            1 => 1.0e-5, // below the shortest kept distance
            _ => 10f32.powf(rng.random_range(-3.0..4.7)),
        };
        let n = random_unit(&mut rng);
        let metal = if k % 3 == 0 {
            1.0
        } else {
            rng.random_range(0.0..1.0)
        };
        let albedo = Vec3::new(rng.random(), rng.random(), rng.random());
        input.extend_from_slice(&[pixel[0] as f32, pixel[1] as f32, frame as f32, distance]);
        input.extend_from_slice(&[n.x, n.y, n.z, metal]);
        input.extend_from_slice(&[albedo.x, albedo.y, albedo.z, 0.0]);
        let u = reference::blue_noise_2d(pixel, frame);
        let (dir, cos) = reference::cosine_direction(n, u);
        expected.push((
            u,
            dir,
            cos,
            pack_hit(Some(distance), albedo),
            reference::uniform_weight(u.x),
            reference::hit_albedo(albedo, metal),
        ));
    }
    let in_buf = ctx
        .device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("test.rtgi.in"),
            contents: bytemuck::cast_slice(&input),
            usage: wgpu::BufferUsages::STORAGE,
        });
    let mut rt = GraphRuntime::new();
    let mut g = rt.begin_frame(&ctx);
    let inputs = g.import_buffer("test.rtgi.in", &in_buf);
    let outputs = g.buffer("test.rtgi.out", (cases * 48) as u64).unwrap();
    rtgi.record_check(&mut g, inputs, outputs, cases as u32)
        .unwrap();
    g.readback(outputs);
    let r = g.execute().unwrap();
    let out: Vec<[u32; 4]> = bytemuck::pod_collect_to_vec(r.buffer("test.rtgi.out").unwrap());
    let f = |v: u32| f32::from_bits(v);
    let mut worst_dir = 0.0f32;
    for (k, (u, dir, cos, word, weight, albedo)) in expected.iter().enumerate() {
        let [a, b, c] = [out[3 * k], out[3 * k + 1], out[3 * k + 2]];
        assert_eq!(Vec2::new(f(b[0]), f(b[1])), *u, "case {k}: blue noise");
        let gdir = Vec3::new(f(a[0]), f(a[1]), f(a[2]));
        worst_dir = worst_dir.max((gdir - *dir).abs().max_element());
        assert!(
            (gdir - *dir).abs().max_element() <= 1e-3,
            "case {k}: direction {gdir} vs {dir}"
        );
        assert!((f(a[3]) - cos).abs() <= 1e-6, "case {k}: cosine");
        assert_eq!(b[2], *word, "case {k}: hit word {:#x} vs {word:#x}", b[2]);
        // Two square roots (3 ulp each in Vulkan) subtracted and scaled by 256: at most
        // 2e-4 absolute on weights of at least 0.5.
        assert!(
            (f(b[3]) - weight).abs() <= 1e-3 * weight,
            "case {k}: weight"
        );
        let galb = Vec3::new(f(c[0]), f(c[1]), f(c[2]));
        assert!(
            (galb - *albedo).abs().max_element() <= 1e-6,
            "case {k}: albedo"
        );
    }
    eprintln!("worst direction component error {worst_dir:e}");
}

/// The hit word keeps the distance to f16's half-ulp (2^-11 relative) and √albedo to half a
/// step of 5 (R, B) or 6 (G) bits; special words stay apart from every hit.
#[test]
fn hit_words_keep_their_stated_precision() {
    let mut rng = SmallRng::seed_from_u64(5);
    for _ in 0..20_000 {
        let t = 10f32.powf(rng.random_range(-3.0..4.7));
        let a = Vec3::new(rng.random(), rng.random(), rng.random());
        match unpack_hit(pack_hit(Some(t), a)) {
            HitWord::Hit { distance, albedo } => {
                assert!(
                    (distance - t).abs() <= t * 2f32.powi(-11) * 1.0001,
                    "{t} -> {distance}"
                );
                let s = |x: f32| x.sqrt();
                assert!((s(albedo.x) - s(a.x)).abs() <= 0.5 / 31.0 + 1e-6);
                assert!((s(albedo.y) - s(a.y)).abs() <= 0.5 / 63.0 + 1e-6);
                assert!((s(albedo.z) - s(a.z)).abs() <= 0.5 / 31.0 + 1e-6);
            }
            other => panic!("{t}, {a}: {other:?}"),
        }
    }
    // The shortest distance and black albedo are still a hit, not "not traced".
    assert!(matches!(
        unpack_hit(pack_hit(Some(0.0), Vec3::ZERO)),
        HitWord::Hit { .. }
    ));
    assert_eq!(unpack_hit(pack_hit(None, Vec3::ONE)), HitWord::Miss);
    assert_eq!(unpack_hit(reference::HIT_NOT_TRACED), HitWord::NotTraced);
    assert_eq!(unpack_hit(reference::HIT_UNRESOLVED), HitWord::Unresolved);
    assert!(matches!(
        unpack_hit(pack_hit(Some(f32::NAN), Vec3::splat(f32::NAN))),
        HitWord::Hit { .. }
    ));
}

/// The rays of a 64 x 64 tile over one frame follow the cosine lobe (E[cos] = 2/3) and the
/// uniform-hemisphere weight averages to 1 (its estimator of the hemisphere's solid angle
/// over 2π), both analytic; the 8-bit noise and 4096 strata leave well under 1 % of E[cos].
#[test]
fn rays_follow_the_cosine_lobe_and_weights_average_to_one() {
    let n = Vec3::new(0.3, 0.8, -0.52).normalize();
    for frame in [0u32, 1, 17, 63] {
        let (mut cos_sum, mut w_sum, mut below) = (0.0f64, 0.0f64, 0);
        for y in 0..64 {
            for x in 0..64 {
                let (d, cos) = reference::ray_direction([x, y], frame, n);
                assert!((d.dot(n) - cos).abs() < 1e-5);
                below += (d.dot(n) <= 0.0) as u32;
                cos_sum += cos as f64;
                let (d2, w) = reference::ray([x, y], frame, n);
                assert_eq!(d, d2);
                w_sum += w as f64;
            }
        }
        let cos_mean = cos_sum / 4096.0;
        let w_mean = w_sum / 4096.0;
        assert_eq!(below, 0);
        assert!(
            (cos_mean - 2.0 / 3.0).abs() < 0.01,
            "frame {frame}: E[cos] {cos_mean}"
        );
        // Each 8-bit value appears 16 times in a slice, so the bin-averaged weight's mean is 1
        // to rounding.
        assert!((w_mean - 1.0).abs() < 1e-4, "frame {frame}: E[w] {w_mean}");
    }
    // Frames differ (the set is sampled by frame), and repeat after 64.
    assert_ne!(
        reference::blue_noise_2d([3, 4], 0),
        reference::blue_noise_2d([3, 4], 1)
    );
    assert_eq!(
        reference::blue_noise_2d([3, 4], 5),
        reference::blue_noise_2d([3, 4], 69)
    );
}
