//! The renderer's conventions, as a wgpu engine picks them: depth format and Z direction, how the
//! G-buffer stores normals, the index type of its meshes and the format of the shadow image.

use glam::Mat4;

/// Depth direction and far plane of the camera projection.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DepthDirection {
    /// Reversed Z with an infinite far plane (1 at the near plane, 0 at infinity).
    ReversedInfinite,
    /// Reversed Z with a finite far plane.
    ReversedFinite,
    /// Standard Z with a finite far plane (0 at the near plane, 1 at the far plane).
    ForwardFinite,
    /// Standard Z with an infinite far plane.
    ForwardInfinite,
}

impl DepthDirection {
    /// Every direction.
    pub const ALL: [Self; 4] = [
        Self::ReversedInfinite,
        Self::ReversedFinite,
        Self::ForwardFinite,
        Self::ForwardInfinite,
    ];

    /// Whether nearer is greater.
    pub fn reversed(self) -> bool {
        matches!(self, Self::ReversedInfinite | Self::ReversedFinite)
    }

    /// wgpu's view-to-clip matrix (clip y up, depth 0..1) for a vertical field of view `fov_y`, `aspect`,
    /// and `near`/`far` planes (`far` ignored by infinite projections).
    pub fn projection(self, fov_y: f32, aspect: f32, near: f32, far: f32) -> Mat4 {
        match self {
            Self::ReversedInfinite => Mat4::perspective_infinite_reverse_rh(fov_y, aspect, near),
            Self::ReversedFinite => Mat4::perspective_rh(fov_y, aspect, far, near),
            Self::ForwardFinite => Mat4::perspective_rh(fov_y, aspect, near, far),
            Self::ForwardInfinite => Mat4::perspective_infinite_rh(fov_y, aspect, near),
        }
    }

    /// The depth the clear writes: the farthest value.
    pub fn clear_depth(self) -> f32 {
        if self.reversed() {
            0.0
        } else {
            1.0
        }
    }

    /// The depth test that keeps the nearest surface.
    pub fn compare(self) -> wgpu::CompareFunction {
        if self.reversed() {
            wgpu::CompareFunction::Greater
        } else {
            wgpu::CompareFunction::Less
        }
    }
}

/// How the G-buffer stores the surface normal.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NormalTarget {
    /// View-space normal, octahedral, in an `Rg16Float` target.
    OctahedralRg16Float,
    /// View-space normal, octahedral, in an `Rgb10a2Unorm` target (channels map [0, 1] to [-1, 1]).
    OctahedralRgb10a2,
    /// View-space normal, xyz in an `Rgb10a2Unorm` target (channels map [0, 1] to [-1, 1]).
    XyzRgb10a2,
    /// World-space normal, xyz in an `Rgba16Float` target.
    WorldXyzRgba16Float,
}

impl NormalTarget {
    /// Every encoding.
    pub const ALL: [Self; 4] = [
        Self::OctahedralRg16Float,
        Self::OctahedralRgb10a2,
        Self::XyzRgb10a2,
        Self::WorldXyzRgba16Float,
    ];

    /// The target's format.
    pub fn format(self) -> wgpu::TextureFormat {
        match self {
            Self::OctahedralRg16Float => wgpu::TextureFormat::Rg16Float,
            Self::OctahedralRgb10a2 | Self::XyzRgb10a2 => wgpu::TextureFormat::Rgb10a2Unorm,
            Self::WorldXyzRgba16Float => wgpu::TextureFormat::Rgba16Float,
        }
    }

    /// Whether the normal is octahedral (else xyz).
    pub fn octahedral(self) -> bool {
        matches!(self, Self::OctahedralRg16Float | Self::OctahedralRgb10a2)
    }

    /// Whether the channels are unorm (mapped from [-1, 1] to [0, 1]).
    pub fn unorm(self) -> bool {
        matches!(self, Self::OctahedralRgb10a2 | Self::XyzRgb10a2)
    }

    /// Whether the normal is in view space (else world space).
    pub fn view_space(self) -> bool {
        !matches!(self, Self::WorldXyzRgba16Float)
    }

    /// The shaders' code: bit 0 octahedral, bit 1 unorm, bit 2 view space.
    pub fn code(self) -> u32 {
        u32::from(self.octahedral())
            | u32::from(self.unorm()) << 1
            | u32::from(self.view_space()) << 2
    }
}

/// Index type of the renderer's meshes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IndexType {
    /// 16-bit indices (meshes are split to at most 65,536 vertices).
    U16,
    /// 32-bit indices.
    U32,
}

/// All conventions of one renderer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Conventions {
    /// Depth format of the G-buffer.
    pub depth_format: wgpu::TextureFormat,
    /// Z direction and far plane.
    pub depth: DepthDirection,
    /// Normal target.
    pub normals: NormalTarget,
    /// Index type of the meshes.
    pub index: IndexType,
    /// Format of the shadow image the plugin writes.
    pub shadow_format: wgpu::TextureFormat,
    /// A linear view-Z target (`R32Float` or `R16Float`) the G-buffer also writes and the plugin reads
    /// instead of the depth buffer, or none.
    pub view_z: Option<wgpu::TextureFormat>,
}

impl Default for Conventions {
    /// A typical wgpu renderer: the depth format wgpu picks for `Depth24Plus`, reversed infinite Z,
    /// octahedral view-space normals in `Rg16Float`, 16-bit indices, an 8-bit shadow image, no view Z.
    fn default() -> Self {
        Self {
            depth_format: wgpu::TextureFormat::Depth24Plus,
            depth: DepthDirection::ReversedInfinite,
            normals: NormalTarget::OctahedralRg16Float,
            index: IndexType::U16,
            shadow_format: wgpu::TextureFormat::R8Unorm,
            view_z: None,
        }
    }
}
