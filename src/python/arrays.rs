//! NumPy arrays in and out: dtype and shape checks with one-line messages naming the
//! argument, and the copies into the library's pixel layouts (row 0 at the top).

use numpy::ndarray::{Array2, Array3, ArrayViewD};
use numpy::{
    IntoPyArray, PyArray2, PyArray3, PyArrayDescrMethods, PyArrayDyn, PyArrayMethods,
    PyUntypedArray, PyUntypedArrayMethods,
};
use pyo3::prelude::*;

use super::{type_error, value_error};

/// A float32 array argument, copied out of Python (any strides, any memory order).
pub(crate) struct F32Array {
    pub shape: Vec<usize>,
    /// C order.
    pub values: Vec<f32>,
}

/// `obj` as float32 values, or the error naming `name`: TypeError for a non-array,
/// ValueError for another dtype (no silent conversion: a float64 image is usually a
/// mistake upstream, and the caller can convert with `.astype(numpy.float32)`).
pub(crate) fn f32_array(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<F32Array> {
    let untyped = obj.downcast::<PyUntypedArray>().map_err(|_| {
        let kind = obj
            .get_type()
            .name()
            .map(|n| n.to_string())
            .unwrap_or_else(|_| "?".into());
        type_error(format!(
            "{name}: expected a numpy.ndarray of float32, got {kind}"
        ))
    })?;
    let dtype = untyped.dtype();
    if !dtype.is_equiv_to(&numpy::dtype::<f32>(obj.py())) {
        return Err(value_error(format!(
            "{name}: dtype {dtype} where float32 is required; convert with \
             {name}.astype(numpy.float32)"
        )));
    }
    let typed = obj
        .downcast::<PyArrayDyn<f32>>()
        .map_err(|e| type_error(format!("{name}: {e}")))?;
    let readonly = typed.try_readonly().map_err(|e| {
        value_error(format!(
            "{name}: cannot read the array while it is being written: {e}"
        ))
    })?;
    let view: ArrayViewD<'_, f32> = readonly.as_array();
    Ok(F32Array {
        shape: view.shape().to_vec(),
        values: view.iter().copied().collect(),
    })
}

fn shape_text(shape: &[usize]) -> String {
    let parts: Vec<String> = shape.iter().map(|s| s.to_string()).collect();
    format!("({})", parts.join(", "))
}

/// One or more colour layers: (H, W, 3), or (L, H, W, 3) for L layers nearest first.
pub(crate) struct ColorLayers {
    pub width: u32,
    pub height: u32,
    pub layers: Vec<Vec<[f32; 4]>>,
}

pub(crate) fn color_layers(obj: &Bound<'_, PyAny>) -> PyResult<ColorLayers> {
    let a = f32_array(obj, "color")?;
    let (count, h, w) = match a.shape.as_slice() {
        [h, w, 3] => (1, *h, *w),
        [l, h, w, 3] => (*l, *h, *w),
        other => {
            return Err(value_error(format!(
                "color: shape {} where (H, W, 3) linear RGB is required (or (L, H, W, 3) for L \
                 depth layers)",
                shape_text(other)
            )))
        }
    };
    check_size("color", count, h, w)?;
    let per = h * w;
    let mut layers = Vec::with_capacity(count);
    for k in 0..count {
        let layer: Vec<[f32; 4]> = (0..per)
            .map(|i| {
                let at = 3 * (k * per + i);
                [a.values[at], a.values[at + 1], a.values[at + 2], 1.0]
            })
            .collect();
        if let Some(i) = layer.iter().position(|p| p.iter().any(|v| !v.is_finite())) {
            let bad = layer
                .iter()
                .filter(|p| p.iter().any(|v| !v.is_finite()))
                .count();
            let of = if count > 1 {
                format!(" of layer {k}")
            } else {
                String::new()
            };
            return Err(value_error(format!(
                "color: {bad} pixel(s){of} have non-finite colour (NaN or infinity), first at \
                 ({}, {}); replace them (e.g. numpy.nan_to_num) before rendering",
                i % w,
                i / w
            )));
        }
        layers.push(layer);
    }
    Ok(ColorLayers {
        width: w as u32,
        height: h as u32,
        layers,
    })
}

/// Depth in metres along the view axis: (H, W), or (L, H, W) for layers. The CLI's depth
/// policy applies (0 and +inf are the background, nearer than about 2 cm is clamped), except
/// that NaN, negative and −inf depths are refused: an array has no file to blame, and a NaN
/// there is almost always a bug upstream.
pub(crate) fn depth_layers(
    obj: &Bound<'_, PyAny>,
    (width, height, count): (u32, u32, usize),
) -> PyResult<(Vec<Vec<f32>>, Vec<String>)> {
    let a = f32_array(obj, "depth")?;
    let (w, h) = (width as usize, height as usize);
    let layers = match a.shape.as_slice() {
        [dh, dw] if (*dh, *dw) == (h, w) && count == 1 => 1,
        [l, dh, dw] if (*dh, *dw) == (h, w) && *l == count => count,
        other => {
            let want = if count == 1 {
                format!("({h}, {w})")
            } else {
                format!("({count}, {h}, {w})")
            };
            return Err(value_error(format!(
                "depth: shape {} where {want} is required to match color (metres along the view \
                 axis)",
                shape_text(other)
            )));
        }
    };
    let per = w * h;
    let mut out = Vec::with_capacity(layers);
    let mut warnings = Vec::new();
    for k in 0..layers {
        let raw = &a.values[k * per..(k + 1) * per];
        let (depth_m, report) = crate::inputs::depth::apply(raw, width, false, 1.0);
        if report.invalid_px > 0 {
            let (x, y) = report.first_invalid.unwrap_or_default();
            let of = if layers > 1 {
                format!(" of layer {k}")
            } else {
                String::new()
            };
            return Err(value_error(format!(
                "depth: {} pixel(s){of} have invalid depth (NaN, negative or -inf), first at \
                 ({x}, {y}); give +inf (or 0) for the background",
                report.invalid_px
            )));
        }
        // As for a layered EXR, the visible layer's findings are reported (a hidden layer is
        // often one surface at one depth).
        if k == 0 {
            warnings.extend(report.warnings().into_iter().map(|w| format!("depth: {w}")));
        }
        out.push(depth_m);
    }
    Ok((out, warnings))
}

fn check_size(name: &str, count: usize, h: usize, w: usize) -> PyResult<()> {
    let most_layers = crate::inputs::layered::MAX_LAYERS;
    if h == 0 || w == 0 || h > 16384 || w > 16384 {
        return Err(value_error(format!(
            "{name}: {w}×{h} pixels; each side must be 1 to 16384"
        )));
    }
    if count == 0 || count > most_layers {
        return Err(value_error(format!(
            "{name}: {count} layers; need 1 to {most_layers}"
        )));
    }
    Ok(())
}

/// RGBA pixels → an (H, W, 3) float32 array.
pub(crate) fn rgb_out<'py>(
    py: Python<'py>,
    width: u32,
    height: u32,
    pixels: &[[f32; 4]],
) -> Bound<'py, PyArray3<f32>> {
    let flat: Vec<f32> = pixels.iter().flat_map(|p| [p[0], p[1], p[2]]).collect();
    Array3::from_shape_vec((height as usize, width as usize, 3), flat)
        .expect("pixel count matches the frame")
        .into_pyarray(py)
}

/// Row-major values → an (H, W) array.
pub(crate) fn gray_out<'py, T: numpy::Element>(
    py: Python<'py>,
    width: usize,
    height: usize,
    values: Vec<T>,
) -> Bound<'py, PyArray2<T>> {
    Array2::from_shape_vec((height, width), values)
        .expect("value count matches the image")
        .into_pyarray(py)
}
