//! G-buffer for the demo host: depth, the normal target the plugin reads (in any of the encodings engines
//! keep), and, for analysis, frame-relative positions and world normals in RGBA32F.
//!
//! Reads: the scene's index and vertex buffers ([`SceneBuffers`]). Writes: the targets of its [`GBufferLayout`]. Shaders: `gbuffer.vert`
//! and `gbuffer.frag` (analysis), `gbuffer_encoded.frag` (analysis and an encoded normal target),
//! `gbuffer_compact.frag` (depth and the encoded normal alone) in `demo_engine/shaders/`.

use crate::frame_images::{FrameImages, FrameOutput};
use crate::scene_buffers::SceneBuffers;
use crate::view::CameraMatrices;
use bytemuck::{Pod, Zeroable};
use glam::{DMat4, DVec3, Mat3, Mat4, Vec4};
use hrts::{NormalEncoding, NormalSpace};
use rhi::{
    Barrier, BindGroup, BindingKind, ColorTarget, DepthState, DepthTarget, Device, Encoder, Format,
    GraphicsPipeline, GraphicsPipelineDesc, Image, ImageDesc, ImageUsage, Resource,
    ResourceState as S, RhiError,
};

mod shaders {
    include!(concat!(env!("OUT_DIR"), "/shaders.rs"));
}

/// SPIR-V words of the engine's embedded shader `name` (file name in `demo_engine/shaders/`).
fn shader(name: &str) -> Result<Vec<u32>, RhiError> {
    shaders::spirv(name)
        .ok_or_else(|| RhiError::InvalidArgument(format!("no embedded shader named {name}")))
}

/// Push constants of the G-buffer (`gbuffer_push.glsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct GBufferPush {
    /// proj * view with the camera at the origin.
    pub view_proj_rel: Mat4,
    /// Camera position in frame coordinates (xyz); w: the normal target's code ([`GBufferLayout::code`]).
    pub camera_pos: Vec4,
    /// The view rotation's rows (world to view).
    pub view_rows: [Vec4; 3],
    /// The frame origin in world coordinates (xyz, f32), subtracted from every vertex.
    pub origin: Vec4,
}

const _: () = assert!(std::mem::size_of::<GBufferPush>() == 144);

impl GBufferPush {
    /// The constants of `camera` for vertices relative to `origin` (f32) and a G-buffer of `layout`: the
    /// view-projection of coordinates relative to the camera, composed in f64 as the plugin composes its own
    /// (`camera_in_frame` of the passes), so that the G-buffer and the plugin agree on every pixel's ray.
    pub fn for_camera(
        camera: &CameraMatrices,
        origin: DVec3,
        layout: &GBufferLayout,
    ) -> Result<Self, RhiError> {
        let relative_view =
            camera.view.as_dmat4() * DMat4::from_translation(camera.position.as_dvec3());
        let view_proj_rel = (camera.proj.as_dmat4() * relative_view).as_mat4();
        let camera_frame = (camera.position.as_dvec3() - origin).as_vec3();
        if !view_proj_rel.is_finite() || !camera_frame.is_finite() {
            return Err(RhiError::InvalidArgument(
                "camera matrices are not finite".into(),
            ));
        }
        let rows = Mat3::from_mat4(camera.view).transpose();
        Ok(Self {
            view_proj_rel,
            camera_pos: camera_frame.extend(layout.code() as f32),
            view_rows: [rows.x_axis, rows.y_axis, rows.z_axis].map(|r| r.extend(0.0)),
            origin: origin.as_vec3().extend(1.0),
        })
    }
}

/// What the demo's G-buffer keeps: the depth format, the normal target the plugin reads (format,
/// encoding, space), and whether it also keeps the analysis targets that read-backs need.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GBufferLayout {
    /// Depth format (reversed Z).
    pub depth: Format,
    /// Format of the normal target the plugin reads.
    pub normal: Format,
    /// How that target encodes the normal.
    pub normal_encoding: NormalEncoding,
    /// The space of the normals it holds.
    pub normal_space: NormalSpace,
    /// Whether the G-buffer keeps frame-relative positions and world normals (RGBA32F) to read back.
    pub analysis: bool,
}

/// The normal targets the demo can keep, by name: every encoding the plugin reads.
pub const NORMAL_TARGETS: [(&str, Format, NormalEncoding, NormalSpace); 8] = [
    (
        "rgba32f-world",
        Format::Rgba32Float,
        NormalEncoding::XyzCoverage,
        NormalSpace::World,
    ),
    (
        "rgba16f-world",
        Format::Rgba16Float,
        NormalEncoding::Xyz,
        NormalSpace::World,
    ),
    (
        "rgb10a2-view",
        Format::Rgb10A2Unorm,
        NormalEncoding::Xyz,
        NormalSpace::View,
    ),
    (
        "rgba8-world",
        Format::Rgba8Unorm,
        NormalEncoding::Xyz,
        NormalSpace::World,
    ),
    (
        "oct-rg16snorm-view",
        Format::Rg16Snorm,
        NormalEncoding::Octahedral,
        NormalSpace::View,
    ),
    (
        "oct-rg16unorm-world",
        Format::Rg16Unorm,
        NormalEncoding::Octahedral,
        NormalSpace::World,
    ),
    (
        "oct-rg16f-view",
        Format::Rg16Float,
        NormalEncoding::Octahedral,
        NormalSpace::View,
    ),
    (
        "oct-rgb10a2-world",
        Format::Rgb10A2Unorm,
        NormalEncoding::Octahedral,
        NormalSpace::World,
    ),
];

impl GBufferLayout {
    /// The analysis G-buffer: D32 depth and RGBA32F world normals with coverage in w, which the plugin
    /// reads as they are, and positions.
    pub const ANALYSIS: Self = Self {
        depth: Format::D32Float,
        normal: Format::Rgba32Float,
        normal_encoding: NormalEncoding::XyzCoverage,
        normal_space: NormalSpace::World,
        analysis: true,
    };

    /// A compact G-buffer as engines keep one: D24S8 depth (D32 where the device cannot render and sample
    /// D24S8) and octahedral view-space normals in RG16F; nothing to read back.
    pub fn compact(device: &Device) -> Self {
        let d24s8 = Format::D24UnormS8Uint;
        let usable = device.can_render(d24s8) && device.can_sample(d24s8);
        Self {
            depth: if usable { d24s8 } else { Format::D32Float },
            normal: Format::Rg16Float,
            normal_encoding: NormalEncoding::Octahedral,
            normal_space: NormalSpace::View,
            analysis: false,
        }
    }

    /// The analysis G-buffer with the normal target named `name` (one of [`NORMAL_TARGETS`]) for the plugin.
    pub fn analysis_with(name: &str) -> Result<Self, String> {
        let &(_, normal, encoding, space) =
            NORMAL_TARGETS.iter().find(|t| t.0 == name).ok_or_else(|| {
                let names: Vec<&str> = NORMAL_TARGETS.iter().map(|t| t.0).collect();
                format!(
                    "unknown normal target {name:?}: one of {}",
                    names.join(", ")
                )
            })?;
        Ok(Self {
            normal,
            normal_encoding: encoding,
            normal_space: space,
            ..Self::ANALYSIS
        })
    }

    /// The shaders' code of the normal target: bit 0 octahedral, bit 1 unorm channels, bit 2 view space.
    pub fn code(&self) -> u32 {
        u32::from(self.normal_encoding == NormalEncoding::Octahedral)
            | u32::from(self.normal.is_unorm()) << 1
            | u32::from(self.normal_space == NormalSpace::View) << 2
    }

    /// Whether the plugin reads the analysis normals themselves (no separate normal target).
    fn reads_analysis_normals(&self) -> bool {
        self.analysis
            && self.normal == Self::ANALYSIS.normal
            && self.normal_encoding == Self::ANALYSIS.normal_encoding
            && self.normal_space == Self::ANALYSIS.normal_space
    }

    /// Colour formats of the pass, in attachment order.
    fn color_formats(&self) -> Vec<Format> {
        match (self.analysis, self.reads_analysis_normals()) {
            (true, true) => vec![Format::Rgba32Float; 2],
            (true, false) => vec![Format::Rgba32Float, Format::Rgba32Float, self.normal],
            (false, _) => vec![self.normal],
        }
    }

    fn fragment_shader(&self) -> &'static str {
        match (self.analysis, self.reads_analysis_normals()) {
            (true, true) => "gbuffer.frag",
            (true, false) => "gbuffer_encoded.frag",
            (false, _) => "gbuffer_compact.frag",
        }
    }
}

/// The analysis targets: what read-backs and reports need besides what the plugin reads.
pub struct AnalysisTargets {
    /// World position in frame coordinates (xyz), w = 1 on geometry, 0 on background.
    pub position: Image,
    /// Geometric normal facing the camera (world xyz), w = 1 on geometry; none when the plugin's normal
    /// target is this very image.
    pub normal: Option<Image>,
}

/// The G-buffer's images.
pub struct GBufferTargets {
    /// What they hold.
    pub layout: GBufferLayout,
    /// The normal target the plugin reads.
    pub normal: Image,
    /// Reversed-Z depth (1 near, 0 far/background).
    pub depth: Image,
    /// The analysis targets, if the layout keeps them.
    pub analysis: Option<AnalysisTargets>,
}

impl GBufferTargets {
    /// Creates `width` x `height` targets of `layout`.
    pub fn new(
        device: &Device,
        width: u32,
        height: u32,
        layout: GBufferLayout,
    ) -> Result<Self, RhiError> {
        for format in [layout.depth, layout.normal] {
            if !device.can_render(format) || !device.can_sample(format) {
                return Err(RhiError::InvalidArgument(format!(
                    "the device cannot render to and sample {format:?} for the G-buffer"
                )));
            }
        }
        let color = |name, format| ImageDesc {
            name,
            format,
            width,
            height,
            layers: 1,
            usage: ImageUsage::COLOR_TARGET | ImageUsage::SAMPLED | ImageUsage::COPY_SRC,
        };
        let analysis = layout
            .analysis
            .then(|| -> Result<_, RhiError> {
                Ok(AnalysisTargets {
                    position: device
                        .create_image(&color("gbuffer position", Format::Rgba32Float))?,
                    normal: (!layout.reads_analysis_normals())
                        .then(|| device.create_image(&color("gbuffer normal", Format::Rgba32Float)))
                        .transpose()?,
                })
            })
            .transpose()?;
        Ok(Self {
            layout,
            normal: device.create_image(&color("gbuffer engine normal", layout.normal))?,
            depth: device.create_image(&ImageDesc {
                name: "gbuffer depth",
                format: layout.depth,
                width,
                height,
                layers: 1,
                usage: ImageUsage::DEPTH_TARGET | ImageUsage::SAMPLED | ImageUsage::COPY_SRC,
            })?,
            analysis,
        })
    }

    /// The colour targets in attachment order.
    pub fn colors(&self) -> Vec<&Image> {
        match &self.analysis {
            Some(a) => match &a.normal {
                Some(n) => vec![&a.position, n, &self.normal],
                None => vec![&a.position, &self.normal],
            },
            None => vec![&self.normal],
        }
    }

    /// The frame-relative positions (analysis layouts).
    pub fn position(&self) -> Option<&Image> {
        self.analysis.as_ref().map(|a| &a.position)
    }

    /// The world normals with coverage in w (analysis layouts).
    pub fn world_normal(&self) -> Option<&Image> {
        self.analysis
            .as_ref()
            .map(|a| a.normal.as_ref().unwrap_or(&self.normal))
    }

    /// The G-buffer images read back, their state after a frame, and where they go in [`FrameImages`]:
    /// the analysis targets and the depth (none for a compact G-buffer).
    pub fn outputs(&self) -> Vec<(&Image, S, FrameOutput)> {
        let (Some(position), Some(normal)) = (self.position(), self.world_normal()) else {
            return Vec::new();
        };
        let normal_state = if std::ptr::eq(normal, &self.normal) {
            S::ShaderResource
        } else {
            S::RenderTarget
        };
        vec![
            (position, S::RenderTarget, FrameOutput::Position),
            (normal, normal_state, FrameOutput::Normal),
            (&self.depth, S::ShaderResource, FrameOutput::Depth),
        ]
    }

    /// Barriers taking every target from undefined contents to its rendering state.
    pub fn to_render(&self) -> Vec<Barrier<'_>> {
        let mut barriers: Vec<Barrier<'_>> = self
            .colors()
            .into_iter()
            .map(|image| Barrier::Image {
                image,
                before: S::Undefined,
                after: S::RenderTarget,
            })
            .collect();
        barriers.push(Barrier::Image {
            image: &self.depth,
            before: S::Undefined,
            after: S::DepthWrite,
        });
        barriers
    }
}

/// The G-buffer pass over the scene's buffers.
pub struct GBufferPass {
    pipeline: GraphicsPipeline,
    group: BindGroup,
}

impl GBufferPass {
    /// Creates the pass rasterizing `scene`'s triangles into targets of `layout`.
    pub fn new(
        device: &Device,
        scene: &SceneBuffers,
        layout: &GBufferLayout,
    ) -> Result<Self, RhiError> {
        let pipeline = device.create_graphics_pipeline(&GraphicsPipelineDesc {
            name: "gbuffer",
            vertex: &shader("gbuffer.vert")?,
            geometry: None,
            fragment: &shader(layout.fragment_shader())?,
            bindings: &[BindingKind::StorageBuffer; 2],
            push_constant_size: std::mem::size_of::<GBufferPush>() as u32,
            color_formats: &layout.color_formats(),
            depth: Some(DepthState {
                format: layout.depth,
                write: true,
                greater: true,
            }),
            conservative_extra_overestimation: None,
            depth_clamp: false,
        })?;
        let group = device.create_bind_group(
            pipeline.layout(),
            &[
                Resource::Buffer(scene.vertices()),
                Resource::Buffer(scene.normals()),
            ],
        )?;
        Ok(Self { pipeline, group })
    }

    /// Records the pass, drawing through `scene`'s index buffer (the scene the pass was created over);
    /// targets must be in `RenderTarget` / `DepthWrite` state.
    pub fn record(
        &self,
        enc: &mut Encoder<'_>,
        targets: &GBufferTargets,
        push: &GBufferPush,
        scene: &SceneBuffers,
    ) -> Result<(), RhiError> {
        enc.begin_pass("gbuffer");
        let colors: Vec<ColorTarget<'_>> = targets
            .colors()
            .into_iter()
            .map(|image| ColorTarget {
                image,
                clear: [0.0; 4],
            })
            .collect();
        enc.begin_rendering(
            (targets.depth.width(), targets.depth.height()),
            &colors,
            Some(DepthTarget {
                image: &targets.depth,
                clear: 0.0,
            }),
        );
        enc.draw_indexed(
            &self.pipeline,
            &self.group,
            bytemuck::bytes_of(push),
            scene.indices(),
            scene.triangle_count() * 3,
        )?;
        enc.end_rendering();
        enc.end_pass();
        Ok(())
    }
}

/// The read-back of a compact G-buffer (RG16F octahedral view-space normals, D24S8 or D32 depth) as the
/// analysis G-buffer holds it: depth, world normals with coverage in w, and world positions rebuilt from
/// depth through `camera` (in f64).
pub fn decode_compact(
    layout: &GBufferLayout,
    camera: &CameraMatrices,
    (width, height): (u32, u32),
    normal: &[u8],
    depth: &[u8],
) -> Result<FrameImages, RhiError> {
    let pixels = width as usize * height as usize;
    if layout.normal != Format::Rg16Float
        || layout.normal_encoding != NormalEncoding::Octahedral
        || layout.normal_space != NormalSpace::View
        || normal.len() != pixels * 4
        || depth.len() != pixels * 4
    {
        return Err(RhiError::InvalidArgument(format!(
            "a compact G-buffer read back holds RG16F octahedral view-space normals, not {layout:?}"
        )));
    }
    let words: Vec<u32> = bytemuck::pod_collect_to_vec(depth);
    let depth: Vec<f32> = words
        .iter()
        .map(|&w| match layout.depth {
            Format::D32Float => f32::from_bits(w),
            _ => (w & 0xFF_FFFF) as f32 / 16_777_215.0,
        })
        .collect();
    let halves: Vec<u16> = bytemuck::pod_collect_to_vec(normal);
    let view_to_world = Mat3::from_mat4(camera.view).inverse().as_dmat3();
    let inverse = (camera.proj.as_dmat4() * camera.view.as_dmat4()).inverse();
    let mut frame = FrameImages::default();
    for (i, &d) in depth.iter().enumerate() {
        if d <= 0.0 {
            frame.normal.push([0.0; 4]);
            frame.position.push([0.0; 4]);
            continue;
        }
        let e = glam::DVec2::new(
            half::f16::from_bits(halves[2 * i]).to_f64(),
            half::f16::from_bits(halves[2 * i + 1]).to_f64(),
        );
        let mut n = DVec3::new(e.x, e.y, 1.0 - e.x.abs() - e.y.abs());
        let t = (-n.z).max(0.0);
        n.x += if n.x >= 0.0 { -t } else { t };
        n.y += if n.y >= 0.0 { -t } else { t };
        let n = (view_to_world * n).normalize_or_zero().as_vec3();
        frame.normal.push([n.x, n.y, n.z, 1.0]);
        let (x, y) = ((i % width as usize) as f64, (i / width as usize) as f64);
        let ndc = DVec3::new(
            (x + 0.5) / f64::from(width) * 2.0 - 1.0,
            (y + 0.5) / f64::from(height) * 2.0 - 1.0,
            f64::from(d),
        );
        let p = inverse.project_point3(ndc).as_vec3();
        frame.position.push([p.x, p.y, p.z, 1.0]);
    }
    frame.depth = depth;
    Ok(frame)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_demo_shader_is_embedded_spirv() {
        let names: Vec<&str> = shaders::ALL.iter().map(|(n, _)| *n).collect();
        assert_eq!(
            names,
            [
                "gbuffer.frag",
                "gbuffer.vert",
                "gbuffer_compact.frag",
                "gbuffer_encoded.frag"
            ]
        );
        for n in names {
            let words = shader(n).unwrap();
            assert!(words.len() > 5, "{n} is too short for a SPIR-V module");
            assert_eq!(words[0], 0x0723_0203, "{n} lacks the SPIR-V magic number");
        }
        assert!(shader("gbuffer.comp").is_err());
    }
}
