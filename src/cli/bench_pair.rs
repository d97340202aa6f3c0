//! `ocular bench --binocular`: what the second eye costs. The scene's camera is the point
//! between the eyes; each eye sits half the interpupillary distance to its side and turns to
//! the focus point (`render::binocular`), and each timed pair draws and splats the left eye's
//! frame, then the right eye's, one submission each, in the same run as the one-eye frames so
//! that their ratio compares.

use std::time::Instant;

use super::bench::{stat, BenchArgs, SceneInput, Stat};
use crate::eye::Eye;
use crate::gpu::Context;
use crate::render::binocular::{check_ipd_mm, eye_cameras, point_ahead, DEFAULT_IPD_MM};
use crate::render::frame::{EyeState, FrameRenderer, PreparedKernels};
use crate::render::Rasterizer;
use crate::scene::FrameState;
use crate::{Error, Result};

/// The pair's figures, beside the one-eye run's.
#[derive(Clone, Debug, serde::Serialize)]
pub struct PairBench {
    pub ipd_mm: f64,
    /// The right eye (None: `--eye` for both).
    pub eye_right: Option<String>,
    /// Submissions per pair: each eye's frame is its own.
    pub submissions: u32,
    /// GPU time of both eyes' passes, summed per pair.
    pub gpu_total: Stat,
    /// CPU wall time per pair, upload and read-back included.
    pub wall_ms_per_pair: Stat,
    /// Kernel evaluations per pair (both eyes).
    pub kernel_evaluations: u64,
    /// Pair over one eye (the run's own one-eye frames), GPU and wall.
    pub gpu_ratio: f64,
    pub wall_ratio: f64,
}

/// What the pair's timing needs from the one-eye run.
pub struct PairRun<'a, 's> {
    pub ctx: &'a Context,
    pub raster: &'a mut Rasterizer,
    pub state: &'a FrameState<'s>,
    pub eye_state: EyeState,
    pub layers: u32,
    pub gap_d: f32,
    /// The one-eye run's GPU total and wall time per frame (mean, ms).
    pub one_eye_ms: (f64, f64),
}

/// What the right eye's renderer is made of: its eye, kernels, kernel settings and splat
/// settings.
pub type RightRenderer = (
    Eye,
    PreparedKernels,
    crate::psf::axes::KernelSettings,
    crate::render::splat::SplatSettings,
);

/// With `--binocular`, the right eye and its kernels: `--eye-right`'s, planned for the same
/// frame and eye state, or the left eye's again.
pub fn right_eye(
    args: &BenchArgs,
    left: &Eye,
    kernels: &PreparedKernels,
    frame: &crate::render::Frame,
    (state, screen): (EyeState, crate::psf::axes::Screen),
    options: &crate::render::frame::KernelOptions,
) -> Result<Option<(Eye, PreparedKernels)>> {
    if !args.binocular {
        return Ok(None);
    }
    Ok(Some(match &args.eye_right {
        None => (left.clone(), kernels.clone()),
        Some(name) => {
            let right = super::render::load_eye(name)?;
            let k = super::frame_kernels(&right, frame, state, screen, options)?;
            (right, k)
        }
    }))
}

/// The interpupillary distance asked, checked (default 63 mm).
pub fn ipd_mm(args: &BenchArgs) -> Result<f64> {
    match args.ipd_mm {
        None => Ok(DEFAULT_IPD_MM),
        Some(v) => check_ipd_mm(v).map_err(Error::input),
    }
}

impl PairRun<'_, '_> {
    /// Times `warmup + frames` pairs through `left` and `right` (each eye's renderer: its eye
    /// and kernels) and keeps the last `frames`.
    pub fn time(
        &mut self,
        args: &BenchArgs,
        left: &mut FrameRenderer,
        (eye, kernels, options, splat): RightRenderer,
        bar: &indicatif::ProgressBar,
    ) -> Result<PairBench> {
        let right = &mut FrameRenderer::new(self.ctx, eye, kernels, options, splat);
        let ipd_mm = ipd_mm(args)?;
        let camera = self.state.camera;
        let fixation = point_ahead(&camera, 1.0 / self.eye_state.focus_d.max(1e-9));
        let cameras = eye_cameras(&camera, ipd_mm * 1e-3, fixation);
        let states = cameras.map(|c| FrameState {
            camera: c,
            ..*self.state
        });
        let (mut totals, mut walls) = (Vec::new(), Vec::new());
        let mut evaluations = 0;
        let mut submissions = 0;
        for i in 0..args.warmup + args.frames {
            let started = Instant::now();
            let (mut total_ms, mut pair_evaluations, mut pair_submissions) = (0.0, 0, 0);
            for (state, renderer) in states.iter().zip([&mut *left, &mut *right]) {
                let mut input = SceneInput {
                    ctx: self.ctx,
                    raster: self.raster,
                    state,
                    size: args.size,
                    layers: self.layers,
                    gap_d: self.gap_d,
                };
                let out = input.render(renderer, self.eye_state, true)?;
                total_ms += out.timings.map_or(0.0, |t| t.total_ms());
                if let Some(s) = out.stats {
                    pair_evaluations += s.kernel_evaluations;
                    pair_submissions += s.submissions;
                }
            }
            let wall_ms = started.elapsed().as_secs_f64() * 1e3;
            bar.inc(1);
            if i < args.warmup {
                continue;
            }
            totals.push(total_ms);
            walls.push(wall_ms);
            evaluations = pair_evaluations;
            submissions = pair_submissions;
        }
        let gpu_total = stat("pair total", &totals);
        let wall = stat("pair wall", &walls);
        let (one_gpu, one_wall) = self.one_eye_ms;
        Ok(PairBench {
            ipd_mm,
            eye_right: args.eye_right.clone(),
            submissions,
            gpu_ratio: gpu_total.mean_ms / one_gpu.max(1e-9),
            wall_ratio: wall.mean_ms / one_wall.max(1e-9),
            gpu_total,
            wall_ms_per_pair: wall,
            kernel_evaluations: evaluations,
        })
    }
}

/// The pair's lines of the printed report.
pub fn print(p: &PairBench) {
    println!();
    println!(
        "two eyes (IPD {:.1} mm, {}; {} submission(s) per pair, one per eye)",
        p.ipd_mm,
        p.eye_right
            .as_deref()
            .map_or("--eye for both".to_string(), |e| format!("right eye {e}")),
        p.submissions
    );
    println!(
        "  GPU total per pair   {:>10.3} ms mean ({:.2}× one eye)",
        p.gpu_total.mean_ms, p.gpu_ratio
    );
    println!(
        "  wall per pair        {:>10.3} ms mean ({:.2}× one eye)",
        p.wall_ms_per_pair.mean_ms, p.wall_ratio
    );
}
