//! What a viewer's clients may name: the built-in scenes and eye presets, and the scene and
//! eye files found in the folders given at start. Everything is loaded here, once; a request
//! names an entry, never a path, so no path from a client is ever opened. Files are taken only
//! where their real path (symlinks resolved) lies inside the folder given.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::eye::Eye;
use crate::scene::Scene;
use crate::{Error, Result};

/// A scene a client can choose.
pub struct SceneEntry {
    pub scene: Arc<Scene>,
    /// What `ocular render --scene` takes for it: the built-in's name or the file's path.
    pub cli: String,
}

/// An eye file a client can choose.
pub struct EyeEntry {
    pub eye: Eye,
    /// The file's path, for the equivalent command line.
    pub cli: String,
}

/// The scenes and eyes of one server, by the names clients use.
#[derive(Default)]
pub struct Catalog {
    pub scenes: BTreeMap<String, SceneEntry>,
    pub eye_files: BTreeMap<String, EyeEntry>,
    /// Files of the folders that were not taken, and why (printed at start).
    pub skipped: Vec<String>,
}

/// The `.toml` files directly inside `dir` whose real path stays inside it, by file stem.
fn toml_files(
    option: &str,
    dir: &Path,
    skipped: &mut Vec<String>,
) -> Result<Vec<(String, PathBuf)>> {
    let root = dir.canonicalize().map_err(|e| {
        Error::input(format!(
            "{option} {}: not a readable folder ({e})",
            dir.display()
        ))
    })?;
    if !root.is_dir() {
        return Err(Error::input(format!(
            "{option} {}: not a folder",
            dir.display()
        )));
    }
    let entries = std::fs::read_dir(&root)
        .map_err(|e| Error::input(format!("{option} {}: cannot list it ({e})", dir.display())))?;
    let mut found = Vec::new();
    for entry in entries.flatten() {
        let path = entry.path();
        if path.extension().and_then(|e| e.to_str()) != Some("toml") {
            continue;
        }
        let Some(stem) = path
            .file_stem()
            .and_then(|s| s.to_str())
            .map(str::to_string)
        else {
            skipped.push(format!("{}: the name is not UTF-8", path.display()));
            continue;
        };
        match path.canonicalize() {
            Ok(real) if real.starts_with(&root) && real.is_file() => found.push((stem, real)),
            Ok(real) => skipped.push(format!(
                "{}: leads outside {} (to {})",
                path.display(),
                root.display(),
                real.display()
            )),
            Err(e) => skipped.push(format!("{}: {e}", path.display())),
        }
    }
    found.sort();
    Ok(found)
}

impl Catalog {
    /// The built-ins, and the files of `scenes_dir` and `eyes_dir` that load.
    pub fn load(scenes_dir: Option<&Path>, eyes_dir: Option<&Path>) -> Result<Catalog> {
        let mut catalog = Catalog::default();
        for name in Scene::builtin_names() {
            let text = Scene::builtin_text(name).expect("a built-in has its text");
            let scene = Scene::from_toml(text, &format!("built-in scene {name}"), Path::new("."))?;
            catalog.scenes.insert(
                name.to_string(),
                SceneEntry {
                    scene: Arc::new(scene),
                    cli: name.to_string(),
                },
            );
        }
        if let Some(dir) = scenes_dir {
            for (stem, path) in toml_files("--scenes", dir, &mut catalog.skipped)? {
                if catalog.scenes.contains_key(&stem) {
                    catalog
                        .skipped
                        .push(format!("{}: a built-in scene has its name", path.display()));
                    continue;
                }
                match Scene::from_file(&path) {
                    Ok(scene) => {
                        catalog.scenes.insert(
                            stem,
                            SceneEntry {
                                scene: Arc::new(scene),
                                cli: path.display().to_string(),
                            },
                        );
                    }
                    Err(e) => catalog.skipped.push(e.to_string()),
                }
            }
        }
        if let Some(dir) = eyes_dir {
            for (stem, path) in toml_files("--eyes", dir, &mut catalog.skipped)? {
                match crate::eye::file::load(&path) {
                    Ok(file) => {
                        catalog.eye_files.insert(
                            stem,
                            EyeEntry {
                                eye: file.eye,
                                cli: path.display().to_string(),
                            },
                        );
                    }
                    Err(e) => catalog.skipped.push(e.to_string()),
                }
            }
        }
        Ok(catalog)
    }

    /// What the page lists.
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::json!({
            "scenes": self.scenes.keys().collect::<Vec<_>>(),
            "eye_presets": crate::eye::file::preset_names(),
            "eye_files": self.eye_files.keys().collect::<Vec<_>>(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn files_outside_the_folder_are_not_taken() {
        let root = std::env::temp_dir().join(format!("ocular-catalog-{}", std::process::id()));
        let (inside, outside) = (root.join("eyes"), root.join("elsewhere"));
        std::fs::create_dir_all(&inside).unwrap();
        std::fs::create_dir_all(&outside).unwrap();
        let text = crate::eye::file::to_toml(&Eye::preset("healthy").unwrap(), None, "test");
        std::fs::write(inside.join("mine.toml"), &text).unwrap();
        std::fs::write(outside.join("secret.toml"), &text).unwrap();
        std::fs::write(inside.join("broken.toml"), "not = [an eye").unwrap();
        #[cfg(unix)]
        std::os::unix::fs::symlink(outside.join("secret.toml"), inside.join("link.toml")).unwrap();
        let c = Catalog::load(None, Some(&inside)).unwrap();
        let _ = std::fs::remove_dir_all(&root);
        assert_eq!(c.eye_files.keys().collect::<Vec<_>>(), ["mine"]);
        assert!(
            c.skipped.iter().any(|s| s.contains("broken.toml")),
            "{:?}",
            c.skipped
        );
        #[cfg(unix)]
        assert!(
            c.skipped.iter().any(|s| s.contains("leads outside")),
            "{:?}",
            c.skipped
        );
        assert!(c.scenes.contains_key("primitives"));
    }
}
