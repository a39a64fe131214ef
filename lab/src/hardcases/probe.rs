//! Per-pixel access to a frame's receivers for the analytic checks: position, normal, lit or not, and the
//! margin of the checks at each receiver.

use crate::accuracy::absolute_tolerance;
use demo_engine::{FrameImages, View};
use glam::{DMat4, DVec2, DVec3};
use passes::FrameInputs;
use reference::{certainly_blocked, contact_shadow_start};
use scene::hard_cases::Solid;
use scene::Aabb;

/// Margin of the analytic checks, in pixel footprints at the receiver's distance from the camera: a
/// receiver counts as certainly shadowed (or certainly in a contact shadow) only if its shadow ray passes
/// this far inside the blocker.
pub const MARGIN_PIXELS: f64 = 2.0;

/// Light-facing threshold of the acne check: receivers whose normal makes a cosine above this with the
/// direction to the light (89.99°) must be lit where nothing blocks them.
const FACING_COSINE: f64 = 1.7e-4;

/// A receiver seen by one pixel.
pub(super) struct Receiver {
    index: usize,
    position: DVec3,
    /// Camera-facing geometric normal.
    normal: DVec3,
    lit: bool,
    /// Margin of the analytic checks at this receiver (world units).
    margin: f64,
}

/// Per-pixel access to a frame's receivers for the analytic checks.
pub(super) struct Probe<'a> {
    images: &'a FrameImages,
    camera: DVec3,
    view_proj: DMat4,
    pub(super) to_light: DVec3,
    pixel_angle: f64,
    absolute_margin: f64,
    width: f64,
    height: f64,
}

impl<'a> Probe<'a> {
    pub(super) fn new(view: &View, inputs: &FrameInputs, images: &'a FrameImages) -> Self {
        Self {
            images,
            camera: inputs.camera_position.as_dvec3(),
            view_proj: inputs.proj.as_dmat4() * inputs.view.as_dmat4(),
            to_light: -view.light.direction.as_dvec3().normalize(),
            pixel_angle: 2.0 * (f64::from(view.camera.fov_y_radians) / 2.0).tan()
                / f64::from(view.height),
            absolute_margin: absolute_tolerance(view),
            width: f64::from(view.width),
            height: f64::from(view.height),
        }
    }

    fn receivers(&self) -> impl Iterator<Item = Receiver> + '_ {
        let images = self.images;
        (0..images.visibility.len()).filter_map(move |index| {
            let n = images.normal[index];
            let p = images.position[index];
            if n[3] == 0.0 {
                return None;
            }
            let position = DVec3::new(p[0].into(), p[1].into(), p[2].into());
            let normal = DVec3::new(n[0].into(), n[1].into(), n[2].into());
            if !position.is_finite() || !normal.is_finite() {
                return None;
            }
            let margin = MARGIN_PIXELS * position.distance(self.camera) * self.pixel_angle
                + self.absolute_margin;
            Some(Receiver {
                index,
                position,
                normal,
                lit: images.visibility[index] > 0.5,
                margin,
            })
        })
    }

    /// Receivers whose shadow ray passes through `solid` shrunk by the margin, and the lit ones among them.
    pub(super) fn leaks(&self, solid: &Solid, flagged: &mut [bool]) -> (usize, usize) {
        let (mut judged, mut leaks) = (0, 0);
        for r in self.receivers() {
            if certainly_blocked(solid, r.position, self.to_light, r.margin) {
                judged += 1;
                if r.lit {
                    flagged[r.index] = true;
                    leaks += 1;
                }
            }
        }
        (judged, leaks)
    }

    /// Light-facing receivers inside `region`, and the shadowed ones among them.
    pub(super) fn acne(&self, region: &Aabb, flagged: &mut [bool]) -> (usize, usize) {
        let (min, max) = (region.min.as_dvec3(), region.max.as_dvec3());
        let (mut judged, mut acne) = (0, 0);
        for r in self.receivers() {
            let inside = r.position.cmpge(min).all() && r.position.cmple(max).all();
            if inside && r.normal.dot(self.to_light) > FACING_COSINE {
                judged += 1;
                if !r.lit {
                    flagged[r.index] = true;
                    acne += 1;
                }
            }
        }
        (judged, acne)
    }

    /// Receivers in the contact shadow of box `b` (standing on a horizontal receiver at `b.min.y`), and the
    /// largest screen distance (pixels) between a lit one and the footprint edge its shadow ray enters
    /// through.
    pub(super) fn contact_gap(&self, b: &Aabb, flagged: &mut [bool]) -> (usize, f64) {
        let min_y = f64::from(b.min.y);
        let (mut judged, mut gap) = (0, 0.0f64);
        for r in self.receivers() {
            let p = r.position;
            let on_base = (p.y - min_y).abs() <= 1e-3 * r.margin + 1e-6 * (1.0 + min_y.abs());
            if !on_base || r.normal.y < 0.999 {
                continue;
            }
            let Some(contact) = contact_shadow_start(b, p, self.to_light, r.margin) else {
                continue;
            };
            judged += 1;
            if !r.lit {
                continue;
            }
            let distance = self.screen(p).distance(self.screen(contact));
            flagged[r.index] = true;
            gap = gap.max(distance);
        }
        (judged, gap)
    }

    /// Continuous pixel coordinates of a world point.
    fn screen(&self, p: DVec3) -> DVec2 {
        let clip = self.view_proj * p.extend(1.0);
        let ndc = clip.truncate().truncate() / clip.w;
        (ndc * 0.5 + 0.5) * DVec2::new(self.width, self.height)
    }
}
