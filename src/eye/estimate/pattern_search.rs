//! Generalized pattern search over a box with the 2N positive basis ±e_i.
//!
//! Each iteration polls x ± Δ·e_i (points outside the box are projected onto it). A complete
//! poll evaluates all 2N points in parallel and moves to the best improving one; an
//! opportunistic poll evaluates them in fixed chunks, in order, and moves to the best improving point of the
//! first chunk that has one
//! (the direction that last succeeded is polled first). Success doubles the mesh size Δ,
//! failure halves it; the search stops when Δ falls below its minimum (converged), or on the
//! evaluation budget, the deadline or the cancel flag.
//!
//! Determinism: candidates are evaluated by a pure function and chosen by index order, so
//! the path does not depend on the number of threads.

use rayon::prelude::*;
use serde::Serialize;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// Why a search ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Stop {
    /// The mesh (or the step) fell below its minimum: a local minimum to that resolution.
    Converged,
    Evaluations,
    Time,
    Cancelled,
    /// The start point itself is infeasible.
    Infeasible,
}

impl Stop {
    pub fn converged(self) -> bool {
        self == Stop::Converged
    }
}

/// Limits shared by the optimisers.
#[derive(Debug, Clone, Copy)]
pub struct Limits<'a> {
    pub max_evaluations: usize,
    pub deadline: Option<Instant>,
    pub cancel: &'a AtomicBool,
}

impl Limits<'_> {
    /// The reason to stop now, if any.
    pub fn check(&self, evaluations: usize) -> Option<Stop> {
        if self.cancel.load(Ordering::Relaxed) {
            Some(Stop::Cancelled)
        } else if self.deadline.is_some_and(|d| Instant::now() >= d) {
            Some(Stop::Time)
        } else if evaluations >= self.max_evaluations {
            Some(Stop::Evaluations)
        } else {
            None
        }
    }
}

#[derive(Debug, Clone, Copy)]
pub struct GpsSettings {
    pub initial_mesh: f64,
    pub min_mesh: f64,
    pub max_mesh: f64,
    pub opportunistic: bool,
    /// Also stop (as converged) when the last `stall_iterations` iterations together lowered
    /// the loss by less than `stall_fraction` of it: a polish that only creeps along a valley
    /// floor has found its minimum to any precision that matters. 0 disables the test.
    pub stall_iterations: usize,
    pub stall_fraction: f64,
}

impl Default for GpsSettings {
    fn default() -> Self {
        GpsSettings {
            initial_mesh: 0.05,
            min_mesh: 1e-6,
            max_mesh: 0.25,
            opportunistic: false,
            stall_iterations: 0,
            stall_fraction: 0.0,
        }
    }
}

/// State reported after every iteration and returned at the end.
#[derive(Debug, Clone)]
pub struct Outcome {
    pub x: Vec<f64>,
    pub f: f64,
    pub evaluations: usize,
    pub iterations: usize,
    /// Final mesh size (GPS) or damping (least squares).
    pub mesh: f64,
    pub stop: Stop,
}

/// Points evaluated together by an opportunistic poll.
const OPPORTUNISTIC_CHUNK: usize = 8;

/// Minimises `f` over the box [lower, upper] from `x0`; `progress` sees each iteration.
pub fn pattern_search<F>(
    f: &F,
    x0: &[f64],
    lower: &[f64],
    upper: &[f64],
    settings: &GpsSettings,
    limits: &Limits,
    progress: &mut dyn FnMut(&Outcome),
) -> Outcome
where
    F: Fn(&[f64]) -> f64 + Sync,
{
    let n = x0.len();
    let mut best = Outcome {
        x: x0.to_vec(),
        f: f(x0),
        evaluations: 1,
        iterations: 0,
        mesh: settings.initial_mesh,
        stop: Stop::Converged,
    };
    if !best.f.is_finite() {
        best.stop = Stop::Infeasible;
        return best;
    }
    // Poll order: direction indices 0..2n (2i = +e_i, 2i+1 = −e_i), last success first.
    let mut order: Vec<usize> = (0..2 * n).collect();
    // A fixed chunk (not the thread count) keeps the opportunistic path thread-independent.
    let chunk = if settings.opportunistic {
        OPPORTUNISTIC_CHUNK
    } else {
        2 * n
    };
    let mut history: std::collections::VecDeque<f64> = std::collections::VecDeque::new();
    loop {
        if settings.stall_iterations > 0 {
            history.push_back(best.f);
            if history.len() > settings.stall_iterations {
                let old = history.pop_front().unwrap_or(best.f);
                if old - best.f <= settings.stall_fraction * best.f {
                    best.stop = Stop::Converged;
                    return best;
                }
            }
        }
        if best.mesh < settings.min_mesh {
            best.stop = Stop::Converged;
            return best;
        }
        if let Some(stop) = limits.check(best.evaluations) {
            best.stop = stop;
            return best;
        }
        let candidate = |d: usize| -> Option<Vec<f64>> {
            let i = d / 2;
            let step = if d.is_multiple_of(2) {
                best.mesh
            } else {
                -best.mesh
            };
            let v = (best.x[i] + step).clamp(lower[i], upper[i]);
            if v == best.x[i] {
                return None;
            }
            let mut x = best.x.clone();
            x[i] = v;
            Some(x)
        };
        let mut moved: Option<(usize, Vec<f64>, f64)> = None;
        for block in order.chunks(chunk) {
            let values: Vec<Option<(Vec<f64>, f64)>> = block
                .par_iter()
                .map(|&d| candidate(d).map(|x| (x.clone(), f(&x))))
                .collect();
            best.evaluations += values.iter().flatten().count();
            for (k, v) in values.into_iter().enumerate() {
                if let Some((x, fx)) = v {
                    let current = moved.as_ref().map_or(best.f, |m| m.2);
                    if fx < current {
                        moved = Some((block[k], x, fx));
                    }
                }
            }
            if settings.opportunistic && moved.is_some() {
                break;
            }
        }
        best.iterations += 1;
        match moved {
            Some((d, x, fx)) => {
                best.x = x;
                best.f = fx;
                best.mesh = (best.mesh * 2.0).min(settings.max_mesh);
                if settings.opportunistic {
                    let pos = order.iter().position(|&o| o == d).unwrap_or(0);
                    order[..=pos].rotate_right(1);
                }
            }
            None => best.mesh *= 0.5,
        }
        progress(&best);
    }
}
