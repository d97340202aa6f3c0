//! The occlusion-edge band of a frame, where partial occlusion shows: pixels within the local
//! blur radius of a depth discontinuity. A discontinuity lies between two 4-neighbours whose
//! vergences (along their rays) differ by more than the blend's group tolerance; its radius is
//! the larger green blur radius of the two (from the frame's kernels), at least one pixel.

use crate::metrics::{psnr, ImageView};
use crate::psf::kernels::KernelGrid;

/// Quality over the band only.
#[derive(Clone, Debug, serde::Serialize)]
pub struct BandQuality {
    pub pixels: usize,
    pub psnr_db: f64,
    /// The SSIM map (computed on the whole frame) averaged over the band.
    pub mssim: f64,
}

/// The band as a mask, row-major.
pub fn edge_band(
    depth_m: &[f32],
    (width, height): (u32, u32),
    fov_y_deg: f64,
    grid: &KernelGrid,
    (pupil_mm, focus_d): (f64, f64),
    tolerance_d: f64,
) -> Vec<bool> {
    let projection = crate::render::projection::Projection {
        width,
        height,
        fov_y_deg,
    };
    let dioptres = projection.dioptres(depth_m);
    let radii = grid.blended_radii(&grid.blend(pupil_mm, focus_d));
    let radius_at = |d: f64| {
        let index = grid
            .objects
            .index_of(d)
            .clamp(0.0, (radii.len() - 1) as f64);
        let i0 = index.floor() as usize;
        let i1 = (i0 + 1).min(radii.len() - 1);
        let t = index - i0 as f64;
        f64::from(radii[i0][1]) * (1.0 - t) + f64::from(radii[i1][1]) * t
    };
    let (w, h) = (width as usize, height as usize);
    let mut band = vec![false; w * h];
    let mut mark = |x: usize, y: usize, r: f64| {
        let reach = r.max(1.0);
        let k = reach.ceil() as i64;
        for dy in -k..=k {
            for dx in -k..=k {
                if ((dx * dx + dy * dy) as f64) > reach * reach {
                    continue;
                }
                let (xx, yy) = (x as i64 + dx, y as i64 + dy);
                if xx >= 0 && yy >= 0 && (xx as usize) < w && (yy as usize) < h {
                    band[yy as usize * w + xx as usize] = true;
                }
            }
        }
    };
    for y in 0..h {
        for x in 0..w {
            let d = dioptres[y * w + x];
            for (nx, ny) in [(x + 1, y), (x, y + 1)] {
                if nx >= w || ny >= h {
                    continue;
                }
                let e = dioptres[ny * w + nx];
                if (d - e).abs() > tolerance_d {
                    let r = radius_at(d).max(radius_at(e));
                    mark(x, y, r);
                }
            }
        }
    }
    band
}

/// PSNR and mean SSIM of `image` against `truth` (both displayed, 0–1) over the band.
pub fn band_quality(
    image: &[[f32; 4]],
    truth: &[[f32; 4]],
    ssim_map: &[f32],
    band: &[bool],
    width: usize,
) -> BandQuality {
    let pick = |v: &[[f32; 4]]| -> Vec<[f32; 4]> {
        v.iter()
            .zip(band)
            .filter(|(_, &b)| b)
            .map(|(p, _)| *p)
            .collect()
    };
    let (a, b) = (pick(image), pick(truth));
    let pixels = a.len();
    let mssim = ssim_map
        .iter()
        .zip(band)
        .filter(|(_, &b)| b)
        .map(|(s, _)| f64::from(*s))
        .sum::<f64>()
        / pixels.max(1) as f64;
    let _ = width;
    BandQuality {
        pixels,
        psnr_db: if pixels == 0 {
            f64::NAN
        } else {
            psnr(
                ImageView::new(pixels, 1, &a),
                ImageView::new(pixels, 1, &b),
                1.0,
            )
        },
        mssim,
    }
}
