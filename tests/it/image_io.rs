//! EXR and PNG reading and writing: round trips, channel choice, and atomic writes.

use crate::common::temp_dir;
use std::path::Path;

use ocular::image_io::{
    read_exr_depth, read_exr_depth_channel, read_exr_rgba, write_exr_depth, write_exr_gray,
    write_exr_rgba, write_png, ImageGray, ImageRgba, Tonemap, TonemapMode,
};
use ocular::Error;

fn test_rgba(width: u32, height: u32) -> ImageRgba {
    let pixels = (0..width * height)
        .map(|i| {
            let x = i as f32;
            [
                x * 0.37,
                (x * 0.01).sin() * 1e4,
                1.0 / (1.0 + x),
                0.25 + (i % 3) as f32,
            ]
        })
        .collect();
    ImageRgba::new(width, height, pixels)
}

fn leftovers(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains(".tmp-"))
        .collect()
}

#[test]
fn exr_round_trips_exactly() {
    let dir = temp_dir("roundtrip");
    let image = test_rgba(37, 23);
    let path = dir.join("colour.exr");
    write_exr_rgba(&path, &image).unwrap();
    assert_eq!(read_exr_rgba(&path).unwrap(), image);

    let depth = ImageGray::new(
        37,
        23,
        (0..37 * 23).map(|i| 0.2 + i as f32 * 0.031).collect(),
    );
    let depth_path = dir.join("depth.exr");
    write_exr_depth(&depth_path, &depth).unwrap();
    let (back, channel, _) = read_exr_depth_channel(&depth_path).unwrap();
    assert_eq!(back, depth);
    assert_eq!(channel, "Z");
    // The only channel is taken whatever its name.
    let other = dir.join("other.exr");
    write_exr_gray(&other, &depth, "distance").unwrap();
    assert_eq!(read_exr_depth(&other).unwrap(), depth);
    assert!(leftovers(&dir).is_empty());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn rgb_exr_reads_with_alpha_one_and_depth_prefers_z() {
    use exr::prelude::*;
    let dir = temp_dir("channels");
    let rgb = dir.join("rgb.exr");
    Image::from_channels(
        (4, 3),
        SpecificChannels::rgb(|p: Vec2<usize>| (p.x() as f32, p.y() as f32, 0.5f32)),
    )
    .write()
    .to_file(&rgb)
    .unwrap();
    let image = read_exr_rgba(&rgb).unwrap();
    assert_eq!((image.width, image.height), (4, 3));
    assert_eq!(image.pixels[4 + 2], [2.0, 1.0, 0.5, 1.0]);
    assert!(image.pixels.iter().all(|p| p[3] == 1.0));

    // R, G, B and Z: Z is the depth, and R is no candidate (it is colour).
    let mixed = dir.join("mixed.exr");
    Image::from_channels(
        (4, 3),
        SpecificChannels::build()
            .with_channel("R")
            .with_channel("G")
            .with_channel("B")
            .with_channel("Z")
            .with_pixel_fn(|p: Vec2<usize>| (1.0f32, 2.0f32, 3.0f32, 10.0 + p.x() as f32)),
    )
    .write()
    .to_file(&mixed)
    .unwrap();
    let (depth, channel, candidates) = read_exr_depth_channel(&mixed).unwrap();
    assert_eq!(channel, "Z");
    assert_eq!(candidates, vec!["Z".to_string()]);
    assert_eq!(depth.pixels[1], 11.0);

    // Two channels, neither a depth name: an error that lists them.
    let odd = dir.join("odd.exr");
    Image::from_channels(
        (2, 2),
        SpecificChannels::build()
            .with_channel("foo")
            .with_channel("bar")
            .with_pixel_fn(|_p: Vec2<usize>| (1.0f32, 2.0f32)),
    )
    .write()
    .to_file(&odd)
    .unwrap();
    let err = read_exr_depth(&odd).unwrap_err();
    assert_eq!(err.exit_code(), 2);
    let text = err.to_string();
    assert!(
        text.contains("foo") && text.contains("bar") && text.contains("Z"),
        "{text}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn reading_missing_or_corrupt_files_is_a_file_error() {
    let dir = temp_dir("corrupt");
    let missing = dir.join("missing.exr");
    match read_exr_rgba(&missing).unwrap_err() {
        Error::File { path, message } => {
            assert!(
                path.ends_with("missing.exr") && message.contains("no such file"),
                "{message}"
            )
        }
        other => panic!("{other}"),
    }
    let corrupt = dir.join("corrupt.exr");
    std::fs::write(&corrupt, b"not an exr at all").unwrap();
    let err = read_exr_depth(&corrupt).unwrap_err();
    assert_eq!(err.exit_code(), 2);
    assert!(err.to_string().contains("corrupt.exr"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn failed_writes_leave_no_temporary_or_partial_file() {
    let dir = temp_dir("atomic");
    let image = test_rgba(8, 4);
    // The destination is a non-empty folder: the temporary file is written, the rename fails.
    let blocked = dir.join("blocked.exr");
    std::fs::create_dir(&blocked).unwrap();
    std::fs::write(blocked.join("keep"), b"x").unwrap();
    let err = write_exr_rgba(&blocked, &image).unwrap_err();
    assert_eq!(err.exit_code(), 2);
    assert!(err.to_string().contains("blocked.exr"), "{err}");
    let err = write_png(dir.join("blocked.exr"), &image, Tonemap::default()).unwrap_err();
    assert!(err.to_string().contains("rename"), "{err}");
    assert!(leftovers(&dir).is_empty(), "{:?}", leftovers(&dir));
    assert!(blocked.join("keep").exists());

    // An image whose size does not match its pixels is refused before anything is written.
    let bad = ImageRgba {
        width: 5,
        height: 5,
        pixels: vec![[0.0; 4]; 3],
    };
    let target = dir.join("bad.png");
    assert!(write_png(&target, &bad, Tonemap::default()).is_err());
    assert!(!target.exists());
    // A folder that does not exist.
    let err = write_exr_rgba(dir.join("no/such/folder/x.exr"), &image).unwrap_err();
    assert!(err.to_string().contains("x.exr"), "{err}");

    // Overwriting an existing file replaces it whole.
    let path = dir.join("over.exr");
    std::fs::write(&path, b"old").unwrap();
    write_exr_rgba(&path, &image).unwrap();
    assert_eq!(read_exr_rgba(&path).unwrap(), image);
    assert!(leftovers(&dir).is_empty());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn png_preview_encodes_srgb() {
    let dir = temp_dir("png");
    let image = ImageRgba::new(
        3,
        1,
        vec![
            [0.0, 0.0, 0.0, 1.0],
            [0.215_861, 0.215_861, 0.215_861, 1.0],
            [5.0, 1.0, 0.0, 1.0],
        ],
    );
    let path = dir.join("p.png");
    write_png(
        &path,
        &image,
        Tonemap {
            exposure_ev: 0.0,
            mode: TonemapMode::Clamp,
        },
    )
    .unwrap();
    let decoded = image::open(&path).unwrap().to_rgb8();
    assert_eq!(decoded.dimensions(), (3, 1));
    assert_eq!(decoded.get_pixel(0, 0).0, [0, 0, 0]);
    // Linear 0.2159 is sRGB 128/255.
    assert_eq!(decoded.get_pixel(1, 0).0, [128, 128, 128]);
    assert_eq!(decoded.get_pixel(2, 0).0, [255, 255, 0]);
    // One stop down halves linear values.
    let brighter = ImageRgba::new(1, 1, vec![[0.431_722, 0.431_722, 0.431_722, 1.0]]);
    write_png(
        &path,
        &brighter,
        Tonemap {
            exposure_ev: -1.0,
            mode: TonemapMode::Clamp,
        },
    )
    .unwrap();
    assert_eq!(
        image::open(&path).unwrap().to_rgb8().get_pixel(0, 0).0,
        [128, 128, 128]
    );
    // Reinhard maps luminance L to L / (1 + L): a grey of 5 becomes 5/6, below white.
    let bright = ImageRgba::new(1, 1, vec![[5.0, 5.0, 5.0, 1.0]]);
    write_png(
        &path,
        &bright,
        Tonemap {
            exposure_ev: 0.0,
            mode: TonemapMode::Reinhard,
        },
    )
    .unwrap();
    let r = image::open(&path).unwrap().to_rgb8().get_pixel(0, 0).0;
    assert_eq!(r, [235, 235, 235]);
    std::fs::remove_dir_all(&dir).unwrap();
}
