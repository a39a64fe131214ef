//! The visibility of a light shadowed through several frusta (a point light's cube faces, a wide spot
//! light's faces): the minimum over the frusta's outputs, each of which is lit outside its own frustum.
//!
//! Reads: each frustum's output. Writes: the combined visibility.

use crate::screen_pass::{visibility_image, ScreenPass};
use crate::shaders::output_variant;
use crate::PassError;
use rhi::{Barrier, BindingKind, Device, Encoder, Image, Resource, ResourceState as S};

/// The min-combine pass of one light and its output.
pub struct MinCombine {
    steps: Vec<ScreenPass>,
    /// Visibility of the light: `R32_SFLOAT`, or the engine's `R16_SFLOAT` or `R8_UNORM` layer.
    pub output: Image,
}

impl MinCombine {
    /// Creates the pass over `frusta` (at least one, all of the same size), writing `output` when given
    /// (a storage image of their size, such as a layer of the engine's output, in a format of
    /// [`output_variant`]) or an image of its own.
    pub fn new(
        device: &Device,
        frusta: &[&Image],
        output: Option<Image>,
    ) -> Result<Self, PassError> {
        let first = frusta
            .first()
            .ok_or_else(|| PassError::InvalidConfig("a light needs at least one frustum".into()))?;
        let output = match output {
            Some(image) => image,
            None => visibility_image(
                device,
                "light visibility (min over frusta)",
                first.width(),
                first.height(),
            )?,
        };
        let shader_name = output_variant("min_combine.comp", output.format())?;
        let steps = frusta
            .iter()
            .map(|frustum| {
                ScreenPass::new(
                    device,
                    "min over frusta",
                    &shader_name,
                    &[BindingKind::StorageImage, BindingKind::StorageImage],
                    &[Resource::Image(frustum), Resource::Image(&output)],
                    12,
                )
            })
            .collect::<Result<_, _>>()?;
        Ok(Self { steps, output })
    }

    /// GPU bytes of the combined image.
    pub fn bytes(&self) -> u64 {
        self.output.byte_size()
    }

    /// Records the minimum over the outputs of the frusta marked in `recorded` (in `UnorderedAccess`
    /// state; the others were not recorded this frame and count as lit everywhere), or 1 if none is. The
    /// output's former contents are discarded and it is left in `UnorderedAccess` state.
    pub fn record(&self, enc: &mut Encoder<'_>, recorded: &[bool]) -> Result<(), PassError> {
        if recorded.len() != self.steps.len() {
            return Err(PassError::InvalidConfig(format!(
                "{} frusta flagged for a light of {}",
                recorded.len(),
                self.steps.len()
            )));
        }
        let (width, height) = (self.output.width(), self.output.height());
        if !recorded.contains(&true) {
            enc.begin_pass("min over frusta");
            enc.barriers(&[Barrier::Image {
                image: &self.output,
                before: S::Undefined,
                after: S::CopyDest,
            }]);
            enc.clear_uint(&self.output, 1.0f32.to_bits());
            enc.barriers(&[Barrier::Image {
                image: &self.output,
                before: S::CopyDest,
                after: S::UnorderedAccess,
            }]);
            enc.end_pass();
            return Ok(());
        }
        enc.barriers(&[Barrier::Image {
            image: &self.output,
            before: S::Undefined,
            after: S::UnorderedAccess,
        }]);
        for (folded, (step, _)) in self
            .steps
            .iter()
            .zip(recorded)
            .filter(|(_, &r)| r)
            .enumerate()
        {
            let push: [u32; 3] = [width, height, u32::from(folded > 0)];
            step.record(enc, bytemuck::bytes_of(&push), width, height)?;
            enc.barriers(&[Barrier::Uav]);
        }
        Ok(())
    }
}
