//! The atmosphere's tables built on the GPU (`tables.wgsl`): passes `sky.tables.*` that run
//! hikari-atmosphere's `build` (its CPU twin) with the same parameterisations, sizes and
//! working colour space, writing the textures the sky samples (`sky.rayleigh`,
//! `sky.rayleigh_single`, `sky.mie`, `sky.transmittance`; the single-scattering textures carry
//! the scattering distances in alpha) and keeping every other table in one storage buffer
//! (`sky.tables.work`, laid out by [`WorkLayout`]) for read-back and for later techniques.
//!
//! Passes, in order: `sky.tables.clear` (the sums start at zero), `sky.tables.transmittance`,
//! `sky.tables.single`, `sky.tables.ground.1`, `sky.tables.luminance.1`, then for each order
//! n in 2..=max_scattering_orders `sky.tables.density.n`, `sky.tables.multiple.n`,
//! `sky.tables.ground.n`, `sky.tables.luminance.n` (the passes of orders after the CPU's
//! stopping rule fires return at once), then `sky.tables.irradiance` and `sky.tables.store`.

use bytemuck::{Pod, Zeroable};

use hikari_atmosphere::build::BuildReport;
use hikari_atmosphere::geometry::{MU_S_MIN, Shell};
use hikari_atmosphere::table::Table;
use hikari_atmosphere::{AtmosphereParams, TableSizes, Tables};

use crate::context::GpuContext;
use crate::error::{RenderError, Result};
use crate::graph::{Buf, FrameGraph, GraphRuntime, PassTiming, Tex, TextureDesc};
use crate::pipeline::ComputePipeline;
use crate::shader::ShaderLibrary;

/// The uniform of `tables.wgsl` (see its `BuildParams` for each field).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct TableBuildParams {
    pub shell: [f32; 4],
    pub rayleigh: [f32; 4],
    pub ozone: [f32; 4],
    pub mie: [f32; 4],
    pub misc: [f32; 4],
    pub luminance: [f32; 4],
    pub sizes_2d: [u32; 4],
    pub sizes_scattering: [u32; 4],
    pub sizes_density: [u32; 4],
    pub sphere_order: [u32; 4],
    pub offsets0: [u32; 4],
    pub offsets1: [u32; 4],
    pub offsets2: [u32; 4],
    pub offsets3: [u32; 4],
}

/// Where each table lives in `sky.tables.work`, in texels of 16 bytes (RGB + unused).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct WorkLayout {
    pub transmittance: u32,
    pub rayleigh_single: u32,
    pub mie: u32,
    pub scattering_distance: u32,
    /// The last order's multiple scattering.
    pub delta: u32,
    /// Multiple scattering summed over orders 2..n (not divided by the phase).
    pub multiple_sum: u32,
    pub density_rayleigh: u32,
    pub density_mie: u32,
    pub density_rayleigh_sum: u32,
    pub density_mie_sum: u32,
    pub irradiance_rayleigh: u32,
    pub irradiance_mie: u32,
    /// One ground-irradiance table per order (order 1 first).
    pub ground_orders: u32,
    pub ground_irradiance: u32,
    /// 1 + 32 texels: total luminance, stop flag, orders done; then each order's contribution.
    pub control: u32,
    /// One luminance partial sum per 64 scattering texels (x).
    pub partials: u32,
    /// Texels in all.
    pub len: u32,
}

impl WorkLayout {
    pub fn new(sizes: &TableSizes, max_orders: u32) -> Self {
        let [tmu, tr] = sizes.transmittance;
        let t = (tmu * tr) as u32;
        let s = sizes.scattering.iter().product::<usize>() as u32;
        let d = sizes.density.iter().product::<usize>() as u32;
        let [gm, gr] = sizes.ground_irradiance;
        let g = (gm * gr) as u32;
        let mut at = 0u32;
        let mut take = |n: u32| {
            let o = at;
            at += n;
            o
        };
        let l = Self {
            transmittance: take(t),
            rayleigh_single: take(s),
            mie: take(s),
            scattering_distance: take(s),
            delta: take(s),
            multiple_sum: take(s),
            density_rayleigh: take(d),
            density_mie: take(d),
            density_rayleigh_sum: take(d),
            density_mie_sum: take(d),
            irradiance_rayleigh: take(s),
            irradiance_mie: take(s),
            ground_orders: take(g * max_orders),
            ground_irradiance: take(g),
            control: take(33),
            partials: take(s.div_ceil(64)),
            len: 0,
        };
        Self { len: at, ..l }
    }

    pub fn bytes(&self) -> u64 {
        u64::from(self.len) * 16
    }
}

fn f4(v: [f64; 3], w: f64) -> [f32; 4] {
    [v[0] as f32, v[1] as f32, v[2] as f32, w as f32]
}

impl TableBuildParams {
    /// The uniform for validated `p` at `sizes`, for the pass of scattering order `order`.
    pub fn new(p: &AtmosphereParams, sizes: &TableSizes, order: u32) -> Self {
        let shell = Shell::new(p.bottom_radius_km, p.top_radius_km);
        let l = WorkLayout::new(sizes, p.max_scattering_orders);
        let to709 = p.color_space.to_rec709();
        let y = hikari_math::color::REC709_LUMA.map(f64::from);
        let lum: [f64; 3] = std::array::from_fn(|c| (0..3).map(|k| y[k] * to709[k][c]).sum());
        let u = |v: usize| v as u32;
        let [tmu, tr] = sizes.transmittance;
        let [gm, gr] = sizes.ground_irradiance;
        let [smu, smus, sr] = sizes.scattering;
        let [dmu, dmus, dr] = sizes.density;
        Self {
            shell: [
                p.bottom_radius_km as f32,
                p.top_radius_km as f32,
                shell.h as f32,
                MU_S_MIN as f32,
            ],
            rayleigh: f4(p.rayleigh(), p.rayleigh_scale_height_km),
            ozone: f4(p.ozone(), p.ozone_center_km),
            mie: [
                p.mie_scattering_per_km as f32,
                p.mie_extinction_per_km as f32,
                p.mie_scale_height_km as f32,
                p.mie_g as f32,
            ],
            misc: [
                p.ozone_half_width_km as f32,
                p.ground_albedo as f32,
                0.0,
                0.0,
            ],
            luminance: f4(lum, 0.0),
            sizes_2d: [u(tmu), u(tr), u(gm), u(gr)],
            sizes_scattering: [u(smu), u(smus), u(sr), u(sizes.ray_steps)],
            sizes_density: [u(dmu), u(dmus), u(dr), 0],
            sphere_order: [u(sizes.sphere[0]), u(sizes.sphere[1]), order, 0],
            offsets0: [
                l.transmittance,
                l.rayleigh_single,
                l.mie,
                l.scattering_distance,
            ],
            offsets1: [l.delta, l.multiple_sum, l.density_rayleigh, l.density_mie],
            offsets2: [
                l.density_rayleigh_sum,
                l.density_mie_sum,
                l.irradiance_rayleigh,
                l.irradiance_mie,
            ],
            offsets3: [l.ground_orders, l.ground_irradiance, l.control, l.partials],
        }
    }
}

/// The pipelines of `tables.wgsl`.
pub struct TableBuilder {
    transmittance: ComputePipeline,
    single: ComputePipeline,
    ground: ComputePipeline,
    luminance: ComputePipeline,
    density: ComputePipeline,
    multiple: ComputePipeline,
    irradiance: ComputePipeline,
    store: ComputePipeline,
}

/// The graph resources a build writes.
#[derive(Clone, Copy, Debug)]
pub struct TableTargets {
    /// `[mu, mu_s, r]` Rgba32Float 3D: Rayleigh of all orders divided by its phase.
    pub rayleigh: Tex,
    /// `[mu, mu_s, r]` Rgba32Float 3D: Rayleigh single scattering divided by its phase; alpha:
    /// the Rayleigh scattering distance (km).
    pub rayleigh_single: Tex,
    /// `[mu, mu_s, r]` Rgba32Float 3D: Mie single scattering divided by its phase; alpha: the
    /// Mie scattering distance (km).
    pub mie: Tex,
    /// `[mu, r]` Rgba32Float 2D.
    pub transmittance: Tex,
    /// `sky.tables.work`, [`WorkLayout::bytes`] long.
    pub work: Buf,
}

/// The 3D and 2D texture descriptions of the sky's tables at `sizes`.
pub fn table_descs(sizes: &TableSizes) -> (TextureDesc, TextureDesc) {
    let [nmu, nmus, nr] = sizes.scattering.map(|v| v as u32);
    let [tmu, tr] = sizes.transmittance.map(|v| v as u32);
    (
        TextureDesc::d3(nmu, nmus, nr, wgpu::TextureFormat::Rgba32Float),
        TextureDesc::d2(tmu, tr, wgpu::TextureFormat::Rgba32Float),
    )
}

impl TableBuilder {
    pub fn new(ctx: &GpuContext, lib: &mut ShaderLibrary) -> Result<Self> {
        let p = |entry: &str, lib: &mut ShaderLibrary| {
            ComputePipeline::new(ctx, lib, "sky/tables.wgsl", entry, &[])
        };
        Ok(Self {
            transmittance: p("transmittance", lib)?,
            single: p("single", lib)?,
            ground: p("ground", lib)?,
            luminance: p("luminance", lib)?,
            density: p("density", lib)?,
            multiple: p("multiple", lib)?,
            irradiance: p("irradiance", lib)?,
            store: p("store", lib)?,
        })
    }

    /// Records every pass of the build of validated `params` at `sizes` into `to`.
    pub fn record<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        params: &AtmosphereParams,
        sizes: &TableSizes,
        to: TableTargets,
    ) -> Result<()> {
        let work = to.work;
        g.pass("sky.tables.clear")
            .uses(work, true)
            .encode(move |enc, res| enc.clear_buffer(res.buffer(work), 0, None))?;
        let texels = |n: &[usize]| n.iter().product::<usize>() as u32;
        let (s, d) = (texels(&sizes.scattering), texels(&sizes.density));
        let (t, gr) = (
            texels(&sizes.transmittance),
            texels(&sizes.ground_irradiance),
        );
        let mut run = |name: String, pipeline: &'r ComputePipeline, order: u32, threads: u32| {
            g.pass(&name)
                .constants(&TableBuildParams::new(params, sizes, order))
                .write(work)
                .write(to.rayleigh)
                .write(to.mie)
                .write(to.transmittance)
                .write(to.rayleigh_single)
                .dispatch_threads(pipeline, [threads, 1, 1])
        };
        run("sky.tables.transmittance".into(), &self.transmittance, 0, t)?;
        run("sky.tables.single".into(), &self.single, 1, s)?;
        run("sky.tables.ground.1".into(), &self.ground, 1, gr)?;
        run("sky.tables.luminance.1".into(), &self.luminance, 1, 256)?;
        for n in 2..=params.max_scattering_orders {
            run(format!("sky.tables.density.{n}"), &self.density, n, d)?;
            run(format!("sky.tables.multiple.{n}"), &self.multiple, n, s)?;
            run(format!("sky.tables.ground.{n}"), &self.ground, n, gr)?;
            run(format!("sky.tables.luminance.{n}"), &self.luminance, n, 256)?;
        }
        run("sky.tables.irradiance".into(), &self.irradiance, 0, s)?;
        run("sky.tables.store".into(), &self.store, 0, s.max(t).max(gr))?;
        Ok(())
    }

    /// Builds the tables of `params` at `sizes` on the GPU in a graph of its own and reads
    /// them back as hikari-atmosphere's [`Tables`] (for tests, dumps and timing), with the
    /// build's per-order contributions and each pass's GPU time.
    pub fn build_and_read(
        &self,
        ctx: &GpuContext,
        params: &AtmosphereParams,
        sizes: TableSizes,
    ) -> Result<(Tables, BuildReport, Vec<PassTiming>)> {
        params
            .validate()
            .map_err(|e| RenderError::Graph(format!("sky: atmosphere: {e}")))?;
        let layout = WorkLayout::new(&sizes, params.max_scattering_orders);
        let mut rt = GraphRuntime::new();
        let mut g = rt.begin_frame(ctx);
        let (d3, d2) = table_descs(&sizes);
        let to = TableTargets {
            rayleigh: g.texture("sky.rayleigh", d3)?,
            rayleigh_single: g.texture("sky.rayleigh_single", d3)?,
            mie: g.texture("sky.mie", d3)?,
            transmittance: g.texture("sky.transmittance", d2)?,
            work: g.buffer("sky.tables.work", layout.bytes())?,
        };
        self.record(&mut g, params, &sizes, to)?;
        g.readback(to.work);
        g.readback(to.rayleigh);
        g.readback(to.mie);
        g.readback(to.transmittance);
        let start = std::time::Instant::now();
        let mut r = g.execute()?;
        let wall_ms = start.elapsed().as_secs_f64() * 1e3;
        let work: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(
            r.buffer("sky.tables.work")
                .ok_or_else(|| RenderError::Graph("sky.tables.work was not read back".into()))?,
        );
        let mut texture = |name: &str, size: [usize; 3]| -> Result<Table> {
            let image = r
                .take_image(name)
                .ok_or_else(|| RenderError::Graph(format!("{name} was not read back")))?;
            Ok(Table {
                size,
                data: image.rgba.iter().map(|v| [v[0], v[1], v[2]]).collect(),
            })
        };
        let region = |at: u32, size: [usize; 3]| Table {
            size,
            data: work[at as usize..at as usize + size.iter().product::<usize>()]
                .iter()
                .map(|v| [v[0], v[1], v[2]])
                .collect(),
        };
        let [tmu, tr] = sizes.transmittance;
        let [gm, gr] = sizes.ground_irradiance;
        let ss = sizes.scattering;
        let tables = Tables {
            transmittance: texture("sky.transmittance", [tmu, tr, 1])?,
            rayleigh: texture("sky.rayleigh", ss)?,
            mie: texture("sky.mie", ss)?,
            rayleigh_single: region(layout.rayleigh_single, ss),
            scattering_distance: region(layout.scattering_distance, ss),
            irradiance_rayleigh: region(layout.irradiance_rayleigh, ss),
            irradiance_mie: region(layout.irradiance_mie, ss),
            ground_irradiance: region(layout.ground_irradiance, [gm, gr, 1]),
            sizes,
        };
        let control = work[layout.control as usize];
        let orders = control[2].max(1.0) as usize;
        let order_contributions = (1..=orders)
            .map(|k| f64::from(work[layout.control as usize + k][3]))
            .collect();
        let report = BuildReport {
            order_contributions,
            build_ms: r.gpu_span_ms.unwrap_or(wall_ms),
        };
        Ok((tables, report, r.timings))
    }
}

/// The GPU build's time per table, as `bench` prints per-pass timings: each table's passes
/// summed (the orders' passes under the table they feed), then the total.
pub fn print_build_timings(timings: &[PassTiming]) {
    let groups = [
        ("transmittance", "sky.tables.transmittance"),
        ("single scattering", "sky.tables.single"),
        ("scattering density (orders 2..n)", "sky.tables.density."),
        ("multiple scattering (orders 2..n)", "sky.tables.multiple."),
        ("ground irradiance (per order)", "sky.tables.ground."),
        ("order luminance (stopping rule)", "sky.tables.luminance."),
        ("irradiance (Rayleigh, Mie)", "sky.tables.irradiance"),
        ("store (textures, ground sum)", "sky.tables.store"),
    ];
    println!("{:<36} {:>10} {:>7}", "table", "GPU ms", "passes");
    let mut total = 0.0;
    for (label, prefix) in groups {
        let passes: Vec<_> = timings
            .iter()
            .filter(|t| t.name.starts_with(prefix))
            .collect();
        let ms: Option<f64> = passes.iter().map(|t| t.gpu_ms).sum();
        total += ms.unwrap_or(0.0);
        let shown = ms.map_or("n/a".to_string(), |v| format!("{v:.4}"));
        println!("{label:<36} {shown:>10} {:>7}", passes.len());
    }
    println!("{:<36} {:>10.4}", "all tables", total);
}
