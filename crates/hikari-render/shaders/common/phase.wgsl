#define_import_path hikari::phase

// Henyey-Greenstein phase function, per steradian, of the cosine between the light's direction
// of travel and the scattered direction (1: straight on); mean cosine g. The haze's and the
// clouds'. CPU twin: hikari-atmosphere's `phase::henyey_greenstein`.
fn hg_phase(cos_theta: f32, g: f32) -> f32 {
    let d = max(1.0 + g * g - 2.0 * g * cos_theta, 1e-6);
    return (1.0 - g * g) / (4.0 * 3.14159265358979 * d * sqrt(d));
}
