//! Exact CPU reference for the hybrid ray-traced shadow renderer.
//!
//! Everything is computed in `f64` from the `f32` scene and matrices exactly as they
//! are uploaded to the GPU, so that GPU results can be compared against it in
//! tests:
//!
//! - [`reference_visibility`]: per-pixel light visibility of the camera-ray receiver
//!   points, with pixels whose outcome hinges on an event within a tolerance of a
//!   triangle edge or plane classified [`PixelClass::Ambiguous`];
//! - [`conservative_texel_sets`]: the exact conservative set of triangles per texel
//!   of a light-space grid (the "deep primitive map" of Jon Story's GDC 2015 talk on
//!   hybrid ray-traced shadows);
//! - [`soft_visibility`]: soft-shadow ground truth, the visible fraction of an
//!   [`AreaLight`] per pixel by stratified Monte Carlo with a stated error bound,
//!   exact where the light's cone is provably clear;
//! - [`area_reference`]: the visible count of a fixed set of light samples per pixel, each sample an
//!   exact hard shadow ray, with the pixels whose every sample is decided beyond the tolerance marked
//!   stable (what the GPU's area shadows must match exactly).
//!
//! All are built on [`intersect_watertight`] (Woop, Benthin and Wald's watertight
//! ray/triangle test), exact orientation predicates, and a BVH over the scene
//! ([`RefScene`]).
//!
//! [`certainly_blocked`] and [`contact_shadow_start`] are the conservative predicates of the
//! hard cases' analytic checks (leaks, contact shadows), decided with a margin.
//!
//! Conventions: right-handed world with +Y up; Vulkan clip depth `[0, 1]`;
//! framebuffer pixel `(x, y)` with `y = 0` the top row has its centre at NDC
//! `((x + 0.5) / W * 2 - 1, (y + 0.5) / H * 2 - 1)` (NDC y = -1 is the top row). The
//! camera projection is reversed-Z with an infinite far plane. A light direction is
//! the direction the light travels. Visibility 1 means lit.

#![forbid(unsafe_code)]

mod area;
mod exact;
mod geometry;
mod predicates;
mod ref_scene;
mod soft;
mod texels;
mod visibility;

#[cfg(test)]
mod tests;

pub use area::{
    area_counts_at, area_reference, area_reference_with_progress, local_area_reference,
    AreaReference,
};
pub use geometry::{intersect_watertight, line_segment_distance};
pub use predicates::{certainly_blocked, contact_shadow_start};
pub use ref_scene::RefScene;
pub use soft::{
    soft_visibility, soft_visibility_with_progress, AreaLight, SoftParams, SoftReference,
    RELATIVE_RAY_OFFSET,
};
pub use texels::{conservative_texel_sets, overlaps_texel_with_margin, FaceSelection, TexelSets};
pub use visibility::{
    disc_basis, reference_pixel_classes, reference_visibility, reference_visibility_with_progress,
    Light, PixelClass, VisibilityParams, VisibilityReference, DISC_BASIS_POLE,
};
