//! The atmosphere's physical parameters, validated, and the colour space it is computed in.
//!
//! Units: lengths and radii in km, coefficients in km⁻¹ (at sea level for Rayleigh and Mie, at the
//! ozone layer's peak for ozone), illuminance in lux.

use hikari_math::color::rayleigh::{
    MIE_EXTINCTION_BRUNETON, MIE_SCALE_HEIGHT_KM, MIE_SCATTERING_BRUNETON, RAYLEIGH_LMS_PATRY,
    RAYLEIGH_REC709_BRUNETON, RAYLEIGH_SCALE_HEIGHT_KM,
};
use serde::{Deserialize, Serialize};

use crate::AtmosphereError;

/// The three-channel space the tables are computed in. Both have the D65 white, so a D65 sun is
/// `(1, 1, 1)` times its illuminance in either.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ColorSpace {
    /// The talk's LMS Rayleigh space (spectral primaries L, M, S near 605, 530, 455 nm) with its
    /// refined Rayleigh coefficients.
    #[default]
    LmsRayleigh,
    /// Linear Rec.709 with Bruneton & Neyret 2008's Rayleigh coefficients (point samples at 680,
    /// 550, 440 nm): the comparison the talk shows.
    Rec709,
}

/// Ozone absorption at the layer's peak density in the LMS Rayleigh space, km⁻¹: fitted to the
/// spectral transmittance of the D65 sun through 1 to 12 vertical ozone columns
/// (`tools/atmosphere_lms_coefficients.py`; absorption does not project linearly, see
/// `docs/atmosphere.md`).
pub const OZONE_LMS_FITTED: [f64; 3] = [0.0022841, 0.0015971, 0.0001873];
/// Ozone absorption at peak density for Rec.709, point-sampled at Bruneton's 680, 550, 440 nm
/// from the same cross-sections (Bruneton 2017's values), km⁻¹.
pub const OZONE_REC709_BRUNETON: [f64; 3] = [6.497e-4, 1.8809e-3, 8.502e-5];

/// The extraterrestrial solar illuminance at normal incidence, lux (the luminous solar constant,
/// about 133 klux; Darula, Kittler & Gueymard 2005).
pub const SOLAR_ILLUMINANCE_LUX: f64 = 133_334.0;

impl ColorSpace {
    /// Rayleigh scattering at sea level for this space, km⁻¹.
    pub fn rayleigh_per_km(self) -> [f64; 3] {
        match self {
            ColorSpace::LmsRayleigh => RAYLEIGH_LMS_PATRY,
            ColorSpace::Rec709 => RAYLEIGH_REC709_BRUNETON,
        }
    }

    /// Ozone absorption at the layer's peak for this space, km⁻¹.
    pub fn ozone_per_km(self) -> [f64; 3] {
        match self {
            ColorSpace::LmsRayleigh => OZONE_LMS_FITTED,
            ColorSpace::Rec709 => OZONE_REC709_BRUNETON,
        }
    }

    /// The space's RGB → linear Rec.709 matrix (rows).
    pub fn to_rec709(self) -> [[f64; 3]; 3] {
        match self {
            ColorSpace::LmsRayleigh => hikari_math::color::rayleigh::lms_rayleigh_to_rec709(),
            ColorSpace::Rec709 => [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        }
    }

    /// Linear Rec.709 → the space (rows).
    pub fn from_rec709(self) -> [[f64; 3]; 3] {
        match self {
            ColorSpace::LmsRayleigh => hikari_math::color::rayleigh::rec709_to_lms_rayleigh(),
            ColorSpace::Rec709 => [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        }
    }
}

/// Everything the tables depend on. Defaults: Earth as Bruneton & Neyret 2008 model it (ground
/// radius 6360 km, top of the atmosphere 6420 km; Rayleigh scale height 8 km; grey Mie aerosols,
/// 4e-3 km⁻¹ scattering, 1.2 km scale height, single-scattering albedo 0.9, Cornette-Shanks
/// asymmetry 0.8) and Bruneton 2017's ozone layer (a tent from 10 to 40 km, peak at 25 km, 300
/// Dobson units), in the LMS Rayleigh space.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AtmosphereParams {
    /// The space the tables are computed in.
    pub color_space: ColorSpace,
    /// Radius of the ground sphere, km.
    pub bottom_radius_km: f64,
    /// Radius of the top of the atmosphere, km (nothing scatters above it).
    pub top_radius_km: f64,
    /// Rayleigh scattering at sea level per channel of `color_space`, km⁻¹; `None` takes the
    /// space's own ([`ColorSpace::rayleigh_per_km`]).
    pub rayleigh_scattering_per_km: Option<[f64; 3]>,
    /// Rayleigh density `exp(−h / H)`: H in km.
    pub rayleigh_scale_height_km: f64,
    /// Mie scattering at sea level, km⁻¹ (grey: the same in every channel and every space).
    pub mie_scattering_per_km: f64,
    /// Mie extinction (scattering + absorption) at sea level, km⁻¹; at least the scattering.
    pub mie_extinction_per_km: f64,
    /// Mie density `exp(−h / H)`: H in km.
    pub mie_scale_height_km: f64,
    /// Asymmetry g of the Cornette-Shanks phase function, in [−0.999, 0.999].
    pub mie_g: f64,
    /// Ozone absorption at the layer's peak per channel, km⁻¹; `None` takes the space's own.
    pub ozone_absorption_per_km: Option<[f64; 3]>,
    /// Altitude of the ozone tent's peak, km.
    pub ozone_center_km: f64,
    /// Half width of the ozone tent, km (density falls linearly to 0 at centre ± this).
    pub ozone_half_width_km: f64,
    /// Lambertian ground albedo (grey), in [0, 1].
    pub ground_albedo: f64,
    /// Extraterrestrial solar illuminance at normal incidence, lux.
    pub solar_illuminance_lux: f64,
    /// At most this many scattering orders; at least 4 are computed (when this allows), then the
    /// build stops once an order adds under 1 % of the sky's luminance. In [1, 32].
    pub max_scattering_orders: u32,
}

impl Default for AtmosphereParams {
    fn default() -> Self {
        Self::earth(ColorSpace::LmsRayleigh)
    }
}

impl AtmosphereParams {
    /// The default Earth in the given space.
    pub fn earth(color_space: ColorSpace) -> Self {
        Self {
            color_space,
            bottom_radius_km: 6360.0,
            top_radius_km: 6420.0,
            rayleigh_scattering_per_km: None,
            rayleigh_scale_height_km: RAYLEIGH_SCALE_HEIGHT_KM,
            mie_scattering_per_km: MIE_SCATTERING_BRUNETON,
            mie_extinction_per_km: MIE_EXTINCTION_BRUNETON,
            mie_scale_height_km: MIE_SCALE_HEIGHT_KM,
            mie_g: 0.8,
            ozone_absorption_per_km: None,
            ozone_center_km: 25.0,
            ozone_half_width_km: 15.0,
            ground_albedo: 0.1,
            solar_illuminance_lux: SOLAR_ILLUMINANCE_LUX,
            max_scattering_orders: 8,
        }
    }

    /// Rayleigh scattering in use, km⁻¹.
    pub fn rayleigh(&self) -> [f64; 3] {
        self.rayleigh_scattering_per_km
            .unwrap_or(self.color_space.rayleigh_per_km())
    }

    /// Ozone absorption at peak in use, km⁻¹.
    pub fn ozone(&self) -> [f64; 3] {
        self.ozone_absorption_per_km
            .unwrap_or(self.color_space.ozone_per_km())
    }

    /// Checks every field; the error names the first bad one and its allowed range.
    pub fn validate(&self) -> Result<(), AtmosphereError> {
        fn check(
            field: &'static str,
            value: f64,
            ok: impl Fn(f64) -> bool,
            allowed: &'static str,
        ) -> Result<(), AtmosphereError> {
            if value.is_finite() && ok(value) {
                Ok(())
            } else {
                Err(AtmosphereError::OutOfRange {
                    field,
                    value,
                    allowed,
                })
            }
        }
        let nonneg = |v: f64| v >= 0.0;
        check(
            "bottom_radius_km",
            self.bottom_radius_km,
            |v| (1.0..=1e6).contains(&v),
            "finite, in [1, 1e6] km",
        )?;
        let depth = self.top_radius_km - self.bottom_radius_km;
        check(
            "top_radius_km",
            self.top_radius_km,
            |_| (1.0..=1000.0).contains(&depth),
            "finite, between bottom_radius_km + 1 and bottom_radius_km + 1000 km",
        )?;
        for v in self.rayleigh() {
            check(
                "rayleigh_scattering_per_km",
                v,
                nonneg,
                "finite and >= 0 km^-1",
            )?;
        }
        let positive_height = |v: f64| v >= 0.01;
        check(
            "rayleigh_scale_height_km",
            self.rayleigh_scale_height_km,
            positive_height,
            "finite and >= 0.01 km",
        )?;
        check(
            "mie_scattering_per_km",
            self.mie_scattering_per_km,
            nonneg,
            "finite and >= 0 km^-1",
        )?;
        check(
            "mie_extinction_per_km",
            self.mie_extinction_per_km,
            |v| v >= self.mie_scattering_per_km,
            "finite and >= mie_scattering_per_km",
        )?;
        check(
            "mie_scale_height_km",
            self.mie_scale_height_km,
            positive_height,
            "finite and >= 0.01 km",
        )?;
        check(
            "mie_g",
            self.mie_g,
            |v| v.abs() <= 0.999,
            "in [-0.999, 0.999]",
        )?;
        for v in self.ozone() {
            check(
                "ozone_absorption_per_km",
                v,
                nonneg,
                "finite and >= 0 km^-1",
            )?;
        }
        check(
            "ozone_center_km",
            self.ozone_center_km,
            nonneg,
            "finite and >= 0 km",
        )?;
        check(
            "ozone_half_width_km",
            self.ozone_half_width_km,
            |v| v >= 0.01,
            "finite and >= 0.01 km",
        )?;
        check(
            "ground_albedo",
            self.ground_albedo,
            |v| (0.0..=1.0).contains(&v),
            "in [0, 1]",
        )?;
        check(
            "solar_illuminance_lux",
            self.solar_illuminance_lux,
            |v| v > 0.0 && v <= 1e7,
            "finite, in (0, 1e7] lux",
        )?;
        check(
            "max_scattering_orders",
            self.max_scattering_orders as f64,
            |v| (1.0..=32.0).contains(&v),
            "an integer in [1, 32]",
        )?;
        Ok(())
    }

    /// Densities (Rayleigh, Mie, ozone) relative to their reference at altitude `h_km`.
    pub fn densities(&self, h_km: f64) -> [f64; 3] {
        let ozone = (1.0 - (h_km - self.ozone_center_km).abs() / self.ozone_half_width_km).max(0.0);
        [
            (-h_km / self.rayleigh_scale_height_km).exp(),
            (-h_km / self.mie_scale_height_km).exp(),
            ozone,
        ]
    }

    /// Extinction per channel at altitude `h_km`, km⁻¹.
    pub fn extinction(&self, h_km: f64) -> [f64; 3] {
        let [r, m, o] = self.densities(h_km);
        let (br, bo) = (self.rayleigh(), self.ozone());
        std::array::from_fn(|c| br[c] * r + self.mie_extinction_per_km * m + bo[c] * o)
    }
}
