#define_import_path hikari::local_tonemap

// What the local tonemap's passes share. CPU twin: `techniques/local_tonemap/reference.rs`.

struct LocalTonemapParams {
    // x: exposed log2 luminance at the grid's lower end, y: slices per EV, z: the range in EV,
    // w: largest |gain|, EV.
    grid: vec4<f32>,
    // x: contrast above the midpoint, y: below it, z: detail, w: midpoint (exposed log2).
    tone: vec4<f32>,
    // x: the bilateral grid's share of the base layer, yzw: unused.
    blend: vec4<f32>,
}

struct BlurParams {
    // x: sigma in texels of the blurred axis, yzw: unused.
    sigma: vec4<f32>,
    // x: axis (0 x, 1 y, 2 z), y: radius in taps, zw: unused.
    config: vec4<u32>,
}

const GRID_W: u32 = 64u;
const GRID_H: u32 = 32u;
const GRID_D: u32 = 64u;
// The wide Gaussian's upsampled image.
const WIDE_W: u32 = 256u;
const WIDE_H: u32 = 128u;

const LUMA: vec3<f32> = vec3<f32>(0.2126, 0.7152, 0.0722);

// Exposed log2 luminance, relative to the grid's lower end and clamped to its range: black
// and NaN land on the lowest slice.
fn grid_log2(rgb: vec3<f32>, scale: f32, p: LocalTonemapParams) -> f32 {
    let y = dot(rgb, LUMA) * scale;
    let l = log2(max(select(0.0, y, y >= 0.0), 1e-30));
    return clamp(l - p.grid.x, 0.0, p.grid.z);
}

fn gaussian(i: i32, sigma: f32) -> f32 {
    let x = f32(i) / sigma;
    return exp(-0.5 * x * x);
}
