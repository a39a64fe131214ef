//! FXAA over the ray-traced visibility.
//!
//! Where it runs: on the ray-traced hard shadow (RTS), before the hybrid blend. The hard edge is the only
//! aliased signal of the chain (one binary ray per pixel); PCSS is already a filtered, band-limited
//! signal, so antialiasing after the blend would blur the soft shadow a second time and let the
//! penumbra's own gradients trigger the edge detector. Blending the antialiased RTS keeps contact
//! shadows (where `L` is 0 and the result is RTS) antialiased, and leaves PCSS untouched where `L` is 1.
//! The containment of the shrinking PCSS is defined against the ray trace before FXAA.
//!
//! Reads: ray-traced visibility. Writes: antialiased visibility.

use crate::gpu_types::FxaaPush;
use crate::screen_pass::{visibility_image, ScreenPass};
use crate::shaders::output_variant;
use crate::PassError;
use glam::Vec4;
use rhi::{BindGroup, BindingKind, Device, Encoder, Image, Resource};

/// Relative contrast (of the neighbourhood's maximum) below which a pixel is left alone.
pub const FXAA_RELATIVE_THRESHOLD: f32 = 0.125;
/// Absolute contrast below which a pixel is left alone.
pub const FXAA_ABSOLUTE_THRESHOLD: f32 = 0.0312;
/// Strength of the sub-pixel term.
pub const FXAA_SUBPIXEL: f32 = 0.75;
/// Longest edge search, in steps.
pub const FXAA_MAX_STEPS: u32 = 12;

/// The FXAA pass and its output.
pub struct FxaaPass {
    step: ScreenPass,
    /// `R32_SFLOAT` antialiased visibility.
    pub output: Image,
}

impl FxaaPass {
    /// Creates the pass over `input` (same size as its output), writing `output` when given (else an image
    /// of its own).
    pub fn new(device: &Device, input: &Image, output: Option<Image>) -> Result<Self, PassError> {
        let output = match output {
            Some(image) => image,
            None => visibility_image(
                device,
                "rt visibility (FXAA)",
                input.width(),
                input.height(),
            )?,
        };
        let step = ScreenPass::new(
            device,
            "FXAA",
            &output_variant("fxaa.comp", output.format())?,
            &[BindingKind::StorageImage, BindingKind::StorageImage],
            &[Resource::Image(input), Resource::Image(&output)],
            std::mem::size_of::<FxaaPush>() as u32,
        )?;
        Ok(Self { step, output })
    }

    /// A bind group of the pass reading `input` (of the same size as the output), for
    /// [`FxaaPass::use_group`].
    pub fn rebound_input(&self, device: &Device, input: &Image) -> Result<BindGroup, PassError> {
        self.step.rebound(device, 0, Resource::Image(input))
    }

    /// Dispatches with `group` (from [`FxaaPass::rebound_input`]) from now on; returns the group used
    /// before: frames in flight may still use it.
    pub fn use_group(&mut self, group: BindGroup) -> BindGroup {
        self.step.use_group(group)
    }

    /// Records the pass; input and output in `UnorderedAccess` state.
    pub fn record(&self, enc: &mut Encoder<'_>) -> Result<(), PassError> {
        let (width, height) = (self.output.width(), self.output.height());
        let push = FxaaPush {
            width,
            height,
            max_steps: FXAA_MAX_STEPS,
            pad: 0,
            params: Vec4::new(
                FXAA_RELATIVE_THRESHOLD,
                FXAA_ABSOLUTE_THRESHOLD,
                FXAA_SUBPIXEL,
                0.0,
            ),
        };
        self.step
            .record(enc, bytemuck::bytes_of(&push), width, height)
    }
}
