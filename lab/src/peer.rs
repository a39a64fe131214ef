//! The ray-tracing-pipeline peer on the demo's frame: the same shadow rays as the primitive-map ray trace,
//! traced through the GPU's ray-tracing pipeline over acceleration structures the driver builds from a
//! prim buffer of the scene's triangles in the frame's coordinates ([`passes::rt_peer::RtPeerPass`]). What
//! a user would pick instead of our technique.
//! For area shadows ([`run_area_peer`]) each of a pixel's light samples is its own ray: the same samples
//! as the plugin's area trace, so equal samples give equal answers.

use crate::frames::upload_scene;
use anyhow::{Context as _, Result};
use demo_engine::plugin::PluginRenderer;
use demo_engine::{read_images, FrameImages, FrameOutput};
use passes::gpu_types::{AreaSamples, RayTraceConstants};
use passes::prim_buffer::PrimBufferPass;
use passes::rt_peer::{area_peer_constants, shadow_ray_constants, RtPeerPass};
use passes::{FrameInputs, PassError};
use rhi::{Barrier, Device, ResourceState as S};
use scene::Scene;

/// The name of the peer's build pass (bottom and top level).
pub const BUILD_PASS: &str = "rt peer build";
/// The name of the peer's trace pass.
pub const TRACE_PASS: &str = "rt peer trace";

/// What the peer measured on one frame.
#[derive(Debug, Clone, PartialEq)]
pub struct PeerRun {
    /// Median GPU milliseconds of a full acceleration-structure build (bottom + top level).
    pub build_ms: f64,
    /// Median GPU milliseconds of tracing the frame's shadow rays.
    pub trace_ms: f64,
    /// Visibility of the last frame (1 = lit), row-major, y = 0 at the top.
    pub visibility: Vec<f32>,
}

/// Builds the acceleration structures of `scene` (the scene `renderer` draws) and traces the shadow rays
/// of the frame `renderer` last rendered with `inputs`, `frames` times (at least 2), each frame one
/// submission timed by GPU timestamps. Returns the medians over the frames after the first and the last
/// frame's visibility. On a device without ray tracing the error is a [`PassError::Unsupported`] naming
/// what is missing (`downcast_ref` tells it apart).
pub fn run_peer(
    device: &Device,
    renderer: &PluginRenderer,
    scene: &Scene,
    inputs: &FrameInputs,
    frames: u32,
) -> Result<PeerRun> {
    let targets = renderer.targets();
    let size = (targets.depth.width(), targets.depth.height());
    let constants = shadow_ray_constants(inputs, renderer.scene().origin(), size.0, size.1)?;
    run(device, renderer, scene, &constants, None, frames)
}

/// [`run_peer`] for area shadows: each of the `samples` light samples of every pixel of a light of size
/// `light_size` (a directional light's angular radius, a spot or point light's emitter radius) traced as
/// its own any-hit ray, the samples the plugin's area trace takes. The visibility is the visible fraction.
pub fn run_area_peer(
    device: &Device,
    renderer: &PluginRenderer,
    scene: &Scene,
    inputs: &FrameInputs,
    light_size: f32,
    samples: u32,
    frames: u32,
) -> Result<PeerRun> {
    let targets = renderer.targets();
    let size = (targets.depth.width(), targets.depth.height());
    let (constants, area) =
        area_peer_constants(inputs, renderer.scene().origin(), size, light_size, samples)?;
    run(device, renderer, scene, &constants, Some(&area), frames)
}

fn run(
    device: &Device,
    renderer: &PluginRenderer,
    scene: &Scene,
    constants: &RayTraceConstants,
    area: Option<&AreaSamples>,
    frames: u32,
) -> Result<PeerRun> {
    // The scene's triangles relative to the frame origin the renderer's G-buffer and the constants use.
    let geometry = upload_scene(device, scene)?;
    let drawn = renderer.scene();
    if (geometry.origin(), geometry.triangle_count()) != (drawn.origin(), drawn.triangle_count()) {
        anyhow::bail!("the peer's scene is not the one the renderer draws");
    }
    let prim_buffer = PrimBufferPass::new(device, &geometry)?;
    device.submit_and_wait(|enc| {
        prim_buffer.record(enc, &geometry, None).map_err(into_rhi)?;
        enc.barriers(&[Barrier::Full]);
        Ok(())
    })?;
    let targets = renderer.targets();
    let (width, height) = (targets.depth.width(), targets.depth.height());
    let normal = targets
        .world_normal()
        .context("the ray-tracing peer reads the analysis G-buffer's world normals")?;
    let frames = frames.max(2);
    let progress = host_demo::progress::phase("RT peer frames", u64::from(frames));
    let new = if area.is_some() {
        RtPeerPass::new_area
    } else {
        RtPeerPass::new
    };
    let mut peer = new(
        device,
        prim_buffer.prims(),
        geometry.triangle_count(),
        &targets.depth,
        normal,
        width,
        height,
    )?;
    let timer = device.create_timer(2)?;
    let (mut build, mut trace) = (Vec::new(), Vec::new());
    for _ in 0..frames {
        device.submit_and_wait(|enc| {
            enc.attach_timer(&timer);
            peer.record_build(enc).map_err(into_rhi)?;
            match area {
                Some(samples) => peer.record_area_trace(enc, constants, samples),
                None => peer.record_trace(enc, constants),
            }
            .map_err(into_rhi)
        })?;
        for t in timer.resolve()? {
            match t.name.as_str() {
                BUILD_PASS => build.push(t.ms),
                TRACE_PASS => trace.push(t.ms),
                _ => {}
            }
        }
        progress.inc(1);
    }
    let mut images = FrameImages::default();
    for bytes in read_images(device, &[(&peer.visibility, S::UnorderedAccess)])? {
        images.insert(FrameOutput::Visibility, &bytes, geometry.origin());
    }
    Ok(PeerRun {
        build_ms: steady_median(&build),
        trace_ms: steady_median(&trace),
        visibility: images.visibility,
    })
}

/// Median of `samples` after the first (warm-up) one; NaN without samples.
fn steady_median(samples: &[f64]) -> f64 {
    let mut steady = samples.get(1..).unwrap_or_default().to_vec();
    steady.sort_by(f64::total_cmp);
    steady.get(steady.len() / 2).copied().unwrap_or(f64::NAN)
}

/// A pass's error in the form `Device::submit_and_wait` passes on.
fn into_rhi(e: PassError) -> rhi::RhiError {
    match e {
        PassError::Rhi(r) => r,
        other => rhi::RhiError::InvalidArgument(other.to_string()),
    }
}

#[cfg(test)]
mod tests {
    use super::steady_median;

    #[test]
    fn median_skips_the_warm_up_frame() {
        assert_eq!(steady_median(&[100.0, 3.0, 1.0, 2.0]), 2.0);
        assert_eq!(steady_median(&[100.0, 4.0, 1.0, 2.0, 3.0]), 3.0);
        assert!(steady_median(&[100.0]).is_nan());
    }
}
