//! Which object samples of a kernel set get a PSF of their own, and which are filled by the
//! runtime's own blend of the computed samples around them.
//!
//! The runtime blends the kernels of the two object samples around a fragment's vergence,
//! level by level. A sample whose kernels equal that blend of its neighbours' adds nothing to
//! the frame, so it need not be computed: filling it by the same blend makes the runtime's
//! interpolation piecewise linear between the computed samples (the *knots*), exactly as an
//! axis holding only the knots would. The GPU, the merge, the reference and the planner keep
//! the uniform axis and its one dioptre → index map.
//!
//! Where knots are needed is decided from the eye's own kernels, per (pupil, focus) column and
//! channel: knots start [`COARSE_STEP_D`] apart; an interval is halved while the kernel at its
//! midpoint differs from the blend of its ends by more than a tolerance (L1, the fraction of
//! the kernel's energy in the wrong place), down to the axis' own step. Near a channel's focus
//! the shape changes within a few hundredths of a dioptre and the axis stays dense; far from
//! it a step of a dioptre scales a defocus-dominated PSF nearly self-similarly and the blend
//! is close to the truth.

/// Default largest L1 distance between a kernel and the blend of the knots around it.
pub const DEFAULT_OBJECT_TOLERANCE: f64 = 0.005;

/// Spacing of the first knots (D): halved from there where the kernels need it.
pub const COARSE_STEP_D: f64 = 1.0;

/// The first knots of an axis of `count` samples `step_d` apart: every sample when
/// `tolerance` is 0, else samples a power of two apart, at most [`COARSE_STEP_D`], and the
/// last one.
pub fn initial_knots(count: usize, step_d: f64, tolerance: f64) -> Vec<usize> {
    if count == 0 {
        return Vec::new();
    }
    let mut stride = 1usize;
    if tolerance > 0.0 {
        while (2 * stride) as f64 * step_d <= COARSE_STEP_D + 1e-9 && 2 * stride < count {
            stride *= 2;
        }
    }
    let mut knots: Vec<usize> = (0..count).step_by(stride).collect();
    if knots.last() != Some(&(count - 1)) {
        knots.push(count - 1);
    }
    knots
}

/// Consecutive knots (sorted) with samples between them: the intervals still to test.
pub fn open_intervals(knots: &[usize]) -> Vec<(usize, usize)> {
    knots
        .windows(2)
        .filter(|w| w[1] - w[0] >= 2)
        .map(|w| (w[0], w[1]))
        .collect()
}

/// The sample an interval is tested at and split at.
pub fn midpoint((a, b): (usize, usize)) -> usize {
    (a + b) / 2
}

/// Weight of `b` in the blend at `o` between knots `a` < `b`.
pub fn weight(a: usize, o: usize, b: usize) -> f64 {
    (o - a) as f64 / (b - a) as f64
}

/// For every sample of an axis of `count`, the knots around it and the weight of the upper
/// one: a knot is its own bracket `(o, o, 0)`. `is_knot` must hold for the first and last
/// samples.
pub fn brackets(count: usize, is_knot: impl Fn(usize) -> bool) -> Vec<(usize, usize, f64)> {
    let knots: Vec<usize> = (0..count).filter(|&o| is_knot(o)).collect();
    let mut out = Vec::with_capacity(count);
    for w in knots.windows(2) {
        let (a, b) = (w[0], w[1]);
        out.push((a, a, 0.0));
        out.extend((a + 1..b).map(|o| (a, b, weight(a, o, b))));
    }
    if let Some(&last) = knots.last() {
        out.push((last, last, 0.0));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_knots_are_a_dioptre_apart_and_close_the_axis() {
        // 0..10 D in 1/16 D: every 16th sample
        let k = initial_knots(161, 1.0 / 16.0, 0.01);
        assert_eq!(k.len(), 11);
        assert!(k.iter().zip(k.iter().skip(1)).all(|(a, b)| b - a == 16));
        // an axis that does not end on the stride keeps its last sample
        assert_eq!(initial_knots(20, 1.0 / 16.0, 0.01), vec![0, 16, 19]);
        // tolerance 0: every sample; a coarse axis: every sample
        assert_eq!(initial_knots(5, 1.0 / 16.0, 0.0), vec![0, 1, 2, 3, 4]);
        assert_eq!(initial_knots(4, 2.0, 0.01), vec![0, 1, 2, 3]);
        assert_eq!(initial_knots(1, 0.1, 0.01), vec![0]);
    }

    #[test]
    fn brackets_cover_every_sample_with_weights_that_reproduce_a_line() {
        let knots = [0usize, 3, 4, 9];
        let b = brackets(10, |o| knots.contains(&o));
        assert_eq!(b.len(), 10);
        // a linear function is reproduced exactly by its knots' blend
        let f = |o: usize| 2.0 + 0.5 * o as f64;
        for (o, &(lo, hi, t)) in b.iter().enumerate() {
            assert!(lo <= o && o <= hi);
            assert!(knots.contains(&lo) && knots.contains(&hi));
            assert!(((1.0 - t) * f(lo) + t * f(hi) - f(o)).abs() < 1e-12);
        }
        assert_eq!(open_intervals(&knots), vec![(0, 3), (4, 9)]);
        assert_eq!(midpoint((4, 9)), 6);
    }
}
