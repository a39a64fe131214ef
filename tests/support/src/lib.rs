//! Test support: [`ShadowRenderer`], a frame that drives one [`ShadowPipeline`] of the passes directly
//! (the demo's G-buffer over its own scene buffers, the pipeline's passes), submitted and waited for, with read-back of
//! every output its plan produced. The integration tests and wgpu_host's tests compare the plugin's C ABI
//! frames with it; the demo itself drives the plugin through its public API only.

use demo_engine::gbuffer::{GBufferLayout, GBufferPass, GBufferPush, GBufferTargets};
use demo_engine::scene_buffers::SceneBuffers;
use demo_engine::{read_images, FrameImages, FrameOutput, View};
use hrts_lab::frames::ViewInputs;
use passes::{
    FrameInputs, FrameReport, PassError, PassId, ResourceId, ShadowConfig, ShadowInputs,
    ShadowMode, ShadowPipeline,
};
use rhi::{Barrier, Buffer, BufferUsage, Device, Image, MemoryLocation, ResourceState as S};

/// The demo frame: a G-buffer of its own plus the engine-facing [`ShadowPipeline`].
pub struct ShadowRenderer {
    targets: GBufferTargets,
    scene: SceneBuffers,
    gbuffer: GBufferPass,
    pipeline: ShadowPipeline,
}

impl ShadowRenderer {
    /// Uploads `view`'s scene (into the demo's buffers, which its G-buffer draws, and into the pipeline's
    /// geometry) and creates every pass for a frame of its size.
    pub fn new(
        device: &Device,
        view: &View,
        config: impl Into<ShadowConfig>,
    ) -> Result<Self, PassError> {
        let (width, height) = (view.width, view.height);
        if width == 0 || height == 0 {
            return Err(PassError::InvalidConfig(
                "frame size must be non-zero".into(),
            ));
        }
        let geometry = view.upload(device)?;
        let scene = SceneBuffers::upload(device, &view.scene)
            .map_err(|e| PassError::InvalidGeometry(format!("{e:#}")))?;
        let config = with_blocker_distance(config.into());
        let targets = GBufferTargets::new(device, width, height, GBufferLayout::ANALYSIS)?;
        let inputs = ShadowInputs {
            depth: &targets.depth,
            normal: &targets.normal,
            surface: hrts::passes_bridge::surface_input(
                targets.layout.normal_encoding,
                targets.layout.normal_space,
            )
            .map_err(|e| PassError::InvalidConfig(e.to_string()))?,
            direct_output: None,
            scratch_set: 0,
        };
        let pipeline = ShadowPipeline::new(device, geometry, &inputs, config)?;
        let gbuffer = GBufferPass::new(device, &scene, &targets.layout)?;
        Ok(Self {
            targets,
            scene,
            gbuffer,
            pipeline,
        })
    }

    /// The engine-facing pipeline.
    pub fn pipeline(&self) -> &ShadowPipeline {
        &self.pipeline
    }

    /// Renders one frame and waits for it.
    pub fn render(
        &mut self,
        device: &Device,
        inputs: &FrameInputs,
    ) -> Result<FrameReport, PassError> {
        let push = GBufferPush::for_camera(
            &hrts_lab::frames::camera_of(inputs),
            self.scene.origin(),
            &self.targets.layout,
        )?;
        let Self {
            targets,
            scene,
            gbuffer,
            pipeline,
        } = self;
        pipeline.begin_frame(inputs)?;
        device.submit_and_wait(|enc| {
            let (prim_buffer, rest) = PassId::ALL.split_at(1);
            pipeline.record_passes(enc, prim_buffer).map_err(into_rhi)?;
            enc.barriers(&targets.to_render());
            gbuffer.record(enc, targets, &push, scene)?;
            enc.barriers(&[
                Barrier::Image {
                    image: &targets.normal,
                    before: S::RenderTarget,
                    after: S::ShaderResource,
                },
                Barrier::Image {
                    image: &targets.depth,
                    before: S::DepthWrite,
                    after: S::ShaderResource,
                },
            ]);
            pipeline.record_passes(enc, rest).map_err(into_rhi)
        })?;
        self.pipeline.report()
    }

    /// Reads back the last frame's outputs (the primitive map's list entries only if `with_entries`).
    pub fn read_back(&self, device: &Device, with_entries: bool) -> Result<FrameImages, PassError> {
        let p = &self.pipeline;
        let mut wanted = self.targets.outputs();
        wanted.extend(FrameOutput::PIPELINE.iter().filter_map(|&(output, r)| {
            p.image(hrts::passes_bridge::resource_id(r))
                .map(|image| (image, S::UnorderedAccess, output))
        }));
        wanted.push((p.output(), S::UnorderedAccess, FrameOutput::Output));
        let images: Vec<(&Image, S)> = wanted.iter().map(|&(i, s, _)| (i, s)).collect();
        let bytes = read_images(device, &images)?;
        let mut frame = FrameImages::default();
        for ((_, _, output), bytes) in wanted.iter().zip(&bytes) {
            frame.insert(*output, bytes, p.geometry().origin());
        }
        let mut lists = vec![ResourceId::PrimListOffsets];
        if with_entries {
            lists.push(ResourceId::PrimListEntries);
        }
        let buffers: Vec<&Buffer> = lists.iter().filter_map(|&r| p.buffer(r)).collect();
        let mut words = read_buffers(device, &buffers)?.into_iter();
        if let (Some(packed), Some(map)) = (words.next(), p.primitive_map()) {
            let packed: Vec<u32> = bytemuck::pod_collect_to_vec(&packed);
            frame.list_offsets =
                passes::unpack_list_offsets(&packed, map.config().texels() as usize)
                    .map_err(PassError::InvalidConfig)?;
        }
        frame.list_entries = words
            .next()
            .map(|b| bytemuck::pod_collect_to_vec(&b))
            .unwrap_or_default();
        Ok(frame)
    }
}

/// Copies `buffers` (storage writes made visible by the frame's last UAV barrier) into host memory, waits,
/// and returns their bytes.
fn read_buffers(device: &Device, buffers: &[&Buffer]) -> Result<Vec<Vec<u8>>, PassError> {
    let staging = buffers
        .iter()
        .map(|b| {
            device.create_buffer(
                "read-back",
                b.size(),
                BufferUsage::COPY_DST,
                MemoryLocation::GpuToCpu,
            )
        })
        .collect::<Result<Vec<_>, _>>()?;
    device.submit_and_wait(|enc| {
        enc.barriers(&[Barrier::Global {
            before: S::UnorderedAccess,
            after: S::CopySource,
        }]);
        for (src, dst) in buffers.iter().zip(&staging) {
            enc.copy_buffer(src, dst)?;
        }
        enc.barriers(&[Barrier::Global {
            before: S::CopyDest,
            after: S::HostRead,
        }]);
        Ok(())
    })?;
    staging.iter().map(|b| Ok(b.read()?.to_vec())).collect()
}

fn into_rhi(e: PassError) -> rhi::RhiError {
    match e {
        PassError::Rhi(r) => r,
        other => rhi::RhiError::InvalidArgument(other.to_string()),
    }
}

/// `config` asking for the ray trace's blocker distance when its mode traces rays (hard, hybrid): the
/// tests compare blocker distances with the exact reference, and the plugin allocates them only when
/// asked (or for the hybrid).
pub fn with_blocker_distance(mut config: ShadowConfig) -> ShadowConfig {
    if matches!(config.mode, ShadowMode::Hard | ShadowMode::Hybrid) {
        config.extra_outputs = config.extra_outputs.with(ResourceId::BlockerDistance);
    }
    config
}
