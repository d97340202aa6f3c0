//! Keyframed channels with smooth interpolation.
//!
//! Every channel is a piecewise cubic Hermite curve through its keys: it passes through each
//! key exactly, has a continuous first derivative, and is monotone between keys (the
//! Fritsch–Butland tangent choice: a tangent is zero where the data turn, and a weighted
//! harmonic mean of the neighbouring slopes elsewhere), so a focus or pupil ramp never
//! overshoots its keys. Tangents at the first and last key are zero, so motion eases in and
//! out. Before the first key and after the last the value holds.

/// One scalar channel: sorted (time s, value) keys.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Track {
    times: Vec<f64>,
    values: Vec<f64>,
    tangents: Vec<f64>,
}

impl Track {
    /// Keys must have strictly increasing times (the scene parser checks this).
    pub fn new(keys: &[(f64, f64)]) -> Track {
        let times: Vec<f64> = keys.iter().map(|k| k.0).collect();
        let values: Vec<f64> = keys.iter().map(|k| k.1).collect();
        let n = keys.len();
        let mut tangents = vec![0.0; n];
        for k in 1..n.saturating_sub(1) {
            let h0 = times[k] - times[k - 1];
            let h1 = times[k + 1] - times[k];
            let d0 = (values[k] - values[k - 1]) / h0;
            let d1 = (values[k + 1] - values[k]) / h1;
            if d0 * d1 > 0.0 {
                tangents[k] = 3.0 * (h0 + h1) / ((2.0 * h1 + h0) / d0 + (h1 + 2.0 * h0) / d1);
            }
        }
        Track {
            times,
            values,
            tangents,
        }
    }

    pub fn is_empty(&self) -> bool {
        self.times.is_empty()
    }

    pub fn last_time(&self) -> Option<f64> {
        self.times.last().copied()
    }

    /// The value at `t_s`; `None` for a channel without keys.
    pub fn at(&self, t_s: f64) -> Option<f64> {
        let n = self.times.len();
        if n == 0 {
            return None;
        }
        if t_s <= self.times[0] {
            return Some(self.values[0]);
        }
        if t_s >= self.times[n - 1] {
            return Some(self.values[n - 1]);
        }
        // First key strictly after t: the segment is [k-1, k].
        let k = self.times.partition_point(|&x| x <= t_s);
        let (t0, t1) = (self.times[k - 1], self.times[k]);
        let h = t1 - t0;
        let s = (t_s - t0) / h;
        let (s2, s3) = (s * s, s * s * s);
        let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
        let h10 = s3 - 2.0 * s2 + s;
        let h01 = -2.0 * s3 + 3.0 * s2;
        let h11 = s3 - s2;
        Some(
            h00 * self.values[k - 1]
                + h10 * h * self.tangents[k - 1]
                + h01 * self.values[k]
                + h11 * h * self.tangents[k],
        )
    }
}

/// Three tracks interpolated together (a position or a look-at point).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Track3 {
    tracks: [Track; 3],
}

impl Track3 {
    pub fn new(keys: &[(f64, [f64; 3])]) -> Track3 {
        let axis = |i: usize| Track::new(&keys.iter().map(|k| (k.0, k.1[i])).collect::<Vec<_>>());
        Track3 {
            tracks: [axis(0), axis(1), axis(2)],
        }
    }

    pub fn is_empty(&self) -> bool {
        self.tracks[0].is_empty()
    }

    pub fn last_time(&self) -> Option<f64> {
        self.tracks[0].last_time()
    }

    pub fn at(&self, t_s: f64) -> Option<[f64; 3]> {
        Some([
            self.tracks[0].at(t_s)?,
            self.tracks[1].at(t_s)?,
            self.tracks[2].at(t_s)?,
        ])
    }
}

/// Unwraps a sequence of angles (degrees) so that each step takes the shortest way round:
/// interpolating the result turns through at most 180° between keys.
pub fn unwrap_degrees(angles: &[f64]) -> Vec<f64> {
    let mut out: Vec<f64> = Vec::with_capacity(angles.len());
    for &a in angles {
        match out.last() {
            None => out.push(a),
            Some(&previous) => {
                let step = (a - previous).rem_euclid(360.0);
                let step = if step > 180.0 { step - 360.0 } else { step };
                out.push(previous + step);
            }
        }
    }
    out
}
