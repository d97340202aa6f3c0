//! The partial-occlusion options shared by render and compare: `--views` (the multi-view
//! truth) and `--layers` (depth-peeled inputs for splat).

use crate::eye::Eye;
use crate::gpu::Context;
use crate::render::frame::{KernelOptions, Method, RenderedFrame};
use crate::scene::FrameState;
use crate::Result;

/// `--views N`: a whole number of views within the accepted range.
pub(crate) fn parse_views(text: &str) -> std::result::Result<u32, String> {
    use crate::render::views::{MAX_VIEWS, MIN_VIEWS};
    match text.trim().parse::<u32>() {
        Ok(n) if (MIN_VIEWS..=MAX_VIEWS).contains(&n) => Ok(n),
        _ => Err(format!(
            "{text} is not a whole number of views from {MIN_VIEWS} to {MAX_VIEWS}"
        )),
    }
}

/// `--layers K`: a whole number of depth layers within the accepted range.
pub(crate) fn parse_layers(text: &str) -> std::result::Result<u32, String> {
    let most = crate::inputs::layered::MAX_LAYERS as u32;
    match text.trim().parse::<u32>() {
        Ok(k) if (1..=most).contains(&k) => Ok(k),
        _ => Err(format!(
            "{text} is not a whole number of layers from 1 to {most}"
        )),
    }
}

/// How many layers a scene is peeled to: `asked`, else the default where it fits the device.
pub(crate) fn scene_layers(
    ctx: &Context,
    asked: Option<u32>,
    (width, height): (u32, u32),
    notes: &mut Vec<String>,
) -> u32 {
    let fit = crate::render::splat::max_layers(ctx, width, height).max(1);
    match asked {
        Some(k) => k,
        None if fit < crate::render::raster::DEFAULT_LAYERS => {
            notes.push(format!(
                "{fit} depth layer(s), not {}: more would exceed this device's storage-buffer \
                 limit at {width}×{height}",
                crate::render::raster::DEFAULT_LAYERS
            ));
            fit
        }
        None => crate::render::raster::DEFAULT_LAYERS,
    }
}

/// The multi-view truth of a scene state through `eye` at (pupil, focus): `views` views, else
/// the default.
pub(crate) fn render_views(
    ctx: &Context,
    state: &FrameState<'_>,
    size: (u32, u32),
    eye: &Eye,
    (pupil_mm, focus_d): (f64, f64),
    views: Option<u32>,
    options: &KernelOptions,
) -> Result<RenderedFrame> {
    let started = std::time::Instant::now();
    let column = crate::psf::defocus::ColumnOptics::new(
        eye,
        pupil_mm,
        focus_d,
        options.reference_axes.wavelengths_nm,
        &options.settings,
    )?;
    let image = crate::render::views::render(
        ctx,
        &mut crate::render::Rasterizer::new(ctx)?,
        state,
        size,
        &column,
        focus_d,
        views.unwrap_or(crate::render::views::DEFAULT_VIEWS),
    )?;
    Ok(RenderedFrame {
        color: image.color,
        method: Method::Views,
        seconds: started.elapsed().as_secs_f64(),
        timings: None,
        stats: None,
    })
}
