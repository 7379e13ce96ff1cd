//! The renderer's GPU structs and the constants its Rust and WGSL share, registered for the
//! engine's layout checks (`hikari_gpu::layout`, `tests/render/struct_layout.rs`).

pub use hikari_gpu::layout::*;
use hikari_gpu::{gpu_const, gpu_layout};

/// Every GPU struct of the crate.
pub fn all() -> Vec<StructLayout> {
    use crate::checks::{graph_check, math_check};
    use crate::scene::raster;
    use crate::scene::upload;
    use crate::techniques::{
        clouds, debug_view, direct_lighting, exposure, gi_denoiser, haze, irradiance_probes,
        local_tonemap, particles, ray_traced_gi, reflection_probes, sky, sun_shadows, taa, tonemap,
    };
    use crate::view;
    vec![
        gpu_layout!(
            crate::bc6h::gpu::Bc6hParams,
            "bc6h/encode.wgsl",
            [
                blocks_x,
                blocks_y,
                layer,
                quality,
                width,
                height,
                first_block,
                level,
                row_stride,
                layer_stride,
                _pad0,
                _pad1
            ]
        ),
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
            upload::VertexAttr,
            "gbuffer/resolve.wgsl",
            [uv, normal, tangent, color, extra, pad]
        ),
        gpu_layout!(
            upload::InstanceGpu,
            "gbuffer/resolve.wgsl",
            [model, normal_model, prev_model, material, flags, pad]
        ),
        gpu_layout!(
            upload::MaterialGpu,
            "gbuffer/resolve.wgsl",
            [base_color, emissive, params, extra, textures, more_textures]
        ),
        gpu_layout!(
            upload::Chunk,
            "gbuffer/resolve.wgsl",
            [instance, first_triangle, count, pad, bounds_lo, bounds_hi]
        ),
        gpu_layout!(
            upload::LightGpu,
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
            [history_valid, clip, max_history, _pad, jitter, ratio]
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
            crate::scene::bvh_trace::TraceParams,
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
            crate::scene::bvh::AlphaInstance,
            "bvh/trace.wgsl",
            [cutoff, alpha, texture, first_triangle]
        ),
        gpu_layout!(
            crate::scene::bvh::AlphaTriangle,
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

/// Every constant the crate's Rust and WGSL both declare, with the WGSL file that declares it. `tests/render/struct_layout.rs` checks each value against naga's module and that
/// no constant declared in both languages is missing here.
pub fn constants() -> Vec<SharedConstant> {
    vec![
        gpu_const!(crate::bc6h::reference::MAX_HALF_BITS, "bc6h/encode.wgsl"),
        gpu_const!(
            crate::techniques::taa::reference::SPREAD,
            "taa/resolve.wgsl"
        ),
        gpu_const!(
            crate::techniques::haze::reference::AIR_INTERIOR_MASK,
            "haze/light.wgsl"
        ),
        gpu_const!(
            crate::lights::polygon::AREA_LIGHT_DOUBLE_SIDED,
            "lights/area_polygon.wgsl"
        ),
        gpu_const!(
            crate::lights::polygon::AREA_LIGHT_FORCED,
            "lights/area_polygon.wgsl"
        ),
        gpu_const!(
            crate::techniques::area_lights::AREA_POLYGONS,
            "area_lights/shade.wgsl"
        ),
        gpu_const!(
            crate::techniques::area_lights::AREA_PUNCTUAL,
            "area_lights/shade.wgsl"
        ),
        gpu_const!(
            crate::scene::upload::CHUNK_TRIANGLES,
            "common/scene_gpu.wgsl"
        ),
        gpu_const!(
            crate::techniques::clouds::CLOUDS_DENSITY_AA,
            "clouds/density.wgsl"
        ),
        gpu_const!(
            crate::techniques::clouds::CLOUDS_MULTIPLE,
            "clouds/density.wgsl"
        ),
        gpu_const!(crate::techniques::clouds::CLOUDS_ON, "clouds/density.wgsl"),
        gpu_const!(
            crate::techniques::clouds::CLOUDS_SHADOWS,
            "clouds/density.wgsl"
        ),
        gpu_const!(
            crate::techniques::gi_denoiser::reference::EDGE_NORMAL_COS,
            "gi_denoiser/ao.wgsl"
        ),
        gpu_const!(
            crate::techniques::exposure::EXPOSURE_FIXED,
            "exposure/common.wgsl"
        ),
        gpu_const!(
            crate::techniques::exposure::EXPOSURE_HIGHLIGHTS,
            "exposure/common.wgsl"
        ),
        gpu_const!(
            crate::scene::upload::EXTRA_BITANGENT_NEGATIVE,
            "common/scene_gpu.wgsl"
        ),
        gpu_const!(
            crate::scene::upload::EXTRA_HAS_INTERIOR,
            "common/scene_gpu.wgsl"
        ),
        gpu_const!(
            crate::scene::upload::EXTRA_HAS_TANGENT,
            "common/scene_gpu.wgsl"
        ),
        gpu_const!(
            crate::techniques::local_tonemap::reference::FIXED,
            "local_tonemap/fill.wgsl"
        ),
        gpu_const!(
            crate::techniques::gi_denoiser::params::FLAG_RECURRENT,
            "gi_denoiser/common.wgsl"
        ),
        gpu_const!(crate::techniques::haze::HAZE_DENSITY_AA, "haze/common.wgsl"),
        gpu_const!(
            crate::techniques::haze::HAZE_LOCAL_LIGHTS,
            "haze/common.wgsl"
        ),
        gpu_const!(crate::techniques::haze::HAZE_SKY, "haze/common.wgsl"),
        gpu_const!(
            crate::techniques::haze::HAZE_SKY_OCCLUSION,
            "haze/common.wgsl"
        ),
        gpu_const!(
            crate::techniques::haze::HAZE_SUN_SHADOWS,
            "haze/common.wgsl"
        ),
        gpu_const!(crate::techniques::haze::HAZE_TRICUBIC, "haze/common.wgsl"),
        gpu_const!(
            crate::techniques::exposure::reference::INCIDENT_C,
            "exposure/adapt.wgsl"
        ),
        gpu_const!(
            crate::scene::upload::INSTANCE_DOUBLE_SIDED,
            "common/scene_gpu.wgsl"
        ),
        gpu_const!(
            crate::scene::upload::INSTANCE_MOVED,
            "common/scene_gpu.wgsl"
        ),
        gpu_const!(
            crate::scene::upload::INSTANCE_OWN_NORMAL_MATRIX,
            "common/scene_gpu.wgsl"
        ),
        gpu_const!(
            crate::techniques::direct_lighting::LIGHTING_EMISSIVE,
            "direct_lighting/shade.wgsl"
        ),
        gpu_const!(
            crate::techniques::direct_lighting::LIGHTING_PLACEHOLDER_AMBIENT,
            "direct_lighting/shade.wgsl"
        ),
        gpu_const!(
            crate::techniques::direct_lighting::LIGHTING_PROBES,
            "direct_lighting/shade.wgsl"
        ),
        gpu_const!(
            crate::techniques::direct_lighting::LIGHTING_PUNCTUAL,
            "direct_lighting/shade.wgsl"
        ),
        gpu_const!(
            crate::techniques::direct_lighting::LIGHTING_REFLECTION_PROBES,
            "direct_lighting/shade.wgsl"
        ),
        gpu_const!(
            crate::techniques::direct_lighting::LIGHTING_RTGI,
            "direct_lighting/shade.wgsl"
        ),
        gpu_const!(
            crate::techniques::direct_lighting::LIGHTING_SKY,
            "direct_lighting/shade.wgsl"
        ),
        gpu_const!(
            crate::techniques::direct_lighting::LIGHTING_SUN,
            "direct_lighting/shade.wgsl"
        ),
        gpu_const!(
            crate::reference::lighting::MAX_RADIANCE,
            "direct_lighting/shade.wgsl"
        ),
        gpu_const!(
            crate::techniques::area_lights::denoise::MAX_VISIBILITY,
            "area_lights/denoise_common.wgsl"
        ),
        gpu_const!(
            crate::techniques::exposure::reference::NO_HIGHLIGHT,
            "exposure/common.wgsl"
        ),
        gpu_const!(
            crate::techniques::gbuffer::NO_INSTANCE,
            "ray_traced_gi/pretrace.wgsl"
        ),
        gpu_const!(crate::scene::upload::NO_TEXTURE, "common/scene_gpu.wgsl"),
        gpu_const!(
            crate::techniques::irradiance_probes::gpu_data::PROBES_GRID,
            "irradiance_probes/lookup.wgsl"
        ),
        gpu_const!(
            crate::techniques::irradiance_probes::gpu_data::PROBES_INTERIOR_MASK,
            "irradiance_probes/lookup.wgsl"
        ),
        gpu_const!(
            crate::techniques::irradiance_probes::gpu_data::PROBES_PRESENT,
            "irradiance_probes/lookup.wgsl"
        ),
        gpu_const!(
            crate::techniques::area_lights::reference::PUNCTUAL_KEY,
            "area_lights/shade.wgsl"
        ),
        gpu_const!(
            crate::techniques::exposure::reference::REFLECTED_K,
            "exposure/adapt.wgsl"
        ),
        gpu_const!(
            crate::techniques::irradiance_probes::RELIGHT_BOOST,
            "irradiance_probes/relight.wgsl"
        ),
        gpu_const!(
            crate::techniques::irradiance_probes::RELIGHT_BOUNCE,
            "irradiance_probes/relight.wgsl"
        ),
        gpu_const!(
            crate::techniques::irradiance_probes::RELIGHT_DERING,
            "irradiance_probes/relight.wgsl"
        ),
        gpu_const!(
            crate::techniques::reflection_probes::RELIGHT_PROBES,
            "reflection_probes/relight.wgsl"
        ),
        gpu_const!(
            crate::techniques::reflection_probes::RELIGHT_SHADOWS,
            "reflection_probes/relight.wgsl"
        ),
        gpu_const!(
            crate::techniques::reflection_probes::RELIGHT_SKY,
            "reflection_probes/relight.wgsl"
        ),
        gpu_const!(
            crate::techniques::irradiance_probes::RELIGHT_SUN_BOUNCE,
            "irradiance_probes/relight.wgsl"
        ),
        gpu_const!(
            crate::techniques::ray_traced_gi::reference::REPROJECTION_MIN_WEIGHT,
            "common/view.wgsl"
        ),
        gpu_const!(
            crate::techniques::ray_traced_gi::reference::REPROJECTION_SNAP,
            "common/view.wgsl"
        ),
        gpu_const!(
            crate::techniques::reflection_probes::RP_HORIZON,
            "reflection_probes/common.wgsl"
        ),
        gpu_const!(
            crate::techniques::reflection_probes::RP_NORMALIZE,
            "reflection_probes/common.wgsl"
        ),
        gpu_const!(
            crate::techniques::reflection_probes::RP_ON,
            "reflection_probes/common.wgsl"
        ),
        gpu_const!(
            crate::techniques::reflection_probes::RP_PARALLAX_ROUGHNESS,
            "reflection_probes/common.wgsl"
        ),
        gpu_const!(
            crate::techniques::area_lights::denoise::SHADOW_DENOISE_RESET,
            "area_lights/denoise_common.wgsl"
        ),
        gpu_const!(crate::scene::raster::TILE_SIZE, "raster/setup.wgsl"),
        gpu_const!(
            crate::techniques::area_lights::denoise::VISIBILITY_EPS,
            "area_lights/denoise_common.wgsl"
        ),
    ]
}

/// Names both languages declare for different things, so the completeness check skips them.
pub const UNRELATED_SAME_NAMES: [&str; 3] = [
    // The LUT strip's tile (its PNG layout) and the particles', TAA's and GI hit mean's
    // workgroup tiles.
    "TILE",
    // The GPU bake's workgroup and the GI trace's.
    "WORKGROUP",
    // The haze twin's f16 ceiling (65504) and the probes', G-buffer's and TAA's clamps below it.
    "MAX_HALF",
];
