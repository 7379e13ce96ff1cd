//! CPU twin of the exposure passes (`exposure.meter`, `exposure.adapt`).

use super::{EXPOSURE_FIXED, EXPOSURE_HIGHLIGHTS, ExposureParams};

/// Bins of each of the two histograms.
pub const HISTOGRAM_BINS: usize = 128;

/// ISO 2720's incident-light calibration constant (EV100 = log2(E × 100 / C), E in lux).
pub const INCIDENT_C: f32 = 250.0;
/// The reflected-light constant K (EV100 = log2(L × 100 / K), L in nits).
pub const REFLECTED_K: f32 = 12.5;

/// Rec.709 luminance weights.
pub const LUMA: [f32; 3] = hikari_math::color::REC709_LUMA;

/// Where the histograms' bins lie.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HistogramLayout {
    /// log2 lux at the lower edge of illuminance bin 0.
    pub illuminance_log2_min: f32,
    pub illuminance_bins_per_ev: f32,
    /// log2 nits at the lower edge of luminance bin 0.
    pub luminance_log2_min: f32,
    pub luminance_bins_per_ev: f32,
}

impl HistogramLayout {
    /// Illuminance from 2^-12 lux (a moonless overcast night is ~10^-4) to 2^20 (the sun is
    /// ~2^17) in quarter stops; luminance from 2^-16 to 2^32 nits (the sun's disk is ~2^30)
    /// in 3/8 stops. The ends collect everything beyond them.
    pub const DEFAULT: Self = Self {
        illuminance_log2_min: -12.0,
        illuminance_bins_per_ev: HISTOGRAM_BINS as f32 / 32.0,
        luminance_log2_min: -16.0,
        luminance_bins_per_ev: HISTOGRAM_BINS as f32 / 48.0,
    };
}

pub fn histogram_bin(log2_value: f32, lo: f32, bins_per_ev: f32) -> usize {
    ((log2_value - lo) * bins_per_ev)
        .floor()
        .clamp(0.0, (HISTOGRAM_BINS - 1) as f32) as usize
}

/// Luminance in nits of linear Rec.709 radiance; NaN and negatives give 0.
pub fn luminance(rgb: [f32; 3]) -> f32 {
    let y = rgb[0] * LUMA[0] + rgb[1] * LUMA[1] + rgb[2] * LUMA[2];
    if y >= 0.0 { y } else { 0.0 }
}

/// Twin of `exposure.meter`: the illuminance bins (pixels with `illuminance[i] >= 0`), then
/// the luminance bins (every pixel).
pub fn meter(radiance: &[[f32; 3]], illuminance: &[f32], params: &ExposureParams) -> Vec<u32> {
    let n = [illuminance.len() as u32, 1];
    meter_scaled(radiance, n, illuminance, n, params)
}

/// [`meter`] below render scale 1: `illuminance` at the render's `size`, `radiance` at the
/// output's `radiance_size` (row-major); each illuminance pixel `p` counts the radiance pixel
/// `p * radiance_size / size` (integer division, as the shader does), so both histograms
/// count the render's pixels.
pub fn meter_scaled(
    radiance: &[[f32; 3]],
    radiance_size: [u32; 2],
    illuminance: &[f32],
    size: [u32; 2],
    params: &ExposureParams,
) -> Vec<u32> {
    let h = params.histogram;
    let mut bins = vec![0u32; 2 * HISTOGRAM_BINS];
    for (i, &e) in illuminance.iter().enumerate() {
        let (x, y) = (i as u32 % size[0], i as u32 / size[0]);
        if e >= 0.0 {
            bins[histogram_bin(e.max(1e-30).log2(), h[0], h[1])] += 1;
        }
        let (rx, ry) = (
            x * radiance_size[0] / size[0],
            y * radiance_size[1] / size[1],
        );
        let l = luminance(radiance[(ry * radiance_size[0] + rx) as usize]);
        bins[HISTOGRAM_BINS + histogram_bin(l.max(1e-30).log2(), h[2], h[3])] += 1;
    }
    bins
}

/// Mean of the bin centres between the fractions `lo` and `hi` of the counts.
pub fn trimmed_mean(bins: &[u32], lo: f32, hi: f32, bin0: f32, per_ev: f32) -> f32 {
    let n: f32 = bins.iter().map(|&c| c as f32).sum();
    let (a, b) = (lo * n, hi * n);
    let (mut cum, mut sum, mut w) = (0f32, 0f32, 0f32);
    for (i, &c) in bins.iter().enumerate() {
        let c = c as f32;
        let overlap = ((cum + c).min(b) - cum.max(a)).max(0.0);
        sum += overlap * (bin0 + (i as f32 + 0.5) / per_ev);
        w += overlap;
        cum += c;
    }
    sum / w.max(1e-6)
}

/// The value below which the fraction `p` of the counts lies, linear within its bin.
pub fn percentile(bins: &[u32], p: f32, bin0: f32, per_ev: f32) -> f32 {
    let n: f32 = bins.iter().map(|&c| c as f32).sum();
    let t = p * n;
    let mut cum = 0f32;
    for (i, &c) in bins.iter().enumerate() {
        let c = c as f32;
        if c > 0.0 && cum + c >= t {
            return bin0 + (i as f32 + ((t - cum) / c).clamp(0.0, 1.0)) / per_ev;
        }
        cum += c;
    }
    bin0 + bins.len() as f32 / per_ev
}

/// The metered illuminance (log2 lux) and the target EV100 before adaptation.
pub fn target(bins: &[u32], p: &ExposureParams) -> (f32, f32) {
    let h = p.histogram;
    let (illum, lum) = bins.split_at(HISTOGRAM_BINS);
    let n_e: f32 = illum.iter().map(|&c| c as f32).sum();
    let n_l: f32 = lum.iter().map(|&c| c as f32).sum();
    let mut log2_lux = (INCIDENT_C / 100.0).log2();
    if n_e >= (0.01 * n_l).max(1.0) {
        log2_lux = trimmed_mean(illum, p.meter[0], p.meter[1], h[0], h[1]);
    } else if n_l > 0.0 {
        log2_lux = trimmed_mean(lum, p.meter[0], p.meter[1], h[2], h[3])
            + (INCIDENT_C / REFLECTED_K).log2();
    }
    let mut ev = log2_lux + (100.0 / INCIDENT_C).log2();
    if p.config[0] & EXPOSURE_HIGHLIGHTS != 0 && n_l > 0.0 {
        let hi = percentile(lum, p.meter[2], h[2], h[3]);
        let excess = hi - 1.2f32.log2() - ev - p.meter[3];
        ev += p.rule[0] * excess.max(0.0);
    }
    (log2_lux, (ev - p.rule[1]).clamp(p.rule[2], p.rule[3]))
}

/// One frame of adaptation from `prev` (`None`: no history, snap) towards `target`.
pub fn adapt(prev: Option<f32>, target: f32, p: &ExposureParams) -> f32 {
    let dt = p.adapt[2];
    if p.config[0] & EXPOSURE_FIXED != 0 {
        return p.adapt[3];
    }
    match prev {
        Some(prev) if dt > 0.0 => prev + (target - prev).clamp(-p.adapt[1] * dt, p.adapt[0] * dt),
        _ => target,
    }
}

/// `exposure.value.w` when no pixel was metered (a fixed exposure): no highlight, so the local
/// tonemap's highlight fit leaves the look's contrast alone.
pub const NO_HIGHLIGHT: f32 = -1000.0;

/// Exposure multiplier for a camera at `ev100` (saturation-based sensitivity, Lagarde and de
/// Rousiers 2014, eq. 15 with q = 0.65, S = 100, K = 12.5): the scale of `exposure.value`.
pub fn scale_from_ev100(ev100: f32) -> f32 {
    1.0 / (1.2 * 2f32.powf(ev100))
}

/// Twin of `exposure.adapt`: `exposure.value` for histograms `bins` and last frame's EV100.
pub fn value(bins: &[u32], prev: Option<f32>, p: &ExposureParams) -> [f32; 4] {
    let (log2_lux, t) = target(bins, p);
    let ev = adapt(prev, t, p);
    [
        scale_from_ev100(ev),
        ev,
        log2_lux.exp2(),
        highlight(bins, ev, p),
    ]
}

/// `exposure.value.w`: the exposed log2 luminance (at `ev`) of the highlight percentile of all
/// pixels, or [`NO_HIGHLIGHT`] when nothing was metered.
pub fn highlight(bins: &[u32], ev: f32, p: &ExposureParams) -> f32 {
    let lum = &bins[HISTOGRAM_BINS..];
    if lum.iter().all(|&c| c == 0) {
        return NO_HIGHLIGHT;
    }
    percentile(lum, p.meter[2], p.histogram[2], p.histogram[3]) - 1.2f32.log2() - ev
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::techniques::exposure::ExposureSettings;

    fn params(s: &ExposureSettings) -> ExposureParams {
        ExposureParams::new(s, 0.0, 0.0)
    }

    /// A uniform grey world of E lux meters to the incident-meter rule EV100 = log2(E / 2.5),
    /// within the bin's half width, from starlight to noon.
    #[test]
    fn uniform_illuminance_meters_to_the_incident_rule() {
        let s = ExposureSettings {
            highlights: false,
            ..Default::default()
        };
        let p = params(&s);
        for lux in [0.05f32, 1.0, 300.0, 100_000.0] {
            let rgb = [0.18 * lux / std::f32::consts::PI; 3];
            let bins = meter(&vec![rgb; 64], &[lux; 64], &p);
            let v = value(&bins, None, &p);
            let want = (lux / 2.5).log2();
            assert!(
                (v[1] - want).abs() <= 0.125 + 1e-4,
                "{lux} lux: {} vs {want}",
                v[1]
            );
            assert!((v[0] - 1.0 / (1.2 * 2f32.powf(v[1]))).abs() < 1e-6 * v[0].max(1.0));
        }
    }

    /// The highlight rule against its definition: 5 % of the pixels are a fire of luminance
    /// L under the same 1000 lux. Below the limit the fire changes nothing (luminance takes no
    /// part); above it, EV100 rises by `highlight_strength` × (log2(L × scale) − limit), within
    /// the bins' widths (1/8 EV for the illuminance mean, 3/8 for the fire's percentile).
    #[test]
    fn only_highlights_over_the_limit_raise_the_exposure() {
        let s = ExposureSettings::default();
        let p = params(&s);
        let off = params(&ExposureSettings {
            highlights: false,
            ..s.clone()
        });
        let lux = 1000.0f32;
        let grey = [0.18 * lux / std::f32::consts::PI; 3];
        let ev_of = |fire_nits: f32, p: &ExposureParams| {
            let radiance: Vec<[f32; 3]> = (0..1000)
                .map(|i| if i % 20 == 0 { [fire_nits; 3] } else { grey })
                .collect();
            value(&meter(&radiance, &[lux; 1000], p), None, p)[1]
        };
        let ev0 = (lux / 2.5).log2();
        let tolerance = 0.125 * (1.0 + s.highlight_strength) + 0.375 * s.highlight_strength;
        for over_ev in [-3.0f32, 2.0, 4.0, 8.0] {
            // The fire exposed at ev0 is 2^(limit + over_ev).
            let nits = 1.2 * (ev0 + s.highlight_limit_ev + over_ev).exp2();
            let plain = ev_of(nits, &off);
            assert!((plain - ev0).abs() <= 0.125 + 1e-4, "{plain} vs {ev0}");
            let got = ev_of(nits, &p);
            if over_ev < 0.0 {
                assert_eq!(got, plain, "a fire under the limit counts for nothing");
            } else {
                let want = ev0 + s.highlight_strength * over_ev;
                assert!(
                    (got - want).abs() <= tolerance,
                    "{over_ev} EV over: {got} vs {want}"
                );
            }
        }
    }

    #[test]
    fn adaptation_moves_at_its_speeds_and_a_fixed_ev_wins() {
        let mut s = ExposureSettings {
            frame_seconds: 0.5,
            ..Default::default()
        };
        let p = params(&s);
        assert_eq!(adapt(Some(0.0), 10.0, &p), 1.5);
        assert_eq!(adapt(Some(10.0), 0.0, &p), 9.5);
        assert_eq!(adapt(Some(10.0), 10.2, &p), 10.2);
        assert_eq!(adapt(None, 7.0, &p), 7.0);
        s.ev100 = Some(3.0);
        assert_eq!(adapt(Some(10.0), 0.0, &params(&s)), 3.0);
    }
}
