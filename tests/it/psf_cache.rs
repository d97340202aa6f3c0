//! Kernel grid files and the cache: round trip, and every kind of damage is detected, reported
//! and recomputed, never loaded.

use crate::common::temp_dir;
use ocular::eye::Eye;
use ocular::psf::{
    cache_path, cached, compute_grid, grid_key, no_progress, read_grid, write_grid, CacheOutcome,
    DioptreAxis, GridAxes, GridReport, KernelGrid, KernelSettings, Screen,
};
use std::cell::Cell;

fn inputs() -> (Eye, GridAxes, Screen, KernelSettings) {
    (
        Eye::navarro(),
        GridAxes {
            objects: DioptreAxis::spanning(0.0, 2.0, 3),
            focus_d: vec![0.5, 1.0],
            pupils_mm: vec![3.0],
            wavelengths_nm: [612.0, 549.0, 464.0],
        },
        Screen {
            fov_y_deg: 20.0,
            height_px: 120,
        },
        KernelSettings::default(),
    )
}

fn compute() -> (KernelGrid, GridReport) {
    let (eye, axes, screen, settings) = inputs();
    compute_grid(&eye, &axes, &screen, &settings, &no_progress).unwrap()
}

#[test]
fn grid_files_round_trip_and_damage_is_detected() {
    let dir = temp_dir("file");
    let (grid, _) = compute();
    let path = dir.join("grid.bin");
    write_grid(&path, &grid, "k1").unwrap();
    assert_eq!(read_grid(&path, Some("k1")).unwrap(), grid);
    assert_eq!(read_grid(&path, None).unwrap(), grid);
    // no temporary file is left behind
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
    // another key
    let e = read_grid(&path, Some("k2")).unwrap_err();
    assert!(e.contains("key"), "{e}");
    let bytes = std::fs::read(&path).unwrap();
    // one flipped byte anywhere in the payload, in the header, or in the checksum
    for at in [bytes.len() / 2, bytes.len() - 40, 20, bytes.len() - 1] {
        let mut bad = bytes.clone();
        bad[at] ^= 0x10;
        std::fs::write(&path, &bad).unwrap();
        assert!(read_grid(&path, Some("k1")).is_err(), "flip at {at} loaded");
    }
    // truncated, padded, empty, wrong magic, newer version
    for bad in [
        bytes[..bytes.len() - 9].to_vec(),
        [bytes.clone(), vec![0]].concat(),
        Vec::new(),
        [b"NOTGRID\0".to_vec(), bytes[8..].to_vec()].concat(),
        [
            bytes[..8].to_vec(),
            99u32.to_le_bytes().to_vec(),
            bytes[12..].to_vec(),
        ]
        .concat(),
    ] {
        std::fs::write(&path, &bad).unwrap();
        let e = read_grid(&path, Some("k1")).unwrap_err();
        assert!(!e.is_empty());
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_cache_hits_and_recomputes_a_corrupted_file() {
    let dir = temp_dir("cache");
    let (eye, axes, screen, settings) = inputs();
    let key = grid_key(&eye, &axes, &screen, &settings);
    let runs = Cell::new(0);
    let run = || {
        runs.set(runs.get() + 1);
        Ok(compute())
    };
    let (first, report, outcome) = cached(Some(&dir), &key, run).unwrap();
    assert!(report.is_some());
    assert!(matches!(
        outcome,
        CacheOutcome::Stored { warning: None, .. }
    ));
    let (second, report, outcome) = cached(Some(&dir), &key, run).unwrap();
    assert!(report.is_none() && matches!(outcome, CacheOutcome::Hit(_)));
    assert_eq!(first, second);
    assert_eq!(runs.get(), 1);

    // a corrupted byte: warned about and recomputed, then good again
    let path = cache_path(&dir, &key);
    let mut bytes = std::fs::read(&path).unwrap();
    let at = bytes.len() * 2 / 3;
    bytes[at] = bytes[at].wrapping_add(1);
    std::fs::write(&path, &bytes).unwrap();
    let (third, _, outcome) = cached(Some(&dir), &key, run).unwrap();
    assert_eq!(runs.get(), 2);
    match outcome {
        CacheOutcome::Stored {
            warning: Some(w), ..
        } => assert!(w.contains("checksum"), "{w}"),
        other => panic!("expected a recompute with a warning, got {other:?}"),
    }
    assert_eq!(third, first);
    let (_, _, outcome) = cached(Some(&dir), &key, run).unwrap();
    assert!(matches!(outcome, CacheOutcome::Hit(_)));

    // every input is in the key
    let mut other = settings.clone();
    other.energy = 0.99;
    assert_ne!(grid_key(&eye, &axes, &screen, &other), key);
    let mut eye2 = eye.clone();
    eye2.axial_length_mm += 0.01;
    assert_ne!(grid_key(&eye2, &axes, &screen, &settings), key);
    let screen2 = Screen {
        height_px: 121,
        ..screen
    };
    assert_ne!(grid_key(&eye, &axes, &screen2, &settings), key);
    let _ = std::fs::remove_dir_all(&dir);
}
