//! Eye estimation: from one set of on-axis Zernike coefficients (pupil, wavelength) to a
//! physical eye whose measured aberrations match them while its parameters stay plausible
//! (the seed paper's Section 4 and Table 1; the loss is in [`loss`]).
//!
//! The target is every term of orders 1…`order` (6 by default): a term the input does not name
//! is a measured zero, so a "healthy" input asks for an eye free of aberrations up to that
//! order, not for an eye that merely has no defocus. The eye is measured relaxed, for an object
//! at infinity, over the input's entrance pupil at the input's wavelength (the model is
//! chromatic, so a 470 nm measurement and a 590 nm one give different eyes).
//!
//! Two optimisers share the loss: the generalized pattern search of the paper (the reference,
//! [`Method::PatternSearch`]) and [`Method::Hybrid`], a box-constrained Levenberg–Marquardt
//! on the residual vector followed by a pattern-search polish from its result. Both are
//! deterministic: evaluations are pure and chosen by index, never by arrival order.

pub mod least_squares;
pub mod loss;
pub mod params;
pub mod pattern_search;
pub mod prescription;

use crate::aberrations::ZernikeSet;
use crate::eye::error::EyeError;
use crate::eye::model::Eye;
use crate::optics::zernike::{num_terms, osa_index, osa_nm};
use least_squares::{levenberg_marquardt, LmSettings};
use loss::{Evaluator, Objective, ORDER_WEIGHTS};
use params::{prior_centre, Groups, ParamMap, ParamSpec};
use pattern_search::{pattern_search, GpsSettings, Limits, Outcome, Stop};
use serde::Serialize;
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

/// The hybrid's polish ends when this many pattern-search iterations together gain less
/// than this fraction of the loss. Where the input is not exactly reachable (keratoconus:
/// measured tilt terms that a chief-ray-referenced wavefront cannot carry together with its
/// coma), the loss has a long, nearly flat valley floor; creeping along it changes the
/// achieved coefficients by far less than 0.001 µm while costing minutes.
const POLISH_STALL_ITERATIONS: usize = 30;
const POLISH_STALL_FRACTION: f64 = 1e-4;

/// Which optimiser runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// Generalized pattern search alone (the paper's optimiser).
    PatternSearch,
    /// Levenberg–Marquardt, then a pattern-search polish.
    Hybrid,
}

impl std::str::FromStr for Method {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "gps" | "pattern-search" => Ok(Method::PatternSearch),
            "hybrid" | "lm" => Ok(Method::Hybrid),
            _ => Err(format!("unknown method {s:?}; allowed: hybrid, gps")),
        }
    }
}

/// Estimation settings.
#[derive(Debug, Clone, Serialize)]
pub struct Settings {
    pub method: Method,
    pub w_f: f64,
    pub w_a: f64,
    /// f_k of orders 1, 2, …; orders past the end reuse the last.
    pub order_weights: Vec<f64>,
    /// Highest fitted order (at least the input's, at most 10).
    pub order: u32,
    pub max_time_s: Option<f64>,
    pub max_evaluations: usize,
    /// Pattern-search mesh at which the search counts as converged (normalised units).
    pub min_mesh: f64,
    pub opportunistic: bool,
    /// Worker threads (None = rayon's default pool).
    pub threads: Option<usize>,
    /// Free parameter groups (None = chosen from the input, see [`Groups::for_target`]).
    pub groups: Option<Groups>,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            method: Method::Hybrid,
            w_f: 200.0,
            w_a: 0.1,
            order_weights: ORDER_WEIGHTS.to_vec(),
            order: 6,
            max_time_s: None,
            max_evaluations: 2_000_000,
            min_mesh: 1e-6,
            opportunistic: false,
            threads: None,
            groups: None,
        }
    }
}

/// What the optimiser reports while it runs.
#[derive(Debug, Clone, Copy)]
pub struct Progress {
    pub stage: &'static str,
    pub loss: f64,
    pub evaluations: usize,
    pub iterations: usize,
    pub elapsed_s: f64,
}

/// Input vs achieved value of one Zernike term.
#[derive(Debug, Clone, Serialize, serde::Deserialize, PartialEq)]
pub struct TermFit {
    pub n: u32,
    pub m: i32,
    /// Whether the input named this term (otherwise its target is 0).
    pub given: bool,
    pub input_um: f64,
    pub achieved_um: f64,
    pub residual_um: f64,
}

/// One fitted parameter.
#[derive(Debug, Clone, Serialize, serde::Deserialize, PartialEq)]
pub struct ParamRecord {
    pub name: String,
    pub value: f64,
    pub mean: f64,
    pub sigma: f64,
    pub lower: f64,
    pub upper: f64,
    pub in_bounds: bool,
}

/// Everything an estimate reports next to the eye (written into the eye file).
#[derive(Debug, Clone, Serialize, serde::Deserialize, PartialEq)]
pub struct Report {
    pub converged: bool,
    pub stop: String,
    pub method: String,
    pub pupil_mm: f64,
    pub wavelength_nm: f64,
    pub order: u32,
    pub loss: f64,
    pub coefficient_loss: f64,
    pub prior_loss: f64,
    /// RMS of the residuals over the terms the input names (piston excluded), µm.
    pub rms_error_given_um: f64,
    /// RMS of the residuals over every fitted term (orders 1…order), µm.
    pub rms_error_um: f64,
    pub all_in_bounds: bool,
    pub evaluations: usize,
    pub iterations: usize,
    pub time_s: f64,
    pub threads: usize,
    pub w_f: f64,
    pub w_a: f64,
    pub order_weights: Vec<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_time_s: Option<f64>,
    pub terms: Vec<TermFit>,
    pub parameters: Vec<ParamRecord>,
}

/// The fitted eye and its report.
#[derive(Debug, Clone)]
pub struct Estimate {
    pub eye: Eye,
    pub report: Report,
}

/// Why an estimate could not start.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EstimateError {
    #[error("{0}")]
    Input(String),
    #[error(transparent)]
    Eye(#[from] EyeError),
}

/// Checks the target the way the CLI promises: pupil 1–9 mm, wavelength 380–1000 nm,
/// finite coefficients of existing terms up to order 10.
pub fn check_target(target: &ZernikeSet) -> Result<(), EstimateError> {
    crate::limits::PUPIL_MM
        .check("pupil diameter", target.pupil_diameter_mm)
        .map_err(EstimateError::Input)?;
    crate::limits::WAVELENGTH_NM
        .check("wavelength", target.wavelength_nm)
        .map_err(EstimateError::Input)?;
    for &(n, m, v) in &target.coefficients {
        if n > 10 || !crate::optics::zernike::is_valid_nm(n, m) {
            return Err(EstimateError::Input(format!(
                "Zernike term ({n}, {m}) is not allowed; need an existing term of order 0 to 10"
            )));
        }
        if !v.is_finite() {
            return Err(EstimateError::Input(format!(
                "coefficient of ({n}, {m}) is {v}; need a finite value in µm"
            )));
        }
    }
    Ok(())
}

/// Fits an eye to `target`. `cancel` (set from a signal handler, say) and the time limit stop
/// the search early; the best eye so far is returned with `converged = false`.
pub fn estimate(
    target: &ZernikeSet,
    settings: &Settings,
    cancel: &AtomicBool,
    progress: &mut (dyn FnMut(&Progress) + Send),
) -> Result<Estimate, EstimateError> {
    check_target(target)?;
    if let Some(t) = settings.max_time_s {
        if !(t.is_finite() && t > 0.0) {
            return Err(EstimateError::Input(format!(
                "time limit {t} s is not allowed; need a positive number of seconds"
            )));
        }
    }
    match settings.threads {
        Some(0) => Err(EstimateError::Input(
            "threads must be at least 1".to_string(),
        )),
        Some(t) => rayon::ThreadPoolBuilder::new()
            .num_threads(t)
            .build()
            .map_err(|e| EstimateError::Input(format!("cannot start {t} threads: {e}")))?
            .install(|| run(target, settings, cancel, progress)),
        None => run(target, settings, cancel, progress),
    }
}

fn run(
    target: &ZernikeSet,
    settings: &Settings,
    cancel: &AtomicBool,
    progress: &mut (dyn FnMut(&Progress) + Send),
) -> Result<Estimate, EstimateError> {
    let start = Instant::now();
    let order = settings.order.max(target.max_order()).clamp(1, 10);
    let mut target_um = vec![0.0; num_terms(order)];
    for &(n, m, v) in &target.coefficients {
        target_um[osa_index(n, m)] += v;
    }
    let objective = Objective::new(
        target.pupil_diameter_mm,
        target.wavelength_nm,
        order,
        target_um,
        settings.w_f,
        settings.w_a,
        &settings.order_weights,
    );
    let groups = settings
        .groups
        .unwrap_or_else(|| Groups::for_target(&target.coefficients));
    let map = ParamMap::new(ParamSpec::table(groups), &prior_centre());
    let eval = Evaluator::new(&map, &objective);
    let x0 = map.unit_of(&prior_centre());
    let n = map.len();
    let (lower, upper) = (vec![0.0; n], vec![1.0; n]);
    let limits = Limits {
        max_evaluations: settings.max_evaluations,
        deadline: settings
            .max_time_s
            .map(|t| start + Duration::from_secs_f64(t)),
        cancel,
    };
    let loss = |x: &[f64]| eval.loss(x);
    let gps = GpsSettings {
        min_mesh: settings.min_mesh,
        opportunistic: settings.opportunistic,
        ..GpsSettings::default()
    };
    let mut report_stage = |stage: &'static str, o: &Outcome, evals_before: usize| {
        progress(&Progress {
            stage,
            loss: o.f,
            evaluations: evals_before + o.evaluations,
            iterations: o.iterations,
            elapsed_s: start.elapsed().as_secs_f64(),
        })
    };
    let outcome = match settings.method {
        Method::PatternSearch => {
            pattern_search(&loss, &x0, &lower, &upper, &gps, &limits, &mut |o| {
                report_stage("pattern search", o, 0)
            })
        }
        Method::Hybrid => {
            let r = |x: &[f64], out: &mut [f64]| eval.residuals(x, out);
            let lm = levenberg_marquardt(
                &r,
                eval.residual_len(),
                &x0,
                &lower,
                &upper,
                &LmSettings::default(),
                &limits,
                &mut |o| report_stage("least squares", o, 0),
            );
            if lm.stop != Stop::Converged {
                lm
            } else {
                let polish = GpsSettings {
                    initial_mesh: 1e-3,
                    stall_iterations: POLISH_STALL_ITERATIONS,
                    stall_fraction: POLISH_STALL_FRACTION,
                    ..gps
                };
                let rest = Limits {
                    max_evaluations: limits.max_evaluations.saturating_sub(lm.evaluations),
                    ..limits
                };
                let before = lm.evaluations;
                let mut o =
                    pattern_search(&loss, &lm.x, &lower, &upper, &polish, &rest, &mut |o| {
                        report_stage("pattern search", o, before)
                    });
                o.evaluations += before;
                o.iterations += lm.iterations;
                o
            }
        }
    };
    if outcome.stop == Stop::Infeasible {
        return Err(EstimateError::Input(
            "the start eye cannot be measured at this pupil and wavelength".to_string(),
        ));
    }
    let eye = map.eye(&outcome.x);
    eye.validate()?;
    let report = make_report(
        &eval,
        target,
        settings,
        &outcome,
        start.elapsed().as_secs_f64(),
    );
    Ok(Estimate { eye, report })
}

fn make_report(
    eval: &Evaluator,
    target: &ZernikeSet,
    settings: &Settings,
    o: &Outcome,
    time_s: f64,
) -> Report {
    let obj = eval.objective;
    let nt = obj.target_um.len();
    let mut achieved = vec![0.0; nt];
    eval.coefficients(&o.x, &mut achieved);
    let given = |j: usize| {
        target
            .coefficients
            .iter()
            .any(|&(n, m, _)| osa_index(n, m) == j)
    };
    let terms: Vec<TermFit> = (1..nt)
        .map(|j| {
            let (n, m) = osa_nm(j);
            TermFit {
                n,
                m,
                given: given(j),
                input_um: obj.target_um[j],
                achieved_um: achieved[j],
                residual_um: achieved[j] - obj.target_um[j],
            }
        })
        .collect();
    let rms = |it: &mut dyn Iterator<Item = &TermFit>| {
        let (s, k) = it.fold((0.0, 0usize), |(s, k), t| {
            (s + t.residual_um * t.residual_um, k + 1)
        });
        if k == 0 {
            0.0
        } else {
            (s / k as f64).sqrt()
        }
    };
    let values = eval.map.values_of(&eval.map.eye(&o.x));
    let parameters: Vec<ParamRecord> = eval
        .map
        .specs
        .iter()
        .zip(values)
        .map(|(s, v)| ParamRecord {
            name: s.name.clone(),
            value: v,
            mean: s.mean,
            sigma: s.sigma,
            lower: s.lower,
            upper: s.upper,
            in_bounds: v >= s.lower && v <= s.upper,
        })
        .collect();
    let (coefficient_loss, prior_loss) = eval.loss_parts(&o.x);
    Report {
        converged: o.stop.converged(),
        stop: format!("{:?}", o.stop).to_lowercase(),
        method: match settings.method {
            Method::PatternSearch => "gps".into(),
            Method::Hybrid => "hybrid".into(),
        },
        pupil_mm: obj.pupil_mm,
        wavelength_nm: obj.wavelength_nm,
        order: obj.order,
        loss: o.f,
        coefficient_loss,
        prior_loss,
        rms_error_given_um: rms(&mut terms.iter().filter(|t| t.given)),
        rms_error_um: rms(&mut terms.iter()),
        all_in_bounds: parameters.iter().all(|p| p.in_bounds),
        evaluations: o.evaluations,
        iterations: o.iterations,
        time_s,
        threads: rayon::current_num_threads(),
        w_f: settings.w_f,
        w_a: settings.w_a,
        order_weights: settings.order_weights.clone(),
        max_time_s: settings.max_time_s,
        terms,
        parameters,
    }
}
