//! PCSS over the shadow map — blocker search, penumbra estimate, PCF — with the standard or the shrinking
//! penumbra filter, and the classic single-tap shadow-map test (the talk's "shadow map" images). The
//! algorithm and its numerics are described in `shaders/pcss_main.glsl`.
//!
//! Reads: depth, normal, shadow map, light (and the ray-traced visibility for a shrinking filter whose hard
//! edge comes from the ray trace). Writes: PCSS visibility, or classic shadow-map visibility.

use crate::frame_plan::{HardEdge, PenumbraFilter};
use crate::gpu_types::PcssConstants;
use crate::screen_pass::{visibility_image, ScreenPass};
use crate::shaders::output_variant;
use crate::PassError;

use crate::gpu_types::constant_buffer;
use rhi::{BindingKind, Buffer, Device, Encoder, Image, Resource};

/// PCSS settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PcssConfig {
    /// Directional light: angular radius of the emitter in radians (default 0.02, about 1.15°; the sun
    /// is 0.0047). A blocker edge `h` above a receiver gives a penumbra of `h tan(radius)` on each side.
    pub angular_radius: f32,
    /// Spot light: emitter radius in world units (default 0.05).
    pub spot_radius: f32,
    /// Blocker-search taps (default 16).
    pub blocker_search_taps: u32,
    /// PCF taps (default 32).
    pub pcf_taps: u32,
    /// Largest blocker-search radius in shadow-map texels (default 48).
    pub max_search_radius: f32,
    /// Smallest PCF radius in texels (default 1): filters shadow-map aliasing even at contact.
    pub min_filter_radius: f32,
    /// Largest PCF radius in texels (default 32).
    pub max_filter_radius: f32,
    /// Standard or shrinking penumbra (default shrinking, as the hybrid needs).
    pub filter: PenumbraFilter,
}

impl Default for PcssConfig {
    fn default() -> Self {
        Self {
            angular_radius: 0.02,
            spot_radius: 0.05,
            blocker_search_taps: 16,
            pcf_taps: 32,
            max_search_radius: 48.0,
            min_filter_radius: 1.0,
            max_filter_radius: 32.0,
            filter: PenumbraFilter::Shrinking,
        }
    }
}

/// Most taps of either kind.
pub const MAX_TAPS: u32 = 256;

impl PcssConfig {
    /// Checks ranges: taps in 1..=`MAX_TAPS`, finite non-negative sizes, radii ordered, angular radius below
    /// 90°.
    pub fn validate(&self) -> Result<(), PassError> {
        let bad = |m: &str| Err(PassError::InvalidConfig(format!("PCSS: {m}")));
        for taps in [self.blocker_search_taps, self.pcf_taps] {
            if taps == 0 || taps > MAX_TAPS {
                return bad(&format!("tap counts must be in 1..={MAX_TAPS}"));
            }
        }
        let sizes = [
            self.angular_radius,
            self.spot_radius,
            self.max_search_radius,
            self.min_filter_radius,
            self.max_filter_radius,
        ];
        if sizes.iter().any(|v| !v.is_finite() || *v < 0.0) {
            return bad("sizes and radii must be finite and non-negative");
        }
        if self.angular_radius >= std::f32::consts::FRAC_PI_2 {
            return bad("the angular radius must be below pi/2");
        }
        if self.min_filter_radius > self.max_filter_radius {
            return bad("the smallest filter radius exceeds the largest");
        }
        Ok(())
    }

    /// The shader's emitter size for a light: tan(angular radius) for a directional light, the radius
    /// for a spot light.
    pub(crate) fn light_size(&self, spot: bool) -> f32 {
        if spot {
            self.spot_radius
        } else {
            self.angular_radius.tan()
        }
    }
}

/// What a [`PcssPass`] computes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum PcssKind {
    /// PCSS; a shrinking filter takes its hard edge from `HardEdge`.
    Pcss(HardEdge),
    /// The classic single-tap test with a depth bias.
    ClassicTest,
}

/// Images a [`PcssPass`] reads.
pub(crate) struct PcssInputs<'a> {
    /// Engine depth (`ShaderResource`).
    pub depth: &'a Image,
    /// Engine normal (`ShaderResource`).
    pub normal: &'a Image,
    /// Shadow map (`ShaderResource`).
    pub shadow_map: &'a Image,
    /// Ray-traced visibility (`UnorderedAccess`), bound when the hard edge comes from the ray trace.
    pub rt_visibility: Option<&'a Image>,
}

/// A PCSS or classic-test pass and its output.
pub struct PcssPass {
    step: ScreenPass,
    constants: Buffer,
    mode: u32,
    /// `R32_SFLOAT` visibility, 1 = lit.
    pub output: Image,
}

impl PcssPass {
    /// Creates the pass and its `width` x `height` output (`output` when given).
    pub(crate) fn new(
        device: &Device,
        inputs: &PcssInputs<'_>,
        kind: PcssKind,
        filter: PenumbraFilter,
        (width, height): (u32, u32),
        output: Option<Image>,
    ) -> Result<Self, PassError> {
        let (name, image_name, mode) = match kind {
            PcssKind::ClassicTest => ("shadow map test", "shadow map visibility", 2),
            PcssKind::Pcss(_) => (
                "PCSS",
                "pcss visibility",
                match filter {
                    PenumbraFilter::Standard => 0,
                    PenumbraFilter::Shrinking => 1,
                },
            ),
        };
        let output = match output {
            Some(image) => image,
            None => visibility_image(device, image_name, width, height)?,
        };
        let constants = constant_buffer::<PcssConstants>(device, image_name)?;
        let mut bindings = vec![
            BindingKind::UniformBuffer,
            BindingKind::SampledImage,
            BindingKind::SampledImage,
            BindingKind::SampledImage,
            BindingKind::StorageImage,
        ];
        let mut resources = vec![
            Resource::Buffer(&constants),
            Resource::Image(inputs.depth),
            Resource::Image(inputs.normal),
            Resource::Image(inputs.shadow_map),
            Resource::Image(&output),
        ];
        let shader_name = match (kind, inputs.rt_visibility) {
            (PcssKind::Pcss(HardEdge::RayTrace), Some(rt)) => {
                bindings.push(BindingKind::StorageImage);
                resources.push(Resource::Image(rt));
                "pcss_rt.comp"
            }
            (PcssKind::Pcss(HardEdge::RayTrace), None) => {
                return Err(PassError::InvalidConfig(
                    "PCSS with the ray-traced hard edge needs the ray-traced visibility".into(),
                ))
            }
            _ => "pcss.comp",
        };
        let shader_name = output_variant(shader_name, output.format())?;
        let step = ScreenPass::new(device, name, &shader_name, &bindings, &resources, 0)?;
        drop(resources);
        Ok(Self {
            step,
            constants,
            mode,
            output,
        })
    }

    /// Records the constants' update (into the command buffer) and the pass.
    pub(crate) fn record(
        &mut self,
        enc: &mut Encoder<'_>,
        constants: &PcssConstants,
    ) -> Result<(), PassError> {
        let mut c = *constants;
        c.dims.w = self.mode;
        enc.update_buffer(&self.constants, 0, bytemuck::bytes_of(&c))?;
        self.step.record(enc, &[], c.dims.x, c.dims.y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_ranges_checked() {
        let ok = PcssConfig::default();
        assert!(ok.validate().is_ok());
        assert!(PcssConfig { pcf_taps: 0, ..ok }.validate().is_err());
        assert!(PcssConfig {
            blocker_search_taps: MAX_TAPS + 1,
            ..ok
        }
        .validate()
        .is_err());
        assert!(PcssConfig {
            angular_radius: f32::NAN,
            ..ok
        }
        .validate()
        .is_err());
        assert!(PcssConfig {
            min_filter_radius: 40.0,
            ..ok
        }
        .validate()
        .is_err());
        assert!((ok.light_size(false) - 0.02f32.tan()).abs() < 1e-7);
        assert_eq!(ok.light_size(true), 0.05);
    }
}
