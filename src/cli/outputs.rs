//! Output files of the commands that write several: every path is checked before any work
//! (extension, folder, no two options naming one file), each file is written to a temporary
//! name, and the set is renamed into place only when all of them were written. A failure
//! leaves none of the final names behind.

use std::path::{Path, PathBuf};

use crate::{Error, Result};

/// Refuses a file name whose extension is not one of `allowed` (case-insensitive), so that no
/// command writes EXR data under a .png name or the reverse.
pub fn check_extension(option: &str, path: &Path, allowed: &[&str]) -> Result<()> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    if allowed.iter().any(|a| *a == ext) {
        return Ok(());
    }
    let want = allowed
        .iter()
        .map(|a| format!(".{a}"))
        .collect::<Vec<_>>()
        .join(" or ");
    Err(Error::input(format!(
        "{option} {}: the file name must end in {want}",
        path.display()
    )))
}

/// The folder a file will be written to must exist already (no command creates it silently)
/// and the name must not be a folder.
pub fn check_folder(option: &str, path: &Path) -> Result<()> {
    if path.file_name().is_none() {
        return Err(Error::input(format!(
            "{option} {}: not a file name",
            path.display()
        )));
    }
    if path.is_dir() {
        return Err(Error::input(format!(
            "{option} {}: is a folder; give a file name",
            path.display()
        )));
    }
    let dir = parent_of(path);
    if !dir.is_dir() {
        return Err(Error::input(format!(
            "{option} {}: the folder {} does not exist",
            path.display(),
            dir.display()
        )));
    }
    Ok(())
}

fn parent_of(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// The same file however it is spelled (`a.exr`, `./a.exr`, `dir/../a.exr`).
fn identity(path: &Path) -> PathBuf {
    let dir = parent_of(path);
    let dir = dir.canonicalize().unwrap_or(dir);
    dir.join(path.file_name().unwrap_or_default())
}

struct Entry {
    option: String,
    path: PathBuf,
    tmp: PathBuf,
}

/// The outputs of one command run.
#[derive(Default)]
pub struct Outputs {
    entries: Vec<Entry>,
    committed: bool,
}

impl Outputs {
    pub fn new() -> Outputs {
        Outputs::default()
    }

    /// Registers an output; `extensions` empty means any name. Refuses a bad extension, a
    /// missing folder, and a path another option already names.
    pub fn add(&mut self, option: &str, path: &Path, extensions: &[&str]) -> Result<()> {
        if !extensions.is_empty() {
            check_extension(option, path, extensions)?;
        }
        check_folder(option, path)?;
        let id = identity(path);
        if let Some(other) = self.entries.iter().find(|e| identity(&e.path) == id) {
            return Err(Error::input(format!(
                "{} {} and {option} {} name the same file; give each output its own name",
                other.option,
                other.path.display(),
                path.display()
            )));
        }
        let mut tmp_name = path.file_name().unwrap_or_default().to_os_string();
        tmp_name.push(format!(".tmp-{}-all", std::process::id()));
        self.entries.push(Entry {
            option: option.to_string(),
            path: path.to_path_buf(),
            tmp: path.with_file_name(tmp_name),
        });
        Ok(())
    }

    /// Checks that every output folder accepts a new file, before any expensive work.
    pub fn probe(&self) -> Result<()> {
        for e in &self.entries {
            std::fs::write(&e.tmp, b"").map_err(|err| {
                Error::input(format!(
                    "{} {}: cannot write in {} ({err})",
                    e.option,
                    e.path.display(),
                    parent_of(&e.path).display()
                ))
            })?;
            let _ = std::fs::remove_file(&e.tmp);
        }
        Ok(())
    }

    /// Where to write the output registered for `path` until `commit`.
    pub fn temporary(&self, path: &Path) -> &Path {
        &self
            .entries
            .iter()
            .find(|e| e.path == path)
            .expect("outputs are registered before they are written")
            .tmp
    }

    /// Renames every written temporary into place. Every output must have been written.
    pub fn commit(mut self) -> Result<()> {
        for e in &self.entries {
            if !e.tmp.is_file() {
                return Err(Error::file(&e.path, "was not written; nothing was kept"));
            }
        }
        for e in &self.entries {
            std::fs::rename(&e.tmp, &e.path)
                .map_err(|err| Error::file(&e.path, format!("cannot rename into place: {err}")))?;
        }
        self.committed = true;
        Ok(())
    }
}

impl Drop for Outputs {
    fn drop(&mut self) {
        if !self.committed {
            for e in &self.entries {
                let _ = std::fs::remove_file(&e.tmp);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extensions_and_duplicates_are_refused() {
        assert!(check_extension("-o", Path::new("a.EXR"), &["exr"]).is_ok());
        let e = check_extension("-o", Path::new("a.png"), &["exr"]).unwrap_err();
        assert!(e.to_string().contains("-o a.png") && e.to_string().contains(".exr"));
        let mut o = Outputs::new();
        o.add("-o", Path::new("x.exr"), &["exr"]).unwrap();
        let e = o
            .add("--depth-out", Path::new("./x.exr"), &["exr"])
            .unwrap_err();
        assert!(e.to_string().contains("same file"), "{e}");
        let e = o
            .add("--png", Path::new("no-such-folder-here/p.png"), &["png"])
            .unwrap_err();
        assert!(e.to_string().contains("does not exist"), "{e}");
    }
}
