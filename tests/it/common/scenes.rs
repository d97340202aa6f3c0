//! Scenes written inline for the tests.

use std::path::Path;

use ocular::scene::Scene;

/// A scene from TOML text (relative paths from the current folder).
pub fn scene(text: &str) -> Scene {
    Scene::from_toml(text, "test scene", Path::new(".")).unwrap()
}

/// A self-lit square of half-width `half_m` at `distance_m` on the axis: black background, no
/// lights, so colour is coverage × emission exactly.
pub fn square_scene(half_m: f64, distance_m: f64, fov_y_deg: f64) -> Scene {
    scene(&format!(
        r#"
[camera]
position = [0.0, 0.0, 0.0]
fov_y_deg = {fov_y_deg}
far_m = 100.0

[[object]]
kind = "plane"
size_m = {}
translate = [0.0, 0.0, {}]
color = [0.0, 0.0, 0.0]
emission_cd_m2 = 100.0
"#,
        2.0 * half_m,
        -distance_m
    ))
}
