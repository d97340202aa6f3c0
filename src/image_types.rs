//! The in-memory images every module passes around, on their own so that the EXR reading in
//! `inputs::exr` and the writing in `image_io` can both use them without importing each other.
//! `image_io` re-exports them; that is their public path.

/// Linear RGBA, row-major, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct ImageRgba {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<[f32; 4]>,
}

/// One channel (depth in metres, luminance, …), row-major, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct ImageGray {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<f32>,
}

impl ImageRgba {
    pub fn new(width: u32, height: u32, pixels: Vec<[f32; 4]>) -> ImageRgba {
        assert_eq!(pixels.len(), width as usize * height as usize);
        ImageRgba {
            width,
            height,
            pixels,
        }
    }
}

impl ImageGray {
    pub fn new(width: u32, height: u32, pixels: Vec<f32>) -> ImageGray {
        assert_eq!(pixels.len(), width as usize * height as usize);
        ImageGray {
            width,
            height,
            pixels,
        }
    }
}
