//! The scene model.

use glam::{Mat4, Vec3};
use thiserror::Error;

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
    #[error("the scene has no camera named `{wanted}`; it has: {have}")]
    NoSuchCamera { wanted: String, have: String },
}

/// Triangle mesh, counter-clockwise front faces, in metres.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    pub name: String,
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    pub indices: Vec<u32>,
}

/// Metallic-roughness material; colours are linear Rec.709.
#[derive(Clone, Debug)]
pub struct Material {
    pub name: String,
    pub base_color: Vec3,
    /// Perceptual roughness in [0, 1].
    pub roughness: f32,
    pub metalness: f32,
    /// Emitted luminance in nits (cd/m²).
    pub emissive_nits: Vec3,
}

impl Material {
    pub fn diffuse(name: &str, base_color: Vec3) -> Self {
        Self {
            name: name.into(),
            base_color,
            roughness: 0.8,
            metalness: 0.0,
            emissive_nits: Vec3::ZERO,
        }
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
}

impl Camera {
    pub fn view(&self) -> Mat4 {
        Mat4::look_at_rh(self.position, self.target, Vec3::Y)
    }

    /// Reverse-Z, infinite far plane: depth 1 at `near`, 0 at infinity.
    pub fn projection(&self, aspect: f32) -> Mat4 {
        Mat4::perspective_infinite_reverse_rh(self.vfov_deg.to_radians(), aspect, self.near)
    }
}

/// The sun (or moon) as a directional light.
#[derive(Clone, Debug)]
pub struct Sun {
    /// Unit vector from the scene towards the sun.
    pub direction: Vec3,
    /// Illuminance on a surface facing the sun, in lux.
    pub illuminance_lux: f32,
    /// Linear Rec.709 colour, scaled so its luminance is 1.
    pub color: Vec3,
}

#[derive(Clone, Debug, Default)]
pub struct Scene {
    pub meshes: Vec<Mesh>,
    pub materials: Vec<Material>,
    pub instances: Vec<Instance>,
    pub cameras: Vec<Camera>,
    pub sun: Option<Sun>,
}

fn finite(v: Vec3) -> bool {
    v.is_finite()
}

impl Scene {
    /// Checks everything the GPU would trust blindly: index ranges, finite numbers.
    pub fn validate(&self) -> Result<(), SceneError> {
        for m in &self.meshes {
            let err = |what: String| SceneError::Mesh { mesh: m.name.clone(), what };
            if m.normals.len() != m.positions.len() {
                return Err(err(format!(
                    "{} normals for {} positions",
                    m.normals.len(),
                    m.positions.len()
                )));
            }
            if m.indices.len() % 3 != 0 {
                return Err(err(format!("{} indices is not a whole number of triangles", m.indices.len())));
            }
            if let Some(i) = m.positions.iter().position(|p| !finite(*p)) {
                return Err(err(format!("position {i} is not finite: {:?}", m.positions[i])));
            }
            if let Some(i) = m.normals.iter().position(|n| !finite(*n)) {
                return Err(err(format!("normal {i} is not finite: {:?}", m.normals[i])));
            }
            if let Some(i) = m.indices.iter().position(|&ix| ix as usize >= m.positions.len()) {
                return Err(err(format!(
                    "index {i} is {} but there are {} vertices",
                    m.indices[i],
                    m.positions.len()
                )));
            }
        }
        for (index, inst) in self.instances.iter().enumerate() {
            let err = |what: String| SceneError::Instance { index, what };
            if inst.mesh >= self.meshes.len() {
                return Err(err(format!("mesh {} of {}", inst.mesh, self.meshes.len())));
            }
            if inst.material >= self.materials.len() {
                return Err(err(format!("material {} of {}", inst.material, self.materials.len())));
            }
            if !inst.transform.is_finite() {
                return Err(err("transform is not finite".into()));
            }
        }
        for c in &self.cameras {
            let err = |what: String| SceneError::Camera { camera: c.name.clone(), what };
            if !(c.vfov_deg > 0.0 && c.vfov_deg < 180.0) {
                return Err(err(format!("vertical field of view {} is outside (0, 180) degrees", c.vfov_deg)));
            }
            if !(c.near > 0.0 && c.near.is_finite()) {
                return Err(err(format!("near plane {} must be positive", c.near)));
            }
            if !(c.position.is_finite() && c.target.is_finite()) || c.position == c.target {
                return Err(err("position and target must be finite and distinct".into()));
            }
        }
        if let Some(s) = &self.sun
            && (!s.direction.is_finite() || s.direction.length() < 0.5 || !(s.illuminance_lux >= 0.0) || !s.color.is_finite())
        {
            return Err(SceneError::Sun(format!("{s:?} has a non-unit direction or a negative or non-finite value")));
        }
        Ok(())
    }

    pub fn camera(&self, name: &str) -> Result<&Camera, SceneError> {
        self.cameras.iter().find(|c| c.name == name).ok_or_else(|| SceneError::NoSuchCamera {
            wanted: name.into(),
            have: self.cameras.iter().map(|c| c.name.as_str()).collect::<Vec<_>>().join(", "),
        })
    }

    pub fn triangle_count(&self) -> usize {
        self.instances.iter().map(|i| self.meshes[i.mesh].indices.len() / 3).sum()
    }
}
