//! Plain-text description of an eye: its structure and derived optics (for `ocular eye show`).

use super::error::EyeError;
use super::measure::measure;
use super::model::Eye;
use super::paraxial::paraxial;
use std::fmt::Write;

/// Structure and first-order optics of `eye` at `wavelength_nm`, with its aberrations over
/// `pupil_mm` for an object at infinity, as an aligned text table.
pub fn describe(eye: &Eye, wavelength_nm: f64, pupil_mm: f64) -> Result<String, EyeError> {
    let sys = eye.system()?;
    let g = eye.lens_geometry()?;
    let n = sys.indices(wavelength_nm);
    let names = [
        "anterior cornea",
        "posterior cornea",
        "anterior lens",
        "posterior lens",
    ];
    let mut s = String::new();
    let _ = writeln!(
        s,
        "structure at {wavelength_nm} nm (mm; light along +z, cornea vertex at 0)"
    );
    let _ = writeln!(
        s,
        "{:<18} {:>9} {:>9} {:>9} {:>8} {:>7} {:>9}",
        "surface", "z", "R x'", "R y'", "conic", "axis°", "n after"
    );
    for (i, surf) in sys.surfaces.iter().enumerate() {
        let r = |c: f64| if c == 0.0 { f64::INFINITY } else { 1.0 / c };
        let _ = writeln!(
            s,
            "{:<18} {:>9.4} {:>9.4} {:>9.4} {:>8.4} {:>7.1} {:>9.5}",
            names.get(i).copied().unwrap_or("surface"),
            surf.vertex_z_mm,
            r(surf.curvature[0]),
            r(surf.curvature[1]),
            surf.conic,
            surf.axis_rad.to_degrees(),
            n[i + 1]
        );
    }
    let _ = writeln!(s, "{:<18} {:>9.4}", "retina", sys.retina_z_mm);
    let l = &eye.lens;
    let _ = writeln!(
        s,
        "lens: diameter {:.4} mm, volume {:.2} mm³, thickness {:.4} = {:.4} + {:.4} mm, \
         decentration ({:.3}, {:.3}) mm, tilt ({:.2}, {:.2})°",
        l.diameter_mm,
        l.volume_mm3,
        g.thickness_mm(),
        g.anterior_thickness_mm,
        g.posterior_thickness_mm,
        l.decentration_mm[0],
        l.decentration_mm[1],
        l.tilt_deg[0],
        l.tilt_deg[1]
    );
    let px = paraxial(&sys, wavelength_nm, 0.0);
    let py = paraxial(&sys, wavelength_nm, 90.0);
    let _ = writeln!(
        s,
        "power {:.3} D (x) / {:.3} D (y); paraxial refraction at the cornea {:+.3} D (x) / {:+.3} D (y)",
        px.power_d, py.power_d, px.refraction_d, py.refraction_d
    );
    let m = measure(&sys, wavelength_nm, pupil_mm, None, 6)?;
    let _ = writeln!(
        s,
        "{pupil_mm} mm pupil: M {:+.3} D, J0 {:+.3} D, J45 {:+.3} D, HO RMS {:.4} µm; entrance pupil at {:.3} mm \
         (×{:.4}/×{:.4}), exit pupil at {:.3} mm, {:.3} mm wide, {:.3} mm from the retina, NA {:.4}",
        m.refraction.m,
        m.refraction.j0,
        m.refraction.j45,
        m.coefficients_um.iter().skip(6).map(|c| c * c).sum::<f64>().sqrt(),
        m.entrance_pupil_z_mm,
        m.entrance_pupil_magnification[0],
        m.entrance_pupil_magnification[1],
        m.exit_pupil_z_mm,
        m.exit_pupil_diameter_mm,
        m.pupil_retina_mm,
        m.image_numerical_aperture
    );
    Ok(s)
}
