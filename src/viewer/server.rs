//! HTTP and WebSocket: the page, the catalog, and one socket per client that carries its
//! settings in and its frames out. Every message is checked before it reaches the render
//! thread; a bad one is answered with the CLI's message and the connection stays open.

use std::net::SocketAddr;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Instant;

use axum::extract::ws::{Message, WebSocket, WebSocketUpgrade};
use axum::extract::State;
use axum::http::{header, HeaderMap, HeaderValue, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::routing::get;
use axum::Router;
use tokio::sync::mpsc;

use super::catalog::Catalog;
use super::request::{Bounds, SettingsIn, ViewRequest};
use super::worker::{Format, Hub};

/// Largest text message a client may send (its settings are well under 2 KiB).
pub const MAX_MESSAGE_BYTES: usize = 16 * 1024;
/// What the socket layer reads at most before it closes the connection (1009).
const MAX_FRAME_BYTES: usize = 64 * 1024;
/// Messages a client may send per second, on average and in a burst.
pub const RATE_PER_S: f64 = 30.0;
const BURST: f64 = 60.0;

pub struct Shared {
    pub hub: Arc<Hub>,
    pub catalog: Arc<Catalog>,
    pub bounds: Bounds,
    pub max_clients: usize,
    pub device: String,
    /// Host names the page may be reached by (a check against DNS rebinding).
    pub hosts: Vec<String>,
    pub started: Instant,
    next_id: AtomicU64,
}

impl Shared {
    pub fn new(
        hub: Arc<Hub>,
        catalog: Arc<Catalog>,
        bounds: Bounds,
        max_clients: usize,
        device: String,
        hosts: Vec<String>,
    ) -> Shared {
        Shared {
            hub,
            catalog,
            bounds,
            max_clients,
            device,
            hosts,
            started: Instant::now(),
            next_id: AtomicU64::new(1),
        }
    }
}

type App = Arc<Shared>;

pub fn router(shared: App) -> Router {
    Router::new()
        .route("/", get(index))
        .route("/viewer.js", get(script))
        .route("/viewer.css", get(style))
        .route("/api/catalog", get(catalog))
        .route("/api/stats", get(stats))
        .route("/ws", get(socket))
        .with_state(shared)
}

/// Refuses a request whose Host is not one this server answers to: a page on another site
/// that rebinds its name to 127.0.0.1 must not reach the viewer.
fn host_allowed(app: &Shared, headers: &HeaderMap) -> bool {
    let Some(host) = headers.get(header::HOST).and_then(|h| h.to_str().ok()) else {
        return false;
    };
    let name = match host.rsplit_once(':') {
        Some((n, port)) if port.chars().all(|c| c.is_ascii_digit()) => n,
        _ => host,
    };
    app.hosts.iter().any(|h| h.eq_ignore_ascii_case(name))
}

fn refused() -> Response {
    (StatusCode::FORBIDDEN, "this host name is not served here\n").into_response()
}

fn asset(content_type: &'static str, body: &'static str) -> Response {
    (
        [
            (header::CONTENT_TYPE, HeaderValue::from_static(content_type)),
            (
                header::CONTENT_SECURITY_POLICY,
                HeaderValue::from_static(
                    "default-src 'self'; img-src 'self' blob: data:; connect-src 'self'; \
                     frame-ancestors 'none'",
                ),
            ),
            (
                header::X_CONTENT_TYPE_OPTIONS,
                HeaderValue::from_static("nosniff"),
            ),
            (header::CACHE_CONTROL, HeaderValue::from_static("no-cache")),
        ],
        body,
    )
        .into_response()
}

async fn index(State(app): State<App>, headers: HeaderMap) -> Response {
    if !host_allowed(&app, &headers) {
        return refused();
    }
    asset("text/html; charset=utf-8", include_str!("page/index.html"))
}

async fn script(State(app): State<App>, headers: HeaderMap) -> Response {
    if !host_allowed(&app, &headers) {
        return refused();
    }
    asset(
        "text/javascript; charset=utf-8",
        include_str!("page/viewer.js"),
    )
}

async fn style(State(app): State<App>, headers: HeaderMap) -> Response {
    if !host_allowed(&app, &headers) {
        return refused();
    }
    asset("text/css; charset=utf-8", include_str!("page/viewer.css"))
}

async fn catalog(State(app): State<App>, headers: HeaderMap) -> Response {
    if !host_allowed(&app, &headers) {
        return refused();
    }
    let mut v = app.catalog.to_json();
    v["device"] = serde_json::json!(app.device);
    v["max_pixels"] = serde_json::json!(app.bounds.max_pixels);
    v["max_layers"] = serde_json::json!(app.bounds.max_layers);
    v["version"] = serde_json::json!(env!("CARGO_PKG_VERSION"));
    axum::Json(v).into_response()
}

async fn stats(State(app): State<App>, headers: HeaderMap) -> Response {
    if !host_allowed(&app, &headers) {
        return refused();
    }
    let v = serde_json::json!({
        "clients": app.hub.clients(),
        "uptime_s": app.started.elapsed().as_secs_f64(),
        "rss_kib": resident_kib(),
        "peak_rss_kib": peak_resident_kib(),
        "work": app.hub.stats(),
    });
    axum::Json(v).into_response()
}

/// A field of /proc/self/status in KiB (Linux; None elsewhere).
fn status_kib(field: &str) -> Option<u64> {
    let text = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = text.lines().find(|l| l.starts_with(field))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

pub fn resident_kib() -> Option<u64> {
    status_kib("VmRSS:")
}

pub fn peak_resident_kib() -> Option<u64> {
    status_kib("VmHWM:")
}

async fn socket(State(app): State<App>, headers: HeaderMap, upgrade: WebSocketUpgrade) -> Response {
    if !host_allowed(&app, &headers) {
        return refused();
    }
    // A browser always sends its page's origin: a page of another site may not drive the viewer.
    if let Some(origin) = headers.get(header::ORIGIN).and_then(|o| o.to_str().ok()) {
        let host = headers
            .get(header::HOST)
            .and_then(|h| h.to_str().ok())
            .unwrap_or("");
        let same = origin
            .strip_prefix("http://")
            .or_else(|| origin.strip_prefix("https://"))
            .is_some_and(|o| o.eq_ignore_ascii_case(host));
        if !same {
            return (
                StatusCode::FORBIDDEN,
                "the viewer's socket takes connections from its own page only\n",
            )
                .into_response();
        }
    }
    upgrade
        .max_message_size(MAX_FRAME_BYTES)
        .max_frame_size(MAX_FRAME_BYTES)
        .on_upgrade(move |ws| client(app, ws))
}

/// A token bucket: `RATE_PER_S` messages a second, bursts of `BURST`.
struct Rate {
    tokens: f64,
    at: Instant,
}

impl Rate {
    fn allow(&mut self) -> bool {
        let now = Instant::now();
        self.tokens =
            (self.tokens + now.duration_since(self.at).as_secs_f64() * RATE_PER_S).min(BURST);
        self.at = now;
        if self.tokens >= 1.0 {
            self.tokens -= 1.0;
            true
        } else {
            false
        }
    }
}

#[derive(serde::Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
enum Incoming {
    Render { seq: u64, settings: Box<SettingsIn> },
    Export { format: String, side: usize },
    Ping { seq: u64 },
}

fn error_text(seq: u64, message: &str) -> Message {
    Message::Text(
        serde_json::json!({"type": "error", "seq": seq, "message": message})
            .to_string()
            .into(),
    )
}

/// What a client's text message asks, or the message to answer it with.
fn handle(app: &Shared, id: u64, text: &str) -> Option<Message> {
    if text.len() > MAX_MESSAGE_BYTES {
        return Some(error_text(
            0,
            &format!(
                "message of {} bytes is over the {MAX_MESSAGE_BYTES}-byte limit",
                text.len()
            ),
        ));
    }
    let incoming: Incoming = match serde_json::from_str(text) {
        Ok(m) => m,
        Err(e) => {
            // the seq of a render with bad settings, so that the page can show it in place
            let seq = serde_json::from_str::<serde_json::Value>(text)
                .ok()
                .and_then(|v| v.get("seq").and_then(|s| s.as_u64()))
                .unwrap_or(0);
            return Some(error_text(seq, &format!("malformed message: {e}")));
        }
    };
    match incoming {
        Incoming::Render { seq, settings } => {
            match ViewRequest::check(*settings, &app.catalog, &app.bounds) {
                Ok(request) => {
                    app.hub.submit(id, seq, request);
                    None
                }
                Err(message) => Some(error_text(seq, &message)),
            }
        }
        Incoming::Export { format, side } => {
            let format = match format.as_str() {
                "png" => Format::Png,
                "exr" => Format::Exr,
                other => {
                    return Some(error_text(
                        0,
                        &format!("export format {other:?} is not png or exr"),
                    ))
                }
            };
            if side > 1 {
                return Some(error_text(0, "export side must be 0 or 1"));
            }
            app.hub.export(id, format, side);
            None
        }
        Incoming::Ping { seq } => Some(Message::Text(
            serde_json::json!({"type": "pong", "seq": seq})
                .to_string()
                .into(),
        )),
    }
}

async fn client(app: App, mut ws: WebSocket) {
    let id = app.next_id.fetch_add(1, Ordering::Relaxed);
    // A few frames in flight at most: a client that stops reading loses frames, not memory.
    let (out, mut outbox) = mpsc::channel::<Message>(8);
    if !app.hub.join(id, out, app.max_clients) {
        let message = format!(
            "this server has {} clients already (its --max-clients)",
            app.max_clients
        );
        let _ = ws.send(error_text(0, &message)).await;
        let _ = ws.send(Message::Close(None)).await;
        return;
    }
    let hello = serde_json::json!({"type": "hello", "client": id, "device": app.device});
    let mut rate = Rate {
        tokens: BURST,
        at: Instant::now(),
    };
    if ws
        .send(Message::Text(hello.to_string().into()))
        .await
        .is_ok()
    {
        loop {
            tokio::select! {
                incoming = ws.recv() => {
                    let reply = match incoming {
                        Some(Ok(Message::Text(text))) => {
                            if rate.allow() {
                                handle(&app, id, text.as_str())
                            } else {
                                Some(error_text(0, &format!(
                                    "too many messages: at most {RATE_PER_S} a second; this one was ignored"
                                )))
                            }
                        }
                        Some(Ok(Message::Binary(_))) => {
                            Some(error_text(0, "binary messages are not understood; send JSON text"))
                        }
                        Some(Ok(Message::Close(_))) | None | Some(Err(_)) => break,
                        Some(Ok(_)) => None,
                    };
                    if let Some(reply) = reply {
                        if ws.send(reply).await.is_err() {
                            break;
                        }
                    }
                }
                Some(message) = outbox.recv() => {
                    if ws.send(message).await.is_err() {
                        break;
                    }
                }
            }
        }
    }
    app.hub.leave(id);
}

/// Serves until Ctrl-C (or SIGTERM).
pub async fn serve(listener: tokio::net::TcpListener, app: App) -> std::io::Result<()> {
    let shutdown = async {
        let ctrl_c = tokio::signal::ctrl_c();
        #[cfg(unix)]
        {
            let mut term =
                tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate())
                    .expect("a SIGTERM handler");
            tokio::select! { _ = ctrl_c => {}, _ = term.recv() => {} }
        }
        #[cfg(not(unix))]
        {
            let _ = ctrl_c.await;
        }
    };
    // Open sockets are not waited for: the process ends with the server.
    tokio::select! {
        served = axum::serve(
            listener,
            router(app).into_make_service_with_connect_info::<SocketAddr>(),
        ) => served,
        _ = shutdown => Ok(()),
    }
}
