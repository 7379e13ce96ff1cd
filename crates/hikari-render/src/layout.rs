//! Rust mirrors of WGSL structs are checked against naga's layout of the WGSL, field by field,
//! in a test (`tests/render/struct_layout.rs`), so the two never drift.

/// A Rust struct's layout as the layout test compares it with the WGSL struct of that name.
#[derive(Debug)]
pub struct StructLayout {
    /// WGSL struct name (the Rust struct has the same name and field names).
    pub name: &'static str,
    /// Entry shader that declares or imports the struct.
    pub shader: &'static str,
    pub size: usize,
    pub fields: Vec<(&'static str, usize)>,
}

/// `gpu_layout!(Type, "shader/path.wgsl", [field, ...])`.
#[macro_export]
macro_rules! gpu_layout {
    ($t:ty, $shader:literal, [$($f:ident),* $(,)?]) => {
        $crate::layout::StructLayout {
            name: stringify!($t).rsplit("::").next().unwrap_or(stringify!($t)).trim(),
            shader: $shader,
            size: ::std::mem::size_of::<$t>(),
            fields: vec![$((stringify!($f), ::std::mem::offset_of!($t, $f))),*],
        }
    };
}

/// Every GPU struct of the crate.
pub fn all() -> Vec<StructLayout> {
    use crate::checks::{graph_check, math_check};
    use crate::raster;
    use crate::scene_gpu;
    use crate::techniques::{
        clouds, debug_view, direct_lighting, exposure, gi_denoiser, haze, irradiance_probes,
        local_tonemap, particles, ray_traced_gi, reflection_probes, sky, sun_shadows, taa, tonemap,
    };
    use crate::view;
    vec![
        gpu_layout!(
            reflection_probes::ReflectionProbeGpu,
            "reflection_probes/relight.wgsl",
            [to_box, capture, half_m]
        ),
        gpu_layout!(
            reflection_probes::CaptureParams,
            "reflection_probes/capture.wgsl",
            [face, capture]
        ),
        gpu_layout!(
            reflection_probes::RelightParams,
            "reflection_probes/relight.wgsl",
            [sun, sun_color, probes, config, cutoff]
        ),
        gpu_layout!(
            reflection_probes::PrefilterParams,
            "reflection_probes/prefilter.wgsl",
            [level, probes]
        ),
        gpu_layout!(
            clouds::CloudParams,
            "clouds/march.wgsl",
            [layer, shape, offset, sun, phase, march, slice, shadow]
        ),
        gpu_layout!(
            haze::HazeParams,
            "haze/light.wgsl",
            [
                grid,
                slicing,
                exponential,
                layer,
                scatter,
                sun,
                sun_lux,
                lights
            ]
        ),
        gpu_layout!(
            haze::HazeTemporal,
            "haze/light.wgsl",
            [jitter_blend, rescale]
        ),
        gpu_layout!(
            particles::ParticleGpu,
            "particles/particles.wgsl",
            [position_radius, albedo_opacity, rect]
        ),
        gpu_layout!(
            particles::ParticleParams,
            "particles/particles.wgsl",
            [sun_lux, sun_dir, sky, ms, count]
        ),
        gpu_layout!(
            gi_denoiser::GiDenoiserParams,
            "gi_denoiser/spatial.wgsl",
            [radius, rotation, scales, flags, disk]
        ),
        gpu_layout!(
            view::View,
            "gbuffer/resolve.wgsl",
            [
                view_proj,
                inv_view_proj,
                position,
                viewport,
                prev_view_proj,
                forward_near,
                jitter
            ]
        ),
        gpu_layout!(
            scene_gpu::VertexAttr,
            "gbuffer/resolve.wgsl",
            [uv, normal, tangent, color, extra, pad]
        ),
        gpu_layout!(
            scene_gpu::InstanceGpu,
            "gbuffer/resolve.wgsl",
            [model, normal_model, prev_model, material, flags, pad]
        ),
        gpu_layout!(
            scene_gpu::MaterialGpu,
            "gbuffer/resolve.wgsl",
            [base_color, emissive, params, extra, textures, more_textures]
        ),
        gpu_layout!(
            scene_gpu::Chunk,
            "gbuffer/resolve.wgsl",
            [instance, first_triangle, count, pad, bounds_lo, bounds_hi]
        ),
        gpu_layout!(
            scene_gpu::LightGpu,
            "direct_lighting/shade.wgsl",
            [position_range, direction_kind, intensity, spot]
        ),
        gpu_layout!(
            raster::RasterParams,
            "raster/triangles.wgsl",
            [view_proj, viewport, config, views, limits]
        ),
        gpu_layout!(
            sun_shadows::ShadowParams,
            "direct_lighting/shade.wgsl",
            [light_view_proj, texel_world, config, depth_bias, origin]
        ),
        gpu_layout!(
            sun_shadows::CopyParams,
            "sun_shadows/copy.wgsl",
            [regions, config]
        ),
        gpu_layout!(
            direct_lighting::LightingParams,
            "direct_lighting/shade.wgsl",
            [
                direction_lux,
                color,
                sky_zenith,
                sky_horizon,
                config,
                cutoff,
                reflection,
                reflection_values
            ]
        ),
        gpu_layout!(
            sky::SkyParams,
            "direct_lighting/shade.wgsl",
            [
                sun,
                moon,
                disks,
                shell,
                table,
                light_coords,
                rec709_from_working,
                white,
                transmittance_size,
                ground
            ]
        ),
        gpu_layout!(
            ray_traced_gi::RtGiParams,
            "ray_traced_gi/shade.wgsl",
            [
                config,
                distances,
                pretrace,
                sun,
                sun_color,
                sky_zenith,
                sky_horizon,
                area,
                firefly,
                exposure
            ]
        ),
        gpu_layout!(
            sky::ResampleParams,
            "sky/resample.wgsl",
            [table, light_coords]
        ),
        gpu_layout!(
            sky::SkyAmbientParams,
            "direct_lighting/shade.wgsl",
            [balance]
        ),
        gpu_layout!(
            sky::gpu_build::TableBuildParams,
            "sky/tables.wgsl",
            [
                shell,
                rayleigh,
                ozone,
                mie,
                misc,
                luminance,
                sizes_2d,
                sizes_scattering,
                sizes_density,
                sphere_order,
                offsets0,
                offsets1,
                offsets2,
                offsets3
            ]
        ),
        gpu_layout!(
            debug_view::DisplayParams,
            "debug_view/display.wgsl",
            [mode, sizes, values]
        ),
        gpu_layout!(
            taa::TaaParams,
            "taa/resolve.wgsl",
            [history_valid, clip, max_history, _pad]
        ),
        gpu_layout!(
            exposure::ExposureParams,
            "exposure/adapt.wgsl",
            [histogram, meter, rule, adapt, config]
        ),
        gpu_layout!(
            local_tonemap::LocalTonemapParams,
            "local_tonemap/apply.wgsl",
            [grid, tone, blend]
        ),
        gpu_layout!(
            local_tonemap::BlurParams,
            "local_tonemap/blur_grid.wgsl",
            [sigma, config]
        ),
        gpu_layout!(
            tonemap::TonemapParams,
            "tonemap/apply.wgsl",
            [
                lmsr_from_rgb,
                rgb_from_lms_gain,
                purkinje_fade,
                tonemap_from_rec709,
                rec709_from_tonemap,
                curve,
                curve_shoulder,
                lut_domain_min,
                lut_domain_max,
                switches,
                local
            ]
        ),
        gpu_layout!(graph_check::FillParams, "graph_check/fill.wgsl", [value]),
        gpu_layout!(graph_check::EmptyParams, "graph_check/empty.wgsl", [value]),
        gpu_layout!(
            math_check::MathCheckParams,
            "math_check/color.wgsl",
            [count, pad_a, pad_b, pad_c]
        ),
        gpu_layout!(
            crate::bvh_trace::TraceParams,
            "bvh/trace.wgsl",
            [count, image_width, pad0, pad1]
        ),
        gpu_layout!(
            crate::probe_bake_gpu::BakeParams,
            "probe_bake_gpu/bounce_rays.wgsl",
            [
                probes,
                rays_per_probe,
                bounce_rays,
                row_width,
                enclosure_radius,
                t_min,
                surface_offset,
                offset_per_metre,
                far,
                pad_a,
                pad_b,
                pad_c
            ]
        ),
        gpu_layout!(
            hikari_bvh::Ray,
            "bvh/trace.wgsl",
            [origin, t_min, dir, t_max]
        ),
        gpu_layout!(
            hikari_bvh::Hit,
            "bvh/trace.wgsl",
            [t, u, v, primitive, instance, _pad]
        ),
        gpu_layout!(
            crate::scene_bvh::AlphaInstance,
            "bvh/trace.wgsl",
            [cutoff, alpha, texture, first_triangle]
        ),
        gpu_layout!(
            crate::scene_bvh::AlphaTriangle,
            "bvh/trace.wgsl",
            [uv, alpha]
        ),
        gpu_layout!(
            irradiance_probes::RelightParams,
            "irradiance_probes/relight.wgsl",
            [light_dir, light_rgb, config, amounts]
        ),
        gpu_layout!(
            irradiance_probes::gpu_data::ProbeLookupParams,
            "direct_lighting/shade.wgsl",
            [grid, grid_size, topology]
        ),
        gpu_layout!(
            hikari_bvh::TriangleRecord,
            "bvh/trace.wgsl",
            [v0, primitive, v1, flags, v2, _pad2]
        ),
        gpu_layout!(
            hikari_bvh::InstanceRecord,
            "bvh/trace.wgsl",
            [
                world_to_object,
                blas_node_offset,
                blas_triangle_offset,
                instance_index,
                blas_index
            ]
        ),
        gpu_layout!(
            crate::techniques::area_lights::AreaLightParams,
            "area_lights/shade.wgsl",
            [config, counts, values, rotation]
        ),
        gpu_layout!(
            crate::techniques::area_lights::AreaLightGpu,
            "area_lights/shade.wgsl",
            [centroid_radius, normal_area, radiance_flux, range]
        ),
        gpu_layout!(
            crate::techniques::area_lights::AreaTriangleGpu,
            "area_lights/shade.wgsl",
            [p0_cdf, p1, p2]
        ),
        gpu_layout!(
            crate::techniques::area_lights::ShadowDenoiseParams,
            "area_lights/temporal.wgsl",
            [config, values]
        ),
    ]
}
