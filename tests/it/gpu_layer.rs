//! The GPU layer on a real Vulkan implementation (lavapipe in CI): buffers, images, the
//! pipeline builder, timings, error reporting and validation capture.

use crate::common;

use half::f16;
use ocular::gpu::texture_probe::TextureProbe;
use ocular::gpu::{
    vk, Binding, BindingKind, Buffer, ComputePipeline, Context, ContextOptions, Edge, GpuError,
    Image, ImageUsage, Residency, Sampler, TexelFormat,
};

/// Smooth test signal with a different phase per channel; slopes stay small so that GPUs with
/// 8-bit filter weights (1/256 texel) still land well inside 1e-3 of the exact blend.
fn signal(x: u32, y: u32, z: u32, c: u32) -> f32 {
    let (x, y, z, c) = (x as f32, y as f32, z as f32, c as f32);
    0.5 + 0.45 * (0.11 * x + 0.07 * y + 0.013 * z + 1.3 * c).sin() * (0.05 * y - 0.4 * c).cos()
}

/// Exact trilinear filtering with a zero border, written independently of any GPU: texel
/// centres at integer + 0.5, texels outside the volume read as 0.
fn trilinear(texels: &[[f32; 4]], [w, h, d]: [u32; 3], p: [f32; 3]) -> [f32; 4] {
    let fetch = |x: i64, y: i64, z: i64| -> [f32; 4] {
        if x < 0 || y < 0 || z < 0 || x >= w as i64 || y >= h as i64 || z >= d as i64 {
            [0.0; 4]
        } else {
            texels[((z * h as i64 + y) * w as i64 + x) as usize]
        }
    };
    let u = [p[0] as f64 - 0.5, p[1] as f64 - 0.5, p[2] as f64 - 0.5];
    let base = u.map(|v| v.floor());
    let t = [u[0] - base[0], u[1] - base[1], u[2] - base[2]];
    let mut out = [0.0f64; 4];
    for corner in 0..8 {
        let (dx, dy, dz) = (corner & 1, (corner >> 1) & 1, (corner >> 2) & 1);
        let weight = (if dx == 1 { t[0] } else { 1.0 - t[0] })
            * (if dy == 1 { t[1] } else { 1.0 - t[1] })
            * (if dz == 1 { t[2] } else { 1.0 - t[2] });
        let v = fetch(
            base[0] as i64 + dx,
            base[1] as i64 + dy,
            base[2] as i64 + dz,
        );
        for c in 0..4 {
            out[c] += weight * v[c] as f64;
        }
    }
    out.map(|v| v as f32)
}

/// Deterministic pseudo-random sample points, including some in the border band.
fn probe_points([w, h, d]: [u32; 3], count: usize) -> Vec<[f32; 3]> {
    let mut bits = common::xorshift(0x9E37_79B9_7F4A_7C15);
    let mut next = move || (bits() >> 11) as f64 / (1u64 << 53) as f64;
    (0..count)
        .map(|_| {
            // Range [-1, size + 1]: covers the zero border on every side.
            [
                (next() * (w as f64 + 2.0) - 1.0) as f32,
                (next() * (h as f64 + 2.0) - 1.0) as f32,
                (next() * (d as f64 + 2.0) - 1.0) as f32,
            ]
        })
        .collect()
}

fn check_3d_texture(format: TexelFormat, extent: [u32; 3]) {
    let ctx = common::gpu();
    let [w, h, d] = extent;
    let count = (w * h * d) as usize;
    // The values the GPU actually holds (rounded to half precision for RGBA16F).
    let mut exact = Vec::with_capacity(count);
    for z in 0..d {
        for y in 0..h {
            for x in 0..w {
                exact.push([0, 1, 2, 3].map(|c| signal(x, y, z, c)));
            }
        }
    }
    let image =
        Image::new_3d(&ctx, "psf-like volume", extent, format, ImageUsage::SAMPLED).unwrap();
    match format {
        TexelFormat::Rgba16Float => {
            let halves: Vec<[f16; 4]> = exact.iter().map(|t| t.map(f16::from_f32)).collect();
            for (e, h) in exact.iter_mut().zip(&halves) {
                *e = h.map(f16::to_f32);
            }
            image.upload(&ctx, &halves).unwrap();
        }
        TexelFormat::Rgba32Float => image.upload(&ctx, &exact).unwrap(),
        other => panic!("unexpected format {other:?}"),
    }
    let sampler = Sampler::linear(&ctx, Edge::ZeroBorder).unwrap();
    let probe = TextureProbe::new(&ctx).unwrap();
    let points = probe_points(extent, 200_000);
    let gpu = probe.sample(&ctx, &image, &sampler, &points).unwrap();
    let mut worst = 0.0f32;
    for (p, g) in points.iter().zip(&gpu) {
        let cpu = trilinear(&exact, extent, *p);
        for c in 0..4 {
            worst = worst.max((cpu[c] - g[c]).abs());
        }
    }
    eprintln!(
        "{} {w}x{h}x{d}: worst |GPU - CPU trilinear| = {worst:.2e}",
        format.name()
    );
    assert!(
        worst < 1e-3,
        "{}: trilinear sample differs from CPU reference by {worst}",
        format.name()
    );
    drop((image, sampler, probe));
    common::finish(ctx);
}

#[test]
fn rgba16f_3d_texture_filters_like_cpu_trilinear() {
    check_3d_texture(TexelFormat::Rgba16Float, [97, 97, 2000]);
}

#[test]
fn rgba32f_3d_texture_filters_like_cpu_trilinear() {
    check_3d_texture(TexelFormat::Rgba32Float, [97, 97, 2000]);
}

#[test]
fn buffers_round_trip_and_fill() {
    let ctx = common::gpu();
    let data: Vec<u32> = (0..100_003).map(|i| i * 7 + 1).collect();
    let buffer = Buffer::from_slice(&ctx, "round trip", &data).unwrap();
    assert_eq!(buffer.read::<u32>(&ctx).unwrap()[..data.len()], data[..]);
    ctx.submit(|rec| {
        rec.fill_buffer(&buffer, 0xDEAD_BEEF);
        Ok(())
    })
    .unwrap();
    assert!(buffer
        .read::<u32>(&ctx)
        .unwrap()
        .iter()
        .all(|&v| v == 0xDEAD_BEEF));
    let too_big = vec![0u8; 1 << 20];
    let err = buffer.upload(&ctx, &too_big).unwrap_err();
    assert!(matches!(err, GpuError::Usage { .. }), "{err}");
    drop(buffer);
    common::finish(ctx);
}

#[test]
fn images_round_trip() {
    let ctx = common::gpu();
    let texels: Vec<[f32; 4]> = (0..7 * 5 * 3)
        .map(|i| [i as f32, -(i as f32), 0.5, 1.0])
        .collect();
    let image = Image::new_3d(
        &ctx,
        "small",
        [7, 5, 3],
        TexelFormat::Rgba32Float,
        ImageUsage::SAMPLED,
    )
    .unwrap();
    image.upload(&ctx, &texels).unwrap();
    assert_eq!(image.read::<[f32; 4]>(&ctx).unwrap(), texels);
    let storage = Image::new_2d(
        &ctx,
        "storage",
        16,
        9,
        TexelFormat::Rgba16Float,
        ImageUsage::STORAGE,
    )
    .unwrap();
    ctx.submit(|rec| {
        rec.clear_image(&storage, [0.25, 0.5, 1.0, 2.0]);
        Ok(())
    })
    .unwrap();
    let cleared: Vec<[f16; 4]> = storage.read(&ctx).unwrap();
    assert!(cleared
        .iter()
        .all(|t| t.map(f16::to_f32) == [0.25, 0.5, 1.0, 2.0]));
    drop((image, storage));
    common::finish(ctx);
}

#[test]
fn pipeline_builder_checks_bindings_and_times_passes() {
    let ctx = common::gpu();
    let probe_pipeline = ComputePipeline::builder("probe", ocular::shaders::GPU_TEXTURE_PROBE_COMP)
        .bindings(&[
            BindingKind::SampledImage,
            BindingKind::StorageBuffer,
            BindingKind::StorageBuffer,
        ])
        .push_constants::<u32>()
        .build(&ctx)
        .unwrap();
    let buffer = Buffer::new(&ctx, "b", 64, Residency::Device).unwrap();
    // Too few bindings, and a buffer where an image belongs: errors, not crashes.
    let err = ctx
        .submit(|rec| {
            rec.dispatch(
                &probe_pipeline,
                &[Binding::Buffer(&buffer)],
                &0u32,
                [1, 1, 1],
            )
        })
        .unwrap_err();
    assert!(
        err.to_string()
            .contains("1 bindings given, the pipeline declares 3"),
        "{err}"
    );
    let err = ctx
        .submit(|rec| {
            rec.dispatch(
                &probe_pipeline,
                &[
                    Binding::Buffer(&buffer),
                    Binding::Buffer(&buffer),
                    Binding::Buffer(&buffer),
                ],
                &0u32,
                [1, 1, 1],
            )
        })
        .unwrap_err();
    assert!(
        err.to_string().contains("binding 0 must be a SampledImage"),
        "{err}"
    );

    // A real dispatch reports a timing per named pass.
    let image = Image::new_3d(
        &ctx,
        "v",
        [4, 4, 4],
        TexelFormat::Rgba32Float,
        ImageUsage::SAMPLED,
    )
    .unwrap();
    let sampler = Sampler::linear(&ctx, Edge::ZeroBorder).unwrap();
    let timings = ctx
        .submit(|rec| {
            rec.begin_pass("first");
            rec.dispatch(
                &probe_pipeline,
                &[
                    Binding::Sampled(&image, &sampler),
                    Binding::Buffer(&buffer),
                    Binding::Buffer(&buffer),
                ],
                &4u32,
                [1, 1, 1],
            )?;
            rec.begin_pass("second");
            rec.dispatch(
                &probe_pipeline,
                &[
                    Binding::Sampled(&image, &sampler),
                    Binding::Buffer(&buffer),
                    Binding::Buffer(&buffer),
                ],
                &4u32,
                [1, 1, 1],
            )
        })
        .unwrap();
    let names: Vec<&str> = timings.passes.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["first", "second"]);
    assert!(timings
        .passes
        .iter()
        .all(|p| p.ms.is_finite() && p.ms >= 0.0));
    assert!((timings.total_ms() - timings.passes.iter().map(|p| p.ms).sum::<f64>()).abs() < 1e-12);
    drop((probe_pipeline, buffer, image, sampler));
    common::finish(ctx);
}

#[test]
fn unsupported_sizes_are_clear_errors() {
    let ctx = common::gpu();
    let err = Image::new_3d(
        &ctx,
        "huge",
        [8, 8, 1 << 20],
        TexelFormat::Rgba16Float,
        ImageUsage::SAMPLED,
    )
    .unwrap_err();
    let text = err.to_string();
    assert!(matches!(err, GpuError::Unsupported(_)), "{text}");
    assert!(
        text.contains("8×8×1048576") && text.contains("allows up to"),
        "{text}"
    );
    let err = Image::new_2d(
        &ctx,
        "empty",
        0,
        4,
        TexelFormat::Rgba16Float,
        ImageUsage::STORAGE,
    )
    .unwrap_err();
    assert!(err.to_string().contains("no texels"), "{err}");
    common::finish(ctx);
}

#[test]
fn out_of_memory_is_a_clear_error() {
    let ctx = common::gpu();
    // Far more than any device has (1 PiB): the allocator must refuse without a crash.
    match Buffer::new(&ctx, "enormous", 1 << 50, Residency::Device) {
        Err(err) => {
            let text = err.to_string();
            assert!(text.contains("enormous"), "{text}");
        }
        Ok(_) => panic!("a 1 PiB buffer cannot exist"),
    }
    // The layer may warn about the impossible request itself; what matters is no crash.
    let _ = ctx.validation_log().take();
    common::finish(ctx);
}

#[test]
fn deliberate_validation_error_is_caught() {
    let ctx = common::gpu();
    if !ctx.is_validating() {
        eprintln!("validation layer not installed: skipping (CI requires it via OCULAR_VALIDATION=required)");
        return;
    }
    // A zero-sized buffer violates VUID-VkBufferCreateInfo-size-00912. Go around the safe
    // layer on purpose; the layer must report it and check_validation must turn it into an error.
    let info = vk::BufferCreateInfo::default()
        .size(0)
        .usage(vk::BufferUsageFlags::STORAGE_BUFFER);
    // SAFETY: deliberately invalid create info, to provoke the validation layer; the handle
    // (if any) is destroyed right after.
    unsafe {
        if let Ok(buffer) = ctx.raw_device().create_buffer(&info, None) {
            ctx.raw_device().destroy_buffer(buffer, None);
        }
    }
    let err = ctx.check_validation().unwrap_err();
    match &err {
        GpuError::Validation(messages) => {
            assert!(
                messages
                    .iter()
                    .any(|m| m.contains("00912") || m.contains("size")),
                "{messages:?}"
            )
        }
        other => panic!("expected a validation error, got {other}"),
    }
    // Once reported, the log is clear again.
    ctx.check_validation().unwrap();
    common::finish(ctx);
}

#[test]
fn unknown_device_is_rejected_with_the_list() {
    let options = ContextOptions {
        device: Some("no such device 123".into()),
        ..ContextOptions::for_tests()
    };
    let err = Context::new(&options)
        .err()
        .expect("no device has that name");
    let text = err.to_string();
    assert!(matches!(err, GpuError::DeviceNotFound { .. }), "{text}");
    assert!(
        text.contains("no such device 123") && text.contains("available"),
        "{text}"
    );
}

/// Barriers come from what each command declares it reads and writes (the shader's
/// readonly/writeonly, reflected): two dispatches that only share a read-only input run
/// without a barrier between them, a dispatch that reads what an earlier one wrote waits for
/// it. Synchronization validation (on in every test) would report a missing dependency.
/// A pass whose declared bindings or push constants disagree with its shader is refused when
/// the pipeline is built.
#[test]
fn barriers_follow_declared_access_and_declarations_match_shaders() {
    let ctx = common::gpu();
    let kinds = [
        BindingKind::SampledImage,
        BindingKind::StorageBuffer,
        BindingKind::StorageBuffer,
    ];
    let probe = ComputePipeline::builder("probe", ocular::shaders::GPU_TEXTURE_PROBE_COMP)
        .bindings(&kinds)
        .push_constants::<u32>()
        .build(&ctx)
        .unwrap();
    let image = Image::new_3d(
        &ctx,
        "v",
        [4, 4, 4],
        TexelFormat::Rgba32Float,
        ImageUsage::SAMPLED,
    )
    .unwrap();
    let sampler = Sampler::linear(&ctx, Edge::ZeroBorder).unwrap();
    let buffers: Vec<Buffer> = (0..4)
        .map(|i| Buffer::new(&ctx, &format!("b{i}"), 256, Residency::Device).unwrap())
        .collect();
    let [a, b, c, d] = [&buffers[0], &buffers[1], &buffers[2], &buffers[3]];
    let mut counts = Vec::new();
    ctx.submit(|rec| {
        let run = |rec: &mut ocular::gpu::Recorder<'_>, input: &Buffer, output: &Buffer| {
            rec.dispatch(
                &probe,
                &[
                    Binding::Sampled(&image, &sampler),
                    Binding::Buffer(input),
                    Binding::Buffer(output),
                ],
                &16u32,
                [1, 1, 1],
            )
        };
        rec.fill_buffer(a, 0);
        counts.push(rec.barrier_counts());
        run(rec, a, b)?; // reads what the fill wrote: waits
        counts.push(rec.barrier_counts());
        run(rec, a, c)?; // shares only the read of a: no barrier
        counts.push(rec.barrier_counts());
        run(rec, b, d)?; // reads b, written two commands ago: waits
        counts.push(rec.barrier_counts());
        Ok(())
    })
    .unwrap();
    assert_eq!(
        counts,
        [(0, 1), (1, 2), (1, 3), (2, 4)],
        "(barriers, commands)"
    );

    let wrong_kind = ComputePipeline::builder("probe", ocular::shaders::GPU_TEXTURE_PROBE_COMP)
        .bindings(&[
            BindingKind::SampledImage,
            BindingKind::StorageBuffer,
            BindingKind::StorageImage,
        ])
        .push_constants::<u32>()
        .build(&ctx)
        .err()
        .expect("refused")
        .to_string();
    assert!(
        wrong_kind.contains("binding 2 is a StorageBuffer in the shader"),
        "{wrong_kind}"
    );
    let wrong_push = ComputePipeline::builder("probe", ocular::shaders::GPU_TEXTURE_PROBE_COMP)
        .bindings(&kinds)
        .push_constants::<[u32; 2]>()
        .build(&ctx)
        .err()
        .expect("refused")
        .to_string();
    assert!(
        wrong_push.contains("push-constant block is 4 bytes, the pass's struct 8"),
        "{wrong_push}"
    );
    let too_few = ComputePipeline::builder("probe", ocular::shaders::GPU_TEXTURE_PROBE_COMP)
        .bindings(&kinds[..2])
        .push_constants::<u32>()
        .build(&ctx)
        .err()
        .expect("refused")
        .to_string();
    assert!(too_few.contains("uses binding 2"), "{too_few}");
    // A uniform block is checked against the struct declared for it: the tile-count pass's
    // frame block (binding 5, after five fragment and count buffers) is 22 four-byte scalars.
    let tile_count = |uniform_bytes: usize| {
        let builder =
            ComputePipeline::builder("tile count", ocular::shaders::RENDER_SPLAT_TILE_COUNT_COMP)
                .bindings(&[BindingKind::StorageBuffer; 5]);
        match uniform_bytes {
            88 => builder.uniform::<[u32; 22]>(),
            _ => builder.uniform::<[u32; 16]>(),
        }
        .bindings(&[BindingKind::StorageBuffer]) // the Field table (6), after the uniform
        .build(&ctx)
    };
    assert!(tile_count(88).is_ok());
    let wrong_uniform = tile_count(64).err().expect("refused").to_string();
    assert!(
        wrong_uniform
            .contains("uniform block at binding 5 is 88 bytes in the shader, the pass's struct 64"),
        "{wrong_uniform}"
    );
    drop((probe, buffers, image, sampler));
    common::finish(ctx);
}
