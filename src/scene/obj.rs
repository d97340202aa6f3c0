//! Wavefront OBJ + MTL through `tobj`, with errors that name the file and line.
//!
//! tobj reports only an error kind; to give a line, the OBJ and MTL text are fed to it through
//! a reader that hands out one line per read and counts them, so the count at failure is the
//! offending line. Face-index errors are detected by tobj only when a group ends, so those are
//! located by a separate scan of the face lines.

use std::cell::{Cell, RefCell};
use std::io::BufRead;
use std::path::{Path, PathBuf};
use std::rc::Rc;

use super::mesh::LocalMesh;
use crate::{Error, Result};

/// One drawable part of an OBJ (a group/object with one material).
#[derive(Clone, Debug)]
pub struct ObjPart {
    pub name: String,
    pub mesh: LocalMesh,
    /// MTL diffuse colour (Kd), if the part has a material that sets it.
    pub diffuse: Option<[f64; 3]>,
    /// Diffuse texture (map_Kd) resolved against the MTL's folder, with the MTL file and line
    /// that named it.
    pub texture: Option<TextureRef>,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TextureRef {
    pub path: PathBuf,
    pub referenced_from: String,
    pub line: usize,
}

/// A `BufRead` over text that yields at most one line per `fill_buf`, counting lines.
struct LineCounter<'a> {
    data: &'a [u8],
    pos: usize,
    lines_done: Rc<Cell<usize>>,
}

impl std::io::Read for LineCounter<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let available = self.fill_buf()?;
        let n = available.len().min(buf.len());
        buf[..n].copy_from_slice(&available[..n]);
        self.consume(n);
        Ok(n)
    }
}

impl BufRead for LineCounter<'_> {
    fn fill_buf(&mut self) -> std::io::Result<&[u8]> {
        let rest = &self.data[self.pos..];
        let end = rest
            .iter()
            .position(|&b| b == b'\n')
            .map_or(rest.len(), |i| i + 1);
        Ok(&rest[..end])
    }

    fn consume(&mut self, amount: usize) {
        let consumed = &self.data[self.pos..self.pos + amount];
        // A line ends at its newline, or at the end of the text without one.
        if consumed.last() == Some(&b'\n') || (amount > 0 && self.pos + amount == self.data.len()) {
            self.lines_done.set(self.lines_done.get() + 1);
        }
        self.pos += amount;
    }
}

fn describe(error: tobj::LoadError) -> &'static str {
    use tobj::LoadError as E;
    match error {
        E::PositionParseError => "a vertex needs 3 numbers (v x y z [w])",
        E::ScalingByZeroError => "vertex weight w is zero",
        E::ColorParseError => "a colour needs 3 numbers (Kd r g b)",
        E::NormalParseError => "a normal needs 3 numbers (vn x y z)",
        E::TexcoordParseError => "a texture coordinate needs 2 numbers (vt u v)",
        E::FaceParseError => {
            "malformed face: expected f v1 v2 v3 … with v, v/vt, v//vn or v/vt/vn indices"
        }
        E::MaterialParseError => "malformed material statement",
        E::InvalidObjectName => "newmtl needs a name",
        E::InvalidPolygon => "a face needs at least 3 vertices",
        E::FaceVertexOutOfBounds => "face refers to a vertex that does not exist",
        E::FaceTexCoordOutOfBounds => "face refers to a texture coordinate that does not exist",
        E::FaceNormalOutOfBounds => "face refers to a normal that does not exist",
        E::FaceColorOutOfBounds => "face refers to a vertex colour that does not exist",
        E::UnrecognizedCharacter => "unrecognised character",
        E::ReadError => "the file is not valid UTF-8 text",
        _ => "cannot parse",
    }
}

fn read_text(path: &Path, what: &str) -> Result<String> {
    let bytes = std::fs::read(path).map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound => Error::file(path, format!("{what} not found")),
        _ => Error::file(path, format!("cannot read {what}: {e}")),
    })?;
    String::from_utf8(bytes)
        .map_err(|e| Error::file(path, format!("{what} is not UTF-8 text ({e})")))
}

/// Finds the first face line with an index outside what has been declared before it (OBJ
/// indices are 1-based; negative ones count back from the latest vertex).
fn find_bad_face(text: &str) -> Option<(usize, String)> {
    let (mut v, mut vt, mut vn) = (0i64, 0i64, 0i64);
    for (number, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => v += 1,
            Some("vt") => vt += 1,
            Some("vn") => vn += 1,
            Some("f") => {
                for word in words {
                    for (k, part) in word.split('/').enumerate() {
                        if part.is_empty() {
                            continue;
                        }
                        let count = [v, vt, vn][k.min(2)];
                        let kind = ["vertex", "texture coordinate", "normal"][k.min(2)];
                        let ok = match part.parse::<i64>() {
                            Ok(i) if i > 0 => i <= count,
                            Ok(i) if i < 0 => -i <= count,
                            _ => false,
                        };
                        if !ok {
                            return Some((
                                number + 1,
                                format!(
                                    "face index {part} refers to a {kind} that does not exist \
                                     ({count} declared so far)"
                                ),
                            ));
                        }
                    }
                }
            }
            _ => {}
        }
    }
    None
}

/// First MTL line whose Ka/Kd/Ks/Ke statement has fewer than 3 values.
fn short_colour_line(text: &str) -> Option<usize> {
    text.lines()
        .position(|l| {
            let mut words = l.split_whitespace();
            matches!(words.next(), Some("Ka" | "Kd" | "Ks" | "Ke")) && words.count() < 3
        })
        .map(|i| i + 1)
}

/// Line of the first `keyword argument` statement in `text`, for messages.
fn line_of(text: &str, keyword: &str, argument: &str) -> usize {
    text.lines()
        .position(|l| {
            let mut w = l.split_whitespace();
            w.next() == Some(keyword) && l.contains(argument)
        })
        .map_or(0, |i| i + 1)
}

/// Loads an OBJ: n-gons are fan-triangulated, negative indices resolved, missing normals
/// replaced by flat face normals.
pub fn load(path: &Path) -> Result<Vec<ObjPart>> {
    let text = read_text(path, "OBJ file")?;
    let obj_lines = Rc::new(Cell::new(0usize));
    let mut reader = LineCounter {
        data: text.as_bytes(),
        pos: 0,
        lines_done: obj_lines.clone(),
    };
    let folder = path.parent().map(Path::to_path_buf).unwrap_or_default();
    // The MTL that failed (path, line, message), and every MTL's text for later look-ups.
    let mtl_failure: RefCell<Option<Error>> = RefCell::new(None);
    let mtl_texts: RefCell<Vec<(PathBuf, String)>> = RefCell::new(Vec::new());
    let options = tobj::LoadOptions {
        single_index: true,
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let loaded = tobj::load_obj_buf(&mut reader, &options, |mtl_name| {
        let mtl_path = folder.join(mtl_name);
        let mtl_text = match read_text(&mtl_path, "MTL file") {
            Ok(t) => t,
            Err(e) => {
                let line = line_of(&text, "mtllib", &mtl_name.to_string_lossy());
                let message = match &e {
                    Error::File { message, .. } => message.clone(),
                    other => other.to_string(),
                };
                mtl_failure.borrow_mut().get_or_insert(Error::file(
                    path,
                    format!("line {line}: mtllib {}: {message}", mtl_path.display()),
                ));
                return Err(tobj::LoadError::OpenFileFailed);
            }
        };
        // tobj panics on a colour with fewer than 3 numbers: catch those first.
        if let Some(line) = short_colour_line(&mtl_text) {
            mtl_failure.borrow_mut().get_or_insert(Error::file(
                &mtl_path,
                format!(
                    "line {line}: {}",
                    describe(tobj::LoadError::ColorParseError)
                ),
            ));
            return Err(tobj::LoadError::ColorParseError);
        }
        let mtl_lines = Rc::new(Cell::new(0usize));
        let mut mtl_reader = LineCounter {
            data: mtl_text.as_bytes(),
            pos: 0,
            lines_done: mtl_lines.clone(),
        };
        let result = tobj::load_mtl_buf(&mut mtl_reader);
        if let Err(e) = result {
            mtl_failure.borrow_mut().get_or_insert(Error::file(
                &mtl_path,
                format!(
                    "line {}: {}; MTL statements: newmtl NAME, Kd r g b, map_Kd FILE, …",
                    mtl_lines.get(),
                    describe(e)
                ),
            ));
        }
        mtl_texts.borrow_mut().push((mtl_path, mtl_text));
        result
    });
    if let Some(e) = mtl_failure.borrow_mut().take() {
        return Err(e);
    }
    let (models, materials) = match loaded {
        Ok(ok) => ok,
        Err(e) => {
            use tobj::LoadError as E;
            let (line, message) = match e {
                E::FaceVertexOutOfBounds
                | E::FaceTexCoordOutOfBounds
                | E::FaceNormalOutOfBounds => {
                    find_bad_face(&text).unwrap_or((obj_lines.get(), describe(e).to_string()))
                }
                _ => (obj_lines.get(), describe(e).to_string()),
            };
            return Err(Error::file(path, format!("line {line}: {message}")));
        }
    };
    // A face index beyond the data is caught by tobj only sometimes; check once more.
    if let Some((line, message)) = find_bad_face(&text) {
        return Err(Error::file(path, format!("line {line}: {message}")));
    }
    let materials = materials.unwrap_or_default();
    let mtl_texts = mtl_texts.into_inner();
    let mut parts = Vec::new();
    for model in models {
        let mesh = &model.mesh;
        if mesh.indices.is_empty() {
            continue;
        }
        let material = mesh.material_id.and_then(|i| materials.get(i));
        let diffuse = material.and_then(|m| m.diffuse).map(|c| c.map(f64::from));
        let texture = material.and_then(|m| {
            let name = m.diffuse_texture.as_ref()?;
            // The MTL that defined this material names the texture relative to itself.
            let (mtl_path, mtl_text) = mtl_texts
                .iter()
                .find(|(_, t)| t.lines().any(|l| l.trim() == format!("newmtl {}", m.name)))
                .or(mtl_texts.first())?;
            let texture_path = mtl_path
                .parent()
                .map(|p| p.join(name))
                .unwrap_or_else(|| PathBuf::from(name));
            Some(TextureRef {
                path: texture_path,
                referenced_from: mtl_path.display().to_string(),
                line: line_of(mtl_text, "map_Kd", name),
            })
        });
        parts.push(ObjPart {
            name: model.name.clone(),
            mesh: to_local_mesh(mesh),
            diffuse,
            texture,
        });
    }
    if parts.is_empty() {
        return Err(Error::file(path, "the OBJ file has no faces (f lines)"));
    }
    Ok(parts)
}

fn to_local_mesh(mesh: &tobj::Mesh) -> LocalMesh {
    let position = |i: u32| {
        let i = i as usize * 3;
        [0, 1, 2].map(|k| f64::from(mesh.positions[i + k]))
    };
    let uv = |i: u32| {
        if mesh.texcoords.is_empty() {
            [0.0, 0.0]
        } else {
            let i = i as usize * 2;
            // OBJ's v runs upwards; images are stored top row first.
            [
                f64::from(mesh.texcoords[i]),
                1.0 - f64::from(mesh.texcoords[i + 1]),
            ]
        }
    };
    let mut out = LocalMesh::default();
    if mesh.normals.is_empty() {
        // Without normals, each triangle gets its own vertices with its face normal: correct
        // for faceted models, and never wrong at creases.
        for tri in mesh.indices.chunks_exact(3) {
            let p = [position(tri[0]), position(tri[1]), position(tri[2])];
            let e1 = [0, 1, 2].map(|k| p[1][k] - p[0][k]);
            let e2 = [0, 1, 2].map(|k| p[2][k] - p[0][k]);
            let n = glam::DVec3::from(e1)
                .cross(glam::DVec3::from(e2))
                .normalize_or_zero()
                .to_array();
            for (k, &i) in tri.iter().enumerate() {
                out.positions.push(p[k]);
                out.normals.push(n);
                out.uvs.push(uv(i));
                out.indices.push(out.indices.len() as u32);
            }
        }
    } else {
        let count = mesh.positions.len() / 3;
        for i in 0..count as u32 {
            out.positions.push(position(i));
            let k = i as usize * 3;
            out.normals
                .push([0, 1, 2].map(|c| f64::from(mesh.normals[k + c])));
            out.uvs.push(uv(i));
        }
        out.indices = mesh.indices.clone();
    }
    out
}

/// Decodes a PNG texture to sRGB RGBA8; `referenced` says where it was named.
pub fn load_texture(path: &Path, referenced: &str) -> Result<super::mesh::Texture> {
    let bytes = std::fs::read(path).map_err(|e| {
        let what = match e.kind() {
            std::io::ErrorKind::NotFound => "texture not found".to_string(),
            _ => format!("cannot read texture: {e}"),
        };
        Error::file(path, format!("{what} (referenced at {referenced})"))
    })?;
    let image = image::load_from_memory(&bytes).map_err(|e| {
        Error::file(
            path,
            format!(
                "cannot decode texture ({e}); textures must be PNG (referenced at {referenced})"
            ),
        )
    })?;
    let rgba = image.to_rgba8();
    let (width, height) = rgba.dimensions();
    Ok(super::mesh::Texture {
        width,
        height,
        rgba8_srgb: rgba.pixels().map(|p| p.0).collect(),
        source: path.display().to_string(),
    })
}
