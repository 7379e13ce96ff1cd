//! Builds the default tables and prints the build time, the per-order contributions and a few
//! values: `cargo run --release -p hikari-atmosphere --example atmosphere_build [rec709]`.

use glam::Vec3;
use hikari_atmosphere::{Atmosphere, AtmosphereParams, ColorSpace};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let space = if std::env::args().any(|a| a == "rec709") {
        ColorSpace::Rec709
    } else {
        ColorSpace::LmsRayleigh
    };
    let a = Atmosphere::new(AtmosphereParams::earth(space))?;
    println!("build: {:.0} ms", a.report.build_ms);
    for (i, c) in a.report.order_contributions.iter().enumerate() {
        println!("order {}: {:.4} of the orders before it", i + 1, c);
    }
    for zenith_deg in [0.0f32, 30.0, 60.0, 85.0, 90.0] {
        let z = zenith_deg.to_radians();
        let sun = Vec3::new(z.sin(), z.cos(), 0.0);
        let e = a.sun_illuminance_at_ground(z);
        let sky = a.sky_irradiance(0.0, z, a.solar_illuminance());
        let zen = a.sky_radiance(0.0, Vec3::Y, sun, a.solar_illuminance());
        println!(
            "sun {zenith_deg:>4}°: direct normal {e:.0} lux, sky on horizontal {sky:.0} lux, zenith {zen:.0} nits"
        );
    }
    Ok(())
}
