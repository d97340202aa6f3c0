//! Zernike set files (TOML, CSV, ABP) and the built-in presets.

use crate::common::temp_dir;
use ocular::aberrations::*;
use ocular::optics::zernike::Prescription;

#[test]
fn presets_load_and_match_the_seed_paper() {
    assert_eq!(
        preset_names(),
        vec!["healthy", "myopia", "myopia3", "astigmatism", "keratoconus"]
    );
    for name in preset_names() {
        let p = preset(name).unwrap();
        assert!(p.pupil_diameter_mm > 0.0);
    }
    let m = preset("myopia").unwrap();
    assert_eq!(m.coefficients, vec![(2, 0, 5.4127)]);
    assert_eq!((m.pupil_diameter_mm, m.wavelength_nm), (5.0, 587.56));
    // the preset is the −6 D sphere of the prescription formula
    let rx = Prescription::from_zernike(0.0, 5.4127, 0.0, 5.0);
    assert!((rx.sphere_d + 6.0).abs() < 1e-4);
    let k = preset("Keratoconus").unwrap();
    assert_eq!(k.coefficients.len(), 27);
    assert_eq!(k.wavelength_nm, 470.0);
    assert_eq!(k.max_order(), 6);
    let a = preset("astigmatism").unwrap();
    let v = a.osa_vector(2);
    let rx = Prescription::from_osa_coefficients(&v, 5.0).unwrap();
    assert!((rx.sphere_d + 6.0).abs() < 0.02 && (rx.cylinder_d + 3.0).abs() < 0.02);
    assert!((rx.axis_deg - 102.0).abs() < 0.5, "{rx:?}");
    let e = preset("myopic").unwrap_err().to_string();
    assert!(e.contains("available") && e.contains("keratoconus"), "{e}");
}

#[test]
fn toml_round_trip_and_errors() {
    let k = preset("keratoconus").unwrap();
    let text = k.to_toml_string();
    let back = ZernikeSet::from_toml_str(&text, "x.toml").unwrap();
    assert_eq!(back, k);
    let bad = "pupil_diameter_mm = 5.0\nwavelength_nm = 550\n\n[[term]]\nn = 3\nm = 2\num = 0.1\n";
    let e = ZernikeSet::from_toml_str(bad, "eye.toml")
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("eye.toml:4:") && e.contains("(3, 2)"), "{e}");
    let bad = "pupil_diameter_mm = 5.0\nwavelength_nm = 550\npupil = 3\n";
    let e = ZernikeSet::from_toml_str(bad, "eye.toml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("eye.toml:3") && e.contains("pupil"), "{e}");
    let bad = "pupil_diameter_mm = -5.0\nwavelength_nm = 550\n";
    let e = ZernikeSet::from_toml_str(bad, "eye.toml")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("pupil diameter") && e.contains("1 to 9 mm"),
        "{e}"
    );
    let bad = "pupil_diameter_mm = 5.0\nwavelength_nm = 1550\n";
    assert!(ZernikeSet::from_toml_str(bad, "e")
        .unwrap_err()
        .to_string()
        .contains("380 to 1000 nm"));
    let bad = "pupil_diameter_mm = 5.0\nwavelength_nm = 550\n[[term]]\nn = 2\nm = 0\num = nan\n";
    assert!(ZernikeSet::from_toml_str(bad, "e")
        .unwrap_err()
        .to_string()
        .contains("finite"));
    assert!(ZernikeSet::from_toml_str("not toml [", "e").is_err());
}

#[test]
fn csv_format() {
    let text = "# pupil_diameter_mm = 6\n# wavelength_nm = 555\nj,coefficient_um\n4, 0.5\n12,-0.1\n\n7,0.02\n";
    let s = ZernikeSet::from_csv_str(text, "w.csv", None, None).unwrap();
    assert_eq!(s.pupil_diameter_mm, 6.0);
    assert_eq!(s.wavelength_nm, 555.0);
    assert_eq!(
        s.coefficients,
        vec![(2, 0, 0.5), (4, 0, -0.1), (3, -1, 0.02)]
    );
    let s = ZernikeSet::from_csv_str("4,1\n", "w.csv", Some(4.0), Some(600.0)).unwrap();
    assert_eq!((s.pupil_diameter_mm, s.wavelength_nm), (4.0, 600.0));
    let e = ZernikeSet::from_csv_str("4,1\n", "w.csv", None, Some(600.0))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("w.csv") && e.contains("pupil_diameter_mm"),
        "{e}"
    );
    let e = ZernikeSet::from_csv_str("4,1\n5;2\n", "w.csv", Some(5.0), Some(600.0))
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("w.csv:2:"), "{e}");
    let e = ZernikeSet::from_csv_str("-1,2\n", "w.csv", Some(5.0), Some(600.0))
        .unwrap_err()
        .to_string();
    assert!(e.contains("w.csv:1") && e.contains("non-negative"), "{e}");
    let e = ZernikeSet::from_csv_str("4,abc\n", "w.csv", Some(5.0), Some(600.0))
        .unwrap_err()
        .to_string();
    assert!(e.contains("not a number"), "{e}");
    let e = ZernikeSet::from_csv_str("4,inf\n", "w.csv", Some(5.0), Some(600.0))
        .unwrap_err()
        .to_string();
    assert!(e.contains("finite"), "{e}");
}

/// The README documents `# pupil_mm = …`; `# pupil_diameter_mm = …` stays an alias, and the
/// two must not disagree.
#[test]
fn csv_pupil_header_spellings() {
    let body = "# wavelength_nm = 555\n4, 0.5\n";
    for key in ["pupil_mm", "PUPIL_MM", "pupil_diameter_mm"] {
        let text = format!("# {key} = 6.5\n{body}");
        let s = ZernikeSet::from_csv_str(&text, "w.csv", None, None).unwrap();
        assert_eq!(s.pupil_diameter_mm, 6.5, "{key}");
    }
    let same = format!("# pupil_mm = 6\n# pupil_diameter_mm = 6\n{body}");
    assert!(ZernikeSet::from_csv_str(&same, "w.csv", None, None).is_ok());
    let e = ZernikeSet::from_csv_str(
        &format!("# pupil_mm = 6\n# pupil_diameter_mm = 5\n{body}"),
        "w.csv",
        None,
        None,
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.starts_with("w.csv:2:") && e.contains("contradicts"),
        "{e}"
    );
    let e = ZernikeSet::from_csv_str("# pupil_mm = wide\n4,1\n", "w.csv", None, Some(555.0))
        .unwrap_err()
        .to_string();
    assert!(e.contains("pupil_mm needs a number"), "{e}");
}

#[test]
fn abp_format() {
    // the seed paper's framework format, including a file without a trailing newline
    let text = "Ap = 5.0\nWa = 470.0\nZ[1, -1] = -1.9320\nZ[3,  1] =  0.1320\nZ[6,  6] =  0.0002";
    let s = ZernikeSet::from_abp_str(text, "k.abp").unwrap();
    assert_eq!(s.pupil_diameter_mm, 5.0);
    assert_eq!(
        s.coefficients,
        vec![(1, -1, -1.932), (3, 1, 0.132), (6, 6, 0.0002)]
    );
    let e = ZernikeSet::from_abp_str("Ap = 5\nWa = 500\nZ[2, 1] = 3\n", "k.abp")
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("k.abp:3:") && e.contains("(2, 1)"), "{e}");
    let e = ZernikeSet::from_abp_str("Ap = 5\nZ[2, 0] = 3\n", "k.abp")
        .unwrap_err()
        .to_string();
    assert!(e.contains("Wa"), "{e}");
    let e = ZernikeSet::from_abp_str("Ap = 5\nWa = 500\nQ = 1\n", "k.abp")
        .unwrap_err()
        .to_string();
    assert!(e.contains("k.abp:3") && e.contains("unknown key"), "{e}");
    let e = ZernikeSet::from_abp_str("Ap = 0\nWa = 500\n", "k.abp")
        .unwrap_err()
        .to_string();
    assert!(e.contains("pupil"), "{e}");
}

#[test]
fn inline_comments_and_blank_lines_are_ignored() {
    // As in two of the seed framework's presets: comments after values, blank lines, a BOM.
    let text = "\u{feff}# keratoconus, estimated\nAp = 5.0   # mm\n\n  Wa = 470.0 % nm\n\
                Z[1, -1] = -1.150  # estimated\nZ[3, 1] = 0.25 // coma\n";
    let s = ZernikeSet::from_abp_str(text, "k.abp").unwrap();
    assert_eq!(s.wavelength_nm, 470.0);
    assert_eq!(s.coefficients, vec![(1, -1, -1.15), (3, 1, 0.25)]);
    // A bad value is still refused with file:line and what is allowed.
    let e = ZernikeSet::from_abp_str("Ap = 5\nWa = 500\n\nZ[2, 0] = 1.0x # typo\n", "k.abp")
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("k.abp:4:") && e.contains("\"1.0x\"") && e.contains("number"),
        "{e}"
    );
    // CSV: inline comments after data and header values.
    let csv = "# pupil_diameter_mm = 6.0  # measured\n4, 0.5  # defocus\n\n12,0.1\n";
    let s = ZernikeSet::from_csv_str(csv, "w.csv", None, Some(555.0)).unwrap();
    assert_eq!(s.pupil_diameter_mm, 6.0);
    assert_eq!(s.coefficients, vec![(2, 0, 0.5), (4, 0, 0.1)]);
    let e = ZernikeSet::from_csv_str("4, 0.5\n5 # no value\n", "w.csv", Some(5.0), Some(600.0))
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("w.csv:2:") && e.contains("j,coefficient_um"),
        "{e}"
    );
}

#[test]
fn load_from_files_by_extension() {
    let dir = temp_dir("files");
    let p = dir.join("eye.abp");
    std::fs::write(&p, "Ap = 5\nWa = 587.56\nZ[2,  0] =  5.4127").unwrap();
    let s = ZernikeSet::load(&p, None, None).unwrap();
    assert_eq!(s, preset("myopia").unwrap());
    let p = dir.join("eye.toml");
    std::fs::write(&p, preset("astigmatism").unwrap().to_toml_string()).unwrap();
    assert_eq!(
        ZernikeSet::load(&p, None, None).unwrap(),
        preset("astigmatism").unwrap()
    );
    let p = dir.join("eye.csv");
    std::fs::write(&p, "4,5.4127\n").unwrap();
    let s = ZernikeSet::load(&p, Some(5.0), Some(587.56)).unwrap();
    assert_eq!(s, preset("myopia").unwrap());
    let e = ZernikeSet::load(&dir.join("missing.toml"), None, None)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("missing.toml") && e.contains("cannot read"),
        "{e}"
    );
    let p = dir.join("eye.txt");
    std::fs::write(&p, "x").unwrap();
    assert!(ZernikeSet::load(&p, None, None)
        .unwrap_err()
        .to_string()
        .contains(".abp"));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn rescaled_pupil() {
    let m = preset("myopia").unwrap().with_pupil(3.0).unwrap();
    // pure defocus scales with the square of the pupil ratio
    let c20 = m
        .coefficients
        .iter()
        .find(|c| (c.0, c.1) == (2, 0))
        .unwrap()
        .2;
    assert!((c20 - 5.4127 * 0.36).abs() < 1e-12);
    assert_eq!(m.pupil_diameter_mm, 3.0);
}
