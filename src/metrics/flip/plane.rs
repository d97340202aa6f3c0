//! One channel of an image in f64 and the separable filtering FLIP's filters need. Borders
//! repeat the edge pixel (the reference implementation's choice, so that maps agree at the
//! border too), which also keeps a flat image flat after filtering.

use rayon::prelude::*;

#[derive(Clone, Debug)]
pub struct Plane {
    pub width: usize,
    pub height: usize,
    pub values: Vec<f64>,
}

impl Plane {
    pub fn new(width: usize, height: usize, values: Vec<f64>) -> Plane {
        assert_eq!(values.len(), width * height, "plane of {width}×{height}");
        Plane {
            width,
            height,
            values,
        }
    }

    pub fn at(&self, x: usize, y: usize) -> f64 {
        self.values[y * self.width + x]
    }

    /// Correlation along rows with `taps_x`, then along columns with `taps_y` (each of odd
    /// length, centred): out(x, y) = Σ_j Σ_i taps_y[j] taps_x[i] in(x + i − r_x, y + j − r_y).
    pub fn separable(&self, taps_x: &[f64], taps_y: &[f64]) -> Plane {
        self.along_rows(taps_x).along_columns(taps_y)
    }

    pub fn along_rows(&self, taps: &[f64]) -> Plane {
        let w = self.width;
        let r = (taps.len() / 2) as isize;
        self.rows_from(|y, row| {
            let src = &self.values[y * w..(y + 1) * w];
            for (x, o) in row.iter_mut().enumerate() {
                let mut sum = 0.0;
                for (i, t) in taps.iter().enumerate() {
                    let xx = (x as isize + i as isize - r).clamp(0, w as isize - 1) as usize;
                    sum += t * src[xx];
                }
                *o = sum;
            }
        })
    }

    pub fn along_columns(&self, taps: &[f64]) -> Plane {
        let (w, h) = (self.width, self.height);
        let r = (taps.len() / 2) as isize;
        self.rows_from(|y, row| {
            for (i, t) in taps.iter().enumerate() {
                let yy = (y as isize + i as isize - r).clamp(0, h as isize - 1) as usize;
                let src = &self.values[yy * w..(yy + 1) * w];
                for (o, s) in row.iter_mut().zip(src) {
                    *o += t * s;
                }
            }
        })
    }

    /// A plane of this one's size whose row y (zeroed first) `fill(y, row)` writes, rows in
    /// parallel.
    fn rows_from(&self, fill: impl Fn(usize, &mut [f64]) + Sync + Send) -> Plane {
        let (w, h) = (self.width, self.height);
        let mut out = vec![0.0; w * h];
        if w > 0 {
            out.par_chunks_mut(w)
                .enumerate()
                .for_each(|(y, row)| fill(y, row));
        }
        Plane::new(w, h, out)
    }
}
