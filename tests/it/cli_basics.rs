//! The binary end to end: version, device listing, and a clear exit-2 error for a bad device.

use crate::common::{json_ok, ocular};

#[test]
fn version_prints_the_crate_version() {
    let out = ocular().arg("--version").output().unwrap();
    assert!(out.status.success());
    assert_eq!(
        String::from_utf8_lossy(&out.stdout).trim(),
        format!("ocular {}", env!("CARGO_PKG_VERSION"))
    );
}

#[test]
fn devices_lists_and_marks_the_selected_device() {
    let out = ocular()
        .args(["devices", "--json"])
        .env_remove("OCULAR_DEVICE")
        .output()
        .unwrap();
    let report = json_ok(&out);
    let devices = report["devices"].as_array().unwrap();
    assert!(!devices.is_empty());
    let selected = report["selected"].as_u64().unwrap() as usize;
    assert!(selected < devices.len());
    assert!(devices[selected]["name"]
        .as_str()
        .is_some_and(|n| !n.is_empty()));

    let table = ocular()
        .arg("devices")
        .env_remove("OCULAR_DEVICE")
        .output()
        .unwrap();
    assert!(table.status.success());
    assert!(String::from_utf8_lossy(&table.stdout)
        .lines()
        .any(|l| l.starts_with('*')));
}

#[test]
fn nonexistent_device_fails_with_exit_code_2_and_one_line() {
    for args in [
        &["--device", "nonexistent", "devices"][..],
        &["devices", "--device", "nonexistent"][..],
    ] {
        let out = ocular().args(args).output().unwrap();
        assert_eq!(out.status.code(), Some(2));
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
        assert!(
            stderr.starts_with("error:") && stderr.contains("nonexistent"),
            "{stderr}"
        );
    }
    let out = ocular()
        .arg("devices")
        .env("OCULAR_DEVICE", "nonexistent")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
}

/// `--age` outside the pupil formula's range (or not a number) is refused at the boundary.
#[test]
fn age_outside_the_pupil_formula_is_refused() {
    for bad in ["-5", "0", "300", "inf", "nan", "abc"] {
        let out = ocular()
            .args(["render", "--age", bad, "-o", "/nonexistent/x.png"])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "--age {bad}: {err}");
        assert!(err.contains("--age"), "--age {bad}: {err}");
    }
}
