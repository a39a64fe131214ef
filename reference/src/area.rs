//! The exact reference of area shadows with a fixed set of light samples: per pixel, how many of the sample
//! directions reach the light, each decided by [`reference_visibility`] as a hard shadow ray of its own, and
//! whether every one of them is decided beyond the tolerance (a stable pixel).
//!
//! [`reference_visibility`]: crate::reference_visibility

use glam::{DVec2, DVec3};

use crate::{
    reference_pixel_classes, reference_visibility_with_progress, Light, PixelClass, RefScene,
    VisibilityParams,
};

/// Visible sample counts of every pixel; row-major with `y = 0` the top row, like
/// [`crate::VisibilityReference`].
#[derive(Debug, Clone, PartialEq)]
pub struct AreaReference {
    /// Framebuffer width in pixels.
    pub width: u32,
    /// Framebuffer height in pixels.
    pub height: u32,
    /// Samples per pixel.
    pub samples: u32,
    /// Samples that reach the light (all of them on background pixels).
    pub visible: Vec<u32>,
    /// Whether no sample of the pixel is [`PixelClass::Ambiguous`]: its count is exact.
    pub stable: Vec<bool>,
    /// Whether the camera ray hits nothing.
    pub background: Vec<bool>,
}

/// The visible count of each pixel of `params`' view over the sample directions `towards_light` (each the
/// direction from a receiver *towards* the light, as the area trace holds them; `params.light` is
/// replaced). A sample is visible where [`reference_visibility`](crate::reference_visibility) calls the
/// pixel lit for a directional light travelling along its opposite.
pub fn area_reference(
    scene: &RefScene,
    params: &VisibilityParams,
    towards_light: &[DVec3],
) -> AreaReference {
    area_reference_with_progress(scene, params, towards_light, &|| {})
}

/// [`area_reference`], calling `row_done` once per row of each sample it finishes (from any thread of its
/// pool), for a caller's progress display: `params.height * towards_light.len()` calls in all.
pub fn area_reference_with_progress(
    scene: &RefScene,
    params: &VisibilityParams,
    towards_light: &[DVec3],
    row_done: &(dyn Fn() + Sync),
) -> AreaReference {
    count_samples(
        scene,
        params,
        towards_light
            .iter()
            .map(|&w| Light::Directional { direction: -w }),
        row_done,
    )
}

/// The visible count of each pixel of `params`' view for a spherical emitter of `radius` at `centre` (a sized
/// spot or point light), sampled at `offsets` on the unit disc facing each receiver ([`Light::DiscSample`];
/// `params.light` is replaced).
pub fn local_area_reference(
    scene: &RefScene,
    params: &VisibilityParams,
    centre: DVec3,
    radius: f64,
    offsets: &[DVec2],
) -> AreaReference {
    count_samples(
        scene,
        params,
        offsets.iter().map(|&offset| Light::DiscSample {
            centre,
            radius,
            offset,
        }),
        &|| {},
    )
}

/// The visible count of each pixel of `pixels` ((x, y) of `params`' view) over `lights`, one per sample
/// (a directional light along the opposite of each direction towards the light, as [`area_reference`]
/// takes them, or a [`Light::DiscSample`] of a sized spot or point light), and whether every sample is
/// decided beyond the tolerance (stable): [`area_reference`] or [`local_area_reference`] at those pixels
/// alone.
pub fn area_counts_at(
    scene: &RefScene,
    params: &VisibilityParams,
    lights: &[Light],
    pixels: &[(u32, u32)],
) -> Vec<(u32, bool)> {
    let mut counts = vec![(0, true); pixels.len()];
    for &light in lights {
        let per_sample = VisibilityParams { light, ..*params };
        for (count, class) in
            counts
                .iter_mut()
                .zip(reference_pixel_classes(scene, &per_sample, pixels))
        {
            match class {
                PixelClass::Background | PixelClass::Lit => count.0 += 1,
                PixelClass::Shadowed => {}
                PixelClass::Ambiguous => count.1 = false,
            }
        }
    }
    counts
}

/// Counts, per pixel, the `lights` (one per sample) that reach it, calling `row_done` per row of each.
fn count_samples(
    scene: &RefScene,
    params: &VisibilityParams,
    lights: impl ExactSizeIterator<Item = Light>,
    row_done: &(dyn Fn() + Sync),
) -> AreaReference {
    let pixels = params.width as usize * params.height as usize;
    let mut out = AreaReference {
        width: params.width,
        height: params.height,
        samples: lights.len() as u32,
        visible: vec![0; pixels],
        stable: vec![true; pixels],
        background: vec![false; pixels],
    };
    for light in lights {
        let per_sample = VisibilityParams { light, ..*params };
        let r = reference_visibility_with_progress(scene, &per_sample, row_done);
        for (i, class) in r.class.iter().enumerate() {
            match class {
                PixelClass::Background => {
                    out.background[i] = true;
                    out.visible[i] += 1;
                }
                PixelClass::Lit => out.visible[i] += 1,
                PixelClass::Shadowed => {}
                PixelClass::Ambiguous => out.stable[i] = false,
            }
        }
    }
    out
}
