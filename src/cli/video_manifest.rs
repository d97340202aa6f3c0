//! The trust record of a `video` frames folder, so that a resumed or split export never keeps
//! a frame of another configuration and never skips a damaged one.
//!
//! - `ocular-video.json` holds everything that determines a frame (version, scene and the hash
//!   of its animation, eyes and their hashes, size, fps, frame count, format, sweep, pupil,
//!   exposure, renderer settings). The first job publishes it exclusively (a hard link, atomic
//!   even on NFS); later jobs compare their own and refuse on any difference.
//! - `ocular-video.sums/JOB.sha256` (one file per run, `sha256sum` format, so no two writers
//!   share a file) records each frame's digest *before* the frame takes its final name. A frame
//!   is skipped only when its bytes match a recorded digest; anything else is rendered again.

use std::collections::{HashMap, HashSet};
use std::io::Write;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::sha256;
use crate::{Error, Result};

pub const MANIFEST: &str = "ocular-video.json";
pub const SUMS_DIR: &str = "ocular-video.sums";

/// Everything that determines the bytes of a frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExportConfig {
    pub ocular_version: String,
    pub scene: String,
    /// SHA-256 of the scene's geometry, lights, background and its state at every frame time.
    pub scene_sha256: String,
    pub eye: String,
    pub eye_sha256: String,
    pub side_by_side: Option<String>,
    pub side_by_side_sha256: Option<String>,
    pub size: [u32; 2],
    pub fps: f64,
    pub frame_count: usize,
    pub format: String,
    pub focus_sweep_m: Option<[f64; 2]>,
    pub pupil_mm: Option<f64>,
    pub exposure_ev: Option<f32>,
    /// Depth layers above one (absent for one, so one-layer manifests read as before).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub layers: Option<u32>,
    /// Two eyes (`--binocular`; absent for one, so one-eye manifests read as before).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub binocular: Option<PairConfig>,
    /// SHA-256 of the kernel and splatting settings.
    pub settings_sha256: String,
}

/// What a binocular export adds: the right eye (`eye` is then the left one), both as corrected,
/// the interpupillary distance and how the pair is laid out.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PairConfig {
    pub eye_right: String,
    pub eye_right_sha256: String,
    pub ipd_mm: f64,
    pub stereo: String,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Manifest {
    about: String,
    config: ExportConfig,
}

fn shown<T: std::fmt::Debug>(v: &Option<T>) -> String {
    v.as_ref()
        .map_or("none".to_string(), |v| format!("{v:?}").replace('"', ""))
}

/// "`option` `old` there, `new` here".
fn there_here(option: &str, old: impl std::fmt::Display, new: impl std::fmt::Display) -> String {
    format!("{option} {old} there, {new} here")
}

/// One line per field that differs, naming the option that sets it.
pub fn differences(old: &ExportConfig, new: &ExportConfig) -> Vec<String> {
    let mut out = Vec::new();
    let mut field = |differs: bool, text: String| {
        if differs {
            out.push(text);
        }
    };
    field(
        old.ocular_version != new.ocular_version,
        format!(
            "ocular version {} there, {} here",
            old.ocular_version, new.ocular_version
        ),
    );
    field(
        old.scene != new.scene || old.scene_sha256 != new.scene_sha256,
        if old.scene == new.scene {
            format!(
                "--scene {}: its content or animation changed (sha256 {}… there, {}… here)",
                new.scene,
                &old.scene_sha256[..12.min(old.scene_sha256.len())],
                &new.scene_sha256[..12]
            )
        } else {
            there_here("--scene", &old.scene, &new.scene)
        },
    );
    for (option, (a, ah), (b, bh)) in [
        (
            "--eye",
            (Some(&old.eye), Some(&old.eye_sha256)),
            (Some(&new.eye), Some(&new.eye_sha256)),
        ),
        (
            "--side-by-side",
            (old.side_by_side.as_ref(), old.side_by_side_sha256.as_ref()),
            (new.side_by_side.as_ref(), new.side_by_side_sha256.as_ref()),
        ),
    ] {
        field(
            ah != bh,
            if a == b {
                format!("{option} {}: the eye's content changed", shown(&b.cloned()))
            } else {
                there_here(option, shown(&a.cloned()), shown(&b.cloned()))
            },
        );
    }
    field(
        old.size != new.size,
        format!(
            "--size {}x{} there, {}x{} here",
            old.size[0], old.size[1], new.size[0], new.size[1]
        ),
    );
    field(old.fps != new.fps, there_here("--fps", old.fps, new.fps));
    field(
        old.frame_count != new.frame_count,
        format!(
            "--duration: {} frames there, {} here",
            old.frame_count, new.frame_count
        ),
    );
    field(
        old.format != new.format,
        there_here("--format", &old.format, &new.format),
    );
    field(
        old.focus_sweep_m != new.focus_sweep_m,
        there_here(
            "--focus-sweep",
            shown(&old.focus_sweep_m),
            shown(&new.focus_sweep_m),
        ),
    );
    field(
        old.pupil_mm != new.pupil_mm,
        there_here("--pupil-mm", shown(&old.pupil_mm), shown(&new.pupil_mm)),
    );
    field(
        old.exposure_ev != new.exposure_ev,
        there_here(
            "--exposure",
            shown(&old.exposure_ev),
            shown(&new.exposure_ev),
        ),
    );
    field(
        old.layers != new.layers,
        there_here("--layers", old.layers.unwrap_or(1), new.layers.unwrap_or(1)),
    );
    let eyes = |p: &Option<PairConfig>| if p.is_some() { "two eyes" } else { "one eye" };
    let pair = match (&old.binocular, &new.binocular) {
        (Some(a), Some(b)) => pair_differences(a, b),
        (a, b) if a.is_some() != b.is_some() => vec![there_here("--binocular", eyes(a), eyes(b))],
        _ => Vec::new(),
    };
    for line in pair {
        field(true, line);
    }
    field(
        old.settings_sha256 != new.settings_sha256,
        "renderer settings differ".to_string(),
    );
    out
}

/// One line per field of two pairs' configurations that differs.
fn pair_differences(old: &PairConfig, new: &PairConfig) -> Vec<String> {
    let mut out = Vec::new();
    if old.eye_right_sha256 != new.eye_right_sha256 {
        out.push(if old.eye_right == new.eye_right {
            format!(
                "--eye-right {}: the right eye's content or its --correct-right / --iol-d-right \
                 changed",
                new.eye_right
            )
        } else {
            there_here("--eye-right", &old.eye_right, &new.eye_right)
        });
    }
    if old.ipd_mm != new.ipd_mm {
        out.push(there_here("--ipd-mm", old.ipd_mm, new.ipd_mm));
    }
    if old.stereo != new.stereo {
        out.push(there_here("--stereo", &old.stereo, &new.stereo));
    }
    out
}

/// Whether a name is one of the export's frame files (`frame_NNNNNN.png|exr`, or a pair's
/// `frame_NNNNNN-left.png` and `-right`).
pub fn is_frame_name(name: &str) -> bool {
    let Some(rest) = name.strip_prefix("frame_") else {
        return false;
    };
    let Some((digits, ext)) = rest.split_once('.') else {
        return false;
    };
    let digits = digits
        .strip_suffix("-left")
        .or_else(|| digits.strip_suffix("-right"))
        .unwrap_or(digits);
    digits.len() >= 6
        && digits.bytes().all(|b| b.is_ascii_digit())
        && (ext == "png" || ext == "exr")
}

fn frame_files(dir: &Path) -> Vec<PathBuf> {
    let mut out: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|entries| {
            entries
                .flatten()
                .filter(|e| is_frame_name(&e.file_name().to_string_lossy()))
                .map(|e| e.path())
                .collect()
        })
        .unwrap_or_default();
    out.sort();
    out
}

/// Opens the folder for this configuration: publishes the manifest, or checks the one there.
/// With `overwrite`, a previous export (manifest, digests and frames) is removed first.
/// Returns how many frames `overwrite` removed.
pub fn open(dir: &Path, config: &ExportConfig, overwrite: bool) -> Result<usize> {
    let manifest_path = dir.join(MANIFEST);
    let mut removed = 0;
    if overwrite {
        for frame in frame_files(dir) {
            std::fs::remove_file(&frame)
                .map_err(|e| Error::file(&frame, format!("--overwrite cannot remove it: {e}")))?;
            removed += 1;
        }
        let sums = dir.join(SUMS_DIR);
        if sums.exists() {
            std::fs::remove_dir_all(&sums)
                .map_err(|e| Error::file(&sums, format!("--overwrite cannot remove it: {e}")))?;
        }
        if manifest_path.exists() {
            std::fs::remove_file(&manifest_path).map_err(|e| {
                Error::file(&manifest_path, format!("--overwrite cannot remove it: {e}"))
            })?;
        }
    }
    let text = serde_json::to_string_pretty(&Manifest {
        about: "ocular video export: everything that determines a frame; frame digests are in \
                ocular-video.sums/ (check with: cat ocular-video.sums/*.sha256 | sha256sum -c)"
            .to_string(),
        config: config.clone(),
    })
    .map_err(|e| Error::input(format!("cannot encode the manifest: {e}")))?;
    if !manifest_path.exists() {
        let frames = frame_files(dir);
        if let Some(first) = frames.first() {
            return Err(Error::file(
                dir,
                format!(
                    "holds {} frame files ({} …) but no {MANIFEST}, so their configuration is \
                     unknown; pass --overwrite to replace them, or use another folder",
                    frames.len(),
                    first.file_name().unwrap_or_default().to_string_lossy()
                ),
            ));
        }
        if publish_exclusive(&manifest_path, text.as_bytes())? {
            std::fs::create_dir_all(dir.join(SUMS_DIR))
                .map_err(|e| Error::file(dir.join(SUMS_DIR), format!("cannot create: {e}")))?;
            return Ok(removed);
        }
        // Another job published it first: fall through and compare.
    }
    let existing = std::fs::read_to_string(&manifest_path)
        .map_err(|e| Error::file(&manifest_path, format!("cannot read: {e}")))?;
    let old: Manifest = serde_json::from_str(&existing).map_err(|e| {
        Error::file(
            &manifest_path,
            format!(
                "not a manifest this ocular can read ({e}); pass --overwrite to replace the \
                 folder's export, or use another folder"
            ),
        )
    })?;
    let diffs = differences(&old.config, config);
    if !diffs.is_empty() {
        return Err(Error::file(
            &manifest_path,
            format!(
                "the frames here were rendered with another configuration ({}); pass --overwrite \
                 to replace them, or use another folder",
                diffs.join("; ")
            ),
        ));
    }
    std::fs::create_dir_all(dir.join(SUMS_DIR))
        .map_err(|e| Error::file(dir.join(SUMS_DIR), format!("cannot create: {e}")))?;
    Ok(removed)
}

/// Writes `bytes` under `path` only if nothing is there: a complete temporary file, hard-linked
/// to the final name (fails if it exists, atomically). Returns false if another writer won.
fn publish_exclusive(path: &Path, bytes: &[u8]) -> Result<bool> {
    let tmp = path.with_extension(format!("json.tmp-{}", std::process::id()));
    let result = (|| -> std::io::Result<bool> {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        drop(f);
        match std::fs::hard_link(&tmp, path) {
            Ok(()) => Ok(true),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => Ok(false),
            // No hard links on this file system: create-new is still exclusive.
            Err(_) => match std::fs::OpenOptions::new()
                .write(true)
                .create_new(true)
                .open(path)
            {
                Ok(mut f) => {
                    f.write_all(bytes)?;
                    f.sync_all()?;
                    Ok(true)
                }
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => Ok(false),
                Err(e) => Err(e),
            },
        }
    })();
    let _ = std::fs::remove_file(&tmp);
    result.map_err(|e| Error::file(path, format!("cannot write the manifest: {e}")))
}

/// Every digest recorded for each frame name, from all jobs' digest files.
pub fn recorded_digests(dir: &Path) -> HashMap<String, HashSet<String>> {
    let mut out: HashMap<String, HashSet<String>> = HashMap::new();
    let Ok(entries) = std::fs::read_dir(dir.join(SUMS_DIR)) else {
        return out;
    };
    for entry in entries.flatten() {
        if !entry.file_name().to_string_lossy().ends_with(".sha256") {
            continue;
        }
        let Ok(text) = std::fs::read_to_string(entry.path()) else {
            continue;
        };
        for line in text.lines() {
            // A line cut short by a kill is ignored: its frame never got its final name.
            if let Some((digest, name)) = line.split_once("  ") {
                if digest.len() == 64 && digest.bytes().all(|b| b.is_ascii_hexdigit()) {
                    out.entry(name.to_string())
                        .or_default()
                        .insert(digest.to_string());
                }
            }
        }
    }
    out
}

/// Whether the file holds exactly the bytes of a recorded digest.
pub fn verified(path: &Path, digests: Option<&HashSet<String>>) -> bool {
    let Some(digests) = digests else {
        return false;
    };
    match std::fs::read(path) {
        Ok(bytes) => digests.contains(&sha256::hex(&bytes)),
        Err(_) => false,
    }
}

/// This run's digest file: appended to before each frame is renamed into place.
pub struct DigestLog {
    file: std::fs::File,
    path: PathBuf,
}

impl DigestLog {
    pub fn create(dir: &Path) -> Result<DigestLog> {
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_nanos())
            .unwrap_or(0);
        let path = dir
            .join(SUMS_DIR)
            .join(format!("job-{}-{nanos}.sha256", std::process::id()));
        let file = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(&path)
            .map_err(|e| Error::file(&path, format!("cannot create: {e}")))?;
        Ok(DigestLog { file, path })
    }

    /// Records the digest and makes it durable before the frame may take its final name.
    pub fn record(&mut self, name: &str, bytes: &[u8]) -> Result<()> {
        let line = format!("{}  {name}\n", sha256::hex(bytes));
        self.file
            .write_all(line.as_bytes())
            .and_then(|()| self.file.sync_data())
            .map_err(|e| Error::file(&self.path, format!("cannot write: {e}")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_names_are_recognised_strictly() {
        assert!(is_frame_name("frame_000012.png"));
        assert!(is_frame_name("frame_1000000.exr"));
        assert!(!is_frame_name("frame_000012.png.tmp-5"));
        assert!(!is_frame_name("frame_12.png"));
        assert!(!is_frame_name("frame_00001x.png"));
        assert!(!is_frame_name("walk.mp4"));
    }
}
