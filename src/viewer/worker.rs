//! The render thread: one device, one kernel cache, every client. Each client holds at most
//! one pending request: a newer one replaces it, so a dragged slider never queues a backlog,
//! and a frame in flight is followed by the client's latest request only. Clients take turns.
//! A request is answered with a preview (half the width and height) and then the full frame,
//! unless a newer request arrived meanwhile.

use std::collections::BTreeMap;
use std::sync::{Arc, Condvar, Mutex};
use std::time::Instant;

use axum::extract::ws::Message;
use tokio::sync::mpsc;

use super::catalog::Catalog;
use super::request::{EyeChoice, ViewRequest};
use crate::eye::Eye;
use crate::image_io::{ImageRgba, Tonemap, TonemapMode};
use crate::render::live::{FrameReport, LiveFrame, LiveOptions, LiveRenderer, SceneArg};

/// What goes back to a client.
pub type Outbox = mpsc::Sender<Message>;

/// An export of the last full frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Format {
    Png,
    Exr,
}

struct Client {
    pending: Option<(u64, Arc<ViewRequest>)>,
    exports: Vec<(Format, usize)>,
    out: Outbox,
    /// The last full frame of each side, and its request, for exports.
    last_full: Vec<Option<(Arc<LiveFrame>, Arc<ViewRequest>)>>,
}

#[derive(Default)]
struct State {
    clients: BTreeMap<u64, Client>,
    /// The client served last: the next turn goes to the next one with work.
    last_served: u64,
    shutdown: bool,
}

/// Totals for `/api/stats` and the load test.
#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
pub struct Stats {
    pub requests: u64,
    /// Requests replaced by a newer one before they were rendered.
    pub superseded: u64,
    /// Full frames skipped because a newer request arrived after the preview.
    pub full_frames_skipped: u64,
    pub previews: u64,
    pub full_frames: u64,
    pub errors: u64,
    /// Messages a slow client did not take in time (dropped).
    pub dropped: u64,
}

pub struct Hub {
    state: Mutex<State>,
    wake: Condvar,
    stats: Mutex<Stats>,
}

enum Work {
    Render(u64, Arc<ViewRequest>),
    Export(Format, usize),
}

impl Hub {
    pub fn new() -> Arc<Hub> {
        Arc::new(Hub {
            state: Mutex::new(State::default()),
            wake: Condvar::new(),
            stats: Mutex::new(Stats::default()),
        })
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(|p| p.into_inner())
    }

    fn count(&self, f: impl FnOnce(&mut Stats)) {
        f(&mut self.stats.lock().unwrap_or_else(|p| p.into_inner()))
    }

    pub fn stats(&self) -> Stats {
        *self.stats.lock().unwrap_or_else(|p| p.into_inner())
    }

    pub fn clients(&self) -> usize {
        self.lock().clients.len()
    }

    /// Registers a client; false where `max` are connected already.
    pub fn join(&self, id: u64, out: Outbox, max: usize) -> bool {
        let mut s = self.lock();
        if s.clients.len() >= max {
            return false;
        }
        s.clients.insert(
            id,
            Client {
                pending: None,
                exports: Vec::new(),
                out,
                last_full: Vec::new(),
            },
        );
        true
    }

    pub fn leave(&self, id: u64) {
        self.lock().clients.remove(&id);
    }

    /// The client's latest request, replacing any it had pending.
    pub fn submit(&self, id: u64, seq: u64, request: ViewRequest) {
        let mut s = self.lock();
        if let Some(c) = s.clients.get_mut(&id) {
            if c.pending.replace((seq, Arc::new(request))).is_some() {
                self.count(|st| st.superseded += 1);
            }
            self.count(|st| st.requests += 1);
            self.wake.notify_one();
        }
    }

    pub fn export(&self, id: u64, format: Format, side: usize) {
        let mut s = self.lock();
        if let Some(c) = s.clients.get_mut(&id) {
            if c.exports.len() < 4 {
                c.exports.push((format, side));
            }
            self.wake.notify_one();
        }
    }

    pub fn shutdown(&self) {
        self.lock().shutdown = true;
        self.wake.notify_all();
    }

    /// Whether `id` has a request newer than `seq` waiting (or has left).
    fn superseded(&self, id: u64, seq: u64) -> bool {
        let s = self.lock();
        s.clients
            .get(&id)
            .is_none_or(|c| c.pending.as_ref().is_some_and(|(p, _)| *p > seq))
    }

    /// Blocks until some client has work; the next client after the last served goes first.
    fn next(&self) -> Option<(u64, Work)> {
        let mut s = self.lock();
        loop {
            if s.shutdown {
                return None;
            }
            let after = s.last_served;
            let ids: Vec<u64> = s
                .clients
                .range(after + 1..)
                .chain(s.clients.range(..=after))
                .filter(|(_, c)| c.pending.is_some() || !c.exports.is_empty())
                .map(|(id, _)| *id)
                .collect();
            if let Some(&id) = ids.first() {
                s.last_served = id;
                let c = s.clients.get_mut(&id).expect("listed above");
                if !c.exports.is_empty() {
                    let (f, side) = c.exports.remove(0);
                    return Some((id, Work::Export(f, side)));
                }
                let (seq, r) = c.pending.take().expect("has work");
                return Some((id, Work::Render(seq, r)));
            }
            s = self.wake.wait(s).unwrap_or_else(|p| p.into_inner());
        }
    }

    fn send(&self, id: u64, message: Message) {
        let out = self.lock().clients.get(&id).map(|c| c.out.clone());
        if let Some(out) = out {
            if out.try_send(message).is_err() {
                self.count(|s| s.dropped += 1);
            }
        }
    }

    fn send_error(&self, id: u64, seq: u64, message: &str) {
        self.count(|s| s.errors += 1);
        let text = serde_json::json!({"type": "error", "seq": seq, "message": message});
        self.send(id, Message::Text(text.to_string().into()));
    }

    fn keep_full(&self, id: u64, side: usize, frame: Arc<LiveFrame>, request: Arc<ViewRequest>) {
        let mut s = self.lock();
        if let Some(c) = s.clients.get_mut(&id) {
            if c.last_full.len() <= side {
                c.last_full.resize(side + 1, None);
            }
            c.last_full[side] = Some((frame, request));
        }
    }

    fn last_full(&self, id: u64, side: usize) -> Option<(Arc<LiveFrame>, Arc<ViewRequest>)> {
        let s = self.lock();
        s.clients
            .get(&id)
            .and_then(|c| c.last_full.get(side).cloned().flatten())
    }
}

/// A binary message: a 4-byte big-endian header length, the JSON header, the payload.
fn framed(header: &serde_json::Value, payload: &[u8]) -> Message {
    let h = header.to_string();
    let mut bytes = Vec::with_capacity(4 + h.len() + payload.len());
    bytes.extend_from_slice(&(h.len() as u32).to_be_bytes());
    bytes.extend_from_slice(h.as_bytes());
    bytes.extend_from_slice(payload);
    Message::Binary(bytes.into())
}

/// Stage of an answer.
#[derive(Clone, Copy, PartialEq)]
enum Stage {
    Preview,
    Full,
}

impl Stage {
    fn name(self) -> &'static str {
        match self {
            Stage::Preview => "preview",
            Stage::Full => "full",
        }
    }
}

/// Eyes estimated from prescriptions, most recent last.
const RX_EYES_KEPT: usize = 16;

pub struct Worker {
    pub hub: Arc<Hub>,
    pub live: LiveRenderer,
    pub catalog: Arc<Catalog>,
    rx_eyes: Vec<((String, u64), Eye)>,
}

impl Worker {
    pub fn new(hub: Arc<Hub>, live: LiveRenderer, catalog: Arc<Catalog>) -> Worker {
        Worker {
            hub,
            live,
            catalog,
            rx_eyes: Vec::new(),
        }
    }

    /// Serves until the hub shuts down.
    pub fn run(mut self) {
        while let Some((id, work)) = self.hub.next() {
            match work {
                Work::Render(seq, request) => self.render(id, seq, request),
                Work::Export(format, side) => self.export(id, format, side),
            }
        }
    }

    fn eye(&mut self, choice: &EyeChoice) -> crate::Result<Eye> {
        match choice {
            EyeChoice::Preset(p) => Eye::preset(p)
                .ok_or_else(|| crate::Error::input(format!("--eye {p:?} is not a preset"))),
            EyeChoice::File(f) => self
                .catalog
                .eye_files
                .get(f)
                .map(|e| e.eye.clone())
                .ok_or_else(|| crate::Error::input(format!("--eye {f:?} is not an eye file"))),
            EyeChoice::Rx { rx, pupil_mm } => {
                let key = (rx.clone(), pupil_mm.to_bits());
                if let Some(i) = self.rx_eyes.iter().position(|(k, _)| *k == key) {
                    let kept = self.rx_eyes.remove(i);
                    let eye = kept.1.clone();
                    self.rx_eyes.push(kept);
                    return Ok(eye);
                }
                let target =
                    crate::eye::estimate::prescription::RxTarget::new(rx, *pupil_mm, None, None)
                        .map_err(|e| crate::Error::input(format!("--rx {rx:?}: {e}")))?;
                let est = target
                    .estimate(
                        &Default::default(),
                        &std::sync::atomic::AtomicBool::new(false),
                        &mut |_| {},
                    )
                    .map_err(|e| crate::Error::input(format!("--rx {rx:?}: {e}")))?;
                if self.rx_eyes.len() >= RX_EYES_KEPT {
                    self.rx_eyes.remove(0);
                }
                self.rx_eyes.push((key, est.eye.clone()));
                Ok(est.eye)
            }
        }
    }

    fn render(&mut self, id: u64, seq: u64, request: Arc<ViewRequest>) {
        let started = Instant::now();
        let eyes: crate::Result<Vec<Eye>> =
            request.sides.iter().map(|s| self.eye(&s.eye)).collect();
        let eyes = match eyes {
            Ok(e) => e,
            Err(e) => return self.hub.send_error(id, seq, &e.to_string()),
        };
        let (w, h) = request.size;
        // A preview only where it is much cheaper and still a frame the renderer takes.
        let preview_size = (w / 2, h / 2);
        let stages: &[Stage] = if preview_size.1 >= crate::limits::MIN_FRAME_SIDE
            && preview_size.0 >= crate::limits::MIN_FRAME_SIDE
        {
            &[Stage::Preview, Stage::Full]
        } else {
            &[Stage::Full]
        };
        for &stage in stages {
            if stage == Stage::Full && stages.len() > 1 && self.hub.superseded(id, seq) {
                self.hub.count(|s| s.full_frames_skipped += 1);
                return;
            }
            let size = match stage {
                Stage::Preview => preview_size,
                Stage::Full => request.size,
            };
            let scene = &self.catalog.scenes[&request.scene].scene;
            let options = |side: usize| {
                let mut o: LiveOptions = request.options.clone();
                o.correction = request.sides[side].correction.clone();
                if let (
                    Stage::Preview,
                    Some(crate::render::frame_plan::FocusAsked::AtPixel(x, y)),
                ) = (stage, o.focus)
                {
                    o.focus = Some(crate::render::frame_plan::FocusAsked::AtPixel(
                        (x / 2).min(size.0 - 1),
                        (y / 2).min(size.1 - 1),
                    ));
                }
                o
            };
            // A binocular pair renders both eyes together (one accommodation); each eye's
            // frame then goes out as its side.
            let pair = match request.binocular_ipd_mm {
                Some(ipd_mm) => {
                    let rendered = crate::render::binocular::render_pair(
                        &self.live,
                        &crate::render::binocular::PairRequest {
                            scene,
                            eyes: [&eyes[0], &eyes[1]],
                            options: options(0),
                            corrections: [
                                request.sides[0].correction.clone(),
                                request.sides[1].correction.clone(),
                            ],
                            size,
                            time_s: request.time_s,
                            ipd_m: ipd_mm * 1e-3,
                        },
                    );
                    match rendered {
                        Ok(p) => {
                            // the scene's own warnings; each frame's come with it below
                            let scene_warnings: Vec<String> = p
                                .warnings
                                .iter()
                                .filter(|w| {
                                    !w.starts_with("left eye:") && !w.starts_with("right eye:")
                                })
                                .cloned()
                                .collect();
                            let [l, r] = p.frames;
                            vec![(l, scene_warnings.clone()), (r, scene_warnings)]
                        }
                        Err(e) => return self.hub.send_error(id, seq, &e.to_string()),
                    }
                }
                None => Vec::new(),
            };
            let mut pair = pair.into_iter();
            for (side, eye) in eyes.iter().enumerate() {
                let rendered = match pair.next() {
                    Some(done) => Ok(done),
                    None => self.live.render_scene(
                        SceneArg::Loaded(scene),
                        eye,
                        &options(side),
                        Some(size),
                        request.time_s,
                    ),
                };
                let (frame, mut warnings) = match rendered {
                    Ok(f) => f,
                    Err(e) => return self.hub.send_error(id, seq, &e.to_string()),
                };
                warnings.extend(frame.report.warnings.iter().cloned());
                let png = match encode_png(&frame) {
                    Ok(p) => p,
                    Err(e) => return self.hub.send_error(id, seq, &e),
                };
                let header = serde_json::json!({
                    "type": "frame",
                    "seq": seq,
                    "stage": stage.name(),
                    "side": side,
                    "sides": eyes.len(),
                    "summary": summary(&frame.report, &warnings),
                    "seconds_total": started.elapsed().as_secs_f64(),
                    "command": request.command_line(side, &self.catalog, "ocular.png"),
                });
                self.hub.send(id, framed(&header, &png));
                match stage {
                    Stage::Preview => self.hub.count(|s| s.previews += 1),
                    Stage::Full => {
                        self.hub.count(|s| s.full_frames += 1);
                        self.hub
                            .keep_full(id, side, Arc::new(frame), Arc::clone(&request));
                    }
                }
            }
        }
    }

    fn export(&mut self, id: u64, format: Format, side: usize) {
        let Some((frame, request)) = self.hub.last_full(id, side) else {
            return self
                .hub
                .send_error(id, 0, "export: no full frame has been rendered yet");
        };
        let (ext, bytes) = match format {
            Format::Png => ("png", encode_png(&frame)),
            Format::Exr => {
                let image =
                    ImageRgba::new(frame.report.width, frame.report.height, frame.color.clone());
                ("exr", crate::image_io::exr_rgba_bytes(&image))
            }
        };
        let bytes = match bytes {
            Ok(b) => b,
            Err(e) => return self.hub.send_error(id, 0, &format!("export: {e}")),
        };
        let file = match (request.sides.len(), side) {
            (1, _) => format!("ocular-{}.{ext}", request.scene),
            (_, 0) => format!("ocular-{}-a.{ext}", request.scene),
            _ => format!("ocular-{}-b.{ext}", request.scene),
        };
        let header = serde_json::json!({
            "type": "export",
            "format": ext,
            "side": side,
            "filename": file,
            "command": request.command_line(side, &self.catalog, &file),
        });
        self.hub.send(id, framed(&header, &bytes));
    }
}

/// The frame as the CLI writes a PNG by default: its exposure, clamped.
fn encode_png(frame: &LiveFrame) -> std::result::Result<Vec<u8>, String> {
    let image = ImageRgba::new(frame.report.width, frame.report.height, frame.color.clone());
    crate::image_io::png_bytes(
        &image,
        Tonemap {
            exposure_ev: frame.report.exposure_ev,
            mode: TonemapMode::Clamp,
        },
    )
}

/// The report as the page shows it.
fn summary(r: &FrameReport, warnings: &[String]) -> serde_json::Value {
    let mut v = serde_json::to_value(r).unwrap_or_default();
    v["warnings"] = serde_json::json!(warnings);
    v
}
