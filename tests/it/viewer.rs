//! `ocular serve` from outside, as a hostile or careless client would use it: host and origin
//! checks, malformed, oversized and out-of-range messages answered with the CLI's messages
//! while the server keeps serving, the rate bound, the client bound, and a burst of changes
//! that renders only the latest. (The page itself is tested in a browser: tests/viewer/.)

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Child, Stdio};
use std::time::{Duration, Instant};

use tungstenite::{client::IntoClientRequest, Message};

use crate::common::{module_cache, ocular};

struct Server {
    child: Child,
    port: u16,
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

#[track_caller]
fn server(extra: &[&str]) -> Server {
    let cache = module_cache();
    let mut child = ocular()
        .args(["serve", "--port", "0", "--cache"])
        .arg(&cache)
        .args(extra)
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .unwrap();
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let port = line
        .split("http://127.0.0.1:")
        .nth(1)
        .and_then(|rest| rest.split('/').next())
        .and_then(|p| p.parse().ok())
        .unwrap_or_else(|| panic!("no address in {line:?}"));
    Server { child, port }
}

/// A raw HTTP/1.1 GET with the given Host (and Origin) header: status line and headers.
fn get(port: u16, path: &str, host: &str) -> String {
    let mut s = TcpStream::connect(("127.0.0.1", port)).unwrap();
    write!(
        s,
        "GET {path} HTTP/1.1\r\nHost: {host}\r\nConnection: close\r\n\r\n"
    )
    .unwrap();
    let mut out = String::new();
    s.read_to_string(&mut out).unwrap();
    out
}

type Socket = tungstenite::WebSocket<tungstenite::stream::MaybeTlsStream<TcpStream>>;

fn connect(port: u16) -> Socket {
    let (mut ws, _) = tungstenite::connect(format!("ws://127.0.0.1:{port}/ws")).unwrap();
    if let tungstenite::stream::MaybeTlsStream::Plain(s) = ws.get_mut() {
        s.set_read_timeout(Some(Duration::from_secs(120))).unwrap();
    }
    let hello = text(&mut ws);
    assert!(hello.contains("\"hello\""), "{hello}");
    ws
}

/// The next text message.
fn text(ws: &mut Socket) -> String {
    loop {
        match ws.read().unwrap() {
            Message::Text(t) => return t.to_string(),
            Message::Binary(_) => continue,
            _ => continue,
        }
    }
}

/// The next frame's JSON header and payload, or an error's text.
fn next_frame(ws: &mut Socket) -> Result<(serde_json::Value, Vec<u8>), String> {
    loop {
        match ws.read().unwrap() {
            Message::Text(t) => return Err(t.to_string()),
            Message::Binary(b) => {
                let n = u32::from_be_bytes(b[..4].try_into().unwrap()) as usize;
                let header: serde_json::Value = serde_json::from_slice(&b[4..4 + n]).unwrap();
                return Ok((header, b[4 + n..].to_vec()));
            }
            _ => continue,
        }
    }
}

fn render(seq: u64, settings: serde_json::Value) -> Message {
    Message::Text(
        serde_json::json!({"type": "render", "seq": seq, "settings": settings})
            .to_string()
            .into(),
    )
}

fn small(focus_d: f64) -> serde_json::Value {
    serde_json::json!({
        "scene": "primitives", "size": [64, 36],
        "a": {"eye": {"kind": "preset", "name": "myopia"}},
        "focus": {"mode": "d", "d": focus_d},
        "pupil": {"mode": "mm", "mm": 4.0},
        "age": 30, "quality": "fast"
    })
}

#[test]
fn only_loopback_names_and_its_own_page_are_served() {
    let s = server(&[]);
    let ok = get(s.port, "/", &format!("127.0.0.1:{}", s.port));
    assert!(ok.starts_with("HTTP/1.1 200"), "{ok}");
    assert!(
        ok.to_ascii_lowercase().contains("content-security-policy"),
        "{ok}"
    );
    let rebound = get(s.port, "/api/catalog", "attacker.example");
    assert!(rebound.starts_with("HTTP/1.1 403"), "{rebound}");
    // A page of another site may not open the socket.
    let mut request = format!("ws://127.0.0.1:{}/ws", s.port)
        .into_client_request()
        .unwrap();
    request
        .headers_mut()
        .insert("Origin", "http://attacker.example".parse().unwrap());
    match tungstenite::connect(request) {
        Err(tungstenite::Error::Http(r)) => assert_eq!(r.status(), 403),
        other => panic!("a foreign origin was let in: {:?}", other.map(|_| ())),
    }
}

#[test]
fn a_remote_address_needs_its_flag() {
    let out = ocular()
        .args(["serve", "--host", "0.0.0.0", "--port", "0"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--allow-remote") && err.lines().count() == 1,
        "{err}"
    );
}

#[test]
fn bad_messages_are_answered_and_the_server_keeps_serving() {
    let s = server(&[]);
    let mut ws = connect(s.port);
    let bad_settings = |change: &dyn Fn(&mut serde_json::Value)| {
        let mut v = small(1.0);
        change(&mut v);
        v
    };
    let cases: Vec<(Message, &str)> = vec![
        (Message::Text("{not json".into()), "malformed message"),
        (Message::Text("x".repeat(20_000).into()), "16384-byte limit"),
        (Message::Binary(vec![1, 2, 3].into()), "binary messages"),
        (
            render(
                1,
                bad_settings(&|v| v["scene"] = "../../../etc/passwd".into()),
            ),
            "--scene",
        ),
        (
            render(
                2,
                bad_settings(&|v| {
                    v["a"]["eye"] = serde_json::json!({"kind": "preset", "name": "/etc/hosts"})
                }),
            ),
            "--eye",
        ),
        (
            render(
                3,
                bad_settings(&|v| {
                    v["a"]["eye"] = serde_json::json!({"kind": "file", "name": "../secret"})
                }),
            ),
            "--eye",
        ),
        (
            render(
                4,
                bad_settings(&|v| v["size"] = serde_json::json!([100000, 100000])),
            ),
            "--size",
        ),
        (
            render(
                5,
                bad_settings(&|v| {
                    v["a"]["eye"] =
                        serde_json::json!({"kind": "rx", "rx": "-2 -1 x 200", "pupil_mm": 5})
                }),
            ),
            "--rx",
        ),
        (
            render(
                6,
                bad_settings(&|v| {
                    v["a"]["correction"] = serde_json::json!({"kind": "iol", "power": "99"})
                }),
            ),
            "--iol-d",
        ),
        (
            render(
                7,
                bad_settings(&|v| v["focus"] = serde_json::json!({"mode": "at", "x": 64, "y": 0})),
            ),
            "--focus-at",
        ),
        (
            render(8, bad_settings(&|v| v["unknown"] = 1.into())),
            "malformed message",
        ),
    ];
    for (message, expected) in cases {
        ws.send(message).unwrap();
        let reply = text(&mut ws);
        assert!(
            reply.contains("\"error\"") && reply.contains(expected),
            "{reply} should name {expected}"
        );
    }
    // Still serving: a good request gets a preview and then the full frame.
    ws.send(render(9, small(2.0))).unwrap();
    let (preview, _) = next_frame(&mut ws).unwrap();
    assert_eq!(preview["stage"], "preview");
    assert_eq!(preview["summary"]["width"], 32);
    let (full, png) = next_frame(&mut ws).unwrap();
    assert_eq!(
        (full["stage"].as_str(), full["seq"].as_u64()),
        (Some("full"), Some(9))
    );
    assert_eq!(full["summary"]["width"], 64);
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    assert!((full["summary"]["focus_d"].as_f64().unwrap() - 2.0).abs() < 1e-12);
    let command = full["command"].as_str().unwrap();
    assert!(
        command.contains("--focus-d 2") && command.contains("--size 64x36"),
        "{command}"
    );
    // A message over the socket's own bound closes that connection (1009) and no other.
    let _ = ws.send(Message::Text("y".repeat(200_000).into()));
    let closed = (0..4).any(|_| matches!(ws.read(), Err(_) | Ok(Message::Close(_))));
    assert!(closed, "an oversized message should close its connection");
    let mut again = connect(s.port);
    again.send(render(1, small(0.5))).unwrap();
    assert!(next_frame(&mut again).is_ok());
}

#[test]
fn a_burst_of_changes_renders_the_latest_only() {
    let s = server(&[]);
    let mut ws = connect(s.port);
    for seq in 1..=12u64 {
        ws.send(render(seq, small(seq as f64 * 0.25))).unwrap();
    }
    let started = Instant::now();
    let mut full_frames = Vec::new();
    while full_frames.last() != Some(&12) {
        assert!(
            started.elapsed() < Duration::from_secs(120),
            "no frame for the last change"
        );
        let (h, _) = next_frame(&mut ws).unwrap();
        if h["stage"] == "full" {
            full_frames.push(h["seq"].as_u64().unwrap());
        }
    }
    // The worker may have started the first before the others came; every other is replaced.
    assert!(
        full_frames.len() <= 2,
        "full frames rendered: {full_frames:?}"
    );
}

#[test]
fn the_rate_and_the_number_of_clients_are_bounded() {
    let s = server(&["--max-clients", "1"]);
    let mut ws = connect(s.port);
    // A second client is told why it cannot join.
    let (mut second, _) = tungstenite::connect(format!("ws://127.0.0.1:{}/ws", s.port)).unwrap();
    let refused = text(&mut second);
    assert!(refused.contains("--max-clients"), "{refused}");
    for seq in 0..100u64 {
        ws.send(Message::Text(
            serde_json::json!({"type": "ping", "seq": seq})
                .to_string()
                .into(),
        ))
        .unwrap();
    }
    let replies: Vec<String> = (0..100).map(|_| text(&mut ws)).collect();
    let pongs = replies.iter().filter(|r| r.contains("pong")).count();
    let limited = replies
        .iter()
        .filter(|r| r.contains("too many messages"))
        .count();
    assert_eq!(pongs + limited, 100);
    // A burst of 60 and 30 a second after it: about 60 answered when the 100 arrive at once,
    // more on a slow machine that takes a while to read them; all 100 without the bound.
    assert!(
        (55..=90).contains(&pongs) && limited >= 10,
        "{pongs} answered, {limited} limited"
    );
}

/// Runs a command line the page gave as a user would, in a shell in `dir`, with this build's
/// binary first on the PATH and the module's kernel cache; it must succeed.
fn run_in_shell(command: &str, dir: &std::path::Path) -> std::process::Output {
    let bin_dir = std::path::Path::new(env!("CARGO_BIN_EXE_ocular"))
        .parent()
        .unwrap();
    let path = format!(
        "{}:{}",
        bin_dir.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let out = std::process::Command::new("sh")
        .arg("-c")
        .arg(format!("{command} --cache {}", module_cache().display()))
        .current_dir(dir)
        .env("PATH", path)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

#[test]
fn the_command_line_it_gives_renders_the_same_frame() {
    let s = server(&[]);
    let mut ws = connect(s.port);
    let settings = serde_json::json!({
        "scene": "primitives", "size": [96, 54],
        "a": {"eye": {"kind": "preset", "name": "astigmatism"},
              "correction": {"kind": "glasses", "rx": "-1 -0.5 x 30", "vertex_mm": 13}},
        "focus": {"mode": "at", "x": 36, "y": 33},
        "pupil": {"mode": "luminance", "cdm2": 50.0},
        "age": 45, "quality": "fast"
    });
    ws.send(render(1, settings)).unwrap();
    let (header, png) = loop {
        let (h, png) = next_frame(&mut ws).unwrap();
        if h["stage"] == "full" {
            break (h, png);
        }
    };
    let command = header["command"].as_str().unwrap();
    assert!(command.starts_with("ocular render "), "{command}");
    let dir = crate::common::temp_dir("command");
    let out = run_in_shell(command, &dir);
    let decode = |bytes: &[u8]| image::load_from_memory(bytes).unwrap().to_rgb8();
    let ours = decode(&png);
    let cli = decode(&std::fs::read(dir.join("ocular.png")).unwrap());
    assert_eq!(ours.dimensions(), (96, 54));
    let worst = ours
        .pixels()
        .zip(cli.pixels())
        .flat_map(|(a, b)| (0..3).map(move |c| (i16::from(a[c]) - i16::from(b[c])).abs()))
        .max()
        .unwrap();
    assert!(
        worst <= 1,
        "the viewer's frame and its command's differ by {worst} of 255"
    );
    // The summary agrees with the CLI's on where the eye focused.
    let stdout = String::from_utf8_lossy(&out.stdout);
    let reached = header["summary"]["focus"]["actual_d"].as_f64().unwrap();
    assert!(
        stdout.contains(&format!("{:.3} m", 1.0 / reached)),
        "{stdout} vs {reached}"
    );
}

/// A binocular pair: both eyes' frames come back as two sides, and the one command line the
/// page shows renders the same two frames (OUTPUT-left, OUTPUT-right) with `--binocular`.
/// A lens on one eye only is refused in one line (the CLI's right eye takes the left's kind).
#[test]
fn a_binocular_pair_is_the_clis_pair() {
    let s = server(&[]);
    let mut ws = connect(s.port);
    let settings = serde_json::json!({
        "scene": "primitives", "size": [80, 45],
        "a": {"eye": {"kind": "preset", "name": "healthy"},
              "correction": {"kind": "glasses", "rx": "0"}},
        "b": {"eye": {"kind": "preset", "name": "myopia"},
              "correction": {"kind": "glasses", "rx": "-3"}},
        "focus": {"mode": "d", "d": 1.5},
        "pupil": {"mode": "mm", "mm": 4.0},
        "age": 50, "quality": "fast", "binocular": true, "ipd_mm": 60
    });
    ws.send(render(1, settings)).unwrap();
    let mut full: Vec<(serde_json::Value, Vec<u8>)> = Vec::new();
    while full.len() < 2 {
        let (h, png) = next_frame(&mut ws).unwrap();
        assert_eq!(h["sides"], 2, "{h}");
        if h["stage"] == "full" {
            full.push((h, png));
        }
    }
    let command = full[0].0["command"].as_str().unwrap().to_string();
    assert_eq!(command, full[1].0["command"].as_str().unwrap());
    assert!(
        command.contains("--binocular")
            && command.contains("--eye-right myopia")
            && command.contains("--correct-right -3")
            && command.contains("--ipd-mm 60"),
        "{command}"
    );
    let dir = crate::common::temp_dir("binocular");
    run_in_shell(&command, &dir);
    let decode = |bytes: &[u8]| image::load_from_memory(bytes).unwrap().to_rgb8();
    for (h, png) in &full {
        let side = h["side"].as_u64().unwrap() as usize;
        let name = ["ocular-left.png", "ocular-right.png"][side];
        let (ours, cli) = (decode(png), decode(&std::fs::read(dir.join(name)).unwrap()));
        let worst = ours
            .pixels()
            .zip(cli.pixels())
            .flat_map(|(a, b)| (0..3).map(move |c| (i16::from(a[c]) - i16::from(b[c])).abs()))
            .max()
            .unwrap();
        assert!(
            worst <= 1,
            "side {side}: the viewer and its command differ by {worst}"
        );
    }
    let (l, r) = (decode(&full[0].1), decode(&full[1].1));
    assert_ne!(l, r, "two eyes, two frames");
    // one eye with a lens and the other without: refused, the connection kept
    let one_lens = serde_json::json!({
        "scene": "primitives", "size": [80, 45],
        "a": {"eye": {"kind": "preset", "name": "healthy"}},
        "b": {"eye": {"kind": "preset", "name": "myopia"},
              "correction": {"kind": "glasses", "rx": "-3"}},
        "age": 50, "quality": "fast", "binocular": true
    });
    ws.send(render(2, one_lens)).unwrap();
    let reply: serde_json::Value = serde_json::from_str(&text(&mut ws)).unwrap();
    assert_eq!(reply["type"], "error", "{reply}");
    assert!(
        reply["message"].as_str().unwrap().contains("plano"),
        "{reply}"
    );
}
