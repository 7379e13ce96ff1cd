#define_import_path hikari::area_polygon

// The closed-form light of a polygonal area light on a diffuse surface: Lambert's vector
// irradiance (Lambert 1760; Arvo 1995), summed over the light's triangles, each clipped to the
// receiving surface's horizon first, which makes it exact for the Lambertian lobe. Shared by
// the area lights' pass (area_lights/shade.wgsl) and the lighting of GI hits
// (ray_traced_gi/shade.wgsl). CPU twin: area_lights::reference::light_vector_irradiance.

// An area light's record as both passes read it (`area_lights::lights::AreaLightGpu`). Its
// triangles' record stays in each pass: naga_oil refuses the field names `p1`, `p2` in a
// module, and they are the Rust struct's.
struct AreaLightGpu {
    centroid_radius: vec4<f32>,
    normal_area: vec4<f32>,
    radiance_flux: vec4<f32>,
    range: vec4<u32>,
}

// AreaLightGpu::range.z bits.
const AREA_LIGHT_DOUBLE_SIDED: u32 = 1u;
const AREA_LIGHT_FORCED: u32 = 2u;

// Distance (m) from an area light's centroid beyond which its illuminance is below
// `cutoff_lux`: no point of it is nearer than d - r, and each triangle brings at most
// L A_tri / d_min^2, so E <= L A / (d - r)^2.
fn area_light_reach(light: AreaLightGpu, cutoff_lux: f32) -> f32 {
    let peak = dot(light.radiance_flux.rgb, vec3<f32>(0.2126, 0.7152, 0.0722)) * light.normal_area.w;
    return light.centroid_radius.w + sqrt(max(peak, 0.0) / cutoff_lux);
}

// Half the angle-weighted edge normal of edge a -> b (unit vectors from the point), oriented
// for a polygon whose front faces the point: the vector irradiance is the sum over edges.
fn area_edge_vector(a: vec3<f32>, b: vec3<f32>) -> vec3<f32> {
    let c = cross(b, a);
    let s = length(c);
    let cos_t = dot(a, b);
    let theta = atan2(s, cos_t);
    let k = select(theta / s, 1.0, s < 1e-7);
    return 0.5 * k * c;
}

// Vector irradiance per unit radiance (sr) of triangle qa qb qc (relative to the point, front
// face towards it), clipped to the upper hemisphere of n.
fn area_clipped_vector_irradiance(qa: vec3<f32>, qb: vec3<f32>, qc: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    var q = array<vec3<f32>, 3>(qa, qb, qc);
    var out: array<vec3<f32>, 4>;
    var count = 0u;
    for (var i = 0u; i < 3u; i++) {
        let a = q[i];
        let b = q[(i + 1u) % 3u];
        let da = dot(a, n);
        let db = dot(b, n);
        if da >= 0.0 {
            out[count] = a;
            count++;
        }
        if (da >= 0.0) != (db >= 0.0) {
            out[count] = a + (b - a) * (da / (da - db));
            count++;
        }
    }
    var f = vec3<f32>(0.0);
    if count < 3u {
        return f;
    }
    for (var i = 0u; i < count; i++) {
        let a = normalize(out[i]);
        let b = normalize(out[(i + 1u) % count]);
        f += area_edge_vector(a, b);
    }
    return f;
}

// Vector irradiance per unit radiance at `x` (surface normal `n`) of the world-space light
// triangle (ta, tb, tc), whose emitting face is the side (tb - ta) x (tc - ta) points to: seen
// from behind it gives nothing, unless the light is double-sided, which turns it round.
// The irradiance is the light's radiance times dot(n, sum over its triangles).
fn area_triangle_vector_irradiance(ta: vec3<f32>, tb: vec3<f32>, tc: vec3<f32>, x: vec3<f32>, n: vec3<f32>, double_sided: bool) -> vec3<f32> {
    let qa = ta - x;
    var qb = tb - x;
    var qc = tc - x;
    let side = -dot(qa, cross(qb - qa, qc - qa));
    if side <= 0.0 {
        if !double_sided {
            return vec3<f32>(0.0);
        }
        let t = qb;
        qb = qc;
        qc = t;
    }
    return area_clipped_vector_irradiance(qa, qb, qc, n);
}
