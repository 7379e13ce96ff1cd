//! CPU twin of the G-buffer's visibility: what a visibility id names, and the ray a pixel
//! centre shoots, so tests can hold the compute rasteriser to rays cast through the same
//! pixel centres.

use glam::{Mat4, Vec2, Vec3, Vec4};

pub use crate::reference::textures::TwinTextures;
use crate::scene::upload::{CHUNK_TRIANGLES, SceneCpu};

/// The scene instance and the triangle within its mesh that visibility id `id` names.
pub fn decode_id(scene: &SceneCpu, id: u32, mesh_first_triangle: u32) -> Option<(u32, u32)> {
    let chunk = scene.chunks.get((id / CHUNK_TRIANGLES) as usize)?;
    let lane = id % CHUNK_TRIANGLES;
    (lane < chunk.count).then(|| {
        (
            chunk.instance,
            chunk.first_triangle + lane - mesh_first_triangle,
        )
    })
}

/// Unit direction of the camera ray through the centre of `pixel`, as `view_ray` in WGSL.
pub fn pixel_ray(inv_view_proj: Mat4, eye: Vec3, pixel: [u32; 2], size: [u32; 2]) -> Vec3 {
    let uv = (Vec2::new(pixel[0] as f32, pixel[1] as f32) + 0.5)
        / Vec2::new(size[0] as f32, size[1] as f32);
    uv_ray(inv_view_proj, eye, uv)
}

/// Unit direction of the camera ray through the normalised screen position `uv` (0..1, y
/// down), as `view_ray_uv` in WGSL.
pub fn uv_ray(inv_view_proj: Mat4, eye: Vec3, uv: Vec2) -> Vec3 {
    let near = inv_view_proj * Vec4::new(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, 1.0, 1.0);
    (near.truncate() / near.w - eye).normalize()
}

/// World position at reverse-Z depth `depth` of the centre of `pixel`, as `world_from_depth`.
pub fn world_from_depth(inv_view_proj: Mat4, pixel: [u32; 2], size: [u32; 2], depth: f32) -> Vec3 {
    let uv = (Vec2::new(pixel[0] as f32, pixel[1] as f32) + 0.5)
        / Vec2::new(size[0] as f32, size[1] as f32);
    let w = inv_view_proj * Vec4::new(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, depth, 1.0);
    w.truncate() / w.w
}

/// One pixel of the G-buffer as the resolve should write it, computed in f64 from the scene's
/// uploaded data (`SceneCpu`) and textures: textures are sampled bilinearly from their full
/// resolution image, which equals the GPU's trilinear filtering for the smooth test textures
/// the twin is used with.
#[derive(Clone, Copy, Debug)]
pub struct ResolvedTexel {
    pub normal: Vec3,
    pub base_color: Vec3,
    pub interior: f32,
    pub roughness: f32,
    pub metalness: f32,
    pub anisotropy: f32,
    pub occlusion: f32,
    pub emissive: Vec3,
    /// Dielectric specular weight (`gbuffer.emissive` alpha).
    pub specular: f32,
    /// Previous minus current pixel position.
    pub motion: Vec2,
    pub view_depth: f32,
    pub instance: u32,
}

/// The G-buffer texel of `pixel`, which sees visibility id `id`; `None` for an id that names
/// no triangle, or a material with a normal map (which the twin does not model).
pub fn resolve(
    scene: &hikari_scene::Scene,
    cpu: &SceneCpu,
    view: &crate::view::View,
    pixel: [u32; 2],
    id: u32,
) -> Option<ResolvedTexel> {
    resolve_deformed(scene, cpu, view, pixel, id, &cpu.positions)
}

/// [`resolve`] where the vertices stood at `prev_positions` last frame (`SceneGpu::
/// prev_positions`, object space): the motion follows the point of the same barycentrics on
/// last frame's triangle.
pub fn resolve_deformed(
    scene: &hikari_scene::Scene,
    cpu: &SceneCpu,
    view: &crate::view::View,
    pixel: [u32; 2],
    id: u32,
    prev_positions: &[[f32; 4]],
) -> Option<ResolvedTexel> {
    use glam::{DMat4, DVec2, DVec3, DVec4};
    let chunk = cpu.chunks.get((id / CHUNK_TRIANGLES) as usize)?;
    let lane = id % CHUNK_TRIANGLES;
    if lane >= chunk.count {
        return None;
    }
    let tri = (chunk.first_triangle + lane) as usize;
    let inst = &scene.instances[chunk.instance as usize];
    let material = &scene.materials[inst.material];
    if material.normal_texture.is_some() {
        return None;
    }
    let idx = [
        cpu.indices[tri * 3],
        cpu.indices[tri * 3 + 1],
        cpu.indices[tri * 3 + 2],
    ];
    let model = inst.transform.as_dmat4();
    let object: Vec<DVec3> = idx
        .iter()
        .map(|&i| {
            Vec4::from_array(cpu.positions[i as usize])
                .truncate()
                .as_dvec3()
        })
        .collect();
    let world: Vec<DVec3> = object.iter().map(|&p| model.transform_point3(p)).collect();
    let inv = DMat4::from_cols_array_2d(&view.inv_view_proj.map(|c| c.map(|x| x as f64)));
    let size = DVec2::new(view.viewport[0] as f64, view.viewport[1] as f64);
    let centre = DVec2::new(pixel[0] as f64 + 0.5, pixel[1] as f64 + 0.5);
    let eye = DVec3::new(
        view.position[0] as f64,
        view.position[1] as f64,
        view.position[2] as f64,
    );
    let uv = centre / size;
    let near = inv * DVec4::new(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, 1.0, 1.0);
    let dir = near.truncate() / near.w - eye;
    // Where the ray meets the triangle's plane, and its barycentrics from sub-triangle areas.
    let ng = (world[1] - world[0]).cross(world[2] - world[0]);
    let t = (world[0] - eye).dot(ng) / dir.dot(ng);
    let p = eye + dir * t;
    let area = |a: DVec3, b: DVec3, c: DVec3| (b - a).cross(c - a).dot(ng);
    let total = area(world[0], world[1], world[2]);
    let w = DVec3::new(
        area(p, world[1], world[2]) / total,
        area(world[0], p, world[2]) / total,
        area(world[0], world[1], p) / total,
    );
    let attr: Vec<&crate::scene::upload::VertexAttr> =
        idx.iter().map(|&i| &cpu.attributes[i as usize]).collect();
    let lerp3 = |f: &dyn Fn(&crate::scene::upload::VertexAttr) -> DVec3| {
        f(attr[0]) * w.x + f(attr[1]) * w.y + f(attr[2]) * w.z
    };
    let decode = |p: u32| {
        crate::reference::octahedral::decode(crate::scene::upload::unpack_snorm16x2(p)).as_dvec3()
    };
    let normal_model = glam::DMat3::from_mat4(model).inverse().transpose();
    let mut n = (normal_model * lerp3(&|a| decode(a.normal))).normalize();
    if material.double_sided && ng.dot(dir) > 0.0 {
        n = -n;
    }
    let uv_at = DVec2::new(
        lerp3(&|a| DVec3::new(a.uv[0] as f64, 0.0, 0.0)).x,
        lerp3(&|a| DVec3::new(a.uv[1] as f64, 0.0, 0.0)).x,
    );
    let tex = TwinTextures { scene };
    let sample = |r: Option<hikari_scene::TextureRef>, srgb: bool| {
        r.map_or(DVec4::ONE, |r| tex.sample(r.texture, uv_at, srgb))
    };
    let unorm16 = |c: u32| DVec2::new((c & 0xffff) as f64, (c >> 16) as f64) / 65535.0;
    let color = |a: &crate::scene::upload::VertexAttr| {
        let (rg, ba) = (unorm16(a.color[0]), unorm16(a.color[1]));
        DVec3::new(rg.x, rg.y, ba.x)
    };
    let base = material.base_color.as_dvec3()
        * lerp3(&color)
        * sample(material.base_color_texture, true).truncate();
    let mr = sample(material.metallic_roughness_texture, false);
    let occ_tex = sample(material.occlusion_texture, false).x;
    let emissive =
        material.emissive_nits.as_dvec3() * sample(material.emissive_texture, true).truncate();
    // From the scene model's own rule (`Mesh::interior_at`), not from the packed vertices.
    let mesh = &scene.meshes[inst.mesh];
    let first_vertex: usize = scene.meshes[..inst.mesh]
        .iter()
        .map(|m| m.positions.len())
        .sum();
    let interior = idx
        .iter()
        .zip([w.x, w.y, w.z])
        .map(|(&i, wk)| mesh.interior_at(i as usize - first_vertex, material) as f64 * wk)
        .sum::<f64>();
    let prev_object = idx
        .iter()
        .map(|&i| {
            prev_positions
                .get(i as usize)
                .map(|p| Vec4::from_array(*p).truncate().as_dvec3())
        })
        .collect::<Option<Vec<DVec3>>>()?;
    let q = prev_object[0] * w.x + prev_object[1] * w.y + prev_object[2] * w.z;
    let prev_vp = DMat4::from_cols_array_2d(&view.prev_view_proj.map(|c| c.map(|x| x as f64)));
    let c = prev_vp * model.transform_point3(q).extend(1.0);
    let ndc = c.truncate().truncate() / c.w;
    let prev = DVec2::new(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5) * size;
    let fwd = DVec3::new(
        view.forward_near[0] as f64,
        view.forward_near[1] as f64,
        view.forward_near[2] as f64,
    );
    Some(ResolvedTexel {
        normal: n.as_vec3(),
        base_color: base.clamp(DVec3::ZERO, DVec3::ONE).as_vec3(),
        interior: interior.clamp(0.0, 1.0) as f32,
        roughness: (material.roughness as f64 * mr.y).clamp(0.0, 1.0) as f32,
        metalness: (material.metalness as f64 * mr.z).clamp(0.0, 1.0) as f32,
        anisotropy: material
            .anisotropy
            .map_or(0.0, |a| a.strength.clamp(0.0, 1.0)),
        occlusion: (1.0 + material.occlusion_strength as f64 * (occ_tex - 1.0)).clamp(0.0, 1.0)
            as f32,
        emissive: emissive.as_vec3(),
        specular: material.specular.clamp(0.0, 1.0),
        // Now is the pixel centre less the jitter: `prev_view_proj` has none.
        motion: (prev - centre + DVec2::new(view.jitter[0] as f64, view.jitter[1] as f64))
            .as_vec2(),
        view_depth: (p - eye).dot(fwd) as f32,
        instance: chunk.instance,
    })
}
