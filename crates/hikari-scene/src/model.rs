//! The scene model.
//!
//! Units: lengths in metres; colours linear Rec.709; the sun in lux (illuminance on a surface
//! facing it); point and spot lights in candela (luminous intensity, with constructors from
//! lumens); emissive surfaces in nits (cd/m², emitted luminance). Textures are decoded RGBA8.

use glam::{Mat4, Vec2, Vec3, Vec4};
use thiserror::Error;

use crate::Deformation;

/// Interior mask used when neither the mesh nor the material gives one: "don't know", halfway
/// between outdoors (0) and indoors (1).
pub const DEFAULT_INTERIOR: f32 = 0.5;

#[derive(Debug, Error, PartialEq)]
pub enum SceneError {
    #[error("mesh `{mesh}`: {what}")]
    Mesh { mesh: String, what: String },
    #[error("instance {index}: {what}")]
    Instance { index: usize, what: String },
    #[error("camera `{camera}`: {what}")]
    Camera { camera: String, what: String },
    #[error("sun: {0}")]
    Sun(String),
    #[error("material `{material}`: {what}")]
    Material { material: String, what: String },
    #[error("texture `{texture}`: {what}")]
    Texture { texture: String, what: String },
    #[error("light `{light}`: {what}")]
    Light { light: String, what: String },
    #[error("particles `{emitter}`: {what}")]
    Particles { emitter: String, what: String },
    #[error("the scene has no camera named `{wanted}`; it has: {have}")]
    NoSuchCamera { wanted: String, have: String },
}

/// Triangle mesh, counter-clockwise front faces, in metres.
///
/// `positions`, `normals` and `indices` are always present. The other per-vertex streams are
/// either empty (absent) or exactly one entry per position; [`Scene::validate`] checks that.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    pub name: String,
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    pub indices: Vec<u32>,
    /// Tangent frame as in glTF: `xyz` unit tangent along +u, `w` = ±1 such that the
    /// bitangent (direction of +v) is `w * cross(normal, tangent)`. Empty: none.
    pub tangents: Vec<Vec4>,
    /// First texture coordinate set; (0, 0) is the top-left of the image, as in glTF.
    /// Empty: none.
    pub uvs: Vec<Vec2>,
    /// Linear RGBA vertex colours, multiplied into the base colour. `None`: white.
    pub colors: Option<Vec<Vec4>>,
    /// Per-vertex interior mask in [0, 1] (0 outdoors, 1 indoors). Empty: use the
    /// material's [`Material::interior`], else [`DEFAULT_INTERIOR`].
    pub interior: Vec<f32>,
    /// Vertex animation in object space, evaluated by [`Mesh::deformed`]; `None`: static.
    /// Every instance of the mesh moves the same way.
    pub deformation: Option<Deformation>,
}

impl Mesh {
    /// The interior mask of vertex `vertex` drawn with `material`: the vertex's own value,
    /// else the material's, else [`DEFAULT_INTERIOR`].
    pub fn interior_at(&self, vertex: usize, material: &Material) -> f32 {
        self.interior
            .get(vertex)
            .copied()
            .or(material.interior)
            .unwrap_or(DEFAULT_INTERIOR)
    }

    /// Axis-aligned bounds of the positions in object space; `None` for an empty mesh.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let first = *self.positions.first()?;
        Some(
            self.positions
                .iter()
                .fold((first, first), |(lo, hi), p| (lo.min(*p), hi.max(*p))),
        )
    }
}

/// Texture addressing outside [0, 1], as glTF samplers give it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Wrap {
    #[default]
    Repeat,
    MirroredRepeat,
    ClampToEdge,
}

/// A decoded image with its sampler's addressing, row-major from the top-left texel.
///
/// `data` holds the values as stored in the file: base colour and emissive textures are
/// sRGB-encoded, the others (metallic-roughness, normal, occlusion) are linear, as glTF says.
/// Missing channels are filled as G = B = R for one-channel images and A = 255.
#[derive(Clone, Debug, Default)]
pub struct Texture {
    pub name: String,
    pub width: u32,
    pub height: u32,
    /// `width * height * 4` bytes, RGBA8.
    pub data: Vec<u8>,
    pub wrap_s: Wrap,
    pub wrap_t: Wrap,
}

/// A material's use of one of [`Scene::textures`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TextureRef {
    /// Index into [`Scene::textures`].
    pub texture: usize,
    /// Which UV set; only set 0 ([`Mesh::uvs`]) is loaded.
    pub uv_set: u32,
}

impl TextureRef {
    pub fn new(texture: usize) -> Self {
        Self { texture, uv_set: 0 }
    }
}

/// Anisotropic specular, following KHR_materials_anisotropy's parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Anisotropy {
    /// In [0, 1]: 0 is isotropic.
    pub strength: f32,
    /// Radians, counter-clockwise from the tangent in the tangent plane.
    pub rotation: f32,
}

/// How a material's alpha (the base colour factor's alpha times the base colour texture's A,
/// times vertex colour A) decides coverage, as glTF's `alphaMode`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum AlphaMode {
    /// Alpha is ignored: fully covered.
    #[default]
    Opaque,
    /// Cut-out: covered where alpha >= `cutoff`, absent elsewhere. `cutoff` in [0, 1];
    /// glTF's default is [`AlphaMode::DEFAULT_CUTOFF`].
    Mask { cutoff: f32 },
    /// Alpha blending. Transparency is not drawn yet: renderers treat it as a
    /// [`AlphaMode::Mask`] at [`AlphaMode::BLEND_AS_MASK_CUTOFF`] (see
    /// [`Material::alpha_cutoff`]).
    Blend,
}

impl AlphaMode {
    /// glTF's `alphaCutoff` when a MASK material gives none.
    pub const DEFAULT_CUTOFF: f32 = 0.5;
    /// The cut-off at which [`AlphaMode::Blend`] materials are drawn until transparency exists.
    pub const BLEND_AS_MASK_CUTOFF: f32 = 0.5;

    /// A cut-out at glTF's default cut-off, 0.5.
    pub fn mask() -> Self {
        AlphaMode::Mask {
            cutoff: Self::DEFAULT_CUTOFF,
        }
    }
}

/// Metallic-roughness material; colours are linear Rec.709.
///
/// Each factor multiplies its texture where there is one, as in glTF: the base colour texture
/// (RGB, A for alpha), metallic-roughness (B metalness, G roughness), emissive (RGB), normal
/// (tangent space, scaled in XY by `normal_scale`) and occlusion (R, blended by
/// `occlusion_strength`).
#[derive(Clone, Debug)]
pub struct Material {
    pub name: String,
    pub base_color: Vec3,
    /// Perceptual roughness in [0, 1].
    pub roughness: f32,
    pub metalness: f32,
    /// Emitted luminance in nits (cd/m²).
    pub emissive_nits: Vec3,
    /// Base colour alpha (coverage) in [0, 1], multiplied by the base colour texture's A;
    /// used as [`Material::alpha_mode`] says (ignored when opaque).
    pub alpha: f32,
    pub alpha_mode: AlphaMode,
    /// Both faces are drawn and lit (the back face with the flipped normal); otherwise back
    /// faces are culled.
    pub double_sided: bool,
    pub base_color_texture: Option<TextureRef>,
    pub metallic_roughness_texture: Option<TextureRef>,
    pub normal_texture: Option<TextureRef>,
    pub normal_scale: f32,
    pub emissive_texture: Option<TextureRef>,
    pub occlusion_texture: Option<TextureRef>,
    pub occlusion_strength: f32,
    pub anisotropy: Option<Anisotropy>,
    /// Interior mask in [0, 1] for meshes without a per-vertex one.
    pub interior: Option<f32>,
    /// Whether instances of this emissive material are polygonal area lights (`Some(true)`),
    /// never are (`Some(false)`), or follow the renderer's size and power rule (`None`);
    /// glTF material `extras` `{"hikari": {"area_light": true}}`. docs/area-lights.md.
    pub area_light: Option<bool>,
    /// Albedo (linear Rec.709, each channel in [0, 1]) that ray-traced GI gives hits on this
    /// material instead of the one it measures by rendering each mesh drawn with it from six
    /// directions; `None`: measured. glTF material `extras`
    /// `{"hikari": {"gi_albedo": [r, g, b]}}`. docs/ray-traced-gi.md, "Per-instance albedo".
    pub gi_albedo: Option<Vec3>,
    /// Weight in [0, 1] of the dielectric's specular reflection (glTF KHR_materials_specular
    /// `specularFactor`): 1 is the usual F0 = 0.04 interface, 0 a matte surface that reflects
    /// like Lambert's law (a measured matte paint, the published Cornell box). Metals ignore
    /// it. docs/brdf.md.
    pub specular: f32,
}

impl Default for Material {
    fn default() -> Self {
        Self {
            name: "default".into(),
            base_color: Vec3::splat(0.8),
            roughness: 0.5,
            metalness: 0.0,
            emissive_nits: Vec3::ZERO,
            alpha: 1.0,
            alpha_mode: AlphaMode::Opaque,
            double_sided: false,
            base_color_texture: None,
            metallic_roughness_texture: None,
            normal_texture: None,
            normal_scale: 1.0,
            emissive_texture: None,
            occlusion_texture: None,
            occlusion_strength: 1.0,
            anisotropy: None,
            interior: None,
            area_light: None,
            gi_albedo: None,
            specular: 1.0,
        }
    }
}

impl Material {
    pub fn diffuse(name: &str, base_color: Vec3) -> Self {
        Self {
            name: name.into(),
            base_color,
            roughness: 0.8,
            metalness: 0.0,
            ..Default::default()
        }
    }

    /// A black surface emitting `nits` (cd/m²).
    pub fn emissive(name: &str, nits: Vec3) -> Self {
        Self {
            name: name.into(),
            base_color: Vec3::ZERO,
            roughness: 1.0,
            emissive_nits: nits,
            ..Default::default()
        }
    }

    /// The coverage test a renderer applies: `None` when opaque (draw every fragment), else
    /// `Some(c)`: discard fragments whose alpha is below `c`. [`AlphaMode::Blend`] gives
    /// [`AlphaMode::BLEND_AS_MASK_CUTOFF`] until transparency exists.
    pub fn alpha_cutoff(&self) -> Option<f32> {
        match self.alpha_mode {
            AlphaMode::Opaque => None,
            AlphaMode::Mask { cutoff } => Some(cutoff),
            AlphaMode::Blend => Some(AlphaMode::BLEND_AS_MASK_CUTOFF),
        }
    }

    fn textures(&self) -> impl Iterator<Item = (&'static str, TextureRef)> + '_ {
        [
            ("base colour", self.base_color_texture),
            ("metallic-roughness", self.metallic_roughness_texture),
            ("normal", self.normal_texture),
            ("emissive", self.emissive_texture),
            ("occlusion", self.occlusion_texture),
        ]
        .into_iter()
        .filter_map(|(what, t)| Some((what, t?)))
    }
}

#[derive(Clone, Debug)]
pub struct Instance {
    pub mesh: usize,
    pub material: usize,
    /// Object to world.
    pub transform: Mat4,
}

#[derive(Clone, Debug)]
pub struct Camera {
    pub name: String,
    pub position: Vec3,
    pub target: Vec3,
    /// Vertical field of view in degrees.
    pub vfov_deg: f32,
    /// Near plane distance in metres (the far plane is at infinity).
    pub near: f32,
    /// World-space up hint for the view's roll; need not be orthogonal to the view direction
    /// but must not be parallel to it.
    pub up: Vec3,
}

impl Default for Camera {
    fn default() -> Self {
        Self {
            name: "main".into(),
            position: Vec3::new(0.0, 1.0, 5.0),
            target: Vec3::ZERO,
            vfov_deg: 45.0,
            near: 0.1,
            up: Vec3::Y,
        }
    }
}

impl Camera {
    pub fn view(&self) -> Mat4 {
        Mat4::look_at_rh(self.position, self.target, self.up)
    }

    /// Unit vector along the view direction.
    pub fn forward(&self) -> Vec3 {
        (self.target - self.position).normalize()
    }

    /// Reverse-Z, infinite far plane: depth 1 at `near`, 0 at infinity.
    pub fn projection(&self, aspect: f32) -> Mat4 {
        Mat4::perspective_infinite_reverse_rh(self.vfov_deg.to_radians(), aspect, self.near)
    }
}

/// The sun (or moon) as a directional light.
#[derive(Clone, Debug, PartialEq)]
pub struct Sun {
    /// Unit vector from the scene towards the sun.
    pub direction: Vec3,
    /// Illuminance on a surface facing the sun, in lux.
    pub illuminance_lux: f32,
    /// Linear Rec.709 colour, scaled so its luminance is 1.
    pub color: Vec3,
}

impl Sun {
    /// Illuminance of the default sun: a clear-sky midday sun, in lux.
    pub const DEFAULT_LUX: f32 = 100_000.0;
}

impl Default for Sun {
    /// The sun given to scenes that bring no light of their own: [`Sun::DEFAULT_LUX`], white,
    /// about 49° above the horizon (direction normalize(-0.45, 0.75, 0.35), Y up), so that
    /// vertical faces facing -X and +Z are lit as well as the ground.
    fn default() -> Self {
        Self {
            direction: Vec3::new(-0.45, 0.75, 0.35).normalize(),
            illuminance_lux: Self::DEFAULT_LUX,
            color: Vec3::ONE,
        }
    }
}

/// Point or spot light shape.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightKind {
    Point,
    /// Cone half-angles from the axis in radians, 0 <= inner < outer <= pi/2: full intensity
    /// inside `inner`, none outside `outer` (as KHR_lights_punctual).
    Spot {
        inner_cone: f32,
        outer_cone: f32,
    },
}

/// A punctual light in physical units.
#[derive(Clone, Debug, PartialEq)]
pub struct Light {
    pub name: String,
    pub kind: LightKind,
    /// World position in metres.
    pub position: Vec3,
    /// Unit vector the spot points along (ignored by point lights).
    pub direction: Vec3,
    /// Luminous intensity in candela (lm/sr); for a spot, on its axis.
    pub intensity_cd: f32,
    /// Linear Rec.709 colour, scaled so its luminance is 1.
    pub color: Vec3,
    /// Distance in metres beyond which the light may be treated as zero; `None`: infinite.
    pub range: Option<f32>,
    /// Radius in metres of the light's emitting sphere, which softens its ray-traced shadows
    /// (finite, >= 0; 0 is a hard shadow); `None`: the renderer's setting
    /// (`area_lights.punctual_radius_m`). It does not change the light's intensity.
    pub radius_m: Option<f32>,
}

impl Light {
    pub fn point(name: &str, position: Vec3, intensity_cd: f32, color: Vec3) -> Self {
        Self {
            name: name.into(),
            kind: LightKind::Point,
            position,
            direction: Vec3::NEG_Y,
            intensity_cd,
            color,
            range: None,
            radius_m: None,
        }
    }

    /// An isotropic point light emitting `lumens` in total: I = Φ / 4π.
    pub fn point_lumens(name: &str, position: Vec3, lumens: f32, color: Vec3) -> Self {
        Self::point(name, position, lumens / (4.0 * std::f32::consts::PI), color)
    }

    pub fn spot(
        name: &str,
        position: Vec3,
        direction: Vec3,
        intensity_cd: f32,
        inner_cone: f32,
        outer_cone: f32,
        color: Vec3,
    ) -> Self {
        Self {
            kind: LightKind::Spot {
                inner_cone,
                outer_cone,
            },
            direction: direction.normalize(),
            ..Self::point(name, position, intensity_cd, color)
        }
    }

    /// A spot emitting `lumens` into its outer cone: I = Φ / (2π (1 - cos outer)), the
    /// intensity a spot would have if all its flux were spread evenly over the outer cone's
    /// solid angle (the soft edge between the cones is ignored, so this slightly
    /// underestimates the flux actually emitted).
    pub fn spot_lumens(
        name: &str,
        position: Vec3,
        direction: Vec3,
        lumens: f32,
        inner_cone: f32,
        outer_cone: f32,
        color: Vec3,
    ) -> Self {
        let solid_angle = 2.0 * std::f32::consts::PI * (1.0 - outer_cone.cos());
        Self::spot(
            name,
            position,
            direction,
            lumens / solid_angle,
            inner_cone,
            outer_cone,
            color,
        )
    }
}

#[derive(Clone, Debug, Default)]
pub struct Scene {
    pub meshes: Vec<Mesh>,
    pub materials: Vec<Material>,
    pub instances: Vec<Instance>,
    pub cameras: Vec<Camera>,
    pub sun: Option<Sun>,
    /// Point and spot lights.
    pub lights: Vec<Light>,
    /// Images referenced by [`Material`]s through [`TextureRef`].
    pub textures: Vec<Texture>,
    /// Fog and smoke sprites (docs/particles.md).
    pub particles: Vec<crate::ParticleEmitter>,
}

fn finite(v: Vec3) -> bool {
    v.is_finite()
}

impl Scene {
    /// Checks everything the GPU would trust blindly: index ranges, finite numbers.
    pub fn validate(&self) -> Result<(), SceneError> {
        for m in &self.meshes {
            let err = |what: String| SceneError::Mesh {
                mesh: m.name.clone(),
                what,
            };
            if m.normals.len() != m.positions.len() {
                return Err(err(format!(
                    "{} normals for {} positions",
                    m.normals.len(),
                    m.positions.len()
                )));
            }
            if m.indices.len() % 3 != 0 {
                return Err(err(format!(
                    "{} indices is not a whole number of triangles",
                    m.indices.len()
                )));
            }
            if let Some(i) = m.positions.iter().position(|p| !finite(*p)) {
                return Err(err(format!(
                    "position {i} is not finite: {:?}",
                    m.positions[i]
                )));
            }
            if let Some(i) = m.normals.iter().position(|n| !finite(*n)) {
                return Err(err(format!("normal {i} is not finite: {:?}", m.normals[i])));
            }
            if let Some(i) = m
                .indices
                .iter()
                .position(|&ix| ix as usize >= m.positions.len())
            {
                return Err(err(format!(
                    "index {i} is {} but there are {} vertices",
                    m.indices[i],
                    m.positions.len()
                )));
            }
            let n = m.positions.len();
            let streams = [
                ("tangents", m.tangents.len()),
                ("uvs", m.uvs.len()),
                ("colors", m.colors.as_ref().map_or(n, Vec::len)),
                ("interior", m.interior.len()),
            ];
            for (what, len) in streams {
                if len != 0 && len != n {
                    return Err(err(format!("{len} {what} for {n} positions")));
                }
            }
            if let Some(i) = m.tangents.iter().position(|t| !t.is_finite()) {
                return Err(err(format!(
                    "tangent {i} is not finite: {:?}",
                    m.tangents[i]
                )));
            }
            if let Some(i) = m.uvs.iter().position(|t| !t.is_finite()) {
                return Err(err(format!("uv {i} is not finite: {:?}", m.uvs[i])));
            }
            if let Some(i) = m.colors.iter().flatten().position(|c| !c.is_finite()) {
                return Err(err(format!("colour {i} is not finite")));
            }
            if let Some(i) = m.interior.iter().position(|v| !(0.0..=1.0).contains(v)) {
                return Err(err(format!(
                    "interior mask {i} is {}, outside [0, 1]",
                    m.interior[i]
                )));
            }
            if let Some(d) = &m.deformation {
                d.check().map_err(err)?;
            }
        }
        for (t_index, t) in self.textures.iter().enumerate() {
            let expected = t.width as u64 * t.height as u64 * 4;
            if t.width == 0 || t.height == 0 || t.data.len() as u64 != expected {
                return Err(SceneError::Texture {
                    texture: format!("{t_index} {}", t.name),
                    what: format!(
                        "{}x{} RGBA8 needs {expected} bytes, has {}",
                        t.width,
                        t.height,
                        t.data.len()
                    ),
                });
            }
        }
        for m in &self.materials {
            let err = |what: String| SceneError::Material {
                material: m.name.clone(),
                what,
            };
            if !(m.base_color.is_finite() && m.base_color.min_element() >= 0.0) {
                return Err(err(format!(
                    "base colour {} must be finite and non-negative",
                    m.base_color
                )));
            }
            if !(m.emissive_nits.is_finite() && m.emissive_nits.min_element() >= 0.0) {
                return Err(err(format!(
                    "emission {} nits must be finite and non-negative",
                    m.emissive_nits
                )));
            }
            let unit = [
                ("roughness", m.roughness),
                ("metalness", m.metalness),
                ("alpha", m.alpha),
                ("occlusion strength", m.occlusion_strength),
                ("interior", m.interior.unwrap_or(0.0)),
                ("specular", m.specular),
                (
                    "anisotropy strength",
                    m.anisotropy.map_or(0.0, |a| a.strength),
                ),
            ];
            for (what, v) in unit {
                if !(0.0..=1.0).contains(&v) {
                    return Err(err(format!("{what} {v} is outside [0, 1]")));
                }
            }
            if let Some(a) = m.gi_albedo
                && !(a.is_finite() && a.min_element() >= 0.0 && a.max_element() <= 1.0)
            {
                return Err(err(format!(
                    "GI albedo override {a} must be finite with each channel in [0, 1]"
                )));
            }
            if let AlphaMode::Mask { cutoff } = m.alpha_mode
                && !(0.0..=1.0).contains(&cutoff)
            {
                return Err(err(format!(
                    "alpha cutoff {cutoff} is outside [0, 1] (or not a number)"
                )));
            }
            if !m.normal_scale.is_finite() || !m.anisotropy.is_none_or(|a| a.rotation.is_finite()) {
                return Err(err(
                    "normal scale and anisotropy rotation must be finite".into()
                ));
            }
            for (what, t) in m.textures() {
                if t.texture >= self.textures.len() {
                    return Err(err(format!(
                        "{what} texture {} of {}",
                        t.texture,
                        self.textures.len()
                    )));
                }
            }
        }
        for l in &self.lights {
            l.validate()?;
        }
        for e in &self.particles {
            e.validate()?;
        }
        for (index, inst) in self.instances.iter().enumerate() {
            let err = |what: String| SceneError::Instance { index, what };
            if inst.mesh >= self.meshes.len() {
                return Err(err(format!("mesh {} of {}", inst.mesh, self.meshes.len())));
            }
            if inst.material >= self.materials.len() {
                return Err(err(format!(
                    "material {} of {}",
                    inst.material,
                    self.materials.len()
                )));
            }
            if !inst.transform.is_finite() {
                return Err(err("transform is not finite".into()));
            }
        }
        for c in &self.cameras {
            c.validate()?;
        }
        if let Some(s) = &self.sun {
            s.validate()?;
        }
        Ok(())
    }

    pub fn camera(&self, name: &str) -> Result<&Camera, SceneError> {
        self.cameras
            .iter()
            .find(|c| c.name == name)
            .ok_or_else(|| SceneError::NoSuchCamera {
                wanted: name.into(),
                have: self
                    .cameras
                    .iter()
                    .map(|c| c.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", "),
            })
    }

    pub fn triangle_count(&self) -> usize {
        self.instances
            .iter()
            .map(|i| self.meshes[i.mesh].indices.len() / 3)
            .sum()
    }

    /// World-space axis-aligned bounds of every instance (the transformed corners of each
    /// mesh's bounds); `None` when nothing has geometry.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let mut out: Option<(Vec3, Vec3)> = None;
        for inst in &self.instances {
            let Some((lo, hi)) = self.meshes.get(inst.mesh).and_then(Mesh::bounds) else {
                continue;
            };
            for corner in 0..8 {
                let c = Vec3::new(
                    if corner & 1 == 0 { lo.x } else { hi.x },
                    if corner & 2 == 0 { lo.y } else { hi.y },
                    if corner & 4 == 0 { lo.z } else { hi.z },
                );
                let w = inst.transform.transform_point3(c);
                out = Some(out.map_or((w, w), |(a, b)| (a.min(w), b.max(w))));
            }
        }
        out
    }
}

impl Camera {
    /// A camera named `name` that sees the whole box `lo..hi` at any aspect ratio of at least
    /// 1 (wider than tall): it looks at the box centre from the +Z, +Y, +X side, backed off
    /// until the bounding sphere fits inside the vertical field of view.
    /// Eye height of [`Camera::horizon`], in metres: a standing person's.
    pub const HORIZON_EYE_HEIGHT_M: f32 = 1.7;

    /// A camera for a scene with nothing to frame: at the origin, [`Self::HORIZON_EYE_HEIGHT_M`]
    /// up, looking level along -z so that the horizon crosses the middle of the image.
    pub fn horizon(name: &str) -> Camera {
        let eye = Vec3::new(0.0, Self::HORIZON_EYE_HEIGHT_M, 0.0);
        Camera {
            name: name.into(),
            position: eye,
            target: eye - Vec3::Z,
            ..Default::default()
        }
    }

    pub fn framing(name: &str, lo: Vec3, hi: Vec3) -> Camera {
        let vfov_deg = 45.0f32;
        let center = 0.5 * (lo + hi);
        let radius = (0.5 * (hi - lo).length()).max(1e-3);
        // A sphere of radius r fits a cone of half-angle a when seen from r / sin(a).
        let distance = radius / (0.5 * vfov_deg.to_radians()).sin() * 1.05;
        let dir = Vec3::new(0.35, 0.45, 1.0).normalize();
        Camera {
            name: name.into(),
            position: center + dir * distance,
            target: center,
            vfov_deg,
            near: (distance - radius).max(distance * 1e-3) * 0.5,
            up: Vec3::Y,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f32::consts::PI;

    #[test]
    fn lumens_convert_to_candela() {
        let p = Light::point_lumens("bulb", Vec3::ZERO, 800.0, Vec3::ONE);
        assert!((p.intensity_cd - 800.0 / (4.0 * PI)).abs() < 1e-4);
        // A hemisphere spot (outer cone pi/2) spreads its flux over 2 pi sr.
        let s = Light::spot_lumens(
            "spot",
            Vec3::ZERO,
            Vec3::new(0.0, -2.0, 0.0),
            800.0,
            0.5,
            PI / 2.0,
            Vec3::ONE,
        );
        assert!((s.intensity_cd - 800.0 / (2.0 * PI)).abs() < 1e-3);
        assert_eq!(s.direction, Vec3::NEG_Y);
        let scene = Scene {
            lights: vec![p, s],
            ..Default::default()
        };
        scene.validate().unwrap();
    }

    #[test]
    fn interior_mask_falls_back_from_vertex_to_material_to_default() {
        let mut m = Mesh {
            positions: vec![Vec3::ZERO; 2],
            ..Default::default()
        };
        let plain = Material::default();
        let indoor = Material {
            interior: Some(1.0),
            ..Default::default()
        };
        assert_eq!(m.interior_at(1, &plain), DEFAULT_INTERIOR);
        assert_eq!(m.interior_at(1, &indoor), 1.0);
        m.interior = vec![0.0, 0.25];
        assert_eq!(m.interior_at(1, &indoor), 0.25);
    }

    #[test]
    fn validate_checks_the_new_streams_and_objects() {
        let tri = || Mesh {
            name: "tri".into(),
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            normals: vec![Vec3::Z; 3],
            indices: vec![0, 1, 2],
            ..Default::default()
        };
        let scene = |mesh: Mesh, material: Material| Scene {
            meshes: vec![mesh],
            materials: vec![material],
            instances: vec![Instance {
                mesh: 0,
                material: 0,
                transform: Mat4::IDENTITY,
            }],
            ..Default::default()
        };
        scene(tri(), Material::default()).validate().unwrap();
        let short_uvs = Mesh {
            uvs: vec![Vec2::ZERO; 2],
            ..tri()
        };
        let e = scene(short_uvs, Material::default())
            .validate()
            .unwrap_err()
            .to_string();
        assert!(e.contains("2 uvs for 3 positions"), "{e}");
        let bad_interior = Mesh {
            interior: vec![0.0, 2.0, 0.0],
            ..tri()
        };
        let e = scene(bad_interior, Material::default())
            .validate()
            .unwrap_err()
            .to_string();
        assert!(e.contains("interior mask 1 is 2"), "{e}");
        let bad_tex = Material {
            normal_texture: Some(TextureRef::new(0)),
            ..Default::default()
        };
        let e = scene(tri(), bad_tex).validate().unwrap_err().to_string();
        assert!(e.contains("normal texture 0 of 0"), "{e}");
        let bad_rough = Material {
            roughness: 1.5,
            ..Default::default()
        };
        let e = scene(tri(), bad_rough).validate().unwrap_err().to_string();
        assert!(e.contains("roughness 1.5"), "{e}");
        for v in [f32::NAN, -0.5] {
            let bad_specular = Material {
                specular: v,
                ..Default::default()
            };
            let e = scene(tri(), bad_specular)
                .validate()
                .unwrap_err()
                .to_string();
            assert!(
                e.contains(&format!("specular {v} is outside [0, 1]")),
                "{e}"
            );
        }
        let mut s = scene(tri(), Material::default());
        s.textures.push(Texture {
            name: "t".into(),
            width: 2,
            height: 2,
            data: vec![0; 15],
            ..Default::default()
        });
        assert!(
            s.validate()
                .unwrap_err()
                .to_string()
                .contains("needs 16 bytes, has 15")
        );
        let mut s = scene(tri(), Material::default());
        s.lights.push(Light::spot(
            "s",
            Vec3::ZERO,
            Vec3::Y,
            1.0,
            0.6,
            0.5,
            Vec3::ONE,
        ));
        assert!(
            s.validate()
                .unwrap_err()
                .to_string()
                .contains("cone angles")
        );
        let mut s = scene(tri(), Material::default());
        s.cameras.push(Camera {
            up: Vec3::new(0.0, 0.0, -3.0),
            ..Default::default()
        });
        s.cameras[0].target = s.cameras[0].position + Vec3::Z;
        assert!(s.validate().unwrap_err().to_string().contains("parallel"));
    }
}
