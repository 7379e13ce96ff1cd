//! The physically based BRDF of hikari's direct lighting, and the CPU twin of
//! `crates/hikari-render/shaders/common/brdf.wgsl` (`hikari::brdf`, the same functions with a
//! `brdf_` prefix, in `f32`).
//!
//! Ghost of Tsushima's shading model (Patry 2021): GGX specular NDF with optional anisotropy,
//! Smith visibility, Schlick Fresnel, Lambertian diffuse; energy conserving and energy
//! preserving: the light single scattering loses comes back as a multiple-scattering lobe
//! (Kulla & Conty 2017), and the diffuse lobe gets what the specular lobe does not reflect
//! (Kelemen & Szirmay-Kalos 2001), so a white material reflects all it receives at every
//! roughness and angle (docs/brdf.md).
//!
//! | module | what it holds |
//! |---|---|
//! | [`material`] | [`Material`] (metallic-roughness), `alpha = roughness²`, the anisotropy → `(alpha_x, alpha_y)` mapping, F0 |
//! | [`ggx`] | GGX / Trowbridge-Reitz `D(h)`, isotropic and anisotropic (Walter et al. 2007) |
//! | [`smith`] | Smith `Λ`, `G1`, height-correlated `G2` and `V = G2 / (4 n·l n·v)` (Heitz 2014) |
//! | [`fresnel`] | Schlick's Fresnel (Schlick 1994) |
//! | [`diffuse`] | Lambert, and the albedo-scaled Lambert the full BRDF uses |
//! | [`albedo`] | directional albedo tables `E(μ, r)`, `E_w(μ, r)` and their averages (quadrature, and the data the GPU reads, `hikari::brdf_tables`) |
//! | [`energy`] | [`energy::Compensation`]: the multiple-scattering lobe and the diffuse weights from the tables |
//! | (`evaluate.rs`) | [`evaluate()`]: `f(v, l) · n·l` for a material, also [`evaluate_isotropic`], the `_f64` forms and [`Lobes`] |
//! | [`sampling`] | VNDF importance sampling of the specular lobe (Heitz 2018) |
//!
//! ## Conventions
//!
//! * `v` points toward the viewer, `l` toward the light, `h = normalize(v + l)`; all unit.
//!   Frame `(t, b, n)`: tangent, bitangent, normal, orthonormal; a tangent-frame vector is
//!   `(t·w, b·w, n·w)` (the normal is +Z, as in [`crate::sampling::ggx`]).
//! * `alpha = perceptual_roughness²` (Burley 2012, Karis 2013), roughness clamped to
//!   [[`material::MIN_PERCEPTUAL_ROUGHNESS`], 1].
//! * Units: `D` and the BRDF are in sr⁻¹; `G1`, `G2`, `V`, `F` are dimensionless.
//!   [`evaluate()`] returns `f · n·l` (sr⁻¹): times a light's irradiance (lux or W m⁻²) it
//!   gives reflected radiance (nits or W m⁻² sr⁻¹).
//! * Precision: the scalar kernels and the `_f64` entry points compute in `f64`, which the
//!   quadrature tests need; [`evaluate()`] takes and returns `f32` (`Vec3`), as the G-buffer
//!   stores it, and promotes internally.
//!
//! ```
//! use glam::Vec3;
//! use hikari_math::brdf::{Material, evaluate};
//!
//! let gold = Material::metal(Vec3::new(1.0, 0.78, 0.34), 0.3).with_anisotropy(0.5);
//! let (n, t, b) = (Vec3::Z, Vec3::X, Vec3::Y);
//! let v = Vec3::new(0.3, 0.0, 1.0).normalize();
//! let l = Vec3::new(-0.3, 0.1, 1.0).normalize();
//! let sun_lux = 100_000.0;
//! let nits = evaluate(&gold, n, t, b, v, l) * sun_lux;
//! assert!(nits.x > nits.z);
//! ```
//!
//! ## Sources
//!
//! Walter, Marschner, Li & Torrance 2007, "Microfacet Models for Refraction through Rough
//! Surfaces"; Heitz 2014, "Understanding the Masking-Shadowing Function in Microfacet-Based
//! BRDFs" (JCGT 3(2)); Heitz 2018, "Sampling the GGX Distribution of Visible Normals" (JCGT
//! 7(4)); Burley 2012, "Physically-Based Shading at Disney"; Karis 2013, "Real Shading in
//! Unreal Engine 4"; Schlick 1994, "An Inexpensive BRDF Model for Physically-based
//! Rendering"; Shirley, Hu, Smits & Lafortune 1997, "A Practitioners' Assessment of Light
//! Reflection Models"; Kelemen & Szirmay-Kalos 2001, "A Microfacet Based Coupled
//! Specular-Matte BRDF Model with Importance Sampling"; Kulla & Conty 2017, "Revisiting
//! Physically Based Shading at Imageworks" (SIGGRAPH course); Patry 2021, Ghost of Tsushima (SIGGRAPH Advances).

pub mod albedo;
pub mod diffuse;
pub mod energy;
mod evaluate;
pub mod fresnel;
pub mod ggx;
pub mod material;
pub mod sampling;
pub mod smith;

pub use evaluate::{
    Lobes, evaluate, evaluate_f64, evaluate_isotropic, evaluate_isotropic_f64, evaluate_lobes_f64,
};
pub use material::Material;
