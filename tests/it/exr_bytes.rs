//! EXR output is byte-deterministic: identical pixels give identical files (issue 20, defect 6),
//! which checksums, caches and split verification depend on.

use crate::common::{temp_dir, xorshift};
use ocular::image_io::{write_exr_depth, write_exr_rgba, ImageGray, ImageRgba};

/// Noise that RLE cannot shrink, so every tile costs a different compression time and a
/// writer that emits blocks as they finish would vary its order.
fn noisy(width: u32, height: u32) -> ImageRgba {
    let mut bits = xorshift(0x2545_f491_4f6c_dd1d);
    let mut next = move || (bits() >> 40) as f32 / (1u64 << 24) as f32;
    let pixels = (0..width * height)
        .map(|i| {
            // Flat runs in some rows make tiles unequal in cost.
            if (i / width).is_multiple_of(7) {
                [1.0, 1.0, 1.0, 1.0]
            } else {
                [next() * 1e3, next(), next() * 1e-3, 1.0]
            }
        })
        .collect();
    ImageRgba::new(width, height, pixels)
}

#[test]
fn identical_pixels_give_identical_exr_bytes() {
    let dir = temp_dir("rgba");
    let image = noisy(640, 480);
    let first = dir.join("a.exr");
    write_exr_rgba(&first, &image).unwrap();
    let reference = std::fs::read(&first).unwrap();
    for k in 0..12 {
        let path = dir.join(format!("b{k}.exr"));
        write_exr_rgba(&path, &image).unwrap();
        assert!(
            std::fs::read(&path).unwrap() == reference,
            "write {k} of identical pixels gave different bytes"
        );
    }
    // The bytes still decode to the same pixels.
    let back = ocular::image_io::read_exr_rgba(&first).unwrap();
    assert_eq!(back.pixels, image.pixels);

    let depth = ImageGray::new(640, 480, image.pixels.iter().map(|p| p[0] + 0.5).collect());
    let d0 = dir.join("d0.exr");
    write_exr_depth(&d0, &depth).unwrap();
    let reference = std::fs::read(&d0).unwrap();
    for k in 0..12 {
        let path = dir.join(format!("d{}.exr", k + 1));
        write_exr_depth(&path, &depth).unwrap();
        assert!(
            std::fs::read(&path).unwrap() == reference,
            "depth write {k} gave different bytes"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
