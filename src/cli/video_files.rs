//! The files `ocular video` writes: frames written atomically under a per-host temporary
//! name, stale temporaries of interrupted runs cleared, and the optional MP4 by ffmpeg.

use std::path::Path;

use super::video::{FrameFormat, VideoArgs};
use crate::{Error, Result};

pub(super) fn check_mp4(args: &VideoArgs) -> Result<()> {
    let Some(mp4) = &args.mp4 else {
        return Ok(());
    };
    if args.format != FrameFormat::Png {
        return Err(Error::input("--mp4 needs --format png frames"));
    }
    super::outputs::check_extension("--mp4", mp4, &["mp4"])?;
    super::outputs::check_folder("--mp4", mp4)?;
    if !ffmpeg_on_path() {
        return Err(Error::input(format!(
            "--mp4 {}: ffmpeg is not on PATH (Debian/Ubuntu: apt-get install ffmpeg); nothing \
             was rendered",
            mp4.display()
        )));
    }
    Ok(())
}

fn ffmpeg_on_path() -> bool {
    std::env::var_os("PATH")
        .map(|paths| std::env::split_paths(&paths).any(|p| p.join("ffmpeg").is_file()))
        .unwrap_or(false)
}

pub(super) fn probe_writable(dir: &Path) -> Result<()> {
    let probe = dir.join(format!(".ocular-write-test-{}", std::process::id()));
    std::fs::write(&probe, b"")
        .map_err(|e| Error::file(dir, format!("the output folder is not writable: {e}")))?;
    let _ = std::fs::remove_file(probe);
    Ok(())
}

/// This machine's name, so that a job on a shared folder can tell its own machine's
/// temporaries from those of jobs running elsewhere.
fn host_name() -> String {
    std::fs::read_to_string("/proc/sys/kernel/hostname")
        .ok()
        .or_else(|| std::env::var("HOSTNAME").ok())
        .map(|h| {
            h.trim()
                .replace(|c: char| !c.is_ascii_alphanumeric() && c != '-', "_")
        })
        .filter(|h| !h.is_empty())
        .unwrap_or_else(|| "host".to_string())
}

/// Where frame `name` is written before its rename: `NAME.tmp-HOST-PID`.
fn temporary_name(name: &str) -> String {
    format!("{name}.tmp-{}-{}", host_name(), std::process::id())
}

/// Writes a frame through a temporary name, synced, then renamed into place.
pub(super) fn write_frame(dir: &Path, name: &str, bytes: &[u8]) -> Result<()> {
    use std::io::Write;
    let path = dir.join(name);
    let tmp = dir.join(temporary_name(name));
    let result = (|| -> std::io::Result<()> {
        let mut file = std::fs::File::create(&tmp)?;
        file.write_all(bytes)?;
        file.sync_all()?;
        drop(file);
        std::fs::rename(&tmp, &path)
    })();
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(Error::file(&path, format!("cannot write the frame: {e}")));
    }
    Ok(())
}

/// Temporaries are never valid frames. Removed: those of this machine whose process is gone,
/// and any older than an hour (a frame takes seconds to write). A live split job's
/// temporaries, here or on another machine sharing the folder, are left alone.
pub(super) fn remove_stale_temporaries(dir: &Path) {
    let host = host_name();
    // Without /proc a process cannot be looked up: only age decides.
    let alive =
        |pid: u32| !Path::new("/proc/self").exists() || Path::new(&format!("/proc/{pid}")).exists();
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        let Some((_, owner)) = name.split_once(".tmp-") else {
            continue;
        };
        if !name.starts_with("frame_") {
            continue;
        }
        let gone = match owner.rsplit_once('-') {
            Some((h, pid)) if h == host => pid.parse::<u32>().is_ok_and(|pid| !alive(pid)),
            // Another machine's.
            Some(_) => false,
            // The older `NAME.tmp-PID` form.
            None => owner.parse::<u32>().is_ok_and(|pid| !alive(pid)),
        };
        let old = entry
            .metadata()
            .and_then(|m| m.modified())
            .ok()
            .and_then(|t| t.elapsed().ok())
            .is_some_and(|age| age.as_secs() > 3600);
        if gone || old {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

pub(super) fn encode_mp4(dir: &Path, fps: f64, mp4: &Path) -> Result<()> {
    if !ffmpeg_on_path() {
        return Err(Error::input(format!(
            "--mp4 {}: ffmpeg is not on PATH (Debian/Ubuntu: apt-get install ffmpeg); the frames are in {}",
            mp4.display(),
            dir.display()
        )));
    }
    let status = std::process::Command::new("ffmpeg")
        .args(["-y", "-loglevel", "error", "-framerate"])
        .arg(format!("{fps}"))
        .arg("-i")
        .arg(dir.join("frame_%06d.png"))
        .args([
            "-c:v",
            "libx264",
            "-pix_fmt",
            "yuv420p",
            "-vf",
            "pad=ceil(iw/2)*2:ceil(ih/2)*2",
        ])
        .arg(mp4)
        .status()
        .map_err(|e| Error::file(mp4, format!("cannot run ffmpeg: {e}")))?;
    if !status.success() {
        return Err(Error::file(
            mp4,
            format!(
                "ffmpeg failed ({status}); the frames are in {}",
                dir.display()
            ),
        ));
    }
    println!("wrote {}", mp4.display());
    Ok(())
}
