//! Writers for the demo's outputs: EXR images (exr crate), PNG previews (png crate) and frame.json.

use anyhow::{Context, Result};
use std::path::Path;

/// Writes an RGBA f32 EXR.
pub fn write_exr_rgba(path: &Path, width: u32, height: u32, pixels: &[[f32; 4]]) -> Result<()> {
    let w = width as usize;
    exr::prelude::write_rgba_file(path, w, height as usize, |x, y| {
        let p = pixels[y * w + x];
        (p[0], p[1], p[2], p[3])
    })
    .with_context(|| format!("writing {}", path.display()))
}

/// Writes a scalar image as a grey EXR (R = G = B = value, A = 1).
pub fn write_exr_scalar(path: &Path, width: u32, height: u32, values: &[f32]) -> Result<()> {
    let pixels: Vec<[f32; 4]> = values.iter().map(|&v| [v, v, v, 1.0]).collect();
    write_exr_rgba(path, width, height, &pixels)
}

/// Writes an 8-bit RGBA PNG.
pub fn write_png(path: &Path, width: u32, height: u32, rgba: &[[u8; 4]]) -> Result<()> {
    let file =
        std::fs::File::create(path).with_context(|| format!("creating {}", path.display()))?;
    let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), width, height);
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder
        .write_header()
        .with_context(|| format!("writing {}", path.display()))?;
    writer
        .write_image_data(rgba.as_flattened())
        .with_context(|| format!("writing {}", path.display()))?;
    Ok(())
}

/// Shaded preview: Lambert with the ray-traced visibility over a sky background, sRGB-ish gamma.
pub fn shade_preview(
    normal: &[[f32; 4]],
    visibility: &[f32],
    to_light: glam::Vec3,
) -> Vec<[u8; 4]> {
    normal
        .iter()
        .zip(visibility)
        .map(|(n, &v)| {
            if n[3] == 0.0 {
                return [150, 180, 215, 255];
            }
            let ndl = glam::Vec3::new(n[0], n[1], n[2]).dot(to_light).max(0.0);
            let l = 0.8 * (0.18 + 0.82 * ndl * v);
            let g = (l.powf(1.0 / 2.2) * 255.0).round().clamp(0.0, 255.0) as u8;
            [g, g, g, 255]
        })
        .collect()
}
