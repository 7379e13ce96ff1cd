#define_import_path hikari::exposure

// What the exposure passes share: their constants and the histogram's layout. CPU twin:
// `techniques/exposure/reference.rs`.

struct ExposureParams {
    // x: log2 lux at the lower edge of illuminance bin 0, y: illuminance bins per EV,
    // z: log2 nits at the lower edge of luminance bin 0, w: luminance bins per EV.
    histogram: vec4<f32>,
    // x, y: the fractions of surface pixels between which log2 illuminance is averaged,
    // z: the highlight's fraction of all pixels, w: highlight limit, exposed log2 luminance.
    meter: vec4<f32>,
    // x: highlight strength, y: compensation EV (the weather's hint included),
    // z, w: least and greatest EV100.
    rule: vec4<f32>,
    // x, y: adaptation speed as EV100 rises and falls, EV/s, z: seconds since the last frame
    // (0: snap), w: the fixed EV100 when config.x has EXPOSURE_FIXED.
    adapt: vec4<f32>,
    // x: EXPOSURE_* flags, yzw: unused.
    config: vec4<u32>,
}

const EXPOSURE_FIXED: u32 = 1u;
const EXPOSURE_HIGHLIGHTS: u32 = 2u;

// `exposure.value.w` when no pixel was metered (a fixed exposure): no highlight.
const NO_HIGHLIGHT: f32 = -1000.0;

// Bins of each histogram; the buffer holds the illuminance bins, then the luminance bins.
const HISTOGRAM_BINS: u32 = 128u;

// Rec.709 luminance weights.
const LUMA: vec3<f32> = vec3<f32>(0.2126, 0.7152, 0.0722);

fn histogram_bin(log2_value: f32, lo: f32, bins_per_ev: f32) -> u32 {
    return u32(clamp(floor((log2_value - lo) * bins_per_ev), 0.0, f32(HISTOGRAM_BINS - 1u)));
}
