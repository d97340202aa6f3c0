//! Kernel grid files and the on-disk cache.
//!
//! File layout (little endian): magic `OCKGRID\0`, format version (u32), header length (u32),
//! header (JSON: the key, axes, screen, radius, sizes), then per set its pupil and focus (f64),
//! radii (3 f32 per object), top levels (u32 per object) and the blocks each object distance
//! holds (level-major, then object; its top level and below, 3 f32 per texel; the blocks above
//! are zero and not stored), and last a 64-bit checksum of every byte before it. Files are written to a temporary name in the target folder and renamed, so a
//! reader never sees a partial file; a file that fails any check is reported, never loaded.

use super::axes::{GridAxes, KernelSettings, Screen};
use super::kernels::{DioptreAxis, KernelGrid, KernelSet};
use crate::eye::Eye;
use crate::{Error, Result};
use serde::{Deserialize, Serialize};
use std::io::{BufReader, BufWriter, Read, Write};
use std::path::{Path, PathBuf};

const MAGIC: &[u8; 8] = b"OCKGRID\0";
/// Bump whenever the file layout or the numerics that produce the kernels change.
pub const FORMAT_VERSION: u32 = 3;

/// A streaming 64-bit checksum: every 8-byte word goes through an invertible mix, so any
/// change to one word changes the result.
#[derive(Clone, Debug)]
pub struct Checksum {
    state: u64,
    pending: [u8; 8],
    filled: usize,
    length: u64,
}

impl Default for Checksum {
    fn default() -> Self {
        Checksum {
            state: 0x243f_6a88_85a3_08d3,
            pending: [0; 8],
            filled: 0,
            length: 0,
        }
    }
}

impl Checksum {
    fn mix(&mut self, word: u64) {
        self.state = (self.state ^ word)
            .wrapping_mul(0x9e37_79b9_7f4a_7c15)
            .rotate_left(29)
            .wrapping_add(0x632b_e59b_d9b4_e019);
    }

    pub fn update(&mut self, mut bytes: &[u8]) {
        self.length += bytes.len() as u64;
        if self.filled > 0 {
            let take = (8 - self.filled).min(bytes.len());
            self.pending[self.filled..self.filled + take].copy_from_slice(&bytes[..take]);
            self.filled += take;
            bytes = &bytes[take..];
            if self.filled < 8 {
                return;
            }
            let w = u64::from_le_bytes(self.pending);
            self.mix(w);
            self.filled = 0;
        }
        let mut chunks = bytes.chunks_exact(8);
        for c in &mut chunks {
            self.mix(u64::from_le_bytes(c.try_into().expect("8 bytes")));
        }
        let rest = chunks.remainder();
        self.pending[..rest.len()].copy_from_slice(rest);
        self.filled = rest.len();
    }

    pub fn finish(&self) -> u64 {
        let mut c = self.clone();
        if c.filled > 0 {
            let mut last = [0u8; 8];
            last[..c.filled].copy_from_slice(&c.pending[..c.filled]);
            c.mix(u64::from_le_bytes(last));
        }
        c.mix(c.length);
        c.mix(c.state >> 17);
        c.state
    }
}

/// Hash of the text form of every input, as 16 hex digits.
pub fn key_of(parts: &[&str]) -> String {
    let mut h = Checksum::default();
    h.update(&FORMAT_VERSION.to_le_bytes());
    for p in parts {
        h.update(&(p.len() as u64).to_le_bytes());
        h.update(p.as_bytes());
    }
    format!("{:016x}", h.finish())
}

/// The cache key of a grid: eye, axes, screen, settings and format version.
pub fn grid_key(eye: &Eye, axes: &GridAxes, screen: &Screen, settings: &KernelSettings) -> String {
    let json = |v: &dyn erased::Json| v.json();
    key_of(&[
        &eye.to_toml_string(),
        &json(axes),
        &json(screen),
        &json(settings),
    ])
}

mod erased {
    pub trait Json {
        fn json(&self) -> String;
    }
    impl<T: serde::Serialize> Json for T {
        fn json(&self) -> String {
            serde_json::to_string(self).unwrap_or_default()
        }
    }
}

#[derive(Serialize, Deserialize, Debug, PartialEq)]
struct Header {
    key: String,
    pupils_mm: Vec<f64>,
    focus_d: Vec<f64>,
    wavelengths_nm: [f64; 3],
    objects: DioptreAxis,
    max_radius_px: u32,
    fov_y_deg: f64,
    height_px: u32,
    texels_per_set: u64,
    /// Texels stored over all sets: the blocks each object distance holds (its top level
    /// and below), the rest being zero.
    stored_texels: u64,
}

/// The texel ranges of a set's held blocks, in file order: level-major, then object distance,
/// each object's blocks up to its top level.
fn held_ranges(set: &KernelSet) -> Vec<std::ops::Range<usize>> {
    let levels = super::kernels::level_count(set.max_radius_px);
    let mut out = Vec::new();
    for level in 0..levels {
        let n = super::kernels::kernel_side(super::kernels::level_block_radius(level)).pow(2);
        for (o, &top) in set.top_level.iter().enumerate() {
            if level <= top {
                let start = set.block_offset(level, o);
                out.push(start..start + n);
            }
        }
    }
    out
}

struct HashWriter<W: Write> {
    inner: W,
    sum: Checksum,
}

impl<W: Write> HashWriter<W> {
    fn put(&mut self, bytes: &[u8]) -> std::io::Result<()> {
        self.sum.update(bytes);
        self.inner.write_all(bytes)
    }
}

/// Writes `grid` (tagged with `key`) atomically to `path`.
pub fn write_grid(path: &Path, grid: &KernelGrid, key: &str) -> Result<()> {
    grid.validate()
        .map_err(|e| Error::input(format!("refusing to write an invalid grid: {e}")))?;
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir).map_err(|e| Error::file(dir, e))?;
    let name = path
        .file_name()
        .ok_or_else(|| Error::file(path, "not a file name"))?;
    let tmp = dir.join(format!(
        ".{}.tmp{}",
        name.to_string_lossy(),
        std::process::id()
    ));
    let result = write_to(&tmp, grid, key)
        .and_then(|_| std::fs::rename(&tmp, path).map_err(|e| Error::file(path, e)));
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

fn write_to(tmp: &Path, grid: &KernelGrid, key: &str) -> Result<()> {
    let file = std::fs::File::create(tmp).map_err(|e| Error::file(tmp, e))?;
    let mut w = HashWriter {
        inner: BufWriter::with_capacity(1 << 20, file),
        sum: Checksum::default(),
    };
    let header = Header {
        key: key.to_string(),
        pupils_mm: grid.pupils_mm.clone(),
        focus_d: grid.focus_d.clone(),
        wavelengths_nm: grid.wavelengths_nm,
        objects: grid.objects,
        max_radius_px: grid.max_radius_px,
        fov_y_deg: grid.fov_y_deg,
        height_px: grid.height_px,
        texels_per_set: grid.sets[0].texels.len() as u64,
        stored_texels: grid
            .sets
            .iter()
            .flat_map(held_ranges)
            .map(|r| r.len() as u64)
            .sum(),
    };
    let text = serde_json::to_vec(&header).map_err(|e| Error::file(tmp, e))?;
    let io = |e: std::io::Error| Error::file(tmp, e);
    w.put(MAGIC).map_err(io)?;
    w.put(&FORMAT_VERSION.to_le_bytes()).map_err(io)?;
    w.put(&(text.len() as u32).to_le_bytes()).map_err(io)?;
    w.put(&text).map_err(io)?;
    for set in &grid.sets {
        w.put(&set.pupil_mm.to_le_bytes()).map_err(io)?;
        w.put(&set.focus_d.to_le_bytes()).map_err(io)?;
        w.put(bytemuck::cast_slice(&set.radius_px)).map_err(io)?;
        w.put(bytemuck::cast_slice(&set.top_level)).map_err(io)?;
        for range in held_ranges(set) {
            w.put(bytemuck::cast_slice(&set.texels[range]))
                .map_err(io)?;
        }
    }
    let sum = w.sum.finish();
    let mut inner = w.inner;
    inner.write_all(&sum.to_le_bytes()).map_err(io)?;
    let file = inner
        .into_inner()
        .map_err(|e| Error::file(tmp, e.error()))?;
    file.sync_all().map_err(io)?;
    Ok(())
}

struct HashReader<R: Read> {
    inner: R,
    sum: Checksum,
}

impl<R: Read> HashReader<R> {
    fn get(&mut self, buf: &mut [u8]) -> std::result::Result<(), String> {
        self.inner
            .read_exact(buf)
            .map_err(|e| format!("truncated ({e})"))?;
        self.sum.update(buf);
        Ok(())
    }
}

/// Reads a grid file; `expected_key` (if any) must match the file's. The error says why the
/// file is unusable (wrong magic, version, key, sizes, truncation, checksum).
pub fn read_grid(
    path: &Path,
    expected_key: Option<&str>,
) -> std::result::Result<KernelGrid, String> {
    let file = std::fs::File::open(path).map_err(|e| e.to_string())?;
    let len = file.metadata().map_err(|e| e.to_string())?.len();
    let mut r = HashReader {
        inner: BufReader::with_capacity(1 << 20, file),
        sum: Checksum::default(),
    };
    let mut magic = [0u8; 8];
    r.get(&mut magic)?;
    if &magic != MAGIC {
        return Err("not an ocular kernel grid (bad magic)".into());
    }
    let mut word = [0u8; 4];
    r.get(&mut word)?;
    let version = u32::from_le_bytes(word);
    if version != FORMAT_VERSION {
        return Err(format!(
            "format version {version}, this build reads {FORMAT_VERSION}"
        ));
    }
    r.get(&mut word)?;
    let hlen = u32::from_le_bytes(word) as u64;
    if hlen > 1 << 20 || hlen > len {
        return Err("header length is implausible".into());
    }
    let mut text = vec![0u8; hlen as usize];
    r.get(&mut text)?;
    let h: Header = serde_json::from_slice(&text).map_err(|e| format!("bad header ({e})"))?;
    if let Some(k) = expected_key {
        if h.key != k {
            return Err(format!("key {} does not match the inputs ({k})", h.key));
        }
    }
    let sets = h.pupils_mm.len() * h.focus_d.len();
    let no = h.objects.count;
    let texels = KernelSet::texel_count(no, h.max_radius_px) as u64;
    if texels != h.texels_per_set || sets == 0 || no == 0 {
        return Err("header sizes are inconsistent".into());
    }
    if h.stored_texels > sets as u64 * texels {
        return Err("header sizes are inconsistent".into());
    }
    let expected_len = 16 + hlen + sets as u64 * (16 + 16 * no as u64) + 12 * h.stored_texels + 8;
    if len != expected_len {
        return Err(format!(
            "file is {len} bytes, its header implies {expected_len} (truncated or padded)"
        ));
    }
    let mut out = Vec::with_capacity(sets);
    let mut stored = 0u64;
    for _ in 0..sets {
        let mut d = [0u8; 8];
        r.get(&mut d)?;
        let pupil_mm = f64::from_le_bytes(d);
        r.get(&mut d)?;
        let focus_d = f64::from_le_bytes(d);
        let mut set = KernelSet::zeroed(pupil_mm, focus_d, h.objects, h.max_radius_px);
        r.get(bytemuck::cast_slice_mut(&mut set.radius_px))?;
        r.get(bytemuck::cast_slice_mut(&mut set.top_level))?;
        let levels = super::kernels::level_count(h.max_radius_px);
        if set.top_level.iter().any(|&t| t >= levels) {
            return Err(format!("a top level is not below the {levels} levels"));
        }
        for range in held_ranges(&set) {
            stored += range.len() as u64;
            if stored > h.stored_texels {
                return Err("the sets hold more texels than the header says".into());
            }
            r.get(bytemuck::cast_slice_mut(&mut set.texels[range]))?;
        }
        out.push(set);
    }
    if stored != h.stored_texels {
        return Err("the sets hold fewer texels than the header says".into());
    }
    let computed = r.sum.finish();
    let mut d = [0u8; 8];
    r.inner
        .read_exact(&mut d)
        .map_err(|e| format!("truncated ({e})"))?;
    if u64::from_le_bytes(d) != computed {
        return Err("checksum mismatch (the file is corrupt)".into());
    }
    let grid = KernelGrid {
        pupils_mm: h.pupils_mm,
        focus_d: h.focus_d,
        wavelengths_nm: h.wavelengths_nm,
        objects: h.objects,
        max_radius_px: h.max_radius_px,
        fov_y_deg: h.fov_y_deg,
        height_px: h.height_px,
        sets: out,
    };
    grid.validate()?;
    Ok(grid)
}

/// Where cached grids live: `$XDG_CACHE_HOME/ocular`, else `~/.cache/ocular`.
pub fn default_cache_dir() -> Option<PathBuf> {
    let xdg = std::env::var_os("XDG_CACHE_HOME").filter(|v| !v.is_empty());
    if let Some(x) = xdg {
        return Some(PathBuf::from(x).join("ocular"));
    }
    std::env::var_os("HOME")
        .filter(|v| !v.is_empty())
        .map(|h| PathBuf::from(h).join(".cache").join("ocular"))
}

/// How a grid was obtained through the cache.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub enum CacheOutcome {
    Disabled,
    Hit(PathBuf),
    /// Computed and stored (the warning says why a present file was not used).
    Stored {
        path: PathBuf,
        warning: Option<String>,
    },
    /// Computed, but the file could not be written.
    WriteFailed(String),
}

/// The cache file for a key.
pub fn cache_path(dir: &Path, key: &str) -> PathBuf {
    dir.join(format!("kernels-{key}.bin"))
}

/// Loads the grid for `key` from `dir`, or computes it with `compute` and stores it. A file
/// that is corrupt, truncated or for other inputs is reported in the outcome and replaced.
pub fn cached<T>(
    dir: Option<&Path>,
    key: &str,
    compute: impl FnOnce() -> Result<(KernelGrid, T)>,
) -> Result<(KernelGrid, Option<T>, CacheOutcome)> {
    let Some(dir) = dir else {
        let (g, t) = compute()?;
        return Ok((g, Some(t), CacheOutcome::Disabled));
    };
    let path = cache_path(dir, key);
    let mut warning = None;
    if path.exists() {
        match read_grid(&path, Some(key)) {
            Ok(g) => return Ok((g, None, CacheOutcome::Hit(path))),
            Err(e) => {
                warning = Some(format!(
                    "cached kernels {} are unusable ({e}); recomputing",
                    path.display()
                ))
            }
        }
    }
    let (g, t) = compute()?;
    let outcome = match write_grid(&path, &g, key) {
        Ok(()) => CacheOutcome::Stored { path, warning },
        Err(e) => CacheOutcome::WriteFailed(match warning {
            Some(w) => format!("{w}; and the new file could not be written: {e}"),
            None => format!("cannot write the cache: {e}"),
        }),
    };
    Ok((g, Some(t), outcome))
}
