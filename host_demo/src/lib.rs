//! The standalone demo host as a library: the command line, images and reports of the `host_demo`
//! program, shared with the lab (`hrts_lab`) and the integration tests.
//!
//! The demo renders with its own engine in miniature ([`demo_engine`]: device, scene buffers, G-buffer),
//! which adds the shadows through the plugin's public API ([`hrts`]) alone. This crate names neither the
//! passes nor the RHI.
//!
//! A glTF scene's lights decide its shadows: [`scene_plan`] derives, without a GPU, which shadow each
//! light gets and through which frusta; [`scene_render`] renders them through the plugin and reports per
//! light what ran, what was kept and why; [`shading`] sums the lights into the shaded image.

pub mod cli;
pub mod images;
pub mod interior;

/// Limits of the command line's options, checked before any GPU work.
pub mod limits {
    /// Largest frame (or shadow map) side in pixels.
    pub const FRAME_SIDE: u32 = 16384;
    /// Largest primitive map size N (texel coordinates are packed in 16 bits).
    pub const MAP_SIZE: u32 = u16::MAX as u32;
}
pub mod load_report;
pub mod output;
pub mod progress;
pub mod render;
pub mod report_text;
pub mod scene_plan;
pub mod scene_render;
pub mod shading;

use glam::Vec3;

pub use progress::progress;

/// Parses "x,y,z" into a vector.
pub fn parse_vec3(s: &str) -> Result<Vec3, String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    let [x, y, z] = parts.as_slice() else {
        return Err(format!(
            "expected x,y,z (three numbers, such as -5,2,3) but got '{s}'"
        ));
    };
    let f = |v: &str| {
        v.parse::<f32>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("'{v}' is not a finite number"))
    };
    Ok(Vec3::new(f(x)?, f(y)?, f(z)?))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_vectors() {
        assert_eq!(parse_vec3("1, 2,3").unwrap(), Vec3::new(1.0, 2.0, 3.0));
        assert_eq!(
            parse_vec3("-5,-0.5,-1e2").unwrap(),
            Vec3::new(-5.0, -0.5, -100.0)
        );
        assert!(parse_vec3("1,2").is_err());
        assert!(parse_vec3("1,nan,2").is_err());
        assert!(parse_vec3("a,b,c").is_err());
    }
}
