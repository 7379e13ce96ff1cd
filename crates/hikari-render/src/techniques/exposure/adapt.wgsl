// The frame's exposure from the histograms: the incident-meter rule on a trimmed mean of log2
// illuminance, darkened where highlights exceed their limit, compensated, clamped, and moved
// towards from last frame's value at the adaptation speeds. The workgroup copies the 256 bins
// to workgroup memory together; then one thread walks them there (a serial walk over global
// memory waits on a load each step).

#import hikari::exposure::{ExposureParams, EXPOSURE_FIXED, EXPOSURE_HIGHLIGHTS, HISTOGRAM_BINS, NO_HIGHLIGHT}

@group(0) @binding(0) var<uniform> params: ExposureParams;
@group(0) @binding(1) var<storage, read> histogram_in: array<u32>;
@group(0) @binding(2) var prev_state: texture_2d<f32>;
@group(0) @binding(3) var state: texture_storage_2d<rgba32float, write>;
@group(0) @binding(4) var<storage, read_write> value: vec4<f32>;

// ISO 2720's incident-light calibration constant C and the reflected-light K: a reflected
// reading equals an incident one for E = L * C / K.
var<workgroup> histogram: array<u32, 256>;

const INCIDENT_C: f32 = 250.0;
const REFLECTED_K: f32 = 12.5;

fn count(first: u32) -> f32 {
    var n = 0.0;
    for (var i = 0u; i < HISTOGRAM_BINS; i++) {
        n += f32(histogram[first + i]);
    }
    return n;
}

// Mean of the bin centres between the fractions lo and hi of the n counts.
fn trimmed_mean(first: u32, n: f32, lo: f32, hi: f32, bin0: f32, per_ev: f32) -> f32 {
    let a = lo * n;
    let b = hi * n;
    var cum = 0.0;
    var sum = 0.0;
    var w = 0.0;
    for (var i = 0u; i < HISTOGRAM_BINS; i++) {
        let c = f32(histogram[first + i]);
        let overlap = max(0.0, min(cum + c, b) - max(cum, a));
        sum += overlap * (bin0 + (f32(i) + 0.5) / per_ev);
        w += overlap;
        cum += c;
    }
    return sum / max(w, 1e-6);
}

// The value below which the fraction p of the n counts lies, linear within its bin.
fn percentile(first: u32, n: f32, p: f32, bin0: f32, per_ev: f32) -> f32 {
    let t = p * n;
    var cum = 0.0;
    for (var i = 0u; i < HISTOGRAM_BINS; i++) {
        let c = f32(histogram[first + i]);
        if c > 0.0 && cum + c >= t {
            return bin0 + (f32(i) + clamp((t - cum) / c, 0.0, 1.0)) / per_ev;
        }
        cum += c;
    }
    return bin0 + f32(HISTOGRAM_BINS) / per_ev;
}

@compute @workgroup_size(256, 1, 1)
fn main(@builtin(local_invocation_index) lid: u32) {
    histogram[lid] = histogram_in[lid];
    workgroupBarrier();
    if lid != 0u {
        return;
    }
    let h = params.histogram;
    let n_e = count(0u);
    let n_l = count(HISTOGRAM_BINS);
    var log2_lux = log2(INCIDENT_C / 100.0);
    if n_e >= max(1.0, 0.01 * n_l) {
        log2_lux = trimmed_mean(0u, n_e, params.meter.x, params.meter.y, h.x, h.y);
    } else if n_l > 0.0 {
        // Hardly any surface (the camera sees the sky): a reflected reading of what it sees.
        log2_lux = trimmed_mean(HISTOGRAM_BINS, n_l, params.meter.x, params.meter.y, h.z, h.w)
            + log2(INCIDENT_C / REFLECTED_K);
    }
    var ev = log2_lux + log2(100.0 / INCIDENT_C);
    // Log2 nits of the highlight percentile of all pixels; its exposed value at an EV is
    // hi - log2(1.2) - ev (scale = 1 / (1.2 * 2^ev)).
    var hi = 0.0;
    if n_l > 0.0 {
        hi = percentile(HISTOGRAM_BINS, n_l, params.meter.z, h.z, h.w);
    }
    if (params.config.x & EXPOSURE_HIGHLIGHTS) != 0u && n_l > 0.0 {
        let excess = hi - log2(1.2) - ev - params.meter.w;
        ev += params.rule.x * max(excess, 0.0);
    }
    ev = clamp(ev - params.rule.y, params.rule.z, params.rule.w);
    let prev = textureLoad(prev_state, vec2<u32>(0u), 0);
    let dt = params.adapt.z;
    // prev.y is 1 once a frame has been accepted (a new history holds zeros).
    if (params.config.x & EXPOSURE_FIXED) != 0u {
        ev = params.adapt.w;
    } else if prev.y > 0.5 && dt > 0.0 {
        ev = prev.x + clamp(ev - prev.x, -params.adapt.y * dt, params.adapt.x * dt);
    }
    textureStore(state, vec2<u32>(0u), vec4<f32>(ev, 1.0, 0.0, 0.0));
    // The highlight as this frame exposes it, for the local tonemap's highlight fit.
    let highlight = select(NO_HIGHLIGHT, hi - log2(1.2) - ev, n_l > 0.0);
    value = vec4<f32>(1.0 / (1.2 * exp2(ev)), ev, exp2(log2_lux), highlight);
}
