//! `ocular render`'s output: the image file and the summary (text or JSON).

use super::render::{Input, RenderArgs};
use crate::gpu::Context;
use crate::image_io::{self, ImageRgba, Tonemap};
use crate::render::frame::Method;
use crate::{Error, Result};

#[derive(serde::Serialize)]
pub(super) struct Summary {
    output: String,
    input: String,
    eye: String,
    width: u32,
    height: u32,
    fov_y_deg: f64,
    /// `--headset`: the panel and field the frame was rendered at.
    #[serde(skip_serializing_if = "Option::is_none")]
    headset: Option<crate::render::headset::HeadsetSummary>,
    /// Where the depth came from (file input only).
    depth: Option<String>,
    /// Background, invalid, clamped and constant depth (file input only).
    depth_report: Option<crate::inputs::DepthReport>,
    /// The focus asked for (D; 0 = infinity).
    focus_d: f64,
    /// Where the eye actually focuses (D): `focus_d`, or its far (near) point when `focus_d`
    /// lies beyond (nearer than) it (`focus_clamped`, `focus_limit`).
    focus_reached_d: f64,
    /// The same as `focus_reached_d` (the earlier name).
    focus_actual_d: f64,
    focus_clamped: bool,
    focus_limit: crate::eye::FocusLimit,
    #[serde(flatten)]
    physiology: super::correction::Physiology,
    pupil_mm: f64,
    pupil_source: String,
    /// Things about the input a user should know (also printed on stderr).
    warnings: Vec<String>,
    method: &'static str,
    /// The `--quality` preset splat rendered at (its settings: `ocular bench --json`).
    quality: &'static str,
    seconds_render: f64,
    seconds_kernels: f64,
    kernels_from_cache: bool,
    psfs_computed: usize,
    /// Worst pupil energy the kernels' PSFs missed, per (pupil, focus) column and channel
    /// (null when the kernels came from the cache: they were checked when computed).
    psf_missed_energy: Option<Vec<[f64; 3]>>,
    max_radius_px: u32,
    /// Off axis (`--off-axis`): the lattice of field directions (degrees) and the largest
    /// interpolation error of the wavefront its planning measured (µm RMS).
    #[serde(skip_serializing_if = "Option::is_none")]
    field: Option<crate::psf::field_plan::FieldPlan>,
    gpu_ms: Option<Vec<(String, f64)>>,
    gpu_total_ms: Option<f64>,
    device: String,
}

/// How the kernels of a splat, reference or slices frame were obtained.
pub(super) struct KernelInfo {
    pub(super) from_cache: bool,
    pub(super) psfs: usize,
    pub(super) missed: Option<Vec<[f64; 3]>>,
    pub(super) seconds: f64,
    pub(super) max_radius: u32,
    /// Off axis: the field lattice the kernels were computed over.
    pub(super) field: Option<crate::psf::field_plan::FieldPlan>,
}

/// Writes the output and prints the summary.
pub(super) fn finish(
    args: &RenderArgs,
    ctx: &Context,
    input: &Input,
    frame: crate::render::frame::RenderedFrame,
    focus: crate::render::focus::FocusOutcome,
    (focus_d, pupil_mm, pupil_source, physiology): (
        f64,
        f64,
        String,
        super::correction::Physiology,
    ),
    kernels: Option<KernelInfo>,
) -> Result<()> {
    let output_ext = args
        .output
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let (from_cache, psfs, missed, seconds_kernels, max_radius, field) = match kernels {
        Some(k) => (
            k.from_cache,
            k.psfs,
            k.missed,
            k.seconds,
            k.max_radius,
            k.field,
        ),
        None => (false, 0, None, 0.0, 0, None),
    };
    write_image(args, input, &frame, output_ext.as_deref())?;
    let gpu: Option<Vec<(String, f64)>> = frame
        .timings
        .as_ref()
        .map(|t| t.passes.iter().map(|p| (p.name.clone(), p.ms)).collect());
    let summary = Summary {
        output: args.output.display().to_string(),
        input: input.label.clone(),
        eye: args.eye.clone(),
        width: input.frame.width,
        height: input.frame.height,
        fov_y_deg: input.frame.fov_y_deg,
        headset: args.headset.map(|h| h.summary()),
        depth: input.depth_source.clone(),
        depth_report: input.depth_report.clone(),
        focus_d,
        focus_reached_d: focus.actual_d,
        focus_actual_d: focus.actual_d,
        focus_clamped: focus.clamped(),
        focus_limit: focus.limit,
        physiology,
        pupil_mm,
        pupil_source,
        warnings: input.warnings.clone(),
        method: args.method.name(),
        quality: args.splat.quality.name(),
        seconds_render: frame.seconds,
        seconds_kernels,
        kernels_from_cache: from_cache,
        psfs_computed: psfs,
        psf_missed_energy: missed,
        max_radius_px: max_radius,
        field,
        gpu_total_ms: frame.timings.as_ref().map(|t| t.total_ms()),
        gpu_ms: gpu,
        device: ctx.device_info().name.clone(),
    };
    if args.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&summary)
                .map_err(|e| Error::input(format!("cannot encode JSON: {e}")))?
        );
        return Ok(());
    }
    print_summary(args, input, &summary, &frame);
    Ok(())
}

/// The image: linear EXR, or PNG at the input frame's exposure (or --exposure).
fn write_image(
    args: &RenderArgs,
    input: &Input,
    frame: &crate::render::frame::RenderedFrame,
    output_ext: Option<&str>,
) -> Result<()> {
    let image = ImageRgba::new(input.frame.width, input.frame.height, frame.color.clone());
    if output_ext == Some("exr") {
        return image_io::write_exr_rgba(&args.output, &image);
    }
    let mode = args.tonemap.mode();
    let exposure_ev = exposure_ev(args, input);
    image_io::write_png(&args.output, &image, Tonemap { exposure_ev, mode })
}

/// The exposure the image is shown at: --exposure, else the input frame's automatic one.
/// Exposed for the scene, not the blurred result, so that eyes compare at one exposure; an EXR
/// is judged at it too, and splat's merge bounds its colour error by the white it gives.
pub(super) fn exposure_ev(args: &RenderArgs, input: &Input) -> f32 {
    args.exposure
        .unwrap_or_else(|| Tonemap::auto_exposure_ev_of(&input.frame.color))
}

/// Where the eye focused, in words: the distance, and the limit it met.
fn focus_words(summary: &Summary) -> String {
    let distance = |d: f64| {
        if d > 0.0 {
            format!("{:.3} m", 1.0 / d)
        } else {
            "infinity".into()
        }
    };
    let (asked, reached) = (summary.focus_d, summary.focus_reached_d);
    let focus = match summary.focus_limit {
        crate::eye::FocusLimit::Reached => distance(asked),
        crate::eye::FocusLimit::FarPoint => format!(
            "{} (its far point; asked {}, beyond it)",
            distance(reached),
            distance(asked)
        ),
        crate::eye::FocusLimit::NearPoint => format!(
            "{} (its near point, clamped; asked {}, nearer)",
            distance(reached),
            distance(asked)
        ),
    };
    let through = summary
        .physiology
        .correction
        .as_ref()
        .map(|c| format!(" through {c}"))
        .unwrap_or_default();
    format!("{focus}{through}")
}

fn print_summary(
    args: &RenderArgs,
    input: &Input,
    summary: &Summary,
    frame: &crate::render::frame::RenderedFrame,
) {
    let focus = focus_words(summary);
    println!(
        "wrote {} ({}×{}, {}, eye {} focused at {focus}, pupil {:.2} mm from {}; {} {:.2} s; kernels {})",
        summary.output,
        input.frame.width,
        input.frame.height,
        input.label,
        args.eye,
        summary.pupil_mm,
        summary.pupil_source,
        args.method.name(),
        frame.seconds,
        if args.method == Method::Views {
            "none".to_string()
        } else if summary.kernels_from_cache {
            "from cache".to_string()
        } else {
            format!(
                "{} PSFs in {:.1} s",
                summary.psfs_computed, summary.seconds_kernels
            )
        }
    );
    if let Some(f) = &summary.field {
        let span = |a: &[f64]| format!("{:+.1}..{:+.1}°", a[0], a[a.len() - 1]);
        println!(
            "  off axis: {} × {} field directions (h {}, v {}), wavefront interpolation error \
             ≤ {:.3} µm RMS",
            f.axes.h_deg.len(),
            f.axes.v_deg.len(),
            span(&f.axes.h_deg),
            span(&f.axes.v_deg),
            f.worst_error_um
        );
    }
    if !args.timings {
        return;
    }
    if let Some(t) = &frame.timings {
        for p in &t.passes {
            println!("  {:<12} {:>9.3} ms", p.name, p.ms);
        }
        println!(
            "  {:<12} {:>9.3} ms  (GPU, {})",
            "total",
            t.total_ms(),
            summary.device
        );
    } else {
        println!("  (--timings applies to --method splat)");
    }
}
