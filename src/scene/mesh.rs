//! Triangle geometry in world space, ready for the rasteriser: one vertex and one index array
//! for the whole scene, cut into batches that share a material. Built-in primitives are
//! generated here in their local frame and transformed on the CPU once per scene (objects do
//! not move over time; the camera does).

use glam::{DMat3, DMat4, DVec3};

/// One vertex as the raster shaders read it (`location` 0, 1, 2).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Vertex {
    pub position_m: [f32; 3],
    pub normal: [f32; 3],
    pub uv: [f32; 2],
    /// The longest edge from this vertex in any of its triangles (m): no point of a triangle
    /// lies farther from its vertex than this, so the rasteriser bounds a fragment's depth by
    /// its triangle's first vertex (glsl/render/raster_shade.glsl).
    pub reach_m: f32,
}

/// Lambertian surface: reflectance (linear RGB, 0..1) times an optional texture, plus emitted
/// luminance.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    pub albedo: [f32; 3],
    pub texture: Option<usize>,
    /// Emitted linear RGB whose luminance Y is in cd/m².
    pub emission: [f32; 3],
}

impl Default for Material {
    fn default() -> Self {
        Material {
            albedo: [0.8, 0.8, 0.8],
            texture: None,
            emission: [0.0; 3],
        }
    }
}

/// An sRGB-encoded RGBA8 texture.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    pub width: u32,
    pub height: u32,
    pub rgba8_srgb: Vec<[u8; 4]>,
    pub source: String,
}

/// `index_count` indices from `first_index` drawn with one material: one placed object (or
/// one material of it), with the world-space box that holds its vertices.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Batch {
    pub first_index: u32,
    pub index_count: u32,
    pub material: usize,
    /// Smallest and largest corner of the axis-aligned box around the batch's vertices (m).
    pub bounds_m: [[f64; 3]; 2],
}

impl Batch {
    /// The nearest and farthest distance along `forward_unit` from `eye_m` of any point of the
    /// batch's box. Depth along a direction is linear in position, so its extremes over a box
    /// are at corners.
    pub fn view_depth_range_m(&self, eye_m: [f64; 3], forward_unit: [f64; 3]) -> (f64, f64) {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for corner in 0..8 {
            let d: f64 = (0..3)
                .map(|k| {
                    let p = self.bounds_m[(corner >> k) & 1][k];
                    (p - eye_m[k]) * forward_unit[k]
                })
                .sum();
            lo = lo.min(d);
            hi = hi.max(d);
        }
        (lo, hi)
    }
}

#[derive(Clone, Debug, Default, PartialEq)]
pub struct Geometry {
    pub vertices: Vec<Vertex>,
    pub indices: Vec<u32>,
    pub batches: Vec<Batch>,
    pub materials: Vec<Material>,
    pub textures: Vec<Texture>,
}

/// A mesh in its local frame before placement.
#[derive(Clone, Debug, Default)]
pub struct LocalMesh {
    pub positions: Vec<[f64; 3]>,
    pub normals: Vec<[f64; 3]>,
    pub uvs: Vec<[f64; 2]>,
    pub indices: Vec<u32>,
}

impl LocalMesh {
    fn push(&mut self, p: [f64; 3], n: [f64; 3], uv: [f64; 2]) -> u32 {
        self.positions.push(p);
        self.normals.push(n);
        self.uvs.push(uv);
        (self.positions.len() - 1) as u32
    }

    /// Appends another mesh (indices shifted).
    pub fn append(&mut self, other: &LocalMesh) {
        let base = self.positions.len() as u32;
        self.positions.extend_from_slice(&other.positions);
        self.normals.extend_from_slice(&other.normals);
        self.uvs.extend_from_slice(&other.uvs);
        self.indices.extend(other.indices.iter().map(|i| i + base));
    }

    /// An axis-aligned rectangle [x0, x1] × [y0, y1] at height z facing +Z.
    pub fn rect(&mut self, x0: f64, y0: f64, x1: f64, y1: f64, z: f64) {
        let n = [0.0, 0.0, 1.0];
        let a = self.push([x0, y0, z], n, [0.0, 1.0]);
        let b = self.push([x1, y0, z], n, [1.0, 1.0]);
        let c = self.push([x1, y1, z], n, [1.0, 0.0]);
        let d = self.push([x0, y1, z], n, [0.0, 0.0]);
        self.indices.extend_from_slice(&[a, b, c, a, c, d]);
    }

    /// Planar polygon given as a triangle list of points in the z plane, facing +Z.
    pub fn flat_triangle(&mut self, p: [[f64; 2]; 3], z: f64) {
        let n = [0.0, 0.0, 1.0];
        for q in p {
            let i = self.push([q[0], q[1], z], n, [q[0], -q[1]]);
            self.indices.push(i);
        }
    }
}

/// A `width × height` rectangle in the local XY plane, centred, facing +Z.
pub fn plane(width: f64, height: f64) -> LocalMesh {
    let mut m = LocalMesh::default();
    m.rect(-width / 2.0, -height / 2.0, width / 2.0, height / 2.0, 0.0);
    m
}

/// A box centred at the origin.
pub fn cuboid(size: [f64; 3]) -> LocalMesh {
    let h = size.map(|s| s / 2.0);
    let mut m = LocalMesh::default();
    // Each face: normal axis, sign; the two in-plane axes follow the right-hand rule so that
    // every face is wound counter-clockwise seen from outside.
    for axis in 0..3 {
        for sign in [1.0, -1.0] {
            let u_axis = (axis + 1) % 3;
            let v_axis = (axis + 2) % 3;
            let mut n = [0.0; 3];
            n[axis] = sign;
            let corner = |su: f64, sv: f64| {
                let mut p = [0.0; 3];
                p[axis] = sign * h[axis];
                p[u_axis] = su * h[u_axis];
                p[v_axis] = sv * h[v_axis];
                p
            };
            let quad = if sign > 0.0 {
                [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
            } else {
                [(-1.0, -1.0), (-1.0, 1.0), (1.0, 1.0), (1.0, -1.0)]
            };
            let ids: Vec<u32> = quad
                .iter()
                .map(|&(su, sv)| m.push(corner(su, sv), n, [(su + 1.0) / 2.0, (1.0 - sv) / 2.0]))
                .collect();
            m.indices
                .extend_from_slice(&[ids[0], ids[1], ids[2], ids[0], ids[2], ids[3]]);
        }
    }
    m
}

/// A UV sphere: `segments` around the Y axis, `segments / 2` rings from pole to pole.
pub fn sphere(radius: f64, segments: u32) -> LocalMesh {
    let segments = segments.max(8);
    let rings = (segments / 2).max(4);
    let mut m = LocalMesh::default();
    for r in 0..=rings {
        let v = f64::from(r) / f64::from(rings);
        let theta = v * std::f64::consts::PI;
        for s in 0..=segments {
            let u = f64::from(s) / f64::from(segments);
            let phi = u * std::f64::consts::TAU;
            let n = [
                theta.sin() * phi.sin(),
                theta.cos(),
                theta.sin() * phi.cos(),
            ];
            m.push(n.map(|c| c * radius), n, [u, v]);
        }
    }
    let stride = segments + 1;
    for r in 0..rings {
        for s in 0..segments {
            let a = r * stride + s;
            let b = a + stride;
            m.indices.extend_from_slice(&[a, b, a + 1, a + 1, b, b + 1]);
        }
    }
    m
}

/// A closed cylinder along local Y, centred at the origin.
pub fn cylinder(radius: f64, height: f64, segments: u32) -> LocalMesh {
    let segments = segments.max(6);
    let mut m = LocalMesh::default();
    let h = height / 2.0;
    for s in 0..=segments {
        let u = f64::from(s) / f64::from(segments);
        let phi = u * std::f64::consts::TAU;
        let n = [phi.sin(), 0.0, phi.cos()];
        m.push([radius * n[0], -h, radius * n[2]], n, [u, 1.0]);
        m.push([radius * n[0], h, radius * n[2]], n, [u, 0.0]);
    }
    for s in 0..segments {
        let a = 2 * s;
        m.indices
            .extend_from_slice(&[a, a + 2, a + 1, a + 1, a + 2, a + 3]);
    }
    for (y, ny) in [(h, 1.0), (-h, -1.0)] {
        let n = [0.0, ny, 0.0];
        let centre = m.push([0.0, y, 0.0], n, [0.5, 0.5]);
        let first = m.positions.len() as u32;
        for s in 0..=segments {
            let phi = f64::from(s) / f64::from(segments) * std::f64::consts::TAU;
            let (x, z) = (phi.sin(), phi.cos());
            m.push(
                [radius * x, y, radius * z],
                n,
                [0.5 + 0.5 * x, 0.5 - 0.5 * z],
            );
        }
        for s in 0..segments {
            let (a, b) = (first + s, first + s + 1);
            if ny > 0.0 {
                m.indices.extend_from_slice(&[centre, a, b]);
            } else {
                m.indices.extend_from_slice(&[centre, b, a]);
            }
        }
    }
    m
}

/// Translation · rotation (about X, then Y, then Z, degrees) · scale.
pub fn model_matrix(translate: [f64; 3], rotate_deg: [f64; 3], scale: [f64; 3]) -> DMat4 {
    let r = DMat4::from_rotation_z(rotate_deg[2].to_radians())
        * DMat4::from_rotation_y(rotate_deg[1].to_radians())
        * DMat4::from_rotation_x(rotate_deg[0].to_radians());
    DMat4::from_translation(DVec3::from(translate)) * r * DMat4::from_scale(DVec3::from(scale))
}

/// Whether triangle `t`'s winding (counter-clockwise seen from where its normal points) agrees
/// with its vertex normals. The rasteriser decides which side of a surface the eye sees by the
/// winding (`gl_FrontFacing`), the one test that stays exact on a facet seen edge-on, so every
/// triangle is stored wound to agree with its normals: OBJ windings are unreliable, and a
/// placement's mirror (a negative scale) reverses them.
fn winding_follows_normals(vertices: &[Vertex], t: [u32; 3]) -> bool {
    let [a, b, c] = t.map(|i| vertices[i as usize]);
    let p = |v: Vertex| DVec3::from(v.position_m.map(f64::from));
    let n = |v: Vertex| DVec3::from(v.normal.map(f64::from));
    let winding = (p(b) - p(a)).cross(p(c) - p(a));
    winding.dot(n(a) + n(b) + n(c)) >= 0.0
}

impl Geometry {
    /// Places `mesh` with `model` and draws it with `material` (an index into `materials`).
    pub fn add(&mut self, mesh: &LocalMesh, model: &DMat4, material: usize) {
        if mesh.indices.is_empty() {
            return;
        }
        let normal_matrix = DMat3::from_mat4(*model).inverse().transpose();
        let base = self.vertices.len() as u32;
        let mut bounds_m = [[f64::INFINITY; 3], [f64::NEG_INFINITY; 3]];
        for i in 0..mesh.positions.len() {
            let p = model.transform_point3(DVec3::from(mesh.positions[i]));
            // the box holds the stored (f32) positions, which the GPU sees
            let stored = p.as_vec3().to_array();
            for k in 0..3 {
                bounds_m[0][k] = bounds_m[0][k].min(f64::from(stored[k]));
                bounds_m[1][k] = bounds_m[1][k].max(f64::from(stored[k]));
            }
            let n = (normal_matrix * DVec3::from(mesh.normals[i])).normalize_or_zero();
            self.vertices.push(Vertex {
                position_m: p.as_vec3().to_array(),
                normal: n.as_vec3().to_array(),
                uv: mesh.uvs[i].map(|c| c as f32),
                reach_m: 0.0,
            });
        }
        let first_index = self.indices.len() as u32;
        for t in mesh.indices.chunks_exact(3) {
            let mut t = [t[0] + base, t[1] + base, t[2] + base];
            if !winding_follows_normals(&self.vertices, t) {
                t.swap(1, 2);
            }
            self.indices.extend_from_slice(&t);
            let p = t.map(|i| DVec3::from(self.vertices[i as usize].position_m.map(f64::from)));
            for k in 0..3 {
                let reach = p[(k + 1) % 3]
                    .distance(p[k])
                    .max(p[(k + 2) % 3].distance(p[k]));
                let v = &mut self.vertices[t[k] as usize];
                // rounded up, so that the f32 bound holds what the f64 one does
                v.reach_m = v.reach_m.max((reach * (1.0 + 1e-6)) as f32);
            }
        }
        // One batch per placement, never merged with its neighbours: the rasteriser bounds each
        // fragment's depth by its batch's box, and a batch spanning a row of columns would
        // loosen that bound to the whole row.
        self.batches.push(Batch {
            first_index,
            index_count: mesh.indices.len() as u32,
            material,
            bounds_m,
        });
    }

    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The depth range of a placed cuboid, against its eight corners' depths computed from the
    /// placement itself: an axis-aligned box is its own bounding box, so the range is exact;
    /// a rotated one's range must hold every vertex.
    #[test]
    fn batch_depth_range_holds_every_vertex_and_is_exact_for_a_box() {
        let eye = [0.3, 1.2, 2.0];
        let forward = {
            let f = DVec3::new(0.2, -0.3, -1.0).normalize();
            [f.x, f.y, f.z]
        };
        let depth = |p: [f32; 3]| -> f64 {
            (0..3)
                .map(|k| (f64::from(p[k]) - eye[k]) * forward[k])
                .sum()
        };
        for (rotate, exact) in [([0.0; 3], true), ([20.0, 35.0, -10.0], false)] {
            let mut g = Geometry::default();
            g.add(
                &cuboid([0.5, 1.0, 2.0]),
                &model_matrix([1.0, 0.5, -3.0], rotate, [1.0; 3]),
                0,
            );
            g.add(
                &sphere(0.2, 12),
                &model_matrix([0.0, 0.0, -8.0], [0.0; 3], [1.0; 3]),
                0,
            );
            assert_eq!(g.batches.len(), 2, "one batch per placement");
            let b = g.batches[0];
            let (lo, hi) = b.view_depth_range_m(eye, forward);
            let used: Vec<f64> = g.indices[..b.index_count as usize]
                .iter()
                .map(|&i| depth(g.vertices[i as usize].position_m))
                .collect();
            let (vlo, vhi) = used
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &d| {
                    (a.min(d), b.max(d))
                });
            assert!(
                lo <= vlo + 1e-12 && hi >= vhi - 1e-12,
                "{lo}..{hi} vs {vlo}..{vhi}"
            );
            if exact {
                assert!((lo - vlo).abs() < 1e-9 && (hi - vhi).abs() < 1e-9);
            }
            // the second placement has its own, farther box
            let (lo2, _) = g.batches[1].view_depth_range_m(eye, forward);
            assert!(lo2 > hi, "{lo2} vs {hi}");
        }
    }
}
