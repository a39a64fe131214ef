//! What the demo reads back of a frame: the G-buffer and the plugin's outputs ([`FrameImages`]), and the
//! read-back itself.

use glam::DVec3;
use hrts::Resource;
use rhi::{Barrier, BufferUsage, Device, Image, MemoryLocation, ResourceState as S, RhiError};

/// Everything the frame produced, read back to the host. Row-major, y = 0 at the top. Outputs the plan
/// did not produce are empty.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FrameImages {
    /// World position (frame origin added back in f64), w = 1 on geometry.
    pub position: Vec<[f32; 4]>,
    /// Camera-facing normal, w = 1 on geometry.
    pub normal: Vec<[f32; 4]>,
    /// Reversed-Z depth.
    pub depth: Vec<f32>,
    /// Ray-traced visibility (1 = lit).
    pub visibility: Vec<f32>,
    /// Blocker distance (`HRTS_RESOURCE_BLOCKER_DISTANCE`).
    pub blocker_distance: Vec<f32>,
    /// Occupancy view, N×N RGBA8.
    pub occupancy: Vec<[u8; 4]>,
    /// Primitive map list offsets, unpacked: texel t's list is `list_entries[list_offsets.range(t)]`.
    pub list_offsets: hrts::ListOffsets,
    /// Primitive map list entries (triangle indices); empty unless requested.
    pub list_entries: Vec<u32>,
    /// Classic single-tap shadow-map visibility.
    pub shadow_map_visibility: Vec<f32>,
    /// PCSS visibility.
    pub pcss: Vec<f32>,
    /// Ray-traced visibility after FXAA.
    pub antialiased: Vec<f32>,
    /// Hybrid lerp factor.
    pub lerp_factor: Vec<f32>,
    /// Hybrid visibility.
    pub hybrid: Vec<f32>,
    /// The final output: the layer of the light in the output image.
    pub output: Vec<f32>,
}

/// Copies `images` (each in the given state, restored afterwards) into host buffers, waits, and returns
/// their bytes (all layers, tightly packed). An image listed twice is read twice.
pub fn read_images(device: &Device, images: &[(&Image, S)]) -> Result<Vec<Vec<u8>>, RhiError> {
    let buffers = images
        .iter()
        .map(|(img, _)| {
            device.create_buffer(
                "read-back",
                img.byte_size(),
                BufferUsage::COPY_DST,
                MemoryLocation::GpuToCpu,
            )
        })
        .collect::<Result<Vec<_>, _>>()?;
    // Transition each image once.
    let mut distinct: Vec<(&Image, S)> = Vec::new();
    for &(image, state) in images {
        if !distinct.iter().any(|(i, _)| std::ptr::eq(*i, image)) {
            distinct.push((image, state));
        }
    }
    device.submit_and_wait(|enc| {
        let to_copy: Vec<Barrier<'_>> = distinct
            .iter()
            .map(|&(image, before)| Barrier::Image {
                image,
                before,
                after: S::CopySource,
            })
            .collect();
        enc.barriers(&to_copy);
        for ((img, _), buf) in images.iter().zip(&buffers) {
            enc.copy_image_to_buffer(img, buf)?;
        }
        let back: Vec<Barrier<'_>> = distinct
            .iter()
            .map(|&(image, after)| Barrier::Image {
                image,
                before: S::CopySource,
                after,
            })
            .collect();
        enc.barriers(&back);
        enc.barriers(&[Barrier::Global {
            before: S::CopyDest,
            after: S::HostRead,
        }]);
        Ok(())
    })?;
    buffers.iter().map(|b| Ok(b.read()?.to_vec())).collect()
}

/// Where a read-back image goes in [`FrameImages`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrameOutput {
    /// [`FrameImages::position`] (read in frame coordinates; the origin is added back).
    Position,
    /// [`FrameImages::normal`].
    Normal,
    /// [`FrameImages::depth`].
    Depth,
    /// [`FrameImages::visibility`].
    Visibility,
    /// [`FrameImages::blocker_distance`].
    BlockerDistance,
    /// [`FrameImages::occupancy`].
    Occupancy,
    /// [`FrameImages::shadow_map_visibility`].
    ShadowMapVisibility,
    /// [`FrameImages::pcss`].
    Pcss,
    /// [`FrameImages::antialiased`].
    Antialiased,
    /// [`FrameImages::lerp_factor`].
    LerpFactor,
    /// [`FrameImages::hybrid`].
    Hybrid,
    /// [`FrameImages::output`].
    Output,
}

impl FrameOutput {
    /// The pipeline resources read back into [`FrameImages`].
    pub const PIPELINE: [(FrameOutput, Resource); 8] = [
        (Self::Visibility, Resource::RtVisibility),
        (Self::BlockerDistance, Resource::BlockerDistance),
        (Self::Occupancy, Resource::Occupancy),
        (Self::ShadowMapVisibility, Resource::ShadowMapVisibility),
        (Self::Pcss, Resource::Pcss),
        (Self::Antialiased, Resource::RtAntialiased),
        (Self::LerpFactor, Resource::LerpFactor),
        (Self::Hybrid, Resource::Hybrid),
    ];
}

impl FrameImages {
    /// Stores the read-back `bytes` of `output`; `origin` is the frame origin of the position image.
    pub fn insert(&mut self, output: FrameOutput, bytes: &[u8], origin: DVec3) {
        let floats = || bytemuck::pod_collect_to_vec::<u8, f32>(bytes);
        match output {
            FrameOutput::Position => {
                self.position = to_world(bytemuck::pod_collect_to_vec(bytes), origin)
            }
            FrameOutput::Normal => self.normal = bytemuck::pod_collect_to_vec(bytes),
            FrameOutput::Depth => self.depth = floats(),
            FrameOutput::Visibility => self.visibility = floats(),
            FrameOutput::BlockerDistance => self.blocker_distance = floats(),
            FrameOutput::Occupancy => self.occupancy = bytemuck::pod_collect_to_vec(bytes),
            FrameOutput::ShadowMapVisibility => self.shadow_map_visibility = floats(),
            FrameOutput::Pcss => self.pcss = floats(),
            FrameOutput::Antialiased => self.antialiased = floats(),
            FrameOutput::LerpFactor => self.lerp_factor = floats(),
            FrameOutput::Hybrid => self.hybrid = floats(),
            FrameOutput::Output => self.output = floats(),
        }
    }
}

fn to_world(mut frame: Vec<[f32; 4]>, origin: DVec3) -> Vec<[f32; 4]> {
    for p in frame.iter_mut().filter(|p| p[3] != 0.0) {
        let w = DVec3::new(p[0].into(), p[1].into(), p[2].into()) + origin;
        [p[0], p[1], p[2]] = w.as_vec3().to_array();
    }
    frame
}
