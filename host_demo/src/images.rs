//! Picture helpers of the soft-shadow outputs: the lerp-factor view, a canvas with a small bitmap font
//! for labelled side-by-side composites, and a compact PNG writer for them.

use anyhow::{Context, Result};
use std::path::Path;

/// Lerp-factor view like the talk's: grey levels from black (L = 0, the ray-traced hard shadow) to white
/// (L = 1, all PCSS) inside shadows; dark blue where the ray trace found no blocker (lit: L is 0 there and
/// the result is the lit ray-traced value); the sky colour on background.
pub fn lerp_factor_preview(
    normal: &[[f32; 4]],
    lerp: &[f32],
    rt_visibility: &[f32],
) -> Vec<[u8; 4]> {
    normal
        .iter()
        .zip(lerp)
        .enumerate()
        .map(|(i, (n, &l))| {
            if n[3] == 0.0 {
                return SKY;
            }
            let lit = rt_visibility.get(i).is_some_and(|&v| v >= 1.0);
            if lit {
                return [20, 30, 70, 255];
            }
            let g = (l.clamp(0.0, 1.0) * 255.0).round() as u8;
            [g, g, g, 255]
        })
        .collect()
}

/// Background colour of the previews.
pub const SKY: [u8; 4] = [150, 180, 215, 255];

/// An RGBA8 picture to compose panels and labels on.
pub struct Canvas {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Row-major pixels.
    pub pixels: Vec<[u8; 4]>,
}

impl Canvas {
    /// A canvas filled with `colour`.
    pub fn new(width: u32, height: u32, colour: [u8; 4]) -> Self {
        Self {
            width,
            height,
            pixels: vec![colour; width as usize * height as usize],
        }
    }

    /// Sets one pixel (ignored outside the canvas).
    pub fn put(&mut self, x: i64, y: i64, colour: [u8; 4]) {
        if x >= 0
            && y >= 0
            && (x as u64) < u64::from(self.width)
            && (y as u64) < u64::from(self.height)
        {
            self.pixels[y as usize * self.width as usize + x as usize] = colour;
        }
    }

    /// Copies a `w` x `h` picture with its top-left corner at (`x`, `y`).
    pub fn blit(&mut self, picture: &[[u8; 4]], w: u32, h: u32, x: i64, y: i64) {
        for (i, &p) in picture.iter().enumerate().take(w as usize * h as usize) {
            let (px, py) = ((i % w as usize) as i64, (i / w as usize) as i64);
            self.put(x + px, y + py, p);
        }
    }

    /// Fills a rectangle.
    pub fn fill(&mut self, x: i64, y: i64, w: u32, h: u32, colour: [u8; 4]) {
        for dy in 0..i64::from(h) {
            for dx in 0..i64::from(w) {
                self.put(x + dx, y + dy, colour);
            }
        }
    }

    /// Draws `text` with the 5x7 font, each font pixel `scale` pixels wide, top-left at (`x`, `y`).
    /// Characters without a glyph are drawn as spaces.
    pub fn text(&mut self, x: i64, y: i64, scale: u32, text: &str, colour: [u8; 4]) {
        let s = i64::from(scale.max(1));
        for (k, c) in text.chars().enumerate() {
            let rows = glyph(c);
            let left = x + k as i64 * 6 * s;
            for (r, bits) in rows.iter().enumerate() {
                for col in 0..5 {
                    if bits & (0x10 >> col) != 0 {
                        for dy in 0..s {
                            for dx in 0..s {
                                self.put(left + col * s + dx, y + r as i64 * s + dy, colour);
                            }
                        }
                    }
                }
            }
        }
    }

    /// Width in pixels of `text` drawn at `scale`.
    pub fn text_width(text: &str, scale: u32) -> u32 {
        (text.chars().count() as u32 * 6).saturating_sub(1) * scale.max(1)
    }
}

/// Writes an opaque picture as an RGB PNG with adaptive filtering and the best compression (for
/// composites meant to be committed).
pub fn write_png_compact(path: &Path, width: u32, height: u32, rgba: &[[u8; 4]]) -> Result<()> {
    let rgb: Vec<u8> = rgba.iter().flat_map(|p| [p[0], p[1], p[2]]).collect();
    let file =
        std::fs::File::create(path).with_context(|| format!("creating {}", path.display()))?;
    let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), width, height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_compression(png::Compression::Best);
    encoder.set_adaptive_filter(png::AdaptiveFilterType::Adaptive);
    let mut writer = encoder
        .write_header()
        .with_context(|| format!("writing {}", path.display()))?;
    writer
        .write_image_data(&rgb)
        .with_context(|| format!("writing {}", path.display()))?;
    Ok(())
}

/// Rows (top to bottom, bit 4 = leftmost column) of a 5x7 glyph.
fn glyph(c: char) -> [u8; 7] {
    match c {
        'x' => [0x00, 0x00, 0x11, 0x0A, 0x04, 0x0A, 0x11],
        _ => match c.to_ascii_uppercase() {
            'A' => [0x0E, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11],
            'B' => [0x1E, 0x11, 0x11, 0x1E, 0x11, 0x11, 0x1E],
            'C' => [0x0E, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0E],
            'D' => [0x1C, 0x12, 0x11, 0x11, 0x11, 0x12, 0x1C],
            'E' => [0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x1F],
            'F' => [0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x10],
            'G' => [0x0E, 0x11, 0x10, 0x17, 0x11, 0x11, 0x0F],
            'H' => [0x11, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11],
            'I' => [0x0E, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E],
            'J' => [0x07, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0C],
            'K' => [0x11, 0x12, 0x14, 0x18, 0x14, 0x12, 0x11],
            'L' => [0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1F],
            'M' => [0x11, 0x1B, 0x15, 0x15, 0x11, 0x11, 0x11],
            'N' => [0x11, 0x11, 0x19, 0x15, 0x13, 0x11, 0x11],
            'O' => [0x0E, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E],
            'P' => [0x1E, 0x11, 0x11, 0x1E, 0x10, 0x10, 0x10],
            'Q' => [0x0E, 0x11, 0x11, 0x11, 0x15, 0x12, 0x0D],
            'R' => [0x1E, 0x11, 0x11, 0x1E, 0x14, 0x12, 0x11],
            'S' => [0x0F, 0x10, 0x10, 0x0E, 0x01, 0x01, 0x1E],
            'T' => [0x1F, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04],
            'U' => [0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E],
            'V' => [0x11, 0x11, 0x11, 0x11, 0x11, 0x0A, 0x04],
            'W' => [0x11, 0x11, 0x11, 0x15, 0x15, 0x15, 0x0A],
            'X' => [0x11, 0x11, 0x0A, 0x04, 0x0A, 0x11, 0x11],
            'Y' => [0x11, 0x11, 0x0A, 0x04, 0x04, 0x04, 0x04],
            'Z' => [0x1F, 0x01, 0x02, 0x04, 0x08, 0x10, 0x1F],
            '0' => [0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E],
            '1' => [0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E],
            '2' => [0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F],
            '3' => [0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E],
            '4' => [0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02],
            '5' => [0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E],
            '6' => [0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E],
            '7' => [0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08],
            '8' => [0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E],
            '9' => [0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C],
            '+' => [0x00, 0x04, 0x04, 0x1F, 0x04, 0x04, 0x00],
            '-' => [0x00, 0x00, 0x00, 0x1F, 0x00, 0x00, 0x00],
            '.' => [0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C],
            ',' => [0x00, 0x00, 0x00, 0x00, 0x0C, 0x04, 0x08],
            '(' => [0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02],
            ')' => [0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08],
            '/' => [0x01, 0x02, 0x02, 0x04, 0x08, 0x08, 0x10],
            ':' => [0x00, 0x0C, 0x0C, 0x00, 0x0C, 0x0C, 0x00],
            '=' => [0x00, 0x00, 0x1F, 0x00, 0x1F, 0x00, 0x00],
            _ => [0; 7],
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_draws_inside_its_box_only() {
        let mut c = Canvas::new(64, 16, [0, 0, 0, 255]);
        c.text(1, 1, 1, "PCSS 3K", [255; 4]);
        let lit: Vec<(usize, usize)> = c
            .pixels
            .iter()
            .enumerate()
            .filter(|(_, p)| p[0] == 255)
            .map(|(i, _)| (i % 64, i / 64))
            .collect();
        assert!(!lit.is_empty());
        let w = Canvas::text_width("PCSS 3K", 1) as usize;
        assert!(lit
            .iter()
            .all(|&(x, y)| (1..=w).contains(&x) && (1..8).contains(&y)));
        // Unknown characters and off-canvas drawing are harmless.
        c.text(60, 14, 3, "\u{263a}~", [255; 4]);
    }

    #[test]
    fn lerp_view_colours() {
        let n = [[0.0, 1.0, 0.0, 1.0], [0.0, 1.0, 0.0, 1.0], [0.0; 4]];
        let v = lerp_factor_preview(&n, &[0.5, 0.0, 0.0], &[0.0, 1.0, 1.0]);
        assert_eq!(v[0], [128, 128, 128, 255]);
        assert_eq!(v[1], [20, 30, 70, 255]);
        assert_eq!(v[2], SKY);
    }
}
