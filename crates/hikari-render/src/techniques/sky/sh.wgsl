// Projects the sky's radiance (inscattering and the ground, without the disks: the directional
// light carries the sun and moon) to L2 SH with 4096 directions of a spherical Fibonacci set,
// then derings it as Ghost of Tsushima does (Sloan 2017's window; hikari::sh's Newton step and
// depth-3 binary search). CPU twin: reference::sky_sh.
//
// One pass, `project_dering` (the frame's `sky.sh`): 16 workgroups of 256 threads project a
// direction a thread and sum their terms in workgroup memory into partial sums; the last
// workgroup to finish (an atomic count) adds the 16 partials and derings, testing every
// strength of the search grid at once (see below). It replaced two dispatches (the projection,
// then one workgroup adding and deringing): on the H200 those measured 7.9 + 8.0 us, while a
// single workgroup doing everything measured 22 us (its serial lookups, 4 or 16 a thread,
// cost more than the second launch). `finish` is the deringing alone from 64 given partial
// sums; tests/render/sky.rs feeds it chosen skies.
//
// With CLOUDS defined (`sky.sh_clouds`), the same projection of the sky seen through the
// clouds (`clouds_over_sky`, as the deferred lighting draws them), after the clear sky's pass:
// the clouds' ambient term is lit by the clear sky's mean radiance. CPU twin:
// SkyTwin::sh_with.

#import hikari::sky::sky_background_no_disks
#import hikari::sh::{SH_C0, SH_C1, SH_C2, SH_C3, SH_C4, sh_dering_window, sh_newton_step, sh_poly}
// Imported by both variants (the binding sets follow the imports, not the defines): the pass
// binds the clouds' set either way.
#import hikari::clouds::clouds_over_sky

// 9 coefficients (xyz) per partial sum: project_dering writes 16, finish reads 64.
@group(0) @binding(0) var<storage, read_write> partials: array<vec4<f32>, 576>;
// finish: 9 raw coefficients, then 9 deringed ones.
@group(0) @binding(1) var<storage, read_write> out_sh: array<vec4<f32>, 18>;
// project_dering: how many of its workgroups have stored their partial sums (persistent, 0
// between frames). finish: unused.
@group(0) @binding(2) var<storage, read_write> sh_done: atomic<u32>;

const SAMPLES: u32 = 4096u;
const THREADS: u32 = 64u;
const GOLDEN_ANGLE: f32 = 2.39996322972865332;

var<workgroup> terms: array<array<vec3<f32>, 9>, THREADS>;

#ifdef CLOUDS
// The clear sky's SH (`sky.sh_clear`): the mean radiance of its deringed band 0 lights the
// clouds, as the deferred lighting's clouds over the sky are lit by the sky's.
@group(0) @binding(3) var<storage, read> clear_sh: array<vec4<f32>, 18>;
// xyz: the sun's (or moon's) illuminance, lux.
@group(0) @binding(4) var<uniform> clouds_sun: vec4<f32>;
#endif

// The radiance the pass projects towards unit `d`.
fn sh_radiance(d: vec3<f32>) -> vec3<f32> {
#ifdef CLOUDS
    return clouds_over_sky(d, sky_background_no_disks(d), clouds_sun.xyz, clear_sh[9].xyz * SH_C0);
#else
    return sky_background_no_disks(d);
#endif
}

// Direction i of the spherical Fibonacci set: equal-area bands in z, golden-angle azimuths.
fn fibonacci_dir(i: u32) -> vec3<f32> {
    let z = 1.0 - (2.0 * f32(i) + 1.0) / f32(SAMPLES);
    let r = sqrt(max(1.0 - z * z, 0.0));
    let phi = GOLDEN_ANGLE * f32(i);
    return vec3<f32>(r * cos(phi), z, r * sin(phi));
}

// ---- finish: the 64 partial sums, then deringing with the strength grid searched in parallel ----
//
// hikari::sh's `sh_dering_l2_rgb` tests strength 0 and then three strengths of a binary search
// over (0, 1] one after another, each by a minimum search of 15 starting directions x (value,
// Newton step) per channel on one thread: ~190 Newton steps in a row. Its search only ever
// tests strengths 0 and k/8 (k = 1..7; 1 is its answer when none passes), so `finish` tests
// all 8 of them at once, 24 (strength, channel) minimum searches of 8 threads each, and then
// replays the binary search's path over the 8 verdicts: the same strength as the serial search
// even where the verdict is not monotone in the strength. Each minimum search keeps the serial
// one's tie-breaking (the first of equal values in start order), so the result is that of
// `sh_dering_l2_rgb`, which tests/render/math_twins.rs holds to hikari_math::sh::dering.

const FINISH_THREADS: u32 = 192u;
// Threads per (strength, channel) minimum search; each takes 2 of the 16 start slots
// (slot 0: the negated band-1 direction, 1..14: the fixed directions, 15: none).
const SEARCH_THREADS: u32 = 8u;
// Strengths tested: 0 and k/8 for k = 1..7 (the depth-3 search's grid).
const STRENGTHS: u32 = 8u;
const NO_MINIMUM: vec4<f32> = vec4<f32>(0.0, 0.0, 1.0, 3.4e38);

// Best (direction, value) of each thread's start slots, reduced in place per search.
var<workgroup> candidates: array<vec4<f32>, FINISH_THREADS>;
// Estimated minimum of each (strength, channel): index strength * 3 + channel.
var<workgroup> minima: array<f32, 24>;

// Start slot s of the minimum search (see sh_find_min_l2's list), without a local array.
fn start_direction(s: u32, lin_dir: vec3<f32>) -> vec3<f32> {
    let d = 0.57735026918962573;
    if s == 0u {
        return lin_dir;
    }
    if s <= 6u {
        let axis = (s - 1u) / 2u;
        let sign = select(1.0, -1.0, ((s - 1u) & 1u) == 1u);
        return vec3<f32>(select(0.0, sign, axis == 0u), select(0.0, sign, axis == 1u), select(0.0, sign, axis == 2u));
    }
    let j = s - 7u;
    return vec3<f32>(select(d, -d, (j & 4u) != 0u), select(d, -d, (j & 2u) != 0u), select(d, -d, (j & 1u) != 0u));
}

// Folds start slot s (its direction, then one Newton step from it) into `best` as the serial
// search does: a value replaces the best only when strictly smaller.
fn consider_start(c: array<f32, 9>, s: u32, lin_dir: vec3<f32>, has_lin: bool, best: vec4<f32>) -> vec4<f32> {
    var b = best;
    if s > 14u || (s == 0u && !has_lin) {
        return b;
    }
    let v0 = start_direction(s, lin_dir);
    let f0 = sh_poly(c, v0).f;
    if f0 < b.w {
        b = vec4<f32>(v0, f0);
    }
    let v1 = sh_newton_step(c, v0);
    let f1 = sh_poly(c, v1).f;
    if f1 < b.w {
        b = vec4<f32>(v1, f1);
    }
    return b;
}

// Channel ch of an RGB coefficient (a select, not a dynamically indexed vector).
fn channel_of(v: vec3<f32>, ch: u32) -> f32 {
    return select(select(v.z, v.y, ch == 1u), v.x, ch == 0u);
}

// The depth-3 binary search of sh_dering_strength_rgb replayed over the verdicts of the grid,
// in eighths: 0 when strength 0 passes, else 1..8.
fn search_eighths() -> u32 {
    if strength_passes(0u) {
        return 0u;
    }
    var lo = 0u;
    var hi = 8u;
    for (var i = 0u; i < 3u; i++) {
        let mid = (lo + hi) / 2u;
        if strength_passes(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    return hi;
}

// As sh_rgb_non_negative: no channel's estimated minimum is below zero.
fn strength_passes(k: u32) -> bool {
    return !(minima[k * 3u] < 0.0 || minima[k * 3u + 1u] < 0.0 || minima[k * 3u + 2u] < 0.0);
}

// The 9 coefficients of direction d's radiance l, before the quadrature weight.
fn project_terms(d: vec3<f32>, l: vec3<f32>) -> array<vec3<f32>, 9> {
    return array<vec3<f32>, 9>(
        l * SH_C0,
        l * (SH_C1 * d.y),
        l * (SH_C1 * d.z),
        l * (SH_C1 * d.x),
        l * (SH_C2 * d.x * d.y),
        l * (SH_C2 * d.y * d.z),
        l * (SH_C3 * (3.0 * d.z * d.z - 1.0)),
        l * (SH_C2 * d.x * d.z),
        l * (SH_C4 * (d.x * d.x - d.y * d.y)),
    );
}

// project_dering: 16 workgroups of 256 threads, a direction a thread.
const GROUP_THREADS: u32 = 256u;
const GROUPS: u32 = SAMPLES / GROUP_THREADS;

var<workgroup> last_group: u32;

@compute @workgroup_size(256, 1, 1)
fn project_dering(@builtin(local_invocation_index) lid: u32, @builtin(workgroup_id) wg: vec3<u32>) {
    let d = fibonacci_dir(wg.x * GROUP_THREADS + lid);
    let t = project_terms(d, sh_radiance(d));
    // The 256 rows into the 64 of `terms`, 64 at a time, then a tree of halvings.
    for (var q = 0u; q < GROUP_THREADS / THREADS; q++) {
        if lid / THREADS == q {
            let row = lid % THREADS;
            if q == 0u {
                terms[row] = t;
            } else {
                terms[row][0] += t[0];
                terms[row][1] += t[1];
                terms[row][2] += t[2];
                terms[row][3] += t[3];
                terms[row][4] += t[4];
                terms[row][5] += t[5];
                terms[row][6] += t[6];
                terms[row][7] += t[7];
                terms[row][8] += t[8];
            }
        }
        workgroupBarrier();
    }
    for (var stride = THREADS / 2u; stride > 0u; stride >>= 1u) {
        for (var i = lid; i < stride * 9u; i += GROUP_THREADS) {
            let g = i / 9u;
            let k = i % 9u;
            terms[g][k] += terms[g + stride][k];
        }
        workgroupBarrier();
    }
    if lid < 9u {
        partials[wg.x * 9u + lid] = vec4<f32>(terms[0][lid], 0.0);
    }
    // The last workgroup to finish sums every group's partials and derings: one dispatch, the
    // lookups still spread over 16 workgroups. The partials are stored before the count
    // (storage barrier), and the count's atomic orders the groups. WGSL has no device-scope
    // release/acquire, so this is the usual practice (as single-pass downsamplers do it) rather
    // than a guarantee of the memory model: checked on lavapipe and the H200
    // (tests/render/sky.rs: the SH against the twin, and frame after frame).
    storageBarrier();
    if lid == 0u {
        last_group = select(0u, 1u, atomicAdd(&sh_done, 1u) == GROUPS - 1u);
    }
    if workgroupUniformLoad(&last_group) == 0u {
        return;
    }
    storageBarrier();
    for (var i = lid; i < GROUPS * 9u; i += GROUP_THREADS) {
        terms[i / 9u][i % 9u] = partials[i].xyz;
    }
    workgroupBarrier();
    for (var stride = GROUPS / 2u; stride > 0u; stride >>= 1u) {
        for (var i = lid; i < stride * 9u; i += GROUP_THREADS) {
            let g = i / 9u;
            let k = i % 9u;
            terms[g][k] += terms[g + stride][k];
        }
        workgroupBarrier();
    }
    dering_and_store(lid);
    if lid == 0u {
        // Ready for the next frame (the buffer is persistent and starts at zero).
        atomicStore(&sh_done, 0u);
    }
}

@compute @workgroup_size(192, 1, 1)
fn finish(@builtin(local_invocation_index) lid: u32) {
    // The same tree of halvings as `project` (and as the one-thread-per-partial version before
    // it, so the sums are bit for bit the same), spread over (partial, coefficient) pairs; the
    // first level adds while loading.
    for (var i = lid; i < 32u * 9u; i += FINISH_THREADS) {
        let g = i / 9u;
        let k = i % 9u;
        terms[g][k] = partials[i].xyz + partials[i + 32u * 9u].xyz;
    }
    workgroupBarrier();
    for (var stride = 16u; stride > 0u; stride >>= 1u) {
        for (var i = lid; i < stride * 9u; i += FINISH_THREADS) {
            let g = i / 9u;
            let k = i % 9u;
            terms[g][k] += terms[g + stride][k];
        }
        workgroupBarrier();
    }
    dering_and_store(lid);
}

// Derings the sum in terms[0] and writes out_sh. Needs a workgroup of at least 192 threads
// (FINISH_THREADS: 24 minimum searches of 8 threads); threads past those only keep the barriers.
fn dering_and_store(lid: u32) {
    let searching = lid < FINISH_THREADS;
    let w = 4.0 * 3.14159265358979 / f32(SAMPLES);
    let raw0 = terms[0][0] * w;
    let raw1 = terms[0][1] * w;
    let raw2 = terms[0][2] * w;
    let raw3 = terms[0][3] * w;
    let raw4 = terms[0][4] * w;
    let raw5 = terms[0][5] * w;
    let raw6 = terms[0][6] * w;
    let raw7 = terms[0][7] * w;
    let raw8 = terms[0][8] * w;

    // This thread's share of the minimum search of (strength, channel).
    let search = min(lid, FINISH_THREADS - 1u) / SEARCH_THREADS;
    let j = lid % SEARCH_THREADS;
    let strength = search / 3u;
    let ch = search % 3u;
    let f = sh_dering_window(f32(strength) / 8.0);
    let c = array<f32, 9>(
        channel_of(raw0, ch) * f.x,
        channel_of(raw1, ch) * f.y,
        channel_of(raw2, ch) * f.y,
        channel_of(raw3, ch) * f.y,
        channel_of(raw4, ch) * f.z,
        channel_of(raw5, ch) * f.z,
        channel_of(raw6, ch) * f.z,
        channel_of(raw7, ch) * f.z,
        channel_of(raw8, ch) * f.z,
    );
    let lin = -vec3<f32>(c[3], c[1], c[2]);
    let ll = length(lin);
    let has_lin = ll > 0.0;
    let lin_dir = select(vec3<f32>(0.0, 0.0, 1.0), lin / ll, has_lin);
    if searching {
        var best = consider_start(c, 2u * j, lin_dir, has_lin, NO_MINIMUM);
        best = consider_start(c, 2u * j + 1u, lin_dir, has_lin, best);
        candidates[lid] = best;
    }
    workgroupBarrier();
    // Neighbours first, so the left side always holds the earlier slots: keeping it on equal
    // values keeps the serial search's first-found tie-breaking.
    for (var span = 1u; span < SEARCH_THREADS; span <<= 1u) {
        if searching && (j & (2u * span - 1u)) == 0u {
            let right = candidates[lid + span];
            if right.w < candidates[lid].w {
                candidates[lid] = right;
            }
        }
        workgroupBarrier();
    }
    if searching && j == 0u {
        // The serial search's refinement: one more Newton step from the best.
        var b = candidates[lid];
        let r = sh_newton_step(c, b.xyz);
        let fr = sh_poly(c, r).f;
        if fr < b.w {
            b = vec4<f32>(r, fr);
        }
        minima[search] = b.w;
    }
    workgroupBarrier();

    if lid < 9u {
        let raw = terms[0][lid] * w;
        out_sh[lid] = vec4<f32>(raw, 0.0);
        // A negative mean cannot be windowed to non-negative: zero, as sh_dering_l2_rgb.
        let fw = sh_dering_window(f32(search_eighths()) / 8.0);
        let band = select(select(fw.z, fw.y, lid < 4u), fw.x, lid == 0u);
        let deringed = select(raw * band, vec3<f32>(0.0), any(raw0 < vec3<f32>(0.0)));
        out_sh[9u + lid] = vec4<f32>(deringed, 0.0);
    }
}
