//! The visibility of a light shadowed through several frusta (a point light's cube faces, a wide spot
//! light's faces): the minimum over the frusta's outputs, each of which is lit outside its own frustum.
//!
//! Reads: each frustum's output. Writes: the combined visibility.

use crate::screen_pass::{visibility_image, ScreenPass};
use crate::PassError;
use rhi::{Barrier, BindingKind, Device, Encoder, Image, Resource, ResourceState as S};

/// The min-combine pass of one light and its output.
pub struct MinCombine {
    steps: Vec<ScreenPass>,
    /// Fills the output with 1 (no frustum recorded); bound to the output alone, since a frustum that never
    /// ran has an image in no layout to bind.
    lit: ScreenPass,
    /// `R32_SFLOAT` visibility of the light.
    pub output: Image,
}

impl MinCombine {
    /// Creates the pass over `frusta` (at least one, all of the same size), writing `output` when given
    /// (an `R32_SFLOAT` storage image of their size, such as a layer of the engine's output) or an image of
    /// its own.
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
        let steps = frusta
            .iter()
            .map(|frustum| {
                ScreenPass::new(
                    device,
                    "min over frusta",
                    "min_combine.comp",
                    &[BindingKind::StorageImage, BindingKind::StorageImage],
                    &[Resource::Image(frustum), Resource::Image(&output)],
                    12,
                )
            })
            .collect::<Result<_, _>>()?;
        let lit = ScreenPass::new(
            device,
            "min over frusta",
            "min_combine.comp",
            &[BindingKind::StorageImage, BindingKind::StorageImage],
            &[Resource::Image(&output), Resource::Image(&output)],
            12,
        )?;
        Ok(Self { steps, lit, output })
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
        enc.barriers(&[Barrier::Image {
            image: &self.output,
            before: S::Undefined,
            after: S::UnorderedAccess,
        }]);
        let mut folded = 0;
        for (step, _) in self.steps.iter().zip(recorded).filter(|(_, &r)| r) {
            let push: [u32; 3] = [width, height, u32::from(folded > 0)];
            step.record(enc, bytemuck::bytes_of(&push), width, height)?;
            enc.barriers(&[Barrier::Uav]);
            folded += 1;
        }
        if folded == 0 {
            let push: [u32; 3] = [width, height, MODE_LIT];
            self.lit
                .record(enc, bytemuck::bytes_of(&push), width, height)?;
            enc.barriers(&[Barrier::Uav]);
        }
        Ok(())
    }
}

/// Push-constant mode of `min_combine.comp` that writes 1 (no frustum recorded).
const MODE_LIT: u32 = 2;
