//! The hybrid of the talk: `L = saturate(BD / WSS * PHS)`, `FS = lerp(RTS, PCSS, L)`, as two passes (the
//! lerp factor is a resource of its own, which the talk visualises) and their CPU mirrors.
//!
//! Reads: blocker distance (lerp factor); RTS, PCSS, L (blend). Writes: lerp factor; hybrid visibility.

use crate::gpu_types::HybridPush;
use crate::screen_pass::{visibility_image, ScreenPass};
use crate::shaders::output_variant;
use crate::PassError;
use rhi::{BindingKind, Device, Encoder, Image, Resource};

/// The blend's per-scene constants.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HybridConfig {
    /// WSS: world-space scale, chosen for the model (default 1, in world units).
    pub world_space_scale: f32,
    /// PHS: the talk's "desired percentage of hard shadow" (default 4). With the talk's formula a larger
    /// value reaches `L = 1` (all PCSS) at a shorter blocker distance, `WSS / PHS`.
    pub hard_shadow_percentage: f32,
}

impl Default for HybridConfig {
    fn default() -> Self {
        Self {
            world_space_scale: 1.0,
            hard_shadow_percentage: 4.0,
        }
    }
}

impl HybridConfig {
    /// WSS must be finite and positive, PHS finite and non-negative.
    pub fn validate(&self) -> Result<(), PassError> {
        let wss_ok = self.world_space_scale.is_finite() && self.world_space_scale > 0.0;
        let phs_ok = self.hard_shadow_percentage.is_finite() && self.hard_shadow_percentage >= 0.0;
        if !(wss_ok && phs_ok) {
            return Err(PassError::InvalidConfig(
                "hybrid: the world-space scale must be positive and the percentage of hard shadow \
                 non-negative, both finite"
                    .into(),
            ));
        }
        Ok(())
    }

    /// The GPU's lerp factor for a blocker distance (see [`lerp_factor`]).
    pub fn lerp_factor(&self, blocker_distance: f32) -> f32 {
        lerp_factor(
            blocker_distance,
            self.world_space_scale,
            self.hard_shadow_percentage,
        )
    }
}

/// `L = saturate(BD / WSS * PHS)` for a blocker at `bd`; 0 where there is no blocker (`bd <= 0`: lit,
/// background, or a receiver facing away from the light), so that the hybrid there is the ray-traced
/// result. Mirrors `lerp_factor.comp`.
pub fn lerp_factor(bd: f32, wss: f32, phs: f32) -> f32 {
    if bd > 0.0 {
        (bd / wss * phs).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// `FS = lerp(RTS, PCSS, L)`, written so that `L = 0` gives exactly RTS and `L = 1` exactly PCSS. Mirrors
/// `hybrid_blend.comp`.
pub fn blend(rts: f32, pcss: f32, l: f32) -> f32 {
    rts * (1.0 - l) + pcss * l
}

/// The lerp-factor pass and its output.
pub struct LerpFactorPass {
    step: ScreenPass,
    /// `R32_SFLOAT` lerp factor in [0, 1].
    pub output: Image,
}

impl LerpFactorPass {
    /// Creates the pass over the ray-traced `blocker_distance`.
    pub fn new(device: &Device, blocker_distance: &Image) -> Result<Self, PassError> {
        let (w, h) = (blocker_distance.width(), blocker_distance.height());
        let output = visibility_image(device, "lerp factor", w, h)?;
        let step = ScreenPass::new(
            device,
            "lerp factor",
            "lerp_factor.comp",
            &[BindingKind::StorageImage, BindingKind::StorageImage],
            &[Resource::Image(blocker_distance), Resource::Image(&output)],
            std::mem::size_of::<HybridPush>() as u32,
        )?;
        Ok(Self { step, output })
    }

    /// Records the pass (images in `UnorderedAccess` state).
    pub fn record(&self, enc: &mut Encoder<'_>, config: &HybridConfig) -> Result<(), PassError> {
        let push = push(&self.output, config);
        self.step
            .record(enc, bytemuck::bytes_of(&push), push.width, push.height)
    }
}

/// The blend pass and its output.
pub struct BlendPass {
    step: ScreenPass,
    /// `R32_SFLOAT` hybrid visibility.
    pub output: Image,
}

impl BlendPass {
    /// Creates the pass blending `rts` and `pcss` by `lerp_factor` into `output` when given (else an image
    /// of its own).
    pub fn new(
        device: &Device,
        rts: &Image,
        pcss: &Image,
        lerp_factor: &Image,
        output: Option<Image>,
    ) -> Result<Self, PassError> {
        let output = match output {
            Some(image) => image,
            None => visibility_image(device, "hybrid visibility", rts.width(), rts.height())?,
        };
        let step = ScreenPass::new(
            device,
            "hybrid blend",
            &output_variant("hybrid_blend.comp", output.format())?,
            &[BindingKind::StorageImage; 4],
            &[
                Resource::Image(rts),
                Resource::Image(pcss),
                Resource::Image(lerp_factor),
                Resource::Image(&output),
            ],
            std::mem::size_of::<HybridPush>() as u32,
        )?;
        Ok(Self { step, output })
    }

    /// Records the pass (images in `UnorderedAccess` state).
    pub fn record(&self, enc: &mut Encoder<'_>, config: &HybridConfig) -> Result<(), PassError> {
        let push = push(&self.output, config);
        self.step
            .record(enc, bytemuck::bytes_of(&push), push.width, push.height)
    }
}

fn push(output: &Image, config: &HybridConfig) -> HybridPush {
    HybridPush {
        width: output.width(),
        height: output.height(),
        world_space_scale: config.world_space_scale,
        hard_shadow_percentage: config.hard_shadow_percentage,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lerp_factor_follows_the_talk() {
        // L = saturate(BD / WSS * PHS).
        assert_eq!(lerp_factor(0.5, 2.0, 1.0), 0.25);
        assert_eq!(lerp_factor(0.5, 2.0, 2.0), 0.5);
        assert_eq!(lerp_factor(0.25, 1.0, 4.0), 1.0);
        // Saturated above WSS / PHS.
        assert_eq!(lerp_factor(10.0, 1.0, 4.0), 1.0);
        // As BD -> 0 the ray-traced result wins.
        assert_eq!(lerp_factor(1e-9, 1.0, 4.0), 4e-9);
        assert_eq!(lerp_factor(0.0, 1.0, 4.0), 0.0);
        // No blocker (lit or background, BD = -1): hard result.
        assert_eq!(lerp_factor(-1.0, 1.0, 4.0), 0.0);
        // PHS = 0: always the hard shadow.
        assert_eq!(lerp_factor(3.0, 1.0, 0.0), 0.0);
        // Monotonic in BD.
        let mut last = 0.0;
        for i in 0..100 {
            let l = lerp_factor(i as f32 * 0.01, 1.0, 2.0);
            assert!(l >= last && (0.0..=1.0).contains(&l));
            last = l;
        }
    }

    #[test]
    fn blend_is_exact_at_the_ends() {
        for (rts, pcss) in [(0.0, 0.3), (1.0, 0.7), (0.4, 0.0), (1.0, 1.0)] {
            assert_eq!(blend(rts, pcss, 0.0), rts);
            assert_eq!(blend(rts, pcss, 1.0), pcss);
        }
        assert!((blend(0.0, 1.0, 0.25) - 0.25).abs() < 1e-7);
        assert!((blend(1.0, 0.5, 0.5) - 0.75).abs() < 1e-7);
    }

    #[test]
    fn config_validation() {
        let ok = HybridConfig::default();
        assert!(ok.validate().is_ok());
        assert_eq!(ok.lerp_factor(0.125), 0.5);
        for bad in [
            HybridConfig {
                world_space_scale: 0.0,
                ..ok
            },
            HybridConfig {
                world_space_scale: f32::INFINITY,
                ..ok
            },
            HybridConfig {
                hard_shadow_percentage: -1.0,
                ..ok
            },
            HybridConfig {
                hard_shadow_percentage: f32::NAN,
                ..ok
            },
        ] {
            assert!(bad.validate().is_err(), "{bad:?}");
        }
    }
}
