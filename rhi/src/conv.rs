//! Pure mappings from the RHI's D3D12-flavoured notions to Vulkan. No GPU needed; unit-tested.

use ash::vk;

/// D3D12 conservative-rasterization tier (`D3D12_CONSERVATIVE_RASTERIZATION_TIER`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum ConservativeRasterTier {
    /// No conservative rasterization.
    NotSupported,
    /// Overestimation uncertainty ≤ 1/2 px; degenerate triangles may be culled after snapping.
    Tier1,
    /// Uncertainty ≤ 1/256 px and post-snap degenerate triangles are rasterized.
    Tier2,
    /// Tier 2 plus inner-coverage input (`SV_InnerCoverage` ~ `FullyCoveredEXT`).
    Tier3,
}

impl ConservativeRasterTier {
    /// Short name used in reports ("none", "tier1", ...).
    pub fn name(self) -> &'static str {
        match self {
            Self::NotSupported => "none",
            Self::Tier1 => "tier1",
            Self::Tier2 => "tier2",
            Self::Tier3 => "tier3",
        }
    }
}

/// Maps `VkPhysicalDeviceConservativeRasterizationPropertiesEXT` (None = extension absent) to a D3D12 tier.
///
/// Tier 1 needs overestimation ≤ 1/2 px; Tier 2 also ≤ 1/256 px and `degenerateTrianglesRasterized`;
/// Tier 3 also `fullyCoveredFragmentShaderInputVariable`.
pub fn conservative_raster_tier(
    props: Option<&vk::PhysicalDeviceConservativeRasterizationPropertiesEXT<'_>>,
) -> ConservativeRasterTier {
    let Some(p) = props else {
        return ConservativeRasterTier::NotSupported;
    };
    let size = p.primitive_overestimation_size;
    if !(0.0..=0.5).contains(&size) {
        return ConservativeRasterTier::NotSupported;
    }
    if size > 1.0 / 256.0 || p.degenerate_triangles_rasterized == vk::FALSE {
        return ConservativeRasterTier::Tier1;
    }
    if p.fully_covered_fragment_shader_input_variable == vk::FALSE {
        return ConservativeRasterTier::Tier2;
    }
    ConservativeRasterTier::Tier3
}

/// D3D12-style resource state, used on both sides of a transition.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ResourceState {
    /// Contents may be discarded. As the state before a transition it waits for every earlier command
    /// (so that discarding an image that an earlier frame still reads is not a write-after-read hazard).
    Undefined,
    /// UAV: read/write storage access from any shader stage.
    UnorderedAccess,
    /// SRV: sampled/read-only access from any shader stage.
    ShaderResource,
    /// Colour attachment.
    RenderTarget,
    /// Depth attachment, written.
    DepthWrite,
    /// Depth read-only (as attachment or sampled).
    DepthRead,
    /// Copy source.
    CopySource,
    /// Copy destination (also clears).
    CopyDest,
    /// Vertex or index buffer input.
    VertexIndex,
    /// Host read-back after GPU writes.
    HostRead,
    /// An engine-owned image in the `VkImageLayout` given by its raw value, used by any earlier or later
    /// command of the engine (full scope on both sides of the transition).
    Engine(i32),
}

impl ResourceState {
    /// The raw `VkImageLayout` an image is in while in this state (what a C ABI exchanges).
    pub fn raw_layout(self) -> i32 {
        state_scope(self).0.as_raw()
    }
}

/// Shader stages the RHI's pipelines use; shader-access states are scoped to these.
pub const SHADER_STAGES: vk::PipelineStageFlags2 = vk::PipelineStageFlags2::from_raw(
    vk::PipelineStageFlags2::VERTEX_SHADER.as_raw()
        | vk::PipelineStageFlags2::GEOMETRY_SHADER.as_raw()
        | vk::PipelineStageFlags2::FRAGMENT_SHADER.as_raw()
        | vk::PipelineStageFlags2::COMPUTE_SHADER.as_raw(),
);

/// `stages` without those a device cannot name in a barrier: the geometry stage unless `geometryShader` is
/// enabled (an engine's device may lack it).
pub fn enabled_stages(
    stages: vk::PipelineStageFlags2,
    geometry_shader: bool,
) -> vk::PipelineStageFlags2 {
    if geometry_shader {
        stages
    } else {
        stages & !vk::PipelineStageFlags2::GEOMETRY_SHADER
    }
}

/// Vulkan scope of a resource state: (image layout, pipeline stages, access mask).
pub fn state_scope(
    state: ResourceState,
) -> (vk::ImageLayout, vk::PipelineStageFlags2, vk::AccessFlags2) {
    use vk::{AccessFlags2 as A, ImageLayout as L, PipelineStageFlags2 as S};
    match state {
        ResourceState::Undefined => (L::UNDEFINED, S::ALL_COMMANDS, A::NONE),
        ResourceState::UnorderedAccess => (
            L::GENERAL,
            SHADER_STAGES,
            A::SHADER_STORAGE_READ | A::SHADER_STORAGE_WRITE,
        ),
        ResourceState::ShaderResource => (
            L::SHADER_READ_ONLY_OPTIMAL,
            SHADER_STAGES,
            A::SHADER_SAMPLED_READ | A::SHADER_STORAGE_READ | A::UNIFORM_READ,
        ),
        ResourceState::RenderTarget => (
            L::COLOR_ATTACHMENT_OPTIMAL,
            S::COLOR_ATTACHMENT_OUTPUT,
            A::COLOR_ATTACHMENT_READ | A::COLOR_ATTACHMENT_WRITE,
        ),
        ResourceState::DepthWrite => (
            L::DEPTH_ATTACHMENT_OPTIMAL,
            S::EARLY_FRAGMENT_TESTS | S::LATE_FRAGMENT_TESTS,
            A::DEPTH_STENCIL_ATTACHMENT_READ | A::DEPTH_STENCIL_ATTACHMENT_WRITE,
        ),
        ResourceState::DepthRead => (
            L::DEPTH_READ_ONLY_OPTIMAL,
            S::EARLY_FRAGMENT_TESTS | S::LATE_FRAGMENT_TESTS | SHADER_STAGES,
            A::DEPTH_STENCIL_ATTACHMENT_READ | A::SHADER_SAMPLED_READ,
        ),
        ResourceState::CopySource => (L::TRANSFER_SRC_OPTIMAL, S::ALL_TRANSFER, A::TRANSFER_READ),
        ResourceState::CopyDest => (L::TRANSFER_DST_OPTIMAL, S::ALL_TRANSFER, A::TRANSFER_WRITE),
        ResourceState::VertexIndex => (
            L::UNDEFINED,
            S::VERTEX_INPUT,
            A::VERTEX_ATTRIBUTE_READ | A::INDEX_READ,
        ),
        ResourceState::HostRead => (L::GENERAL, S::HOST, A::HOST_READ),
        ResourceState::Engine(layout) => (
            L::from_raw(layout),
            S::ALL_COMMANDS,
            A::MEMORY_READ | A::MEMORY_WRITE,
        ),
    }
}

/// Whether a state's access mask contains writes (a transition from it must make them available).
pub fn state_writes(state: ResourceState) -> bool {
    matches!(
        state,
        ResourceState::UnorderedAccess
            | ResourceState::RenderTarget
            | ResourceState::DepthWrite
            | ResourceState::CopyDest
            | ResourceState::Engine(_)
    )
}

/// The D3D12 UAV barrier (`D3D12_RESOURCE_BARRIER_TYPE_UAV` on all resources): orders storage writes
/// before later storage reads/writes in any shader stage.
pub fn uav_barrier() -> vk::MemoryBarrier2<'static> {
    vk::MemoryBarrier2::default()
        .src_stage_mask(SHADER_STAGES)
        .src_access_mask(vk::AccessFlags2::SHADER_STORAGE_WRITE)
        .dst_stage_mask(SHADER_STAGES)
        .dst_access_mask(
            vk::AccessFlags2::SHADER_STORAGE_READ | vk::AccessFlags2::SHADER_STORAGE_WRITE,
        )
}

/// Texel formats the RHI supports (DXGI name in the docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Format {
    /// DXGI_FORMAT_R32_UINT.
    R32Uint,
    /// DXGI_FORMAT_R32_FLOAT.
    R32Float,
    /// DXGI_FORMAT_R32G32B32A32_FLOAT.
    Rgba32Float,
    /// DXGI_FORMAT_R8G8B8A8_UNORM.
    Rgba8Unorm,
    /// DXGI_FORMAT_D32_FLOAT.
    D32Float,
    /// DXGI_FORMAT_D16_UNORM.
    D16Unorm,
    /// DXGI_FORMAT_D24_UNORM_S8_UINT's depth alone (`VK_FORMAT_X8_D24_UNORM_PACK32`).
    X8D24Unorm,
    /// DXGI_FORMAT_D24_UNORM_S8_UINT.
    D24UnormS8Uint,
    /// DXGI_FORMAT_D32_FLOAT_S8X24_UINT.
    D32FloatS8Uint,
    /// DXGI_FORMAT_R8_UNORM.
    R8Unorm,
    /// DXGI_FORMAT_R16_FLOAT.
    R16Float,
    /// DXGI_FORMAT_R16G16B16A16_FLOAT.
    Rgba16Float,
    /// DXGI_FORMAT_R10G10B10A2_UNORM (`VK_FORMAT_A2B10G10R10_UNORM_PACK32`).
    Rgb10A2Unorm,
    /// DXGI_FORMAT_R16G16_SNORM.
    Rg16Snorm,
    /// DXGI_FORMAT_R16G16_UNORM.
    Rg16Unorm,
    /// DXGI_FORMAT_R16G16_FLOAT.
    Rg16Float,
    /// DXGI_FORMAT_R32G32B32_FLOAT.
    Rgb32Float,
    /// DXGI_FORMAT_R16G16B16A16_SNORM.
    Rgba16Snorm,
    /// DXGI_FORMAT_R16G16B16A16_UNORM.
    Rgba16Unorm,
}

impl Format {
    /// The depth formats an engine's depth buffer may have, sampled through their depth aspect.
    pub const DEPTH: [Format; 5] = [
        Self::D16Unorm,
        Self::X8D24Unorm,
        Self::D24UnormS8Uint,
        Self::D32Float,
        Self::D32FloatS8Uint,
    ];

    /// The Vulkan format.
    pub fn to_vk(self) -> vk::Format {
        match self {
            Self::R32Uint => vk::Format::R32_UINT,
            Self::R32Float => vk::Format::R32_SFLOAT,
            Self::Rgba32Float => vk::Format::R32G32B32A32_SFLOAT,
            Self::Rgba8Unorm => vk::Format::R8G8B8A8_UNORM,
            Self::D32Float => vk::Format::D32_SFLOAT,
            Self::D16Unorm => vk::Format::D16_UNORM,
            Self::X8D24Unorm => vk::Format::X8_D24_UNORM_PACK32,
            Self::D24UnormS8Uint => vk::Format::D24_UNORM_S8_UINT,
            Self::D32FloatS8Uint => vk::Format::D32_SFLOAT_S8_UINT,
            Self::R8Unorm => vk::Format::R8_UNORM,
            Self::R16Float => vk::Format::R16_SFLOAT,
            Self::Rgba16Float => vk::Format::R16G16B16A16_SFLOAT,
            Self::Rgb10A2Unorm => vk::Format::A2B10G10R10_UNORM_PACK32,
            Self::Rg16Snorm => vk::Format::R16G16_SNORM,
            Self::Rg16Unorm => vk::Format::R16G16_UNORM,
            Self::Rg16Float => vk::Format::R16G16_SFLOAT,
            Self::Rgb32Float => vk::Format::R32G32B32_SFLOAT,
            Self::Rgba16Snorm => vk::Format::R16G16B16A16_SNORM,
            Self::Rgba16Unorm => vk::Format::R16G16B16A16_UNORM,
        }
    }

    /// The formats a vertex position may have in an engine's vertex buffer.
    pub const POSITION: [Format; 4] = [
        Self::Rgb32Float,
        Self::Rgba16Float,
        Self::Rgba16Snorm,
        Self::Rgba16Unorm,
    ];

    /// The position format whose raw `VkFormat` value is `raw`, if it is one of [`Format::POSITION`].
    pub fn position_from_raw_vk(raw: i32) -> Option<Format> {
        Self::POSITION.into_iter().find(|f| f.raw_vk() == raw)
    }

    /// The formats an engine's normal image may have: four channels holding xyz (and w), or two holding
    /// an octahedral encoding (an RGB10A2 image may hold either).
    pub const NORMAL: [Format; 7] = [
        Self::Rgba32Float,
        Self::Rgba16Float,
        Self::Rgb10A2Unorm,
        Self::Rgba8Unorm,
        Self::Rg16Snorm,
        Self::Rg16Unorm,
        Self::Rg16Float,
    ];

    /// The normal-image format whose raw `VkFormat` value is `raw`, if it is one of [`Format::NORMAL`].
    pub fn normal_from_raw_vk(raw: i32) -> Option<Format> {
        Self::NORMAL.into_iter().find(|f| f.raw_vk() == raw)
    }

    /// Whether the format's channels are normalized to [0, 1].
    pub fn is_unorm(self) -> bool {
        matches!(
            self,
            Self::Rgba8Unorm
                | Self::Rgb10A2Unorm
                | Self::Rg16Unorm
                | Self::R8Unorm
                | Self::D16Unorm
        )
    }

    /// Channels the format holds (of its colour aspect; 1 for depth).
    pub fn channels(self) -> u32 {
        match self {
            Self::Rgba32Float
            | Self::Rgba8Unorm
            | Self::Rgba16Float
            | Self::Rgb10A2Unorm
            | Self::Rgba16Snorm
            | Self::Rgba16Unorm => 4,
            Self::Rgb32Float => 3,
            Self::Rg16Snorm | Self::Rg16Unorm | Self::Rg16Float => 2,
            _ => 1,
        }
    }

    /// The one-channel formats a visibility image may have: written by a copy (`R32_SFLOAT`) or a
    /// converting blit.
    pub const VISIBILITY: [Format; 3] = [Self::R8Unorm, Self::R16Float, Self::R32Float];

    /// The visibility format whose raw `VkFormat` value is `raw`, if it is one of [`Format::VISIBILITY`].
    pub fn visibility_from_raw_vk(raw: i32) -> Option<Format> {
        Self::VISIBILITY.into_iter().find(|f| f.raw_vk() == raw)
    }
    /// The depth format whose raw `VkFormat` value is `raw`, if it is one of [`Format::DEPTH`].
    pub fn depth_from_raw_vk(raw: i32) -> Option<Format> {
        Self::DEPTH.into_iter().find(|f| f.raw_vk() == raw)
    }
    /// The raw `VkFormat` value (what a C ABI exchanges).
    pub fn raw_vk(self) -> i32 {
        self.to_vk().as_raw()
    }
    /// Bytes per texel (of the depth aspect, for depth formats: what a copy of it moves).
    pub fn texel_size(self) -> u32 {
        match self {
            Self::Rgba32Float => 16,
            Self::Rgb32Float => 12,
            Self::Rgba16Float | Self::Rgba16Snorm | Self::Rgba16Unorm => 8,
            Self::D16Unorm | Self::R16Float => 2,
            Self::R8Unorm => 1,
            _ => 4,
        }
    }
    /// Whether this is a depth format.
    pub fn is_depth(self) -> bool {
        Self::DEPTH.contains(&self)
    }
    /// Whether the format has a stencil aspect besides its depth.
    pub fn has_stencil(self) -> bool {
        matches!(self, Self::D24UnormS8Uint | Self::D32FloatS8Uint)
    }
    /// Every aspect of the format: what a layout transition covers.
    pub fn aspect(self) -> vk::ImageAspectFlags {
        if self.has_stencil() {
            vk::ImageAspectFlags::DEPTH | vk::ImageAspectFlags::STENCIL
        } else {
            self.view_aspect()
        }
    }
    /// The aspect a view samples and a copy moves: depth for depth formats (stencil aside), else colour.
    pub fn view_aspect(self) -> vk::ImageAspectFlags {
        if self.is_depth() {
            vk::ImageAspectFlags::DEPTH
        } else {
            vk::ImageAspectFlags::COLOR
        }
    }
    /// The largest error of a depth stored in this format, as a bound on |stored - exact| in depth units:
    /// one step of a normalized format (D16, D24). 0 for float formats, whose error is relative (2⁻²⁴ of
    /// the value, rounded to nearest).
    pub fn depth_quantum(self) -> f32 {
        match self {
            Self::D16Unorm => 1.0 / 65535.0,
            Self::X8D24Unorm | Self::D24UnormS8Uint => 1.0 / 16_777_215.0,
            _ => 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn props(
        size: f32,
        degenerate: bool,
        covered: bool,
    ) -> vk::PhysicalDeviceConservativeRasterizationPropertiesEXT<'static> {
        vk::PhysicalDeviceConservativeRasterizationPropertiesEXT::default()
            .primitive_overestimation_size(size)
            .degenerate_triangles_rasterized(degenerate)
            .fully_covered_fragment_shader_input_variable(covered)
    }

    #[test]
    fn lavapipe_without_extension_has_no_tier() {
        assert_eq!(
            conservative_raster_tier(None),
            ConservativeRasterTier::NotSupported
        );
    }

    #[test]
    fn h200_is_tier3() {
        // Measured on an NVIDIA H200: 1/512 px overestimation, degenerates rasterized, fully-covered input.
        let p = props(1.0 / 512.0, true, true);
        assert_eq!(
            conservative_raster_tier(Some(&p)),
            ConservativeRasterTier::Tier3
        );
    }

    #[test]
    fn synthetic_tiers() {
        assert_eq!(
            conservative_raster_tier(Some(&props(0.5, false, false))),
            ConservativeRasterTier::Tier1
        );
        assert_eq!(
            conservative_raster_tier(Some(&props(0.25, true, true))),
            ConservativeRasterTier::Tier1
        );
        assert_eq!(
            conservative_raster_tier(Some(&props(1.0 / 256.0, false, true))),
            ConservativeRasterTier::Tier1
        );
        assert_eq!(
            conservative_raster_tier(Some(&props(1.0 / 256.0, true, false))),
            ConservativeRasterTier::Tier2
        );
        assert_eq!(
            conservative_raster_tier(Some(&props(0.0, true, true))),
            ConservativeRasterTier::Tier3
        );
        assert_eq!(
            conservative_raster_tier(Some(&props(0.75, true, true))),
            ConservativeRasterTier::NotSupported
        );
        assert_eq!(
            conservative_raster_tier(Some(&props(f32::NAN, true, true))),
            ConservativeRasterTier::NotSupported
        );
    }

    #[test]
    fn tiers_are_ordered() {
        assert!(ConservativeRasterTier::Tier3 > ConservativeRasterTier::Tier1);
        assert!(ConservativeRasterTier::Tier1 > ConservativeRasterTier::NotSupported);
    }

    #[test]
    fn uav_state_is_general_layout_with_storage_access() {
        let (layout, stages, access) = state_scope(ResourceState::UnorderedAccess);
        assert_eq!(layout, vk::ImageLayout::GENERAL);
        assert!(stages.contains(vk::PipelineStageFlags2::COMPUTE_SHADER));
        assert!(stages.contains(vk::PipelineStageFlags2::FRAGMENT_SHADER));
        assert!(access.contains(vk::AccessFlags2::SHADER_STORAGE_WRITE));
        assert!(state_writes(ResourceState::UnorderedAccess));
        assert!(!state_writes(ResourceState::ShaderResource));
    }

    #[test]
    fn engine_state_keeps_the_raw_layout_with_full_scope() {
        let (layout, stages, access) = state_scope(ResourceState::Engine(
            vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL.as_raw(),
        ));
        assert_eq!(layout, vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL);
        assert_eq!(stages, vk::PipelineStageFlags2::ALL_COMMANDS);
        assert!(access.contains(vk::AccessFlags2::MEMORY_WRITE));
    }

    #[test]
    fn barriers_leave_out_the_geometry_stage_without_geometry_shaders() {
        let (_, stages, _) = state_scope(ResourceState::ShaderResource);
        assert!(stages.contains(vk::PipelineStageFlags2::GEOMETRY_SHADER));
        let without = enabled_stages(stages, false);
        assert!(!without.contains(vk::PipelineStageFlags2::GEOMETRY_SHADER));
        assert_eq!(
            without | vk::PipelineStageFlags2::GEOMETRY_SHADER,
            stages,
            "only the geometry stage goes"
        );
        assert_eq!(enabled_stages(stages, true), stages);
    }

    #[test]
    fn uav_barrier_orders_storage_writes() {
        let b = uav_barrier();
        assert_eq!(b.src_access_mask, vk::AccessFlags2::SHADER_STORAGE_WRITE);
        assert!(b
            .dst_access_mask
            .contains(vk::AccessFlags2::SHADER_STORAGE_READ));
    }

    #[test]
    fn formats_map() {
        assert_eq!(Format::D32Float.to_vk(), vk::Format::D32_SFLOAT);
        assert!(Format::D32Float.is_depth());
        assert_eq!(Format::Rgba32Float.texel_size(), 16);
        assert_eq!(Format::R32Uint.aspect(), vk::ImageAspectFlags::COLOR);
    }

    #[test]
    fn engine_depth_formats_map_with_their_aspects() {
        let both = vk::ImageAspectFlags::DEPTH | vk::ImageAspectFlags::STENCIL;
        for (format, vk_format, aspect, size, quantum) in [
            (
                Format::D16Unorm,
                vk::Format::D16_UNORM,
                vk::ImageAspectFlags::DEPTH,
                2,
                1.0 / 65535.0,
            ),
            (
                Format::X8D24Unorm,
                vk::Format::X8_D24_UNORM_PACK32,
                vk::ImageAspectFlags::DEPTH,
                4,
                1.0 / 16_777_215.0,
            ),
            (
                Format::D24UnormS8Uint,
                vk::Format::D24_UNORM_S8_UINT,
                both,
                4,
                1.0 / 16_777_215.0,
            ),
            (
                Format::D32Float,
                vk::Format::D32_SFLOAT,
                vk::ImageAspectFlags::DEPTH,
                4,
                0.0,
            ),
            (
                Format::D32FloatS8Uint,
                vk::Format::D32_SFLOAT_S8_UINT,
                both,
                4,
                0.0,
            ),
        ] {
            assert_eq!(format.to_vk(), vk_format);
            assert_eq!(Format::depth_from_raw_vk(vk_format.as_raw()), Some(format));
            assert!(format.is_depth());
            assert_eq!(format.aspect(), aspect, "{format:?}");
            // Sampled and copied through the depth aspect alone.
            assert_eq!(format.view_aspect(), vk::ImageAspectFlags::DEPTH);
            assert_eq!(format.texel_size(), size);
            assert_eq!(format.depth_quantum(), quantum);
        }
        assert_eq!(
            Format::depth_from_raw_vk(vk::Format::R32_SFLOAT.as_raw()),
            None
        );
        assert_eq!(
            Format::depth_from_raw_vk(vk::Format::S8_UINT.as_raw()),
            None
        );
    }
}
