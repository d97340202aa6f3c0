//! Which radius levels a kernel set holds at each object distance.
//!
//! Every object distance's PSF is resampled to radius levels so that a fragment whose radius
//! lies between two levels can mix them; but a fragment at distance o has a radius near o's
//! own. It is interpolated between o's neighbours on the axis; a merged block takes the largest
//! radius of its pixels, whose distances lie within the merge's dioptre tolerance of the
//! block's (at the defaults, 0.05 D per merge level, 0.25 D over five); and the PSF texture
//! blends each set with its neighbours in pupil and focus. So the levels far above an object's
//! radius are never read, and at Rmax 48 they are most of the texels: a 5 px kernel resampled
//! to 48 px is a 97² block that no frame looks at.
//!
//! A set holds at distance o the levels up to the largest radius any of those reads can ask
//! for: over the set and its neighbours in pupil and focus, over the distances within
//! [`BAND_WINDOW_D`] of o, plus one level; the levels above are zero. A knot (an object sample
//! with a PSF of its own, [`super::object_knots`]) is integrated as far as the samples filled
//! from it hold, its window widened by the gap to them, and holds its own band. The merge clamps a
//! block's radius to the highest level held (glsl/render/splat/merge.comp), which at the
//! default tolerance never binds (0.25 D against 0.5 D) and beyond it keeps every read inside
//! the band.

use super::kernels::{level_count, level_of_radius};

/// How far (D) along the object axis the radii that decide a distance's highest level are
/// taken: twice the widest spread five merge levels reach at the default group tolerance.
pub const BAND_WINDOW_D: f64 = 0.5;

/// Per set (pupil-major: `p · focus + f`), per object distance, the highest level any read can
/// ask for: the largest natural radius (px, any channel) over the set and its neighbours in
/// pupil and focus (diagonals included) and over the distances within `window[set]` samples,
/// one level of margin, at most the last level of kernels up to `max_radius`.
pub fn read_tops(
    radii: &[Vec<[f32; 3]>],
    (pupils, focus): (usize, usize),
    window: &[usize],
    max_radius: u32,
) -> Vec<Vec<u32>> {
    let last = level_count(max_radius) - 1;
    let largest: Vec<Vec<f32>> = radii
        .iter()
        .map(|set| set.iter().map(|r| r[0].max(r[1]).max(r[2])).collect())
        .collect();
    (0..radii.len())
        .map(|s| {
            let (p, f) = (s / focus, s % focus);
            let neighbours: Vec<usize> = (p.saturating_sub(1)..(p + 2).min(pupils))
                .flat_map(|q| (f.saturating_sub(1)..(f + 2).min(focus)).map(move |g| q * focus + g))
                .collect();
            let no = largest[s].len();
            (0..no)
                .map(|o| {
                    let (lo, hi) = (o.saturating_sub(window[s]), (o + window[s]).min(no - 1));
                    let r = neighbours
                        .iter()
                        .flat_map(|&n| largest[n][lo..=hi].iter().copied())
                        .fold(0.0f32, f32::max)
                        .min(max_radius as f32);
                    ((level_of_radius(f64::from(r)).ceil() as u32) + 1).min(last)
                })
                .collect()
        })
        .collect()
}

/// Samples along an axis of `step_d` that [`BAND_WINDOW_D`] spans, plus the interpolation step.
pub fn window_samples(step_d: f64) -> usize {
    (BAND_WINDOW_D / step_d).ceil() as usize + 1
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::psf::kernels::level_radius_px;

    #[test]
    fn a_top_covers_the_largest_radius_of_its_neighbourhood() {
        // Two pupils × one focus, five objects; radii grow along the axis, the second set's
        // larger. Window 1.
        let a = vec![
            [1.0, 0.5, 0.2],
            [2.0, 2.0, 2.0],
            [3.5, 1.0, 1.0],
            [6.0; 3],
            [9.0; 3],
        ];
        let b = vec![[1.5; 3], [2.5; 3], [4.2; 3], [7.0; 3], [12.0; 3]];
        let tops = read_tops(&[a, b], (2, 1), &[1, 1], 10);
        // every set sees the other (neighbours in pupil): object 2 of either reads up to 7 px
        for set in &tops {
            assert!(level_radius_px(set[2]) >= 7.0);
            // and one level past the level holding it: 7 px is level 13, so 14
            assert_eq!(set[2], 14);
            // object 0 reaches 2.5 px (object 1 of b): level 8.5 → 9, plus one
            assert_eq!(set[0], 10);
            // the last objects are capped at the 10 px radius' last level
            assert_eq!(set[4], level_count(10) - 1);
        }
    }
}
